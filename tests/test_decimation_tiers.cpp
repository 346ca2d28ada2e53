// Decimation in tiers (DecimationOptions::tiers, docs/format.md "Version 5", part 1): every
// collapse of a tier joins two vertices of one cell, no border vertex of a tier collapses
// (neither v_from nor v_to), the border is the same at both ends of the tier; the files it
// makes decode losslessly and select clusters like any file.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>

#include "decimate/decimate.h"
#include "geometry/quantize.h"
#include "mesh/corner_table.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/mesh_compare.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

/// The mesh replayed collapse by collapse: where each input vertex went.
struct Replay {
  std::vector<uint32_t> to; // to[v] == v while v lives
  explicit Replay(size_t n) : to(n) {
    for (uint32_t v = 0; v < n; ++v)
      to[v] = v;
  }
  uint32_t find(uint32_t v) {
    while (to[v] != v)
      v = to[v] = to[to[v]];
    return v;
  }
  void apply(const Collapse &c) { to[c.v_from] = c.v_to; }
};

/// The border vertices of tier `t` in the mesh `triangles` as replayed so far: those with a
/// neighbour in another cell.
std::set<uint32_t> border_of(const DecimationTier &t, const std::vector<uint32_t> &triangles,
                             const std::vector<int32_t> &q, Replay &r) {
  std::set<uint32_t> border;
  for (size_t f = 0; f < triangles.size(); f += 3) {
    const uint32_t v[3] = {r.find(triangles[f]), r.find(triangles[f + 1]),
                           r.find(triangles[f + 2])};
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
      continue; // a face the collapses removed
    for (int j = 0; j < 3; ++j) {
      const uint32_t a = v[j], b = v[(j + 1) % 3];
      if (tier_cell(t, &q[3 * size_t(a)]) != tier_cell(t, &q[3 * size_t(b)])) {
        border.insert(a);
        border.insert(b);
      }
    }
  }
  return border;
}

TEST(DecimationTiers, CollapsesStayInsideOneCellAndBordersStayLocked) {
  const Mesh mesh = gen::noisy_sphere(6000, 7, 0.05);
  const int bits = 12;
  const Quantizer grid = make_quantizer(mesh.positions.data(), mesh.vertex_count(), bits);
  const std::vector<int32_t> q = quantize(grid, mesh.positions.data(), mesh.vertex_count());
  CornerTable ct;
  build_corner_table(mesh.triangles.data(), mesh.triangle_count(), mesh.vertex_count(), ct);
  DecimationTiers tiers;
  tiers.rounds = 3;
  tiers.cell_vertices = 300;
  tiers.until_vertices = 200;
  tiers.bits = bits;
  DecimationOptions options;
  options.tiers = &tiers;
  const Decimation dec = decimate(std::move(ct), q, options, {});

  ASSERT_GE(dec.tiers.size(), 3u);
  Replay replay(mesh.vertex_count());
  uint32_t round = 0, multi_cell = 0;
  for (size_t i = 0; i < dec.tiers.size(); ++i) {
    const DecimationTier &t = dec.tiers[i];
    EXPECT_EQ(t.first_round, round) << "tier " << i;
    EXPECT_GE(t.rounds, 1u) << "tier " << i;
    EXPECT_LE(t.rounds, tiers.rounds) << "tier " << i;
    EXPECT_EQ(t.shifted, i % 2 == 1) << "tier " << i;
    multi_cell += t.cells > 1;
    const std::set<uint32_t> border = border_of(t, mesh.triangles, q, replay);
    EXPECT_EQ(border.size(), t.border) << "tier " << i;
    EXPECT_EQ(border.empty(), t.cells == 1) << "tier " << i; // (one cell: no border)
    size_t collapses = 0;
    for (uint32_t r = t.first_round; r < t.first_round + t.rounds; ++r)
      for (const Collapse &c : dec.levels[r]) {
        ++collapses;
        ASSERT_EQ(tier_cell(t, &q[3 * size_t(c.v_from)]), tier_cell(t, &q[3 * size_t(c.v_to)]))
            << "tier " << i << " round " << r << ": " << c.v_from << " -> " << c.v_to
            << " joins two cells";
        ASSERT_EQ(border.count(c.v_from), 0u)
            << "tier " << i << ": border vertex " << c.v_from << " collapses";
        ASSERT_EQ(border.count(c.v_to), 0u)
            << "tier " << i << ": border vertex " << c.v_to << " is a v_to";
        replay.apply(c);
      }
    EXPECT_GT(collapses, 0u) << "tier " << i;
    EXPECT_EQ(border_of(t, mesh.triangles, q, replay), border)
        << "tier " << i << ": the border changed during the tier";
    round = t.first_round + t.rounds;
  }
  EXPECT_GE(multi_cell, 3u);
  for (const DecimationTier &t : dec.tiers)
    EXPECT_GT(t.vertices, tiers.until_vertices); // no tier starts on fewer
}

TEST(DecimationTiers, OffByDefaultLeavesTheFileUnchanged) {
  const Mesh mesh = gen::noisy_sphere(3000, 3, 0.05);
  EncodeOptions o;
  o.clusters = 40;
  const std::vector<uint8_t> plain = encode(mesh, o);
  o.tier_cell_vertices = 64; // without tier_rounds: no tiers
  EncodeReport report;
  EXPECT_EQ(encode(mesh, o, &report), plain);
  EXPECT_TRUE(report.tiers.empty());
}

TEST(DecimationTiers, TieredFilesDecodeLosslessly) {
  const Mesh mesh = gen::noisy_sphere(8000, 11, 0.05);
  EncodeOptions o;
  o.clusters = 60;
  o.tier_rounds = 4;
  o.tier_cell_vertices = 256;
  EncodeReport report;
  const std::vector<uint8_t> file = encode(mesh, o, &report);
  ASSERT_GE(report.tiers.size(), 2u);
  const FileInfo info = inspect(file.data(), file.size());
  ASSERT_TRUE(info.clustered());
  EXPECT_EQ(report.tiers.front().first_level + report.tiers.front().levels - 1,
            int(info.levels.size())); // the finest tier ends at full resolution
  // A full decode gives back the input: its quantized positions, its oriented faces.
  const Mesh full = decode(file.data(), file.size());
  ASSERT_EQ(full.vertex_count(), mesh.vertex_count());
  ASSERT_EQ(full.triangle_count(), mesh.triangle_count());
  const Quantizer grid = make_quantizer(mesh.positions.data(), mesh.vertex_count(), o.bits);
  Mesh expected = mesh;
  for (size_t i = 0; i < expected.positions.size(); ++i)
    expected.positions[i] =
        grid.dequantize(int(i % 3), grid.quantize(int(i % 3), mesh.positions[i]));
  EXPECT_EQ(test::canonical(full), test::canonical(expected));
  // So does a selective decode of every cluster to the finest level.
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()));
  d.want_all(d.finest_level());
  d.update();
  EXPECT_EQ(test::canonical(d.mesh()), test::canonical(expected));
  // Per cluster, the block prefixes grow level by level to the block.
  const uint32_t levels = uint32_t(info.levels.size()) - info.global_levels;
  ASSERT_EQ(report.cluster_level_ends.size(), size_t(info.clusters) * levels);
  for (uint32_t c = 0; c < info.clusters; ++c)
    for (uint32_t j = 1; j < levels; ++j)
      ASSERT_LE(report.cluster_level_ends[c * levels + j - 1],
                report.cluster_level_ends[c * levels + j]);
}

} // namespace
} // namespace pomar
