// Comparing meshes independently of vertex and face order (tests only).
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "pomar/pomar.h"

namespace pomar::test {

using PositionTriangle = std::array<std::array<float, 3>, 3>;

/// The mesh as a sorted list of triangles of positions, each in its smallest rotation:
/// equal for two meshes with the same oriented triangles at the same positions, whatever
/// the order of their vertices and faces.
inline std::vector<PositionTriangle> canonical(const Mesh &m) {
  std::vector<PositionTriangle> out;
  out.reserve(m.triangle_count());
  for (size_t f = 0; f < m.triangle_count(); ++f) {
    PositionTriangle t;
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a)
        t[k][a] = m.positions[3 * m.triangles[3 * f + k] + a];
    const PositionTriangle r1 = {t[1], t[2], t[0]}, r2 = {t[2], t[0], t[1]};
    out.push_back(std::min({t, r1, r2}));
  }
  std::sort(out.begin(), out.end());
  return out;
}

} // namespace pomar::test
