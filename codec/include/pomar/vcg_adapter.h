// pomar <-> vcglib conversion, header-only.
//
// Both functions are templated on the vcglib mesh type in the way vcglib's own algorithms
// are (`template <class MeshType>`), so they work with MeshLab's CMeshO as well as with
// any vcg::tri::TriMesh whose vertices have a 3D coordinate and bit flags and whose faces
// have vertex references and bit flags.
//
// Include vcglib before or after this header; it pulls in <vcg/complex/complex.h> itself.
#pragma once

#include <pomar/pomar.h>

#include <vcg/complex/algorithms/update/bounding.h>
#include <vcg/complex/complex.h>
#include <wrap/io_trimesh/io_mask.h>

#include <climits>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace pomar {

/// Position of `v` in m.vert, or m.vert.size() if `v` does not point into m.vert (a face's
/// vertex pointer -> vertex index).
template <class MeshType>
size_t vertex_position(const MeshType &m, const typename MeshType::VertexType *v) {
  using VertexType = typename MeshType::VertexType;
  const VertexType *first = m.vert.empty() ? nullptr : &m.vert[0];
  const std::less<const VertexType *> less;
  if (v == nullptr || first == nullptr || less(v, first) || !less(v, first + m.vert.size()))
    return m.vert.size();
  return static_cast<size_t>(v - first);
}
/// from_vcg's attribute mask: vcg::tri::io::Mask bits IOM_VERTCOLOR (colour; RGBA when an
/// alpha differs from 255), IOM_VERTNORMAL, IOM_VERTQUALITY (a scalar named "quality"),
/// IOM_VERTTEXCOORD (texcoord + m.textures as texture files), IOM_WEDGTEXCOORD (the wedge
/// texture coordinates WT(k) as corner_texcoords; with m.textures, also the texture files,
/// one material "texture_<i>" per texture (texture i) and each face's WT(0).n() as its
/// material, an index naming no texture giving a material with an empty name and no
/// texture), plus kVcgCustomScalars: every named per-vertex float attribute becomes a scalar
/// of that name.
constexpr int kVcgCustomScalars = 1 << 30;
constexpr int kVcgAllAttributes =
    vcg::tri::io::Mask::IOM_VERTCOLOR | vcg::tri::io::Mask::IOM_VERTNORMAL |
    vcg::tri::io::Mask::IOM_VERTQUALITY | vcg::tri::io::Mask::IOM_VERTTEXCOORD |
    vcg::tri::io::Mask::IOM_WEDGTEXCOORD | kVcgCustomScalars;

namespace vcg_detail {

/// Position of `v` in m.vert, or throws if `v` does not point into m.vert.
template <class MeshType>
size_t vertex_index(const MeshType &m, const typename MeshType::VertexType *v, size_t face) {
  const size_t i = vertex_position(m, v);
  if (i == m.vert.size())
    throw Error(Error::Kind::InvalidMesh, "vcg mesh: face " + std::to_string(face) +
                                              " has a vertex pointer outside the vertex array");
  return i;
}

/// Per-vertex float attributes of m by name (vcglib's user attributes), except pomar's own
/// ("pomar_*", written by the MeshLab plugins) and unnamed ones.
template <class MeshType> std::vector<std::string> custom_scalar_names(const MeshType &m) {
  std::vector<std::string> names;
  for (const auto &a : m.vert_attr)
    if (!a._name.empty() && a._name.compare(0, 6, "pomar_") != 0 && a._type == typeid(float))
      names.push_back(a._name);
  return names;
}

/// The attributes of the kept vertices (remap[v] != UINT32_MAX, in order).
template <class MeshType>
void take_attributes(const MeshType &m, const std::vector<uint32_t> &remap, int mask, Mesh &out) {
  using namespace vcg::tri::io;
  const auto kept = [&](size_t v) { return !m.vert[v].IsD() && remap[v] != UINT32_MAX; };
  auto add = [&](AttributeKind kind, const char *name, uint32_t components) -> VertexAttribute & {
    out.attributes.emplace_back();
    VertexAttribute &a = out.attributes.back();
    a.kind = kind;
    a.name = name;
    a.components = components;
    return a;
  };
  if ((mask & Mask::IOM_VERTCOLOR) && vcg::tri::HasPerVertexColor(m)) {
    bool alpha = false;
    for (size_t v = 0; v < m.vert.size(); ++v)
      alpha |= kept(v) && m.vert[v].cC()[3] != 255;
    VertexAttribute &a = add(AttributeKind::Colour, "colour", alpha ? 4 : 3);
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (kept(v))
        for (uint32_t k = 0; k < a.components; ++k)
          a.colour.push_back(m.vert[v].cC()[k]);
  }
  if ((mask & Mask::IOM_VERTNORMAL) && vcg::tri::HasPerVertexNormal(m)) {
    VertexAttribute &a = add(AttributeKind::Normal, "normal", 3);
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (kept(v))
        for (int k = 0; k < 3; ++k)
          a.values.push_back(static_cast<float>(m.vert[v].cN()[k]));
  }
  if ((mask & Mask::IOM_VERTQUALITY) && vcg::tri::HasPerVertexQuality(m)) {
    VertexAttribute &a = add(AttributeKind::Scalar, "quality", 1);
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (kept(v))
        a.values.push_back(static_cast<float>(m.vert[v].cQ()));
  }
  if ((mask & Mask::IOM_VERTTEXCOORD) && vcg::tri::HasPerVertexTexCoord(m)) {
    VertexAttribute &a = add(AttributeKind::TexCoord, "texcoord", 2);
    for (size_t v = 0; v < m.vert.size(); ++v)
      if (kept(v)) {
        a.values.push_back(static_cast<float>(m.vert[v].cT().U()));
        a.values.push_back(static_cast<float>(m.vert[v].cT().V()));
      }
    out.texture_files.assign(m.textures.begin(), m.textures.end());
  }
  if (mask & kVcgCustomScalars) {
    MeshType &mm = const_cast<MeshType &>(m); // vcglib's lookup is not const; it reads only
    for (const std::string &name : custom_scalar_names(m)) {
      if (name == "quality" && out.find(AttributeKind::Scalar, name))
        continue;
      auto h = vcg::tri::Allocator<MeshType>::template FindPerVertexAttribute<float>(mm, name);
      if (!vcg::tri::Allocator<MeshType>::IsValidHandle(mm, h))
        continue;
      VertexAttribute &a = add(AttributeKind::Scalar, name.c_str(), 1);
      for (size_t v = 0; v < m.vert.size(); ++v)
        if (kept(v))
          a.values.push_back(h[v]);
    }
  }
}

/// The wedge texture coordinates of the live faces (in order), their texture indices as
/// face materials and m.textures as texture files and materials (see kVcgAllAttributes).
template <class MeshType> void take_wedge_texcoords(const MeshType &m, Mesh &out) {
  if (!vcg::tri::HasPerWedgeTexCoord(m))
    return;
  const size_t textures = m.textures.size();
  if (textures) {
    out.texture_files.assign(m.textures.begin(), m.textures.end());
    out.materials.clear();
    for (size_t i = 0; i < textures; ++i)
      out.materials.push_back(Material{"texture_" + std::to_string(i), int32_t(i), {}});
  }
  for (size_t f = 0; f < m.face.size(); ++f) {
    const auto &face = m.face[f];
    if (face.IsD())
      continue;
    for (int k = 0; k < 3; ++k) {
      out.corner_texcoords.push_back(static_cast<float>(face.cWT(k).U()));
      out.corner_texcoords.push_back(static_cast<float>(face.cWT(k).V()));
    }
    if (!textures)
      continue;
    const int n = face.cWT(0).N();
    if (n >= 0 && size_t(n) < textures) {
      out.face_materials.push_back(uint32_t(n));
      continue;
    }
    if (out.materials.size() == textures)
      out.materials.push_back(Material{"", -1, {}});
    out.face_materials.push_back(uint32_t(textures));
  }
}

/// Throws pomar::Error unless src's per-corner texture coordinates and face materials fit
/// its triangles and materials (empty, or one entry per triangle naming a material).
inline void check_corner_data(const Mesh &src) {
  const size_t nf = src.triangle_count();
  if (!src.corner_texcoords.empty() && src.corner_texcoords.size() != 6 * nf)
    throw Error(Error::Kind::InvalidMesh, "to_vcg: corner_texcoords does not hold 6 values per "
                                          "triangle");
  if (!src.face_materials.empty() && src.face_materials.size() != nf)
    throw Error(Error::Kind::InvalidMesh,
                "to_vcg: face_materials does not hold one material per triangle");
  for (size_t f = 0; f < src.face_materials.size(); ++f)
    if (src.face_materials[f] >= src.materials.size())
      throw Error(Error::Kind::InvalidMesh,
                  "to_vcg: triangle " + std::to_string(f) + " uses material " +
                      std::to_string(src.face_materials[f]) + " but there are " +
                      std::to_string(src.materials.size()));
}

} // namespace vcg_detail

/// Convert a vcglib triangle mesh to a pomar::Mesh.
///
/// Deleted vertices and faces (IsD()) are skipped. Vertices that no live face references
/// are counted into `*unreferenced` (if given) and dropped, or kept with
/// `keep_unreferenced` (pomar::encode stores them). The remaining vertices keep their
/// relative order and are renumbered compactly; faces keep their order.
/// Per-vertex attributes and wedge texture coordinates are taken as `attribute_mask` says
/// (see kVcgAllAttributes; 0 = positions and triangles only), when the mesh type has them
/// (vcg::tri::HasPerVertex*, HasPerWedgeTexCoord: for optional components, when enabled).
/// Throws pomar::Error if a live face references a deleted vertex or a vertex outside
/// m.vert, or if a face is not a triangle.
template <class MeshType>
Mesh from_vcg(const MeshType &m, size_t *unreferenced = nullptr, int attribute_mask = 0,
              bool keep_unreferenced = false) {
  constexpr uint32_t kUnused = UINT32_MAX;
  std::vector<uint32_t> remap(m.vert.size(), kUnused);
  size_t live_faces = 0;

  // Pass 1: mark the vertices used by live faces (remap[i] = 0 for "used").
  for (size_t f = 0; f < m.face.size(); ++f) {
    const auto &face = m.face[f];
    if (face.IsD())
      continue;
    if (face.VN() != 3)
      throw Error(Error::Kind::InvalidMesh, "vcg mesh: face " + std::to_string(f) + " has " +
                                                std::to_string(face.VN()) +
                                                " vertices, expected a triangle");
    for (int k = 0; k < 3; ++k) {
      const size_t v = vcg_detail::vertex_index(m, face.cV(k), f);
      if (m.vert[v].IsD())
        throw Error(Error::Kind::InvalidMesh, "vcg mesh: face " + std::to_string(f) +
                                                  " references deleted vertex " +
                                                  std::to_string(v));
      remap[v] = 0;
    }
    ++live_faces;
  }

  // Pass 2: number the used vertices in their original order, count the unused live ones.
  Mesh out;
  size_t dropped = 0;
  uint32_t next = 0;
  for (size_t v = 0; v < m.vert.size(); ++v) {
    if (m.vert[v].IsD())
      continue;
    if (remap[v] == kUnused) {
      ++dropped;
      if (!keep_unreferenced)
        continue;
    }
    if (next == kUnused)
      throw Error(Error::Kind::InvalidMesh, "vcg mesh: too many vertices for 32-bit indices");
    remap[v] = next++;
    const auto &p = m.vert[v].cP();
    out.positions.push_back(static_cast<float>(p[0]));
    out.positions.push_back(static_cast<float>(p[1]));
    out.positions.push_back(static_cast<float>(p[2]));
  }

  // Pass 3: emit the live triangles with the new indices.
  out.triangles.reserve(3 * live_faces);
  for (size_t f = 0; f < m.face.size(); ++f) {
    const auto &face = m.face[f];
    if (face.IsD())
      continue;
    for (int k = 0; k < 3; ++k)
      out.triangles.push_back(remap[vcg_detail::vertex_index(m, face.cV(k), f)]);
  }

  if (unreferenced)
    *unreferenced = dropped;
  if (attribute_mask)
    vcg_detail::take_attributes(m, remap, attribute_mask, out);
  if (attribute_mask & vcg::tri::io::Mask::IOM_WEDGTEXCOORD)
    vcg_detail::take_wedge_texcoords(m, out);
  return out;
}

/// Write per-vertex attributes (one value per vertex of m) into m, as to_vcg does; returns
/// the mask of what was written (see to_vcg).
template <class MeshType>
int put_attributes(const std::vector<VertexAttribute> &attributes,
                   const std::vector<std::string> &texture_files, MeshType &m) {
  using CoordType = typename MeshType::CoordType;
  using ScalarType = typename MeshType::ScalarType;
  const size_t nv = m.vert.size();
  using namespace vcg::tri::io;
  int written = 0;
  for (const VertexAttribute &a : attributes) {
    if (a.vertex_count() != nv)
      throw Error(Error::Kind::InvalidMesh,
                  "to_vcg: attribute '" + a.name + "' does not have one value per vertex");
    switch (a.kind) {
    case AttributeKind::Colour:
      if (!vcg::tri::HasPerVertexColor(m) || (written & Mask::IOM_VERTCOLOR))
        break;
      for (size_t v = 0; v < nv; ++v) {
        const uint8_t *c = &a.colour[v * a.components];
        m.vert[v].C() = vcg::Color4b(c[0], c[1], c[2], a.components == 4 ? c[3] : 255);
      }
      written |= Mask::IOM_VERTCOLOR;
      break;
    case AttributeKind::Normal:
      if (!vcg::tri::HasPerVertexNormal(m) || (written & Mask::IOM_VERTNORMAL))
        break;
      for (size_t v = 0; v < nv; ++v)
        m.vert[v].N() = CoordType(ScalarType(a.values[3 * v]), ScalarType(a.values[3 * v + 1]),
                                  ScalarType(a.values[3 * v + 2]));
      written |= Mask::IOM_VERTNORMAL;
      break;
    case AttributeKind::TexCoord:
      if (!vcg::tri::HasPerVertexTexCoord(m) || (written & Mask::IOM_VERTTEXCOORD))
        break;
      for (size_t v = 0; v < nv; ++v) {
        m.vert[v].T().U() = a.values[2 * v];
        m.vert[v].T().V() = a.values[2 * v + 1];
        m.vert[v].T().N() = 0;
      }
      if (!texture_files.empty())
        m.textures.assign(texture_files.begin(), texture_files.end());
      written |= Mask::IOM_VERTTEXCOORD;
      break;
    case AttributeKind::Scalar:
      if (a.name == "quality" && vcg::tri::HasPerVertexQuality(m) &&
          !(written & Mask::IOM_VERTQUALITY)) {
        for (size_t v = 0; v < nv; ++v)
          m.vert[v].Q() = a.values[v];
        written |= Mask::IOM_VERTQUALITY;
      } else {
        auto h = vcg::tri::Allocator<MeshType>::template GetPerVertexAttribute<float>(m, a.name);
        for (size_t v = 0; v < nv; ++v)
          h[v] = a.values[v];
        written |= kVcgCustomScalars;
      }
      break;
    }
  }
  return written;
}

/// Replace the contents of vcglib mesh `m` by `src`.
///
/// m is cleared first: its vertices, faces, edges and tetrahedra (TriMesh::Clear()) and
/// its user-defined attributes (TriMesh::ClearAttributes(), which exists in vcglib 2020.09:
/// Clear() alone would leave the per-vertex/per-face attribute arrays holding stale values),
/// so attribute handles obtained from m before the call become invalid. Mesh-level data that
/// Clear() does not touch (textures, shot) is left as it is. Vertices and faces are then
/// added with vcg::tri::Allocator in the order of `src`, and the bounding box is updated;
/// normals and adjacency are not computed (call vcg::tri::UpdateNormal/UpdateTopology)
/// unless `src` carries them.
/// Attributes of `src` go where the mesh type has room (vcg::tri::HasPerVertex*: for
/// optional components, enable them first): colour (RGB gets alpha 255), normal, the scalar
/// "quality" into Q(), texcoord into T() (and src.texture_files into m.textures), other
/// scalars into per-vertex float attributes of their names; corner_texcoords into the wedge
/// texture coordinates WT(k) when the face type has them (vcg::tri::HasPerWedgeTexCoord: in
/// CMeshO enable them first), with n() the face material's texture (-1 for none; 0 without
/// face materials) and src.texture_files into m.textures. Returns the vcg::tri::io::Mask
/// bits of what was written (IOM_VERTCOLOR, IOM_VERTNORMAL, IOM_VERTQUALITY,
/// IOM_VERTTEXCOORD, IOM_WEDGTEXCOORD) plus kVcgCustomScalars if a named scalar was added.
/// Material names and properties have no place in a vcglib mesh: from_vcg gives them back
/// as "texture_<i>".
/// Throws pomar::Error (leaving m untouched) if `src` is malformed: array sizes not a
/// multiple of 3, an index out of range, corner data that does not fit the triangles, or
/// more elements than vcglib's int counters hold.
template <class MeshType> int to_vcg(const Mesh &src, MeshType &m) {
  using CoordType = typename MeshType::CoordType;
  using ScalarType = typename MeshType::ScalarType;

  if (src.positions.size() % 3 != 0 || src.triangles.size() % 3 != 0)
    throw Error(Error::Kind::InvalidMesh,
                "to_vcg: positions and triangles must hold a multiple of 3 values");
  const size_t nv = src.vertex_count(), nf = src.triangle_count();
  if (nv > size_t(INT_MAX) || nf > size_t(INT_MAX))
    throw Error(Error::Kind::InvalidMesh,
                "to_vcg: mesh too large for vcglib (more than INT_MAX vertices or faces)");
  for (size_t i = 0; i < src.triangles.size(); ++i)
    if (src.triangles[i] >= nv)
      throw Error(Error::Kind::InvalidMesh,
                  "to_vcg: triangle " + std::to_string(i / 3) + " references vertex " +
                      std::to_string(src.triangles[i]) + " but the mesh has " + std::to_string(nv) +
                      " vertices");
  vcg_detail::check_corner_data(src);

  m.Clear();
  m.ClearAttributes();

  auto vi = vcg::tri::Allocator<MeshType>::AddVertices(m, nv);
  for (size_t v = 0; v < nv; ++v, ++vi)
    vi->P() = CoordType(ScalarType(src.positions[3 * v]), ScalarType(src.positions[3 * v + 1]),
                        ScalarType(src.positions[3 * v + 2]));

  // Faces are added after all vertices, so the vertex pointers below stay valid.
  auto fi = vcg::tri::Allocator<MeshType>::AddFaces(m, nf);
  for (size_t f = 0; f < nf; ++f, ++fi)
    for (int k = 0; k < 3; ++k)
      fi->V(k) = &m.vert[src.triangles[3 * f + k]];

  vcg::tri::UpdateBounding<MeshType>::Box(m);

  int written = put_attributes(src.attributes, src.texture_files, m);
  if (!src.corner_texcoords.empty() && vcg::tri::HasPerWedgeTexCoord(m)) {
    for (size_t f = 0; f < nf; ++f) {
      const int n = src.face_materials.empty() ? 0 : src.materials[src.face_materials[f]].texture;
      for (int k = 0; k < 3; ++k) {
        m.face[f].WT(k).U() = src.corner_texcoords[6 * f + 2 * k];
        m.face[f].WT(k).V() = src.corner_texcoords[6 * f + 2 * k + 1];
        m.face[f].WT(k).N() = static_cast<short>(n);
      }
    }
    if (!src.texture_files.empty())
      m.textures.assign(src.texture_files.begin(), src.texture_files.end());
    written |= vcg::tri::io::Mask::IOM_WEDGTEXCOORD;
  }
  return written;
}

} // namespace pomar
