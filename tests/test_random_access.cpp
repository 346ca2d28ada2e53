// Random access: selective decoding against the level map, delta refinement, coarsening.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <set>

#include "format/file_format.h"
#include "mesh/corner_table.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/mesh_compare.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

using Tri = test::PositionTriangle;
using test::canonical;

struct Encoded {
  Mesh input;
  std::vector<uint8_t> file;
  FileInfo info;
};

Encoded encode_clustered(Mesh m, double ratio) {
  Encoded e;
  e.input = std::move(m);
  EncodeOptions o;
  o.cluster_ratio = ratio;
  e.file = encode(e.input, o);
  e.info = inspect(e.file.data(), e.file.size());
  return e;
}

/// The bytes of the file's section `tag` (0 without one).
uint64_t section_bytes(const Encoded &e, uint32_t tag) {
  const FileLayout layout = read_layout(e.file.data(), e.file.size());
  const int i = find_section(layout, tag);
  return i < 0 ? 0 : layout.header.sections[size_t(i)].bytes;
}
/// What opening the file reads: the global part but for the per-cluster sections (the
/// stored errors, read for a view; the blocks' checks, read with the first block).
uint64_t open_bytes(const Encoded &e) {
  return e.info.global_bytes - section_bytes(e, section_tag("CERR")) -
         section_bytes(e, section_tag("BCHK"));
}

std::unique_ptr<SelectiveDecoder> open(const Encoded &e) {
  return std::make_unique<SelectiveDecoder>(
      std::make_unique<MemorySource>(e.file.data(), e.file.size()));
}

/// Everything the result of a request must satisfy.
void check_state(const Encoded &e, const SelectiveDecoder &d) {
  const Mesh m = d.mesh();
  CornerTable ct;
  ASSERT_NO_THROW(build_corner_table(m.triangles.data(), m.triangle_count(), m.vertex_count(), ct));
  const gen::TopologyReport t = gen::analyze(m);
  EXPECT_TRUE(t.manifold && t.oriented);
  // Level map: neighbours at most one level apart, within the file's levels.
  const std::vector<int> &levels = d.levels();
  const FileInfo &info = d.info();
  ASSERT_EQ(levels.size(), info.clusters);
  const Mesh base = decode(e.file.data(), e.file.size(), int(info.global_levels));
  for (size_t f = 0; f < base.triangle_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = base.triangles[3 * f + k], b = base.triangles[3 * f + (k + 1) % 3];
      EXPECT_LE(std::abs(levels[a] - levels[b]), 1);
    }
  // Every vertex exists at its cluster's level, and sits at a full-resolution position.
  const std::vector<uint32_t> vc = d.vertex_cluster(), vl = d.vertex_level();
  std::set<std::array<float, 3>> full;
  const Mesh finest = decode(e.file.data(), e.file.size());
  for (size_t v = 0; v < finest.vertex_count(); ++v)
    full.insert(
        {finest.positions[3 * v], finest.positions[3 * v + 1], finest.positions[3 * v + 2]});
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    EXPECT_LE(int(vl[v]), levels[vc[v]]);
    EXPECT_TRUE(full.count({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]}));
  }
  // Only the blocks the map requires were read (clusters below the finest level read only
  // the part of their block they decode): the global part plus at most their bytes.
  // (The blocks' checks, section BCHK, are read with the first block; the stored errors,
  // CERR, are not read without a view.)
  uint32_t refined = 0;
  uint64_t bytes = open_bytes(e);
  const FileInfo full_info = inspect(e.file.data(), e.file.size());
  for (size_t c = 0; c < levels.size(); ++c)
    if (levels[c] > int(info.global_levels)) {
      ++refined;
      bytes += full_info.cluster_block_bytes[c];
    }
  const uint64_t checks = refined ? section_bytes(e, section_tag("BCHK")) : 0;
  EXPECT_EQ(d.blocks_read(), refined);
  EXPECT_EQ(d.clusters_decoded(), refined);
  EXPECT_LE(d.bytes_read(), bytes + checks);
  EXPECT_GE(d.bytes_read(), open_bytes(e) + checks + refined);
}

std::vector<Encoded> cases() {
  std::vector<Encoded> out;
  out.push_back(encode_clustered(gen::icosphere(5), 0.02));
  out.push_back(encode_clustered(gen::torus(80, 40), 0.04));
  out.push_back(encode_clustered(gen::grid_with_holes(80, 4), 0.03));
  out.push_back(encode_clustered(gen::components(4), 0.05));
  return out;
}

TEST(RandomAccess, FilesAreClustered) {
  for (const Encoded &e : cases()) {
    EXPECT_GT(e.info.clusters, 10u);
    EXPECT_LT(e.info.global_levels, e.info.levels.size());
  }
}

TEST(RandomAccess, NothingRequestedIsTheBaseClusteredMesh) {
  for (const Encoded &e : cases()) {
    auto d = open(e);
    d->update();
    const Mesh m = d->mesh();
    EXPECT_EQ(canonical(m),
              canonical(decode(e.file.data(), e.file.size(), int(e.info.global_levels))));
    EXPECT_EQ(d->blocks_read(), 0u);
    EXPECT_GT(section_bytes(e, section_tag("CERR")), 0u);
    EXPECT_GT(section_bytes(e, section_tag("BCHK")), 0u);
    EXPECT_EQ(d->bytes_read(), open_bytes(e)); // not the per-cluster sections
  }
}

TEST(RandomAccess, EverythingRequestedIsTheLosslessFullDecode) {
  for (const Encoded &e : cases()) {
    auto d = open(e);
    d->want_all(d->finest_level());
    d->update();
    const Mesh full = decode(e.file.data(), e.file.size());
    const Mesh m = d->mesh();
    EXPECT_EQ(m.positions, full.positions); // same vertices in the same order
    EXPECT_EQ(canonical(m), canonical(full));
    // Everything but the stored errors (no view asked for them).
    EXPECT_EQ(d->bytes_read(), e.info.total_bytes - section_bytes(e, section_tag("CERR")));
  }
}

TEST(RandomAccess, RandomRequestsRespectTheLevelMap) {
  std::mt19937 rng(5);
  for (const Encoded &e : cases()) {
    for (int trial = 0; trial < 6; ++trial) {
      auto d = open(e);
      const int lo = d->base_clustered_level(), hi = d->finest_level();
      const int picks = 1 + int(rng() % 4);
      for (int i = 0; i < picks; ++i)
        d->want_cluster(rng() % d->cluster_count(), lo + int(rng() % uint32_t(hi - lo + 1)));
      d->update();
      check_state(e, *d);
    }
  }
}

TEST(RandomAccess, RefiningInTwoStepsEqualsRefiningInOne) {
  std::mt19937 rng(11);
  for (const Encoded &e : cases()) {
    for (int trial = 0; trial < 4; ++trial) {
      auto one = open(e), two = open(e);
      const uint32_t a = rng() % one->cluster_count(), b = rng() % one->cluster_count();
      const int finest = one->finest_level();
      const int mid = (one->base_clustered_level() + finest) / 2;
      one->want_cluster(a, mid);
      one->want_cluster(b, finest);
      one->update();
      two->want_cluster(a, mid);
      two->update();
      two->want_cluster(b, finest);
      two->update();
      EXPECT_EQ(one->levels(), two->levels());
      EXPECT_EQ(canonical(one->mesh()), canonical(two->mesh()));
      check_state(e, *two);
    }
  }
}

TEST(RandomAccess, CoarseningRedecodes) {
  const Encoded e = encode_clustered(gen::icosphere(5), 0.02);
  auto d = open(e), fresh = open(e);
  d->want_all(d->finest_level());
  d->update();
  std::vector<int> wanted(d->cluster_count(), d->base_clustered_level());
  wanted[3] = d->finest_level();
  d->set_wanted(wanted);
  d->update();
  fresh->want_cluster(3, fresh->finest_level());
  fresh->update();
  EXPECT_EQ(canonical(d->mesh()), canonical(fresh->mesh()));
}

TEST(RandomAccess, OneClusterReadsOnlyPartOfTheFile) {
  const Encoded e = encode_clustered(gen::noisy_sphere(60000, 3), 0.03);
  auto d = open(e);
  d->want_cluster(0, d->finest_level());
  d->update();
  check_state(e, *d);
  EXPECT_LT(d->bytes_read(), e.info.total_bytes / 2);
  EXPECT_LT(d->mesh().vertex_count(), e.info.vertices / 2);
}

TEST(RandomAccess, SphereAndBoxRequestsPickNearbyClusters) {
  const Encoded e = encode_clustered(gen::icosphere(5), 0.02);
  auto d = open(e);
  const float c[3] = {0, 0, 1}, lo[3] = {-2, -2, -2}, hi[3] = {2, 2, -0.9f};
  d->want_sphere(c, 0.2f, d->finest_level());
  d->want_box(lo, hi, d->finest_level());
  d->update();
  const Mesh m = d->mesh();
  const std::vector<uint32_t> vl = d->vertex_level();
  // Vertices near the requested spots are at the finest level, the equator is coarser.
  size_t fine_near = 0, fine_equator = 0;
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    const float z = m.positions[3 * v + 2];
    if (int(vl[v]) == d->finest_level())
      (std::abs(z) < 0.2f ? fine_equator : fine_near)++;
  }
  EXPECT_GT(fine_near, 0u);
  EXPECT_EQ(fine_equator, 0u);
  check_state(e, *d);
}

TEST(RandomAccess, BadRequestsAreErrors) {
  const Encoded e = encode_clustered(gen::icosphere(4), 0.02);
  auto d = open(e);
  EXPECT_THROW(d->want_cluster(d->cluster_count(), d->finest_level()), Error);
  EXPECT_THROW(d->want_cluster(0, d->finest_level() + 1), Error);
  EXPECT_THROW(d->want_vertices({1u << 30}, d->finest_level()), Error);
}

TEST(RandomAccess, LevelMapCompletion) {
  // A path of 5 clusters: 0-1-2-3-4.
  const std::vector<uint32_t> start = {0, 1, 3, 5, 7, 8};
  const std::vector<uint32_t> adj = {1, 0, 2, 1, 3, 2, 4, 3};
  EXPECT_EQ(complete_level_map({10, 0, 0, 0, 0}, start, adj, 6),
            (std::vector<int>{10, 9, 8, 7, 6}));
  EXPECT_EQ(complete_level_map({0, 0, 9, 0, 0}, start, adj, 6), (std::vector<int>{7, 8, 9, 8, 7}));
  EXPECT_EQ(complete_level_map({0, 0, 0, 0, 0}, start, adj, 6), (std::vector<int>(5, 6)));
  // Clusters 0 and 4 linked (the copies of a seam vertex): one level, the higher one.
  const std::vector<uint32_t> link_start = {0, 1, 1, 1, 1, 2}, link = {4, 0};
  EXPECT_EQ(complete_level_map({10, 0, 0, 0, 0}, start, adj, 6, link_start, link),
            (std::vector<int>{10, 9, 8, 9, 10}));
  EXPECT_EQ(complete_level_map({0, 0, 0, 7, 0}, start, adj, 6, link_start, link),
            (std::vector<int>{6, 6, 6, 7, 6}));
  EXPECT_EQ(complete_level_map({0, 0, 0, 8, 0}, start, adj, 6, link_start, link),
            (std::vector<int>{7, 6, 7, 8, 7}));
}

/// A colour per vertex from its position, so that take_mesh() has attributes to hand over.
Mesh coloured(Mesh m) {
  VertexAttribute c;
  c.kind = AttributeKind::Colour;
  c.name = "colour";
  c.components = 3;
  for (float x : m.positions)
    c.colour.push_back(static_cast<uint8_t>(int(std::abs(x) * 977.0f) & 255));
  m.attributes.push_back(std::move(c));
  return m;
}

/// Same positions, triangles and colours, in the same order.
void expect_same_mesh(const Mesh &a, const Mesh &b) {
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.triangles, b.triangles);
  ASSERT_EQ(a.attributes.size(), b.attributes.size());
  for (size_t i = 0; i < a.attributes.size(); ++i)
    EXPECT_EQ(a.attributes[i].colour, b.attributes[i].colour);
}

/// take_mesh() gives what mesh() gives, leaves the decoder at the base (clustered) mesh with
/// the requests kept, and the next update() brings the same mesh back.
void expect_take_mesh_round_trip(SelectiveDecoder &d, const Mesh &base) {
  const Mesh before = d.mesh();
  expect_same_mesh(d.take_mesh(), before);
  expect_same_mesh(d.mesh(), base);
  d.update();
  expect_same_mesh(d.mesh(), before);
}

TEST(RandomAccess, TakeMeshHandsTheMeshOverAndGoesBackToTheBase) {
  const Encoded e = encode_clustered(coloured(gen::torus(60, 30)), 0.04);
  ASSERT_GT(e.info.clusters, 10u);
  auto d = open(e);
  const Mesh base = d->mesh();
  ASSERT_FALSE(base.attributes.empty());
  for (uint32_t c = 0; c < d->cluster_count(); c += 3)
    d->want_cluster(c, d->finest_level());
  d->update();
  EXPECT_FALSE(d->complete());
  expect_take_mesh_round_trip(*d, base);
  auto fresh = open(e);
  for (uint32_t c = 0; c < fresh->cluster_count(); c += 3)
    fresh->want_cluster(c, fresh->finest_level());
  fresh->update();
  EXPECT_EQ(d->levels(), fresh->levels());
  // (a fresh decoder: one refined in two steps numbers its vertices in another order)
  auto full = open(e);
  full->want_all(full->finest_level());
  full->update();
  EXPECT_TRUE(full->complete());
  expect_take_mesh_round_trip(*full, base);
}

TEST(RandomAccess, TakeMeshOfAProgressiveFile) {
  EncodeOptions o;
  o.progressive = true;
  const Mesh m = coloured(gen::icosphere(4));
  const std::vector<uint8_t> file = encode(m, o);
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()));
  const Mesh base = d.mesh();
  d.want_all(3);
  d.update();
  expect_take_mesh_round_trip(d, base);
}

TEST(RandomAccess, ProgressiveModeStaysAvailable) {
  EncodeOptions o;
  o.progressive = true;
  const Mesh m = gen::icosphere(4);
  const std::vector<uint8_t> file = encode(m, o);
  const FileInfo info = inspect(file.data(), file.size());
  EXPECT_EQ(info.clusters, 0u);
  EXPECT_EQ(info.global_levels, info.levels.size());
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()));
  d.want_all(3);
  d.update();
  EXPECT_EQ(d.mesh().vertex_count(), info.levels[2].vertices);
}

} // namespace
} // namespace pomar
