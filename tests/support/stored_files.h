// What tests of stored files share: the committed fixtures of earlier encoders, a file's
// bytes, the input as a lossless decode gives it (positions on the file's grid) and the
// descriptor of a file's wedge texture coordinate.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "attributes/attribute_section.h"
#include "format/file_format.h"
#include "lossless/seam_cut.h"
#include "pomar/pomar.h"

namespace pomar::test {

#ifdef POMAR_SOURCE_DIR
/// Files written by earlier encoders (tests/data/legacy/README.md).
inline const std::filesystem::path kLegacyDir =
    std::filesystem::path(POMAR_SOURCE_DIR) / "tests" / "data" / "legacy";
#endif

inline std::vector<uint8_t> read_bytes(const std::filesystem::path &p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

/// The input with every position on the file's grid (what a lossless decode gives).
inline Mesh on_grid(Mesh m, const Quantizer &grid) {
  for (size_t i = 0; i < m.vertex_count(); ++i)
    for (int k = 0; k < 3; ++k)
      m.positions[3 * i + k] = grid.dequantize(k, grid.quantize(k, m.positions[3 * i + k]));
  return m;
}

/// The descriptor of a file's wedge texture coordinate (its ATTR section).
inline StoredAttribute wedge_descriptor(const std::vector<uint8_t> &file) {
  const FileLayout layout = read_layout(file.data(), file.size(), file.size());
  const std::unique_ptr<AttributeTable> table = load_attribute_table(file.data(), layout);
  if (table)
    for (const StoredAttribute &s : table->stored)
      if (s.name == kWedgeTexcoord)
        return s;
  ADD_FAILURE() << "the file has no wedge texture coordinate";
  return StoredAttribute();
}

} // namespace pomar::test
