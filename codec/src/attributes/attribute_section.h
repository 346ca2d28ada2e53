// Per-vertex attributes in the bitstream (format version 4 on).
//
// Each vertex's attributes are integer codes (attribute_quantize.h). The codes of the base
// mesh vertices are stored in the "ATTR" section, with the descriptors of the attributes;
// every other vertex's codes are coded where its position is, in the level streams and
// cluster blocks (refine/level_traversal.h code_vertex -> Codec::attributes): predicted by
// the codes of v_to (the vertex it is split from) and the residuals range-coded with one
// model set per code (adaptive in global levels, frozen per level in clustered levels, as
// the geometry). So every decode (any level, any selection, incremental) holds exactly the
// attributes of the vertices it decoded, and reads only the blocks it decodes.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "attributes/attribute_quantize.h"
#include "entropy/models.h"
#include "format/file_format.h"
#include "pomar/pomar.h"

namespace pomar {

struct LevelMesh;

constexpr uint32_t kAttributeSectionTag = section_tag("ATTR"); // optional (flags 0)
constexpr uint8_t kAttributeSectionVersion = 1;
/// The version whose descriptors have a flags byte (written only when a flag is set).
constexpr uint8_t kAttributeSectionFlagsVersion = 2;
/// The version whose descriptors may also have the positions flag (the wedge texture
/// coordinate predicted from the positions; written only when it is set).
constexpr uint8_t kAttributeSectionPositionsVersion = 3;
/// The version whose wedge texture coordinate may say per level whether it is predicted from
/// the positions (the "level positions" flag; written only when a level does).
constexpr uint8_t kAttributeSectionLevelsVersion = 4;

/// The attributes of a file: descriptors, texture files and the codes of the base mesh.
struct AttributeTable {
  std::vector<StoredAttribute> stored;
  std::vector<uint64_t> estimated_bytes; // per attribute, in the whole file (informative)
  std::vector<std::string> texture_files;
  uint32_t codes = 0;             // integer codes per vertex (all attributes)
  std::vector<int64_t> base;      // codes of the base mesh vertices
  uint64_t base_stream_bytes = 0; // the section's coded base codes
  /// The seam cut's wedge texture coordinate (files with a MATL section): its first code
  /// (-1: none). Its base codes are predicted from the base mesh's connectivity
  /// (predict_wedge_base): the encoder keeps their residuals in `wedge_residuals` (2 a
  /// vertex); a table read from a file holds the residuals in `base` until init_attributes
  /// resolves them (`wedge_pending`).
  int wedge_uv = -1;
  std::vector<int64_t> wedge_residuals;
  bool wedge_pending = false;
};

/// The encoder's side, once `table.base` holds the base mesh's codes and `base` is the base
/// mesh: the residuals of the wedge texture coordinates (table.wedge_residuals), predicted
/// from the positions if that codes smaller than the neighbours' mean (else the
/// descriptor's base_from_positions is cleared).
void plan_wedge_residuals(AttributeTable &table, const LevelMesh &base);

/// The encoder's side: what is kept of `mesh`'s attributes and how (empty table: nothing).
/// Throws pomar::Error if they need more than kMaxAttributeCodes codes per vertex. The seam
/// cut's wedge texture coordinate, if quantized, is predicted in the base mesh from the
/// positions or by its neighbours' mean, whichever codes smaller (plan_wedge_residuals); in
/// the levels as the encoder chooses level by level (set_wedge_levels).
AttributeTable plan_attributes(const Mesh &mesh, const AttributeOptions &options);
/// Whether the table has a quantized wedge texture coordinate (whose predictor the encoder
/// chooses), and whether its base mesh codes are predicted from the positions.
bool has_wedge_grid(const AttributeTable &table);
bool base_wedge_from_positions(const AttributeTable &table);
/// The encoder's side, after the levels: which refinement levels predicted the wedge
/// texture coordinate from the positions (`positions[l]` for level l; index 0 unused): the
/// descriptor's positions flag when all did, its level mask when some did.
void set_wedge_levels(AttributeTable &table, const std::vector<uint8_t> &positions);
/// Codes of every vertex, in the order of `to_input` (to_input[i] = the mesh's vertex).
std::vector<int64_t> attribute_codes(const Mesh &mesh, const AttributeTable &table,
                                     const AttributeOptions &options,
                                     const std::vector<uint32_t> &to_input);
/// The models of the attribute codes (Models::attr) for a table.
std::vector<AttributeCodeModels> attribute_models(const AttributeTable &table);
/// Whether `mask` keeps any attribute of the table.
bool keeps_any(const AttributeTable &table, const AttributeMask &mask);
/// Give `lm` (the base mesh) its attribute codes and ranges from the table. A decoder whose
/// `mask` keeps none of the attributes only reads past their codes (LevelMesh::attr_skipped):
/// the residuals are interleaved with the positions in the same range-coded streams and
/// their models' contexts depend on the residuals alone, so they are decoded as symbols,
/// without prediction, range checks or storage.
void init_attributes(const AttributeTable &table, LevelMesh &lm,
                     const AttributeMask &mask = AttributeMask());

/// The ATTR section body of `table` for a base mesh of `base_vertices` vertices (table.base
/// holds their codes: base_vertices * table.codes values).
std::vector<uint8_t> write_attributes(const AttributeTable &table, uint32_t base_vertices);
/// Parse a section body (bounds-checked; "damaged .pomar file: ATTR section ..." errors).
/// `keep_base` false checks the base mesh's codes without storing them (table.base stays
/// empty: inspection, memory independent of the counts).
AttributeTable read_attributes(const uint8_t *data, size_t size, uint32_t base_vertices,
                               bool keep_base = true);
/// The table of the file's ATTR section (checksum checked), or nullptr if it has none.
std::unique_ptr<AttributeTable> load_attribute_table(const uint8_t *data, const FileLayout &layout,
                                                     bool keep_base = true);

/// Add the attributes `mask` keeps of every vertex of `out` (made from `lm` by to_mesh) to `out`
/// (and the texture files): the codes come from `lm`.
void attach_attributes(const AttributeTable &table, const LevelMesh &lm, const AttributeMask &mask,
                       Mesh &out);

/// The file's attribute summary for FileInfo; `bytes` per attribute from the encoder's
/// ideal code lengths of its residuals in the whole file (0 if unknown).
void describe_attributes(const AttributeTable &table, FileInfo &info);

} // namespace pomar
