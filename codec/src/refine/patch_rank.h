// The patch of a split as one rank (format version 5). A split's patch is the run of
// s_l + s_r = T faces of v_to's ring from v_l to v_r; given T, the run can start at any
// of a few places (a closed fan: m, one per ring index). Every such placement is scored
// from the ring's spokes, the placements are sorted by score, and the rank of the true
// placement is coded (mostly 0). v_ref, which version 4 names by s_e, follows from the
// patch: its longest interior spoke. Integer arithmetic only (a fixed-point log2 on a
// table built at compile time by integer squaring), so that every build (native,
// WebAssembly) scores alike; ties go to the placement that starts first.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/corner_table.h"
#include "refine/patch.h"

namespace pomar {

/// round(256 * log2(1 + i / 256)) for i = 0..255, by integer squaring (bit by bit).
struct Log2Table {
  uint16_t q8[256];
  constexpr Log2Table() : q8() {
    for (uint32_t i = 0; i < 256; ++i) {
      // y in [1, 2) as Q30; 9 fractional bits of log2(y), then rounded to 8.
      uint64_t y = (uint64_t(256 + i) << 30) >> 8;
      uint32_t bits = 0;
      for (int b = 0; b < 9; ++b) {
        y = (y * y) >> 30;
        bits <<= 1;
        if (y >= (uint64_t(2) << 30)) {
          y >>= 1;
          bits |= 1;
        }
      }
      q8[i] = static_cast<uint16_t>((bits + 1) >> 1);
    }
  }
};
inline constexpr Log2Table kLog2Table{};

/// log2(x) in 1/256 units (x >= 1; 0 for x = 0), from the top 9 bits of x.
inline int32_t log2_q8(uint64_t x) {
  x += x == 0;                      // (log2_q8(1) is 0 too: no branch)
  const int z = __builtin_clzll(x); // x << z: the top bit at 63, then the 8 bits below it
  return (63 - z) * 256 + kLog2Table.q8[(x << z) >> 55 & 255];
}

/// The placements of a patch of `faces` (= s_l + s_r) in a ring of m neighbours, as the
/// position of v_l in an extended index: closed fans il = 0..m-1 (v_r at il + T mod m);
/// open fans il = -1..m-T (-1: no v_l; v_r at il + T, m: no v_r), less those without a
/// face or with neither v_l nor v_r. Placement k of an open fan has il = k - 1.
struct PatchPlacements {
  std::vector<int64_t> score; // per placement k (kNone-free: invalid ones are not listed)
  std::vector<int32_t> il;    // per placement: v_l's extended index
  uint32_t count = 0;
  std::vector<int32_t> log; // per ring index i: log2_q8 of the squared spoke length (at i, i + m)
};

/// Whether a patch of T faces from extended index il is a valid split in an open fan of m.
inline bool open_placement_valid(int32_t il, uint32_t faces, uint32_t m) {
  const int32_t ir = il + int32_t(faces);
  if (il < -1 || ir > int32_t(m) || (il == -1 && ir == int32_t(m)))
    return false;
  const int32_t first = il < 0 ? 0 : il, end = ir > int32_t(m) - 1 ? int32_t(m) - 1 : ir;
  return end > first;
}

/// Score every placement of a patch of `faces` faces (1 <= faces, closed: faces < m; open:
/// faces <= m) in `ring` from its interior spokes (those strictly between v_l and v_r: the
/// edges the collapse gave v_to, about as long as v_from's edges plus v_to's): first their
/// smallest log2 length, then the sum of their logs; a one-face patch (no interior spoke)
/// by the sum over its two sides. (Measured against the sum alone: 0.02-0.1 bits per
/// vertex less on bunny, armadillo and rocker arm, 0.005 more on fertility.)
inline void score_placements(const Ring &ring, const Spoke *spokes, uint32_t faces,
                             PatchPlacements &out) {
  const uint32_t m = ring.size();
  // The logs twice over (index i and i + m alike: a closed fan's window never wraps).
  if (out.log.size() < 2 * size_t(m))
    out.log.resize(2 * size_t(m));
  const size_t most = size_t(m) + 2;
  if (out.score.size() < most) {
    out.score.resize(most);
    out.il.resize(most);
  }
  int32_t *lg = out.log.data();
  for (uint32_t i = 0; i < m; ++i)
    lg[i] = lg[i + m] = log2_q8(uint64_t(spokes[i].len2));
  // The placements are one run of il: closed fans 0..m-1; open fans -1..m-T less the
  // invalid ones, which are only at the ends (a one-face patch needs both sides).
  int32_t lo = 0, hi = int32_t(m) - 1;
  if (!ring.closed) {
    lo = -1;
    hi = int32_t(m) - int32_t(faces);
    while (lo <= hi && !open_placement_valid(lo, faces, m))
      ++lo;
    while (hi >= lo && !open_placement_valid(hi, faces, m))
      --hi;
  }
  const uint32_t n = hi >= lo ? uint32_t(hi - lo + 1) : 0;
  int64_t *score = out.score.data();
  int32_t *first = out.il.data();
  for (uint32_t k = 0; k < n; ++k)
    first[k] = lo + int32_t(k);
  // One loop per window size (the interior spokes il+1 .. il+T-1; open fans: inside
  // 0..m-1): T = 2 and 3 are most splits.
  const int32_t *x = lg + (lo + 1); // placement k's first interior spoke is x[k]
  constexpr int64_t kHigh = int64_t(1) << 32;
  if (faces == 1) { // both sides exist (a valid one-face placement)
    for (uint32_t k = 0; k < n; ++k)
      score[k] = int64_t(x[int32_t(k) - 1]) + x[k];
  } else if (faces == 2) {
    for (uint32_t k = 0; k < n; ++k)
      score[k] = int64_t(x[k]) * kHigh + x[k];
  } else if (faces == 3) {
    for (uint32_t k = 0; k < n; ++k) {
      const int32_t a = x[k], b = x[k + 1];
      score[k] = int64_t(a < b ? a : b) * kHigh + (int64_t(a) + b);
    }
  } else {
    for (uint32_t k = 0; k < n; ++k) {
      const int32_t *w = x + k;
      int64_t sum = 0;
      int32_t least = w[0];
      for (uint32_t t = 0; t + 1 < faces; ++t) {
        sum += w[t];
        least = w[t] < least ? w[t] : least;
      }
      score[k] = int64_t(least) * kHigh + sum;
    }
  }
  out.count = n;
}

/// Placement a comes before placement b in the ranking (higher score, then smaller k).
inline bool placement_before(const PatchPlacements &p, uint32_t a, uint32_t b) {
  return p.score[a] != p.score[b] ? p.score[a] > p.score[b] : a < b;
}

/// The rank of placement t (how many placements come before it).
inline uint32_t placement_rank(const PatchPlacements &p, uint32_t t) {
  uint32_t r = 0;
  for (uint32_t k = 0; k < p.count; ++k)
    r += placement_before(p, k, t);
  return r;
}

/// The placement of rank r (r < p.count): the first, then the next after it, r times (the
/// order is total; r is 0 for most splits).
inline uint32_t placement_of_rank(const PatchPlacements &p, uint32_t r) {
  if (r == 0) { // the highest score, the first of equals
    uint32_t best = 0;
    for (uint32_t k = 1; k < p.count; ++k)
      best = p.score[k] > p.score[best] ? k : best;
    return best;
  }
  uint32_t prev = kNone;
  for (uint32_t step = 0; step <= r; ++step) {
    uint32_t best = kNone;
    for (uint32_t k = 0; k < p.count; ++k)
      if ((prev == kNone || placement_before(p, prev, k)) &&
          (best == kNone || placement_before(p, k, best)))
        best = k;
    prev = best;
  }
  return prev;
}

/// The placement's index among p's (kNone if it is not one of them).
inline uint32_t placement_index(const PatchPlacements &p, int32_t il) {
  for (uint32_t k = 0; k < p.count; ++k)
    if (p.il[k] == il)
      return k;
  return kNone;
}

/// v_ref of a patch (v_l at extended index il, T faces): the ring index of its longest
/// interior spoke (ties: smaller key, then smaller ring index); a one-face patch's longer
/// side. Then the split symbols that name the patch from there (resolve_patch's input).
template <class Key>
void patch_symbols(const Ring &ring, const Spoke *spokes, int32_t il, uint32_t faces,
                   const Key &key, uint32_t &j, SplitSymbols &s) {
  const uint32_t m = ring.size();
  const auto better = [&](uint32_t a, uint32_t b) {
    if (spokes[a].len2 != spokes[b].len2)
      return spokes[a].len2 > spokes[b].len2;
    const uint64_t ka = key(ring.neighbour[a]), kb = key(ring.neighbour[b]);
    return ka != kb ? ka < kb : a < b;
  };
  j = kNone;
  const int32_t ir = il + int32_t(faces);
  if (ring.closed) {
    // (il < m and faces < m: each index wraps at most once, by a subtraction)
    const uint32_t l = uint32_t(il), r = uint32_t(ir) >= m ? uint32_t(ir) - m : uint32_t(ir);
    for (uint32_t t = 1, i = l + 1 == m ? 0 : l + 1; t < faces; ++t, i = i + 1 == m ? 0 : i + 1)
      if (j == kNone || better(i, j))
        j = i;
    if (j == kNone)
      j = better(r, l) ? r : l;
    s.s_l = j >= l ? j - l : j + m - l;
    s.s_r = r >= j ? r - j : r + m - j;
  } else {
    for (int32_t i = il + 1; i < ir; ++i)
      if (i >= 0 && i < int32_t(m) && (j == kNone || better(uint32_t(i), j)))
        j = uint32_t(i);
    if (j == kNone) { // one face, both sides in the ring
      j = better(uint32_t(ir), uint32_t(il)) ? uint32_t(ir) : uint32_t(il);
    }
    s.s_l = uint32_t(int32_t(j) - il);
    s.s_r = uint32_t(ir - int32_t(j));
  }
  s.s_e = 0; // (not coded: resolve_patch only checks it against the ring)
}

} // namespace pomar
