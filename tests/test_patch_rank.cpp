// Version 5's patch placements (refine/patch_rank.h): the fixed-point log, the ranking
// both ways, and every placement naming a valid patch with its v_ref inside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "refine/patch_rank.h"

namespace pomar {
namespace {

TEST(PatchRank, FixedPointLog2IsWithinTwoUnitsAndMonotone) {
  EXPECT_EQ(log2_q8(0), 0);
  EXPECT_EQ(log2_q8(1), 0);
  EXPECT_EQ(log2_q8(2), 256);
  EXPECT_EQ(log2_q8(3), 406); // 256 log2(3) = 405.75
  EXPECT_EQ(log2_q8(uint64_t(1) << 40), 40 * 256);
  int32_t prev = 0;
  for (uint64_t x = 1; x < 200000; x += 1 + x / 64) {
    const int32_t l = log2_q8(x);
    EXPECT_GE(l, prev) << x;
    // 9 bits of x are read: within half a unit of the exact value plus the truncation
    // (below 256 log2(1 + 1/256) = 1.44).
    EXPECT_NEAR(double(l), 256.0 * std::log2(double(x)), 1.95) << x;
    prev = l;
  }
}

Ring make_ring(uint32_t m, bool closed) {
  Ring r;
  for (uint32_t i = 0; i < m; ++i) {
    r.neighbour.push_back(100 + i);
    if (closed || i + 1 < m) // (an open fan of m neighbours has m - 1 faces)
      r.corner.push_back(3 * i);
  }
  r.closed = closed;
  return r;
}

TEST(PatchRank, RankAndPlacementOfRankAreInverse) {
  std::mt19937 rng(7);
  PatchPlacements p;
  for (int trial = 0; trial < 200; ++trial) {
    p.count = 1 + rng() % 20;
    p.score.assign(p.count, 0);
    p.il.assign(p.count, 0);
    for (uint32_t k = 0; k < p.count; ++k)
      p.score[k] = int64_t(rng() % 4); // many ties
    std::vector<bool> seen(p.count, false);
    for (uint32_t k = 0; k < p.count; ++k) {
      const uint32_t r = placement_rank(p, k);
      ASSERT_LT(r, p.count);
      EXPECT_FALSE(seen[r]); // a total order: ranks are distinct
      seen[r] = true;
      EXPECT_EQ(placement_of_rank(p, r), k);
    }
  }
}

TEST(PatchRank, EveryPlacementIsAValidPatchAroundItsVRef) {
  std::mt19937 rng(11);
  const auto key = [](uint32_t v) { return uint64_t(v); };
  PatchPlacements p;
  for (bool closed : {true, false})
    for (uint32_t m = 2; m <= 12; ++m) {
      const Ring ring = make_ring(m, closed);
      std::vector<Spoke> spokes(m);
      for (Spoke &s : spokes)
        s.len2 = 1 + int64_t(rng() % 50);
      for (uint32_t faces = 1; faces + (closed ? 1 : 0) <= m; ++faces) {
        SCOPED_TRACE(std::to_string(m) + (closed ? " closed, " : " open, ") +
                     std::to_string(faces) + " faces");
        score_placements(ring, spokes.data(), faces, p);
        // Closed fans: m placements; open fans: every start that leaves a face, minus
        // the one without v_l and v_r.
        uint32_t expected = 0;
        if (closed)
          expected = m;
        else
          for (int32_t il = -1; il + int32_t(faces) <= int32_t(m); ++il)
            expected += open_placement_valid(il, faces, m);
        EXPECT_EQ(p.count, expected);
        for (uint32_t k = 0; k < p.count; ++k) {
          uint32_t j = kNone;
          SplitSymbols s;
          patch_symbols(ring, spokes.data(), p.il[k], faces, key, j, s);
          PatchRange range;
          ASSERT_TRUE(resolve_patch(ring, j, s, range)) << "placement " << k;
          EXPECT_EQ(s.s_l + s.s_r, faces);
          const int32_t il = p.il[k], ir = il + int32_t(faces);
          EXPECT_EQ(range.il, il < 0 ? kNone : uint32_t(il) % m);
          EXPECT_EQ(range.ir, !closed && ir == int32_t(m) ? kNone : uint32_t(ir) % m);
          // v_ref: the longest spoke strictly inside the patch, if any.
          if (faces >= 2)
            for (int32_t t = il + 1; t < ir; ++t) {
              if (!closed && (t < 0 || t >= int32_t(m)))
                continue;
              EXPECT_GE(spokes[j].len2, spokes[uint32_t(t) % m].len2);
            }
        }
      }
    }
}

TEST(PatchRank, ScoresFollowTheirDefinitionOnRandomRings) {
  // Every placement in order of il, scored from the logs of its interior spokes (smallest,
  // then sum; a one-face patch: its two sides), whatever the loop that computes them.
  std::mt19937 rng(5);
  PatchPlacements p;
  for (int round = 0; round < 20; ++round)
    for (bool closed : {true, false})
      for (uint32_t m = 2; m <= 20; ++m) {
        const Ring ring = make_ring(m, closed);
        std::vector<Spoke> spokes(m);
        for (Spoke &s : spokes) // ties, zero and long spokes
          s.len2 = rng() % 4 == 0 ? int64_t(rng() % 3) : int64_t(rng()) * int64_t(rng() % 1000);
        const auto lg = [&](int32_t i) {
          return int64_t(log2_q8(uint64_t(spokes[uint32_t(i) % m].len2)));
        };
        for (uint32_t faces = 1; faces + (closed ? 1 : 0) <= m; ++faces) {
          SCOPED_TRACE(std::to_string(m) + (closed ? " closed, " : " open, ") +
                       std::to_string(faces) + " faces");
          score_placements(ring, spokes.data(), faces, p);
          uint32_t k = 0;
          for (int32_t il = closed ? 0 : -1;
               closed ? il < int32_t(m) : il + int32_t(faces) <= int32_t(m); ++il) {
            if (!closed && !open_placement_valid(il, faces, m))
              continue;
            const int32_t ir = il + int32_t(faces);
            int64_t score = lg(il) + lg(ir);
            if (faces > 1) {
              int64_t least = lg(il + 1), sum = 0;
              for (int32_t t = il + 1; t < ir; ++t) {
                least = std::min(least, lg(t));
                sum += lg(t);
              }
              score = least * (int64_t(1) << 32) + sum;
            }
            ASSERT_LT(k, p.count);
            EXPECT_EQ(p.il[k], il);
            EXPECT_EQ(p.score[k], score) << "il " << il;
            ++k;
          }
          EXPECT_EQ(p.count, k);
        }
      }
}

TEST(PatchRank, LongerInteriorSpokesRankFirst) {
  // A closed fan of 6 whose spokes 2 and 3 are long: the 3-face patch from 1 to 4 holds
  // both inside and ranks first; its v_ref is the longer of them.
  const Ring ring = make_ring(6, true);
  std::vector<Spoke> spokes(6);
  const int64_t len2[6] = {100, 100, 400, 300, 100, 100};
  for (int i = 0; i < 6; ++i)
    spokes[i].len2 = len2[i];
  PatchPlacements p;
  score_placements(ring, spokes.data(), 3, p);
  const uint32_t best = placement_of_rank(p, 0);
  EXPECT_EQ(p.il[best], 1);
  uint32_t j = kNone;
  SplitSymbols s;
  patch_symbols(
      ring, spokes.data(), p.il[best], 3, [](uint32_t v) { return uint64_t(v); }, j, s);
  EXPECT_EQ(j, 2u);
  EXPECT_EQ(s.s_l, 1u);
  EXPECT_EQ(s.s_r, 2u);
}

} // namespace
} // namespace pomar
