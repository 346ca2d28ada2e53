// The MATL section: materials of per-corner values (byte layout: docs/format.md).
#include "attributes/material_section.h"

#include <string>

#include "format/bit_io.h"
#include "lossless/seam_cut.h"

namespace pomar {
namespace {

[[noreturn]] void damaged(const std::string &what) {
  throw Error(Error::Kind::DamagedFile, "damaged .pomar file: MATL section: " + what);
}

constexpr uint8_t kCornerTexcoords = 1, kFaceMaterials = 2;

} // namespace

std::vector<uint8_t> write_materials(const MaterialTable &t) {
  std::vector<uint8_t> out;
  ByteWriter w(out);
  w.u8(kMaterialSectionVersion);
  w.u8(uint8_t((t.corner_texcoords ? kCornerTexcoords : 0) |
               (t.face_materials ? kFaceMaterials : 0)));
  w.u32(static_cast<uint32_t>(t.materials.size()));
  for (const Material &m : t.materials) {
    if (m.name.size() > 0xFFFF)
      throw Error(Error::Kind::InvalidMesh,
                  "material name too long: " + m.name.substr(0, 64) + "...");
    w.u16(static_cast<uint16_t>(m.name.size()));
    w.bytes(reinterpret_cast<const uint8_t *>(m.name.data()), m.name.size());
    w.u32(static_cast<uint32_t>(m.texture)); // -1: none
    w.u32(static_cast<uint32_t>(m.properties.size()));
    w.bytes(reinterpret_cast<const uint8_t *>(m.properties.data()), m.properties.size());
  }
  return out;
}

MaterialTable read_materials(const uint8_t *data, size_t size, size_t textures) {
  ByteReader r(data, size, "damaged .pomar file: MATL section");
  const uint8_t version = r.u8();
  if (version != kMaterialSectionVersion)
    throw Error(Error::Kind::Unsupported, "MATL section version " + std::to_string(version) +
                                              " is not supported (this pomar reads version 1)");
  MaterialTable t;
  const uint8_t flags = r.u8();
  if (flags & ~(kCornerTexcoords | kFaceMaterials))
    damaged("unknown flags " + std::to_string(flags));
  t.corner_texcoords = flags & kCornerTexcoords;
  t.face_materials = flags & kFaceMaterials;
  const uint32_t count = r.u32();
  if (count > size) // each takes 10 bytes at least
    damaged(std::to_string(count) + " materials do not fit in " + std::to_string(size) + " bytes");
  auto read_string = [&](size_t len) {
    if (len > size - r.position())
      damaged("a string runs past the section");
    std::string s(len, '\0');
    for (size_t i = 0; i < len; ++i)
      s[i] = static_cast<char>(r.u8());
    return s;
  };
  for (uint32_t i = 0; i < count; ++i) {
    Material m;
    m.name = read_string(r.u16());
    m.texture = static_cast<int32_t>(r.u32());
    if (m.texture < -1 || (m.texture >= 0 && size_t(m.texture) >= textures))
      damaged("material " + std::to_string(i) + " names texture " + std::to_string(m.texture) +
              " of " + std::to_string(textures));
    m.properties = read_string(r.u32());
    t.materials.push_back(std::move(m));
  }
  if (r.position() != size)
    damaged("it has " + std::to_string(size - r.position()) + " bytes past its materials");
  if (t.face_materials && t.materials.empty())
    damaged("faces have materials but the file names none");
  return t;
}

std::unique_ptr<MaterialTable> load_material_table(const uint8_t *data, const FileLayout &layout,
                                                   size_t textures) {
  const int i = find_section(layout, kMaterialSectionTag);
  if (i < 0)
    return nullptr;
  const uint8_t *body = section_body(data, layout, size_t(i)); // checks its XXH32
  return std::make_unique<MaterialTable>(
      read_materials(body, layout.header.sections[size_t(i)].bytes, textures));
}

void attach_materials(const MaterialTable &t, const AttributeMask &mask, Mesh &out) {
  if (!mask.texcoords)
    return;
  out.materials = t.materials;
  corners_from_wedges(out);
  if ((t.corner_texcoords && out.corner_texcoords.empty()) ||
      (t.face_materials && out.face_materials.empty()))
    damaged("the ATTR section lacks the per-corner values it announces");
}

} // namespace pomar
