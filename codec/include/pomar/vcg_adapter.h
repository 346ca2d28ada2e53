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

} // namespace vcg_detail

/// Convert a vcglib triangle mesh to a pomar::Mesh.
///
/// Deleted vertices and faces (IsD()) are skipped. Vertices that no live face references
/// are counted into `*unreferenced` (if given) and dropped, or kept with
/// `keep_unreferenced` (pomar::encode stores them). The remaining vertices keep their
/// relative order and are renumbered compactly; faces keep their order.
/// Throws pomar::Error if a live face references a deleted vertex or a vertex outside
/// m.vert, or if a face is not a triangle.
template <class MeshType>
Mesh from_vcg(const MeshType &m, size_t *unreferenced = nullptr, bool keep_unreferenced = false) {
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
  return out;
}

/// Replace the contents of vcglib mesh `m` by `src`.
///
/// m is cleared first: its vertices, faces, edges and tetrahedra (TriMesh::Clear()) and
/// its user-defined attributes (TriMesh::ClearAttributes(), which exists in vcglib 2020.09:
/// Clear() alone would leave the per-vertex/per-face attribute arrays holding stale values),
/// so attribute handles obtained from m before the call become invalid. Mesh-level data that
/// Clear() does not touch (textures, shot) is left as it is. Vertices and faces are then
/// added with vcg::tri::Allocator in the order of `src`, and the bounding box is updated;
/// normals and adjacency are not computed (call vcg::tri::UpdateNormal/UpdateTopology).
/// Throws pomar::Error (leaving m untouched) if `src` is malformed: array sizes not a
/// multiple of 3, an index out of range, or more elements than vcglib's int counters hold.
template <class MeshType> void to_vcg(const Mesh &src, MeshType &m) {
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
}

} // namespace pomar
