#include "mesh/reorder.h"

#include <algorithm>
#include <array>

namespace pomar {
namespace {

/// Spread the low 21 bits of x so that they occupy every third bit.
uint64_t spread3(uint64_t x) {
  x &= 0x1FFFFF;
  x = (x | x << 32) & 0x1F00000000FFFFull;
  x = (x | x << 16) & 0x1F0000FF0000FFull;
  x = (x | x << 8) & 0x100F00F00F00F00Full;
  x = (x | x << 4) & 0x10C30C30C30C30C3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

} // namespace

std::vector<uint32_t> reorder_for_locality(std::vector<int32_t> &q,
                                           std::vector<uint32_t> &triangles) {
  const uint32_t nv = static_cast<uint32_t>(q.size() / 3);
  // Morton key from the top 21 bits of each coordinate (grids have at most 24 bits).
  std::vector<std::pair<uint64_t, uint32_t>> key(nv);
  for (uint32_t v = 0; v < nv; ++v) {
    const uint64_t x = uint64_t(q[3 * v]) >> 3, y = uint64_t(q[3 * v + 1]) >> 3,
                   z = uint64_t(q[3 * v + 2]) >> 3;
    key[v] = {spread3(x) | spread3(y) << 1 | spread3(z) << 2, v};
  }
  std::sort(key.begin(), key.end());
  std::vector<uint32_t> old_to_new(nv);
  std::vector<int32_t> nq(q.size());
  for (uint32_t i = 0; i < nv; ++i) {
    const uint32_t v = key[i].second;
    old_to_new[v] = i;
    std::copy(&q[3 * v], &q[3 * v] + 3, &nq[3 * i]);
  }
  q.swap(nq);
  // Faces: rename, then sort by their smallest vertex (rotation and orientation kept).
  const size_t nf = triangles.size() / 3;
  std::vector<std::array<uint32_t, 3>> faces(nf);
  for (size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      faces[f][k] = old_to_new[triangles[3 * f + k]];
  std::sort(faces.begin(), faces.end(), [](const auto &a, const auto &b) {
    return std::min({a[0], a[1], a[2]}) < std::min({b[0], b[1], b[2]});
  });
  for (size_t f = 0; f < nf; ++f)
    std::copy(faces[f].begin(), faces[f].end(), &triangles[3 * f]);
  return old_to_new;
}

} // namespace pomar
