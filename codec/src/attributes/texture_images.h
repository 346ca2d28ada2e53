// Embedded texture images: the optional "TEXI" section (docs/format.md, "TEXI section"): the
// bytes of the image files a mesh's texture file names refer to, kept bit for bit.
#pragma once

#include <cstdint>
#include <vector>

#include "format/file_format.h"
#include "pomar/pomar.h"

namespace pomar {

struct AttributeTable;

constexpr uint32_t kTextureImagesTag = section_tag("TEXI"); // optional (flags 0)
constexpr uint8_t kTextureImagesVersion = 1;

/// Whether the mesh has an image to embed (a non-empty texture_images entry).
bool has_texture_images(const Mesh &mesh);
/// The section body of the mesh's images (throws pomar::Error (InvalidMesh) if there are
/// more images than texture files).
std::vector<uint8_t> write_texture_images(const Mesh &mesh);
/// Per texture file (`textures` of them), its image bytes (empty: not embedded), from the
/// file's TEXI section (checksum checked); empty if the file has none.
std::vector<std::vector<uint8_t>> load_texture_images(const uint8_t *data, const FileLayout &layout,
                                                      size_t textures);
/// Per texture file, its image's size (0: not embedded), from the section (for inspect()).
std::vector<uint64_t> texture_image_sizes(const uint8_t *data, const FileLayout &layout,
                                          size_t textures);

/// A decode's last attribute step: `out` gets the file's embedded images when the file has
/// attributes (`attributes`, nullptr: none) and `mask` keeps texture coordinates.
void attach_texture_images(const uint8_t *data, const FileLayout &layout,
                           const AttributeTable *attributes, const AttributeMask &mask, Mesh &out);

} // namespace pomar
