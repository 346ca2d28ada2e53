// The .pomar container, versions 1 to 5 (byte layout: docs/format.md).
//   header (fixed part + level table [+ cluster header] [+ section table] + checksum)
//   | base mesh block | [section bodies] | global level blocks | [tables | index | cluster blocks]
// Every block carries an XXH32 checksum so damage is reported, never mis-decoded.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

constexpr uint8_t kMagic[8] = {'P', 'O', 'M', 'A', 'R', '\r', '\n', 0x1A};
constexpr uint16_t kFormatVersion = 1;           // pure progressive files
constexpr uint16_t kClusteredFormatVersion = 3;  // files with clustered levels
constexpr uint16_t kClusteredFormatVersion2 = 2; // read only: no cluster data checksum
/// Files carrying sections (what version 1/3 cannot hold: lossless record, attributes).
/// Progressive or clustered (kFlagClustered); files without sections stay version 1 or 3.
constexpr uint16_t kSectionsFormatVersion = 4;
/// What the encoder writes: version 4's container (the section table always present), the
/// patch of every split coded as s_l + s_r and a placement rank (refine/patch_rank.h).
constexpr uint16_t kPatchRankFormatVersion = 5;
constexpr uint16_t kFlagClustered = 1;
constexpr uint16_t kFlagSections = 2; // set exactly in versions 4 and 5: a section table
constexpr size_t kSectionEntryBytes = 20;
constexpr uint32_t kMaxSections = 64;
/// Section flag: a reader that does not know the section's tag must refuse the file
/// (otherwise it may ignore the section).
constexpr uint32_t kSectionRequired = 1;
constexpr size_t kClusterHeaderBytes = 40;
constexpr size_t kFixedHeaderBytes = 60;
constexpr size_t kLevelEntryBytes = 20;
constexpr uint32_t kMaxLevels = 4096;

struct LevelEntry {
  uint32_t vertices = 0, faces = 0; // after this level
  uint32_t connectivity_bytes = 0, geometry_bytes = 0;
  uint32_t checksum = 0; // XXH32 of the level's bytes (connectivity then geometry)
};

/// A section's four ASCII bytes as the little-endian u32 the table stores.
constexpr uint32_t section_tag(const char (&name)[5]) {
  return uint32_t(uint8_t(name[0])) | uint32_t(uint8_t(name[1])) << 8 |
         uint32_t(uint8_t(name[2])) << 16 | uint32_t(uint8_t(name[3])) << 24;
}
std::string section_name(uint32_t tag); // "LSLS", or the bytes in hex if not printable
/// The lossless record (codec/src/lossless/): required.
constexpr uint32_t kLosslessTag = section_tag("LSLS");

/// A section of the global part as a writer hands it over.
struct Section {
  uint32_t tag = 0;
  uint32_t flags = 0; // kSectionRequired
  std::vector<uint8_t> body;
};

/// A section table entry (version 4).
struct SectionEntry {
  uint32_t tag = 0, flags = 0;
  uint64_t bytes = 0;
  uint32_t checksum = 0; // XXH32 (seed 0) of the body
};

struct FileHeader {
  uint16_t version = kFormatVersion;
  uint16_t flags = 0;
  Quantizer grid;
  uint32_t vertices = 0, faces = 0;
  uint32_t base_vertices = 0, base_faces = 0;
  uint32_t base_bytes = 0, base_checksum = 0;
  std::vector<LevelEntry> levels;
  // Clustered files (flags & kFlagClustered): levels 1..global_levels are global, the
  // others live in one block per cluster; the base clustered mesh is the mesh after the
  // global levels and each of its vertices is a cluster.
  uint32_t global_levels = 0, clusters = 0;
  uint32_t tables_bytes = 0, tables_checksum = 0;
  uint32_t index_bytes = 0, index_checksum = 0;
  uint64_t cluster_bytes = 0; // all cluster blocks together
  // The encoder's split of cluster_bytes into connectivity and geometry (from the ideal
  // code lengths; the blocks interleave both). Informative only.
  uint64_t cluster_connectivity_bytes = 0;
  // Version 3: XXH32 of all cluster blocks in order (a full decode checks it; the blocks'
  // own 8-bit checks let 1 damaged block in 256 through).
  bool has_cluster_checksum = false;
  uint32_t cluster_checksum = 0;
  // Version 4: the section table (bodies follow the base mesh block, in this order).
  std::vector<SectionEntry> sections;
  bool clustered() const { return (flags & kFlagClustered) != 0; }
  /// Version 5: the level streams code each patch as s_l + s_r and a placement rank.
  bool ranks_patches() const { return version >= kPatchRankFormatVersion; }
};

/// Where each cluster's block is, and its check: the low byte of its XXH32 from the index,
/// 16 or 32 bits once a BCHK section completes it (format/block_checks.h); `check_mask` says
/// which bits hold.
struct ClusterIndex {
  std::vector<uint64_t> offset; // absolute file offsets
  std::vector<uint32_t> size;
  std::vector<uint32_t> check;
  uint32_t check_mask = 0xFF;
};

/// The base mesh: quantized positions and triangles (range coded, see pack_base_mesh).
struct BaseMesh {
  std::vector<int32_t> q;
  std::vector<uint32_t> triangles;
};

/// Where the pieces of a parsed file are.
struct FileLayout {
  FileHeader header;
  size_t header_bytes = 0;
  size_t base_offset = 0;
  std::vector<size_t> section_offset; // start of each section's body
  std::vector<size_t> level_offset;   // start of each global level's connectivity bytes
  size_t tables_offset = 0, index_offset = 0, clusters_offset = 0;
  size_t global_bytes = 0; // everything before the first cluster block
  uint64_t file_size = 0;  // bytes actually present (less than announced if truncated)
};

uint32_t checksum(const uint8_t *data, size_t size);
/// A cluster block against its check: the bits of `mask` of its XXH32 (the index's low
/// byte, or 16 or 32 bits with a BCHK section).
inline bool passes_block_check(const uint8_t *block, size_t size, uint32_t check,
                               uint32_t mask = 0xFF) {
  return ((checksum(block, size) ^ check) & mask) == 0;
}
/// XXH32 (seed 0) of the concatenation of `blocks`, as checksum() of the whole would give.
uint32_t checksum(const std::vector<const std::vector<uint8_t> *> &blocks);

/// Rotate every face to start at its smallest index and sort the faces (the order the
/// base mesh block stores them in).
void canonical_faces(std::vector<uint32_t> &triangles);
std::vector<uint8_t> pack_base_mesh(const BaseMesh &base, int bits);
/// Assemble a complete file image. `header.levels` must describe `level_blocks` (the
/// global levels); a clustered file also gets its tables, index and cluster blocks.
std::vector<uint8_t> write_file(FileHeader header, const std::vector<uint8_t> &base_block,
                                const std::vector<std::vector<uint8_t>> &level_blocks,
                                const std::vector<uint8_t> &tables = {},
                                const std::vector<std::vector<uint8_t>> &cluster_blocks = {},
                                const std::vector<Section> &sections = {},
                                const std::vector<uint32_t> *block_order = nullptr);
/// The same file with `sections` added (replacing any of the same tags): version 4 (the
/// input may be version 1, 3 or 4) or 5 (a version 5 input). Stages that run after encode() (e.g.
/// the lossless record, which needs the decoder's numbering) attach their data this way.
std::vector<uint8_t> with_sections(const uint8_t *file, size_t size,
                                   const std::vector<Section> &sections);

/// Bytes of the header needed to know more: with fewer than the fixed part, the fixed part;
/// in version 4, up to the section count until it is present; then the whole header. A
/// reader reads that many bytes and asks again until header_size(data, size) <= size.
size_t header_size(const uint8_t *data, size_t size);

/// Parse and check the header (magic, version, checksum, sizes against `file_size`).
/// `data` must hold at least the header; `file_size` is the size of the whole file.
/// `allow_truncated` accepts a file that ends early as long as the part nothing can be
/// decoded without is there (header and base mesh; clustered files: the whole global
/// part); the blocks past the end are then reported missing when they are needed.
FileLayout read_layout(const uint8_t *data, size_t size, uint64_t file_size = 0,
                       bool allow_truncated = false);
/// Decode the cluster index block (`data` = the whole index block).
ClusterIndex read_cluster_index(const uint8_t *data, const FileLayout &layout);
/// The cluster index block of `index`'s sizes and checks (its offsets are not stored: each
/// block follows the one before it).
std::vector<uint8_t> pack_cluster_index(const ClusterIndex &index);
/// Check the base block's checksum and unpack it; `keep` false checks it without storing
/// anything (inspection: memory independent of the counts).
BaseMesh read_base_mesh(const uint8_t *data, const FileLayout &layout, bool keep = true);
/// Throw if level `i` is missing (truncated file) or its checksum does not match.
void check_level(const uint8_t *data, const FileLayout &layout, size_t i);
/// The index of the section with `tag`, or -1.
int find_section(const FileLayout &layout, uint32_t tag);
/// Section `i`'s body after checking its checksum (throws a damaged-file error naming it).
/// `data` holds the global part.
const uint8_t *section_body(const uint8_t *data, const FileLayout &layout, size_t i);
/// The tags of the sections this build's decoders honour.
const std::vector<uint32_t> &known_sections();
/// Throw if the file has a required section whose tag is not in `known` (a newer writer's
/// data this build cannot honour).
void require_known_sections(const FileLayout &layout,
                            const std::vector<uint32_t> &known = known_sections());
/// Check a global block's checksum (tables or index); `what` names it in the error.
void check_block(const uint8_t *data, size_t size, uint32_t expected, const char *what);

FileInfo file_info(const FileLayout &layout, uint64_t file_size);

} // namespace pomar
