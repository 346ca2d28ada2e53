// Decoding random-access files on several threads: the clusters of a level are traversed in
// parallel, numbered in cluster order and applied in parallel, a window of clusters at a
// time (decode/level_schedule.h), so 1, 2 and 7 threads must give the same mesh
// (positions, triangles, attributes, lineage), the same reads and, on damaged files, the same
// errors and the same skipped blocks. Pure progressive files decode on one thread.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

constexpr unsigned kThreadCounts[] = {1, 2, 7};

/// A noisy sphere with a colour and a scalar per vertex.
Mesh sphere_with_attributes(size_t vertices, uint32_t seed) {
  Mesh m = gen::noisy_sphere(vertices, seed);
  VertexAttribute colour{AttributeKind::Colour, "colour", 3, {}, {}};
  VertexAttribute quality{AttributeKind::Scalar, "quality", 1, {}, {}};
  for (size_t v = 0; v < m.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k)
      colour.colour.push_back(
          static_cast<uint8_t>(127.5 + 120 * std::sin(3.0 * m.positions[3 * v + k] + k)));
    quality.values.push_back(m.positions[3 * v] * m.positions[3 * v + 1]);
  }
  m.attributes = {colour, quality};
  return m;
}

std::vector<uint8_t> encode_with(const Mesh &m, double ratio, bool progressive = false) {
  EncodeOptions o;
  o.cluster_ratio = ratio;
  o.progressive = progressive;
  return encode(m, o);
}

void expect_same_mesh(const Mesh &a, const Mesh &b, const std::string &what) {
  EXPECT_EQ(a.positions, b.positions) << what;
  EXPECT_EQ(a.triangles, b.triangles) << what;
  ASSERT_EQ(a.attributes.size(), b.attributes.size()) << what;
  for (size_t i = 0; i < a.attributes.size(); ++i) {
    EXPECT_EQ(a.attributes[i].name, b.attributes[i].name) << what;
    EXPECT_EQ(a.attributes[i].colour, b.attributes[i].colour) << what;
    EXPECT_EQ(a.attributes[i].values, b.attributes[i].values) << what;
  }
}

// The decodes below put every clustered level on the threads (min_parallel_vertices = 0):
// by default small levels stay on the calling thread, which would leave most levels of
// these small meshes off the parallel path under test.
Mesh full_decode(const std::vector<uint8_t> &file, unsigned threads, int level = -1,
                 uint32_t min_parallel_vertices = 0) {
  DecodeOptions o;
  o.threads = threads;
  o.min_parallel_vertices = min_parallel_vertices;
  o.level = level;
  return decode(file.data(), file.size(), o);
}

/// Everything a selective decoder shows after a request.
struct Snapshot {
  Mesh mesh;
  std::vector<uint32_t> cluster, level;
  std::vector<int> levels;
  uint64_t bytes = 0;
  uint32_t blocks = 0;
};

Snapshot snapshot(const SelectiveDecoder &d) {
  return {d.mesh(),   d.vertex_cluster(), d.vertex_level(),
          d.levels(), d.bytes_read(),     d.blocks_read()};
}

void expect_same(const Snapshot &a, const Snapshot &b, const std::string &what) {
  expect_same_mesh(a.mesh, b.mesh, what);
  EXPECT_EQ(a.cluster, b.cluster) << what;
  EXPECT_EQ(a.level, b.level) << what;
  EXPECT_EQ(a.levels, b.levels) << what;
  EXPECT_EQ(a.bytes, b.bytes) << what;
  EXPECT_EQ(a.blocks, b.blocks) << what;
}

/// Three requests in a row on one decoder (a region, a finer and wider one, then a
/// coarser one that re-decodes), seen after each.
std::vector<Snapshot> selective_session(const std::vector<uint8_t> &file, unsigned threads) {
  SelectiveOptions o;
  o.threads = threads;
  o.min_parallel_vertices = 0;
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()), o);
  std::vector<Snapshot> seen;
  std::mt19937 rng(7);
  const uint32_t n = d.cluster_count();
  for (uint32_t i = 0; i < n / 10 + 1; ++i)
    d.want_cluster(rng() % n, d.finest_level());
  d.update();
  seen.push_back(snapshot(d));
  d.want_all(d.base_clustered_level() + 1);
  for (uint32_t i = 0; i < n / 4 + 1; ++i)
    d.want_cluster(rng() % n, d.finest_level() - int(rng() % 2));
  d.update();
  seen.push_back(snapshot(d));
  d.clear_wanted();
  d.want_cluster(n / 2, d.finest_level());
  d.update();
  seen.push_back(snapshot(d));
  return seen;
}

struct Case {
  const char *name;
  Mesh mesh;
  double ratio;
};

std::vector<Case> cases() {
  std::vector<Case> out;
  out.push_back({"noisy sphere 30k, colour + scalar", sphere_with_attributes(30000, 3), 0.01});
  out.push_back({"torus, many small clusters", gen::torus(120, 60), 0.05});
  out.push_back({"grid with holes (boundaries)", gen::grid_with_holes(90, 6), 0.02});
  out.push_back({"several components", gen::components(5), 0.05});
  // More clusters than the decoder's window of 2048 (decode/selective_decoder.cpp): a level
  // runs in three windows, numbered after one another (the test below checks the count).
  out.push_back({"noisy sphere 30k in 5,000 clusters", gen::noisy_sphere(30000, 4), 1.0 / 6});
  return out;
}

TEST(DecodeThreads, TheManyClusterCaseSpansSeveralWindows) {
  const Case c = cases().back();
  const std::vector<uint8_t> file = encode_with(c.mesh, c.ratio);
  EXPECT_GT(inspect(file.data(), file.size()).clusters, 2u * 2048);
}

TEST(DecodeThreads, FullDecodesAreTheSameForAnyThreadCount) {
  for (const Case &c : cases()) {
    const std::vector<uint8_t> file = encode_with(c.mesh, c.ratio);
    const Mesh one = full_decode(file, 1);
    for (unsigned t : kThreadCounts)
      expect_same_mesh(one, full_decode(file, t),
                       std::string(c.name) + ", " + std::to_string(t) + " threads");
    // The default: small levels on the calling thread, the others on the threads.
    expect_same_mesh(one, full_decode(file, 2, -1, DecodeOptions().min_parallel_vertices),
                     std::string(c.name) + ", 2 threads, small levels on one");
    // A level between the base clustered mesh and the finest.
    const FileInfo info = inspect(file.data(), file.size());
    const int mid = int(info.global_levels + info.levels.size()) / 2 + 1;
    for (unsigned t : kThreadCounts)
      expect_same_mesh(full_decode(file, 1, mid), full_decode(file, t, mid),
                       std::string(c.name) + ", level " + std::to_string(mid));
  }
}

TEST(DecodeThreads, SelectiveSessionsAreTheSameForAnyThreadCount) {
  for (const Case &c : cases()) {
    const std::vector<uint8_t> file = encode_with(c.mesh, c.ratio);
    const std::vector<Snapshot> one = selective_session(file, 1);
    for (unsigned t : kThreadCounts) {
      const std::vector<Snapshot> other = selective_session(file, t);
      ASSERT_EQ(one.size(), other.size());
      for (size_t i = 0; i < one.size(); ++i)
        expect_same(one[i], other[i],
                    std::string(c.name) + ", request " + std::to_string(i) + ", " +
                        std::to_string(t) + " threads");
    }
  }
}

TEST(DecodeThreads, ProgressiveFilesAreUnchanged) {
  const Mesh m = gen::noisy_sphere(20000, 5);
  const std::vector<uint8_t> file = encode_with(m, 0.01, true);
  const Mesh one = full_decode(file, 1);
  for (unsigned t : kThreadCounts)
    expect_same_mesh(one, full_decode(file, t), std::to_string(t) + " threads");
}

/// What a decode of a damaged file gives: the mesh and skipped blocks, or the error.
struct Outcome {
  Mesh mesh;
  std::vector<std::string> damaged;
  std::string error;
};

Outcome damaged_decode(const std::vector<uint8_t> &file, unsigned threads, bool skip) {
  Outcome out;
  DecodeOptions o;
  o.threads = threads;
  o.min_parallel_vertices = 0;
  o.skip_damaged = skip;
  DecodeReport report;
  try {
    out.mesh = decode(file.data(), file.size(), o, &report);
  } catch (const Error &e) {
    out.error = e.what();
  }
  for (const DamagedBlock &b : report.damaged)
    out.damaged.push_back(b.block + " @" + std::to_string(b.level_kept) + ": " + b.problem);
  return out;
}

/// Damage in one to three places of the cluster blocks of `file`, `trials` times: 1, 2 and
/// 7 threads give the same errors, skipped blocks and meshes, with and without skipping.
void expect_same_damage_outcomes(const std::vector<uint8_t> &file, int trials, int min_each) {
  const FileInfo info = inspect(file.data(), file.size());
  std::mt19937 rng(11);
  const uint64_t clusters_from = info.global_bytes, size = file.size();
  int failed = 0, skipped = 0; // (the trials must exercise both)
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<uint8_t> bad = file;
    const int flips = 1 + trial % 3; // damage in one to three places of the cluster blocks
    for (int f = 0; f < flips; ++f)
      bad[clusters_from + rng() % (size - clusters_from)] ^= uint8_t(1 + rng() % 255);
    for (bool skip : {false, true}) {
      const Outcome one = damaged_decode(bad, 1, skip);
      failed += !one.error.empty();
      skipped += !one.damaged.empty();
      for (unsigned t : {2u, 7u}) {
        const Outcome other = damaged_decode(bad, t, skip);
        const std::string what = "trial " + std::to_string(trial) + (skip ? ", skip" : "") + ", " +
                                 std::to_string(t) + " threads";
        EXPECT_EQ(one.error, other.error) << what;
        EXPECT_EQ(one.damaged, other.damaged) << what;
        expect_same_mesh(one.mesh, other.mesh, what);
      }
    }
  }
  EXPECT_GT(failed, min_each);
  EXPECT_GT(skipped, min_each);
}

TEST(DecodeThreads, DamagedFilesGiveTheSameResultForAnyThreadCount) {
  expect_same_damage_outcomes(encode_with(gen::noisy_sphere(12000, 9), 0.02), 24, 8);
}

TEST(DecodeThreads, DamagedFilesOfSeveralWindowsGiveTheSameResultForAnyThreadCount) {
  // (5,000 clusters: damage in a later window comes after whole windows were applied.)
  expect_same_damage_outcomes(encode_with(gen::noisy_sphere(30000, 4), 1.0 / 6), 9, 3);
}

} // namespace
} // namespace pomar
