// The TEXI section: embedded texture images (byte layout: docs/format.md).
#include "attributes/texture_images.h"

#include <string>

#include "attributes/attribute_section.h"
#include "format/bit_io.h"

namespace pomar {
namespace {

[[noreturn]] void damaged(const std::string &what) {
  throw Error(Error::Kind::DamagedFile, "damaged .pomar file: TEXI section: " + what);
}

/// Walk the section: `each(texture, offset, bytes)` per image, every field checked.
template <class Each> void walk(const uint8_t *data, size_t size, size_t textures, Each &&each) {
  ByteReader r(data, size, "damaged .pomar file: TEXI section");
  const uint8_t version = r.u8();
  if (version != kTextureImagesVersion)
    throw Error(Error::Kind::Unsupported, "TEXI section version " + std::to_string(version) +
                                              " is not supported (this pomar reads version 1)");
  const uint32_t count = r.u16();
  std::vector<uint8_t> seen(textures, 0);
  for (uint32_t i = 0; i < count; ++i) {
    const uint32_t texture = r.u16();
    const uint32_t bytes = r.u32();
    if (texture >= textures)
      damaged("image " + std::to_string(i) + " is of texture " + std::to_string(texture) +
              "; the file names " + std::to_string(textures) + " texture files");
    if (seen[texture]++)
      damaged("texture " + std::to_string(texture) + " has two images");
    if (bytes > size - r.position())
      damaged("image " + std::to_string(i) + " runs past the section");
    each(texture, r.position(), bytes);
    r.skip(bytes);
  }
  if (r.position() != size)
    damaged("it has " + std::to_string(size - r.position()) + " bytes past its images");
}

const uint8_t *body(const uint8_t *data, const FileLayout &layout, uint64_t &size) {
  const int i = find_section(layout, kTextureImagesTag);
  if (i < 0)
    return nullptr;
  size = layout.header.sections[size_t(i)].bytes;
  return section_body(data, layout, size_t(i)); // checks its XXH32
}

} // namespace

bool has_texture_images(const Mesh &mesh) {
  for (const std::vector<uint8_t> &image : mesh.texture_images)
    if (!image.empty())
      return true;
  return false;
}

std::vector<uint8_t> write_texture_images(const Mesh &mesh) {
  if (mesh.texture_images.size() > mesh.texture_files.size())
    throw Error(Error::Kind::InvalidMesh,
                std::to_string(mesh.texture_images.size()) + " texture images for " +
                    std::to_string(mesh.texture_files.size()) + " texture files");
  std::vector<uint8_t> out;
  ByteWriter w(out);
  w.u8(kTextureImagesVersion);
  uint32_t count = 0;
  for (const std::vector<uint8_t> &image : mesh.texture_images)
    count += !image.empty();
  if (mesh.texture_images.size() > 0xFFFF)
    throw Error(Error::Kind::InvalidMesh, "too many texture images to embed");
  w.u16(static_cast<uint16_t>(count));
  for (size_t i = 0; i < mesh.texture_images.size(); ++i) {
    const std::vector<uint8_t> &image = mesh.texture_images[i];
    if (image.empty())
      continue;
    if (image.size() > 0xFFFFFFFFu)
      throw Error(Error::Kind::InvalidMesh,
                  "texture image '" + mesh.texture_files[i] + "' is larger than 4 GiB");
    w.u16(static_cast<uint16_t>(i));
    w.u32(static_cast<uint32_t>(image.size()));
    w.bytes(image.data(), image.size());
  }
  return out;
}

std::vector<std::vector<uint8_t>> load_texture_images(const uint8_t *data, const FileLayout &layout,
                                                      size_t textures) {
  uint64_t size = 0;
  const uint8_t *p = body(data, layout, size);
  if (!p)
    return {};
  std::vector<std::vector<uint8_t>> images(textures);
  walk(p, size, textures,
       [&](uint32_t t, size_t at, uint32_t bytes) { images[t].assign(p + at, p + at + bytes); });
  return images;
}

void attach_texture_images(const uint8_t *data, const FileLayout &layout,
                           const AttributeTable *attributes, const AttributeMask &mask, Mesh &out) {
  if (attributes && mask.texcoords)
    out.texture_images = load_texture_images(data, layout, attributes->texture_files.size());
}

std::vector<uint64_t> texture_image_sizes(const uint8_t *data, const FileLayout &layout,
                                          size_t textures) {
  uint64_t size = 0;
  const uint8_t *p = body(data, layout, size);
  std::vector<uint64_t> sizes(textures, 0);
  if (p)
    walk(p, size, textures, [&](uint32_t t, size_t, uint32_t bytes) { sizes[t] = bytes; });
  return sizes;
}

} // namespace pomar
