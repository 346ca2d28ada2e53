// The ATTR section (format version 4): per-vertex attributes of the full-resolution mesh.
//
// Every vertex has an attribute index that names it the same way in every decode:
//   progressive files and vertices of the base clustered mesh: its vertex id (global levels
//   number vertices identically in every decode);
//   vertices of clustered levels: clusters + start[cluster] + local - 1, (cluster, local)
//   being its lineage name (refine/level_traversal.h) and start[] the prefix sums of the
//   per-cluster counts stored in the section.
// Each attribute's integer codes (attribute_quantize.h) are predicted from the vertex's
// parent (the v_to it was split from; base vertices: the previous base vertex) and the
// residuals range-coded in attribute-index order, one stream per attribute, with adaptive
// models per code component. A decoder decodes the residuals once, then rebuilds the codes
// of exactly the vertices it holds, parents first (vertex ids grow with creation).
//
// NOT progressive by region: every decode reads and entropy-decodes the whole section
// (it belongs to the global part); see docs/format.md.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "attributes/attribute_quantize.h"
#include "format/file_format.h"
#include "pomar/pomar.h"

namespace pomar {

struct LevelMesh;

constexpr uint32_t kAttributeSectionTag = section_tag("ATTR"); // optional (flags 0)
constexpr uint8_t kAttributeSectionVersion = 1;

/// The section of `mesh`'s attributes (empty vector: nothing to store). `lm` is the encoder's
/// fully refined mesh in decoder numbering, `decoded_to_input[v]` the input vertex of its
/// vertex v, `clusters` the vertex count of the base clustered mesh (0: progressive file).
/// `bytes` (optional) gets the stream size of each stored attribute.
std::vector<uint8_t> write_attributes(const Mesh &mesh, const AttributeOptions &options,
                                      const LevelMesh &lm,
                                      const std::vector<uint32_t> &decoded_to_input,
                                      uint32_t clusters);

/// A parsed section: descriptors, and (if decoded) the residuals of every vertex.
struct AttributeTable {
  std::vector<StoredAttribute> stored;
  std::vector<uint64_t> stream_bytes;
  std::vector<std::string> texture_files;
  uint32_t vertices = 0, clusters = 0;
  std::vector<uint32_t> cluster_start; // clusters + 1 prefix sums (clustered files)
  std::vector<std::vector<int64_t>> residuals; // per attribute: codes() per attribute index
  bool decoded = false;
};

/// Parse the section body (bounds-checked; errors say "damaged .pomar file: ATTR ...").
/// With `decode`, entropy-decode the residuals of the attributes `mask` keeps (the
/// others are dropped from the table). `vertices`/`clusters` from the file header.
AttributeTable read_attributes(const uint8_t *data, size_t size, uint32_t vertices,
                               uint32_t clusters, bool decode, const AttributeMask &mask = {});

/// Add the decoded attributes of every vertex of `lm` to `out` (and the texture files).
void attach_attributes(const AttributeTable &table, const LevelMesh &lm, Mesh &out);

/// The file's attribute summary for FileInfo.
void describe_attributes(const AttributeTable &table, FileInfo &info);

/// The table of the file's ATTR section (checksum checked), or nullptr if it has none or
/// `mask` keeps nothing; `decode` as for read_attributes. `data` = the file's global part.
std::unique_ptr<AttributeTable> load_attribute_table(const uint8_t *data, const FileLayout &layout,
                                                     bool decode, const AttributeMask &mask = {});

} // namespace pomar
