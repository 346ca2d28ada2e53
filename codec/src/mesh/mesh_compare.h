// Comparing two meshes whatever the order of their vertices and faces: the one comparer of
// `pomar verify` and the tests. Geometry by sorted lists (triangles of positions, each in
// its smallest rotation; positions); attributes by vertices or faces matched by position.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

using Position = std::array<float, 3>;
using PositionTriangle = std::array<Position, 3>;

/// The corner positions of face `f` in their smallest rotation (corners may share a
/// position); `rotation` (0..2) is the corner that comes first.
PositionTriangle smallest_rotation(const Mesh &m, size_t f, int &rotation);

/// The mesh as a sorted list of triangles of positions, each in its smallest rotation:
/// equal for two meshes with the same oriented triangles at the same positions, whatever
/// the order of their vertices and faces.
std::vector<PositionTriangle> canonical_triangles(const Mesh &m);

/// The vertex positions of `m`, sorted: equal for meshes with the same vertices.
std::vector<Position> sorted_positions(const Mesh &m);

/// The same triangles and (unless `triangles_only`) the same vertices.
bool same_geometry(const Mesh &a, const Mesh &b, bool triangles_only);

/// Largest difference between attribute values a (of vertex i) and b (of vertex j):
/// degrees for normals, absolute otherwise; exact attributes: 0 when bit-identical.
double attribute_error(const VertexAttribute &a, size_t i, const VertexAttribute &b, size_t j,
                       bool exact);

/// The vertices of a mesh at each position.
using VerticesByPosition = std::map<Position, std::vector<uint32_t>>;
VerticesByPosition vertices_by_position(const Mesh &m);

/// The largest attribute_error between `a` (of the mesh `ref_at` indexes) and `b` (of
/// `out`), each vertex of `out` against the closest of the reference vertices at its
/// position; vertices of `out` at no reference position are left out.
double worst_attribute_error(const VerticesByPosition &ref_at, const VertexAttribute &a,
                             const Mesh &out, const VertexAttribute &b, bool exact);

/// The texture coordinates of every corner of `m`: corner_texcoords, or the per-vertex ones
/// at each corner (what the OBJ reader gives when no vertex has two); empty if none.
std::vector<float> corner_uvs(const Mesh &m);

/// Triangle f's material as "name|texture file|properties" (`names`: else the texture
/// file only), "" without materials.
std::string face_material_text(const Mesh &m, size_t f, bool names);

/// How the per-corner texture coordinates and face materials of two meshes differ.
struct CornerDifference {
  double worst_uv_error = 0;      ///< largest per-corner UV difference (HUGE_VAL: not exact)
  size_t material_mismatches = 0; ///< faces whose material differs
};

/// The per-corner UVs (`ref_uvs`, `out_uvs`: corner_uvs of each; empty: not compared) and
/// face materials (if `ref` has them) of `ref` against `out`, faces matched by their corner
/// positions in their smallest rotation, corners taken in that order; of several faces with
/// the same corners, the closest. `exact`: UVs bit for bit. Materials by name, texture file
/// and properties (`names`), else by texture file. Faces of `out` at no reference face are
/// left out.
CornerDifference compare_corners(const Mesh &ref, const std::vector<float> &ref_uvs,
                                 const Mesh &out, const std::vector<float> &out_uvs, bool exact,
                                 bool names);

} // namespace pomar
