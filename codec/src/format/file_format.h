// The .pomar container, version 1 (byte layout: docs/format.md).
//   header (fixed part + level table + checksum) | base mesh block | level blocks
// Every block carries an XXH32 checksum so damage is reported, never mis-decoded.
#pragma once

#include <cstdint>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

constexpr uint8_t kMagic[8] = {'P', 'O', 'M', 'A', 'R', '\r', '\n', 0x1A};
constexpr uint16_t kFormatVersion = 1;           // pure progressive files
constexpr uint16_t kClusteredFormatVersion = 3;  // files with clustered levels
constexpr uint16_t kClusteredFormatVersion2 = 2; // read only: no cluster data checksum
constexpr uint16_t kSectionsFormatVersion = 4;  // files with a section table
constexpr uint16_t kFlagClustered = 1;
constexpr uint16_t kFlagSections = 2;
constexpr size_t kSectionEntryBytes = 20;
constexpr uint32_t kMaxSections = 64;
constexpr size_t kClusterHeaderBytes = 40;
constexpr size_t kFixedHeaderBytes = 60;
constexpr size_t kLevelEntryBytes = 20;
constexpr uint32_t kMaxLevels = 4096;

struct LevelEntry {
  uint32_t vertices = 0, faces = 0; // after this level
  uint32_t connectivity_bytes = 0, geometry_bytes = 0;
  uint32_t checksum = 0; // XXH32 of the level's bytes (connectivity then geometry)
};

/// A section tag from its 4 ASCII characters ("LSLS" -> bytes 'L','S','L','S' in the file).
constexpr uint32_t section_tag(const char (&s)[5]) {
  return uint32_t(uint8_t(s[0])) | uint32_t(uint8_t(s[1])) << 8 | uint32_t(uint8_t(s[2])) << 16 |
         uint32_t(uint8_t(s[3])) << 24;
}
constexpr uint32_t kLosslessTag = section_tag("LSLS"); ///< the lossless record (issue 13)

/// A global section of a version 4 file (its body follows the base mesh block).
struct Section {
  uint32_t tag = 0;
  std::vector<uint8_t> body;
};

/// A section as the header's table describes it.
struct SectionEntry {
  uint32_t tag = 0, flags = 0;
  uint64_t offset = 0; // absolute file offset of the body (layout only)
  uint64_t bytes = 0;
  uint32_t checksum = 0;
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
  std::vector<SectionEntry> sections; // version 4 (flags & kFlagSections)
  bool clustered() const { return (flags & kFlagClustered) != 0; }
};

/// Where each cluster's block is, and its 8-bit check (low byte of its XXH32).
struct ClusterIndex {
  std::vector<uint64_t> offset; // absolute file offsets
  std::vector<uint32_t> size;
  std::vector<uint8_t> check;
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
  std::vector<SectionEntry> sections; // with their offsets
  std::vector<size_t> level_offset; // start of each global level's connectivity bytes
  size_t tables_offset = 0, index_offset = 0, clusters_offset = 0;
  size_t global_bytes = 0; // everything before the first cluster block
  uint64_t file_size = 0;  // bytes actually present (less than announced if truncated)
};

uint32_t checksum(const uint8_t *data, size_t size);
/// A cluster block against its 8-bit check from the index (the low byte of its XXH32).
inline bool passes_block_check(const uint8_t *block, size_t size, uint8_t check) {
  return (checksum(block, size) & 0xFF) == check;
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
                                const std::vector<Section> &sections = {});

/// Bytes a header needs before it can be parsed: at least the fixed part; then
/// header_size() tells the full size.
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
/// Check the base block's checksum and unpack it.
BaseMesh read_base_mesh(const uint8_t *data, const FileLayout &layout);
/// Throw if level `i` is missing (truncated file) or its checksum does not match.
void check_level(const uint8_t *data, const FileLayout &layout, size_t i);
/// Check a global block's checksum (tables or index); `what` names it in the error.
void check_block(const uint8_t *data, size_t size, uint32_t expected, const char *what);

FileInfo file_info(const FileLayout &layout, uint64_t file_size);

} // namespace pomar
