// Comparing meshes independently of vertex and face order: the library's comparer
// (codec/src/mesh/mesh_compare.h, which `pomar verify` uses) under the tests' names.
#pragma once

#include <vector>

#include "mesh/mesh_compare.h"

namespace pomar::test {

using PositionTriangle = pomar::PositionTriangle;

/// The mesh as a sorted list of triangles of positions, each in its smallest rotation
/// (pomar::canonical_triangles).
inline std::vector<PositionTriangle> canonical(const Mesh &m) { return canonical_triangles(m); }

} // namespace pomar::test
