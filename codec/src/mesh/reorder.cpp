#include "mesh/reorder.h"
#include "memory/prefault.h"
#include "mesh/introsort.h"
#include "mesh/morton.h"
#include "mesh/radix_sort.h"

#include <algorithm>

namespace pomar {

std::vector<uint32_t> reorder_vertices(std::vector<int32_t> &q, std::vector<uint32_t> &triangles) {
  const uint32_t nv = static_cast<uint32_t>(q.size() / 3);
  // Morton key from the top 21 bits of each coordinate (grids have at most 24 bits).
  std::vector<Keyed> key = filled_vector<Keyed>(nv);
  for (uint32_t v = 0; v < nv; ++v) {
    const uint64_t x = uint64_t(q[3 * v]) >> 3, y = uint64_t(q[3 * v + 1]) >> 3,
                   z = uint64_t(q[3 * v + 2]) >> 3;
    key[v] = {morton_key(x, y, z), v};
  }
  sort_by_key(key);
  std::vector<uint32_t> old_to_new = filled_vector<uint32_t>(nv);
  std::vector<int32_t> nq = filled_vector<int32_t>(q.size());
  for (uint32_t i = 0; i < nv; ++i) {
    const uint32_t v = key[i].id;
    old_to_new[v] = i;
    std::copy(&q[3 * v], &q[3 * v] + 3, &nq[3 * i]);
  }
  q.swap(nq);
  for (uint32_t &v : triangles)
    v = old_to_new[v];
  return old_to_new;
}

std::vector<uint32_t> face_order(const std::vector<uint32_t> &t) {
  // A sort's moves depend only on its comparisons' results, so sorting (smallest vertex,
  // face) pairs with the same comparison gives the order sorting the faces does (ties
  // included) while each comparison reads one number instead of six. Faces tie on their
  // smallest vertex: introsort leaves them in one order on every platform (mesh/
  // introsort.h).
  struct Face {
    uint32_t lowest, f;
  };
  const size_t nf = t.size() / 3;
  std::vector<Face> faces = filled_vector<Face>(nf);
  for (size_t f = 0; f < nf; ++f)
    faces[f] = {std::min({t[3 * f], t[3 * f + 1], t[3 * f + 2]}), static_cast<uint32_t>(f)};
  introsort(faces.data(), faces.data() + faces.size(),
            [](const Face &a, const Face &b) { return a.lowest < b.lowest; });
  std::vector<uint32_t> order = filled_vector<uint32_t>(nf);
  for (size_t i = 0; i < nf; ++i)
    order[i] = faces[i].f;
  return order;
}

void reorder_faces(CornerTable &ct, const std::vector<uint32_t> &order) {
  const size_t nf = order.size();
  // Old face -> the first corner of its new place (arrays mapped first: memory/prefault.h).
  std::vector<uint32_t> new_corner = filled_vector<uint32_t>(nf);
  for (size_t i = 0; i < nf; ++i)
    new_corner[order[i]] = static_cast<uint32_t>(3 * i);
  { // corner 3*i+k of the new table is corner 3*order[i]+k of the old one
    std::vector<uint32_t> V = filled_vector<uint32_t>(3 * nf);
    const uint32_t *old = ct.V.data();
    for (size_t i = 0; i < nf; ++i)
      std::copy_n(old + 3 * size_t(order[i]), 3, &V[3 * i]);
    ct.V.swap(V);
  }
  {
    std::vector<uint32_t> O = filled_vector<uint32_t>(3 * nf);
    const uint32_t *old = ct.O.data();
    for (size_t i = 0; i < nf; ++i) {
      const uint32_t *o = old + 3 * size_t(order[i]);
      for (uint32_t k = 0; k < 3; ++k)
        O[3 * i + k] = o[k] == kNone ? kNone : new_corner[o[k] / 3] + o[k] % 3;
    }
    ct.O.swap(O);
  }
  // As build_corner_table sets it: each vertex's last corner.
  const uint32_t *V = ct.V.data();
  uint32_t *VC = ct.VC.data();
  for (uint32_t c = 0, n = static_cast<uint32_t>(3 * nf); c < n; ++c)
    VC[V[c]] = c;
}

} // namespace pomar
