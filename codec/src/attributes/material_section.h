// Per-corner texture coordinates and face materials in the bitstream: the required "MATL"
// section. Its presence says that the file's ATTR section carries the seam cut's wedge
// attributes (lossless/seam_cut.h), which a reader must turn back into corners; it holds
// the materials (name, texture, MTL properties). Byte layout: docs/format.md, "MATL section".
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "format/file_format.h"
#include "pomar/pomar.h"

namespace pomar {

constexpr uint32_t kMaterialSectionTag = section_tag("MATL"); // required (kSectionRequired)
constexpr uint8_t kMaterialSectionVersion = 1;

struct MaterialTable {
  bool corner_texcoords = false; ///< the ATTR section has the wedge texture coordinates
  bool face_materials = false;   ///< the ATTR section has the wedge materials
  std::vector<Material> materials;
};

/// The MATL section body.
std::vector<uint8_t> write_materials(const MaterialTable &table);
/// Parse a section body (bounds-checked; "damaged .pomar file: MATL section ..." errors).
/// `textures`: the file's texture file count (a material's texture must be one of them).
MaterialTable read_materials(const uint8_t *data, size_t size, size_t textures);
/// The table of the file's MATL section (checksum checked), or nullptr if it has none.
std::unique_ptr<MaterialTable> load_material_table(const uint8_t *data, const FileLayout &layout,
                                                   size_t textures);

/// A decoded mesh (its attributes attached): the materials, and the wedge attributes turned
/// into per-corner texture coordinates and face materials (lossless/seam_cut.h).
void attach_materials(const MaterialTable &table, const AttributeMask &mask, Mesh &out);

} // namespace pomar
