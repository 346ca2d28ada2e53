// The .pomar container, version 1 (byte layout: docs/format.md).
//   header (fixed part + level table + checksum) | base mesh block | level blocks
// Every block carries an XXH32 checksum so damage is reported, never mis-decoded.
#pragma once

#include <cstdint>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

constexpr uint8_t kMagic[8] = {'P', 'O', 'M', 'A', 'R', '\r', '\n', 0x1A};
constexpr uint16_t kFormatVersion = 1;
constexpr size_t kFixedHeaderBytes = 60;
constexpr size_t kLevelEntryBytes = 20;
constexpr uint32_t kMaxLevels = 4096;

struct LevelEntry {
  uint32_t vertices = 0, faces = 0; // after this level
  uint32_t connectivity_bytes = 0, geometry_bytes = 0;
  uint32_t checksum = 0; // XXH32 of the level's bytes (connectivity then geometry)
};

struct FileHeader {
  uint16_t version = kFormatVersion;
  uint16_t flags = 0;
  Quantizer grid;
  uint32_t vertices = 0, faces = 0;
  uint32_t base_vertices = 0, base_faces = 0;
  uint32_t base_bytes = 0, base_checksum = 0;
  std::vector<LevelEntry> levels;
};

/// The base mesh: quantized positions and triangles, stored bit-packed, uncompressed.
struct BaseMesh {
  std::vector<int32_t> q;
  std::vector<uint32_t> triangles;
};

/// Where the pieces of a parsed file are.
struct FileLayout {
  FileHeader header;
  size_t header_bytes = 0;
  size_t base_offset = 0;
  std::vector<size_t> level_offset; // start of each level's connectivity bytes
};

uint32_t checksum(const uint8_t *data, size_t size);

std::vector<uint8_t> pack_base_mesh(const BaseMesh &base, int bits);
/// Assemble a complete file image. `header.levels` must describe `level_blocks`.
std::vector<uint8_t> write_file(FileHeader header, const std::vector<uint8_t> &base_block,
                                const std::vector<std::vector<uint8_t>> &level_blocks);

/// Parse and check the header (magic, version, checksum, sizes against the file size).
FileLayout read_layout(const uint8_t *data, size_t size);
/// Check the base block's checksum and unpack it.
BaseMesh read_base_mesh(const uint8_t *data, const FileLayout &layout);
/// Throw if level `i`'s checksum does not match.
void check_level(const uint8_t *data, const FileLayout &layout, size_t i);

FileInfo file_info(const FileLayout &layout, size_t file_size);

} // namespace pomar
