// A vertex split's patch in v_to's ring, and the split symbols that name it (paper
// section 5.1): s_e picks the edge v_to-v_ref among the ring's edges ranked longest first,
// s_l and s_r count the patch faces on either side of it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "mesh/corner_table.h"
#include "mesh/introsort.h"
#include "refine/level_mesh.h"

namespace pomar {

struct SplitSymbols {
  uint32_t s_e = 0, s_l = 0, s_r = 0;
};

/// Where the patch of a split lies in v_to's ring (indices; kNone = the open fan's gap).
struct PatchRange {
  uint32_t j;      // v_ref
  uint32_t il, ir; // v_l, v_r
  uint32_t first_face, faces;
};

/// The edge from a split vertex v to neighbour[i] of its ring: the neighbour's offset
/// from v and the edge's squared length. Loaded once per split (load_spokes) for the edge
/// ranking and the prediction (geometry/predict.h), which read the ring's positions only
/// through them.
struct Spoke {
  int64_t d[3];
  int64_t len2;
};

/// spokes[0..ring.size()) for vertex v (grown as needed, never shrunk).
inline void load_spokes(const std::vector<int32_t> &q, uint32_t v, const Ring &ring,
                        std::vector<Spoke> &spokes) {
  const uint32_t m = ring.size();
  if (spokes.size() < m)
    spokes.resize(m);
  const int32_t *at = &q[3 * size_t(v)];
  const int64_t x = at[0], y = at[1], z = at[2];
  const uint32_t *neighbour = ring.neighbour.data();
  Spoke *out = spokes.data();
  for (uint32_t i = 0; i < m; ++i) { // (components spelled out: the -O2 build kept the loop)
    const int32_t *n = &q[3 * size_t(neighbour[i])];
    const int64_t dx = n[0] - x, dy = n[1] - y, dz = n[2] - z;
    out[i] = {{dx, dy, dz}, dx * dx + dy * dy + dz * dz};
  }
}

/// Ring indices sorted by decreasing edge length (ties: smaller key first) into
/// ranked[0..ring.size()) (grown as needed, never shrunk).
template <class Key>
void rank_edges(const Ring &ring, const Spoke *spokes, std::vector<uint32_t> &ranked,
                const Key &key) {
  const uint32_t m = ring.size();
  if (ranked.size() < m)
    ranked.resize(m);
  uint32_t *r = ranked.data();
  for (uint32_t i = 0; i < m; ++i)
    r[i] = i;
  const auto before = [&](uint32_t a, uint32_t b) {
    if (spokes[a].len2 != spokes[b].len2)
      return spokes[a].len2 > spokes[b].len2;
    return key(ring.neighbour[a]) < key(ring.neighbour[b]);
  };
  if (m > 16) { // (a view ring can name one neighbour twice: the tie's order is coded)
    introsort(r, r + m, before);
    return;
  }
  // What introsort does with 16 elements or fewer, inlined: an insertion sort. (A view
  // ring can name one neighbour twice: such ties must stay in that order.)
  for (uint32_t i = 1; i < m; ++i) {
    const uint32_t x = r[i];
    uint32_t j = i;
    for (; j > 0 && before(x, r[j - 1]); --j)
      r[j] = r[j - 1];
    r[j] = x;
  }
}

/// The ring index of rank `e` in rank_edges' order (e < ring.size() <= 16), without
/// sorting: the longest edges are taken out one by one. What the decoder needs (it reads
/// s_e, then looks up one edge): s_e is 0 for about 2 splits in 3 and rarely above 2.
/// rank_edges sorts <= 16 edges stably, i.e. by (len2 descending, key ascending, index
/// ascending); scanning by increasing index and keeping the first of equals gives the same.
template <class Key>
uint32_t ranked_edge(const Ring &ring, const Spoke *spokes, uint32_t e, const Key &key) {
  const uint32_t m = ring.size();
  uint32_t taken = 0; // bit i: edge i has a rank below the one looked for
  for (uint32_t r = 0;; ++r) {
    uint32_t best = kNone;
    for (uint32_t i = 0; i < m; ++i) {
      if (taken >> i & 1)
        continue;
      if (best == kNone || spokes[i].len2 > spokes[best].len2 ||
          (spokes[i].len2 == spokes[best].len2 &&
           key(ring.neighbour[i]) < key(ring.neighbour[best])))
        best = i;
    }
    if (r == e)
      return best;
    taken |= 1u << best;
  }
}

/// Turn (s_e, s_l, s_r) into ring positions, `j` being the ring index of the edge of rank
/// s_e (when s_e < ring.size()); false if they do not describe a valid patch.
inline bool resolve_patch(const Ring &ring, uint32_t j, const SplitSymbols &s, PatchRange &p) {
  const uint32_t m = ring.size();
  if (s.s_e >= m)
    return false;
  p.j = j;
  if (ring.closed) {
    if (s.s_l >= m || s.s_r >= m || s.s_l + s.s_r == 0 || s.s_l + s.s_r > m - 1)
      return false;
    p.il = (p.j + m - s.s_l) % m;
    p.ir = (p.j + s.s_r) % m;
    p.first_face = p.il;
    p.faces = s.s_l + s.s_r;
    return true;
  }
  if (s.s_l <= p.j)
    p.il = p.j - s.s_l;
  else if (s.s_l == p.j + 1)
    p.il = kNone;
  else
    return false;
  if (uint64_t(p.j) + s.s_r <= m - 1)
    p.ir = p.j + s.s_r;
  else if (uint64_t(p.j) + s.s_r == m)
    p.ir = kNone;
  else
    return false;
  if (p.il == kNone && p.ir == kNone)
    return false;
  p.first_face = p.il == kNone ? 0 : p.il;
  const uint32_t end = p.ir == kNone ? m - 1 : p.ir;
  if (end <= p.first_face)
    return false;
  p.faces = end - p.first_face;
  return true;
}

} // namespace pomar
