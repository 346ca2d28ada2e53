// Lossless round trips of the progressive codec, every intermediate level, bad inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "geometry/quantize.h"
#include "mesh/corner_table.h"
#include "pomar/pomar.h"
#include "support/mesh_attributes.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

using Tri = std::array<uint32_t, 3>;

Tri canonical(uint32_t a, uint32_t b, uint32_t c) { // rotate smallest index first
  if (a <= b && a <= c)
    return {a, b, c};
  if (b <= a && b <= c)
    return {b, c, a};
  return {c, a, b};
}

/// Full decode must give the input's oriented triangles and its quantized positions.
void expect_lossless(const Mesh &input, int bits) {
  EncodeOptions opt;
  opt.bits = bits;
  EncodeReport report;
  const std::vector<uint8_t> file = encode(input, opt, &report);
  const Mesh out = decode(file.data(), file.size());
  ASSERT_EQ(out.vertex_count() + report.unreferenced_vertices, input.vertex_count());
  ASSERT_EQ(out.triangle_count(), input.triangle_count());
  ASSERT_EQ(report.decoded_to_input.size(), out.vertex_count());
  const Quantizer grid = make_quantizer(input.positions.data(), input.vertex_count(), bits);
  const std::vector<int32_t> q = quantize(grid, input.positions.data(), input.vertex_count());
  for (size_t i = 0; i < out.vertex_count(); ++i) {
    const uint32_t v = report.decoded_to_input[i];
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(out.positions[3 * i + k], grid.dequantize(k, uint32_t(q[3 * v + k])))
          << "vertex " << i << " axis " << k;
  }
  std::vector<Tri> a, b;
  for (size_t f = 0; f < input.triangle_count(); ++f)
    a.push_back(
        canonical(input.triangles[3 * f], input.triangles[3 * f + 1], input.triangles[3 * f + 2]));
  for (size_t f = 0; f < out.triangle_count(); ++f) {
    const uint32_t *t = &out.triangles[3 * f];
    b.push_back(canonical(report.decoded_to_input[t[0]], report.decoded_to_input[t[1]],
                          report.decoded_to_input[t[2]]));
  }
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
}

/// Every level decodes to a manifold oriented mesh with the announced counts.
void expect_valid_levels(const Mesh &input) {
  const std::vector<uint8_t> file = encode(input);
  const FileInfo info = inspect(file.data(), file.size());
  for (size_t level = 0; level <= info.levels.size(); ++level) {
    const Mesh m = decode(file.data(), file.size(), int(level));
    const uint32_t nv = level == 0 ? info.base_vertices : info.levels[level - 1].vertices;
    const uint32_t nf = level == 0 ? info.base_faces : info.levels[level - 1].faces;
    ASSERT_EQ(m.vertex_count(), nv) << "level " << level;
    ASSERT_EQ(m.triangle_count(), nf) << "level " << level;
    CornerTable ct;
    EXPECT_NO_THROW(
        build_corner_table(m.triangles.data(), m.triangle_count(), m.vertex_count(), ct))
        << "level " << level;
    const gen::TopologyReport t = gen::analyze(m);
    EXPECT_TRUE(t.manifold && t.oriented) << "level " << level;
  }
}

struct Case {
  const char *name;
  Mesh (*make)();
};

const Case kCases[] = {
    {"icosphere", [] { return gen::icosphere(4); }},
    {"uv_sphere", [] { return gen::uv_sphere(20, 32); }},
    {"torus", [] { return gen::torus(40, 16); }},
    {"genus3", [] { return gen::multi_torus(3, 6); }},
    {"open_with_holes", [] { return gen::grid_with_holes(40, 3); }},
    {"components", [] { return gen::components(5); }},
    {"single_triangle", [] { return gen::single_triangle(); }},
    {"tetrahedron", [] { return gen::tetrahedron(); }},
    {"flat_disk", [] { return gen::flat_disk(12); }},
    {"degenerate_strip", [] { return gen::degenerate_strip(); }},
};

class Roundtrip : public ::testing::TestWithParam<Case> {};

TEST_P(Roundtrip, LosslessAtSeveralBitDepths) {
  const Mesh m = GetParam().make();
  for (int bits : {4, 8, 12, 16, 24})
    expect_lossless(m, bits);
}

TEST_P(Roundtrip, EveryLevelIsAValidMesh) { expect_valid_levels(GetParam().make()); }

INSTANTIATE_TEST_SUITE_P(Generated, Roundtrip, ::testing::ValuesIn(kCases),
                         [](const auto &info) { return std::string(info.param.name); });

TEST(Codec, DecimatesToATinyBaseMesh) {
  const Mesh m = gen::icosphere(5); // 10242 vertices
  const std::vector<uint8_t> file = encode(m);
  const FileInfo info = inspect(file.data(), file.size());
  EXPECT_LT(info.base_vertices, 200u);
  EXPECT_GE(info.levels.size(), 8u);
}

TEST(Codec, UnreferencedVerticesAreKeptAndCounted) {
  Mesh m = gen::tetrahedron();
  m.positions.insert(m.positions.end(), {5.f, 5.f, 5.f});
  EncodeReport r;
  const std::vector<uint8_t> file = encode(m, {}, &r);
  EXPECT_EQ(r.unreferenced_vertices, 1u);
  EXPECT_EQ(decode(file.data(), file.size()).vertex_count(), 5u); // strict: 4 (test_lossless)
}

/// With `strict` the codec refuses what it would have to cut (test_lossless.cpp: the
/// default stores the cut); the other errors are the same either way.
void expect_error(const Mesh &m, const std::string &needle) {
  EncodeOptions strict;
  strict.strict = true;
  try {
    encode(m, strict);
    FAIL() << "expected an error mentioning '" << needle << "'";
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(Codec, RefusesInvalidMeshesWithClearMessages) {
  expect_error(gen::nonmanifold_edge(), "non-manifold");
  expect_error(gen::nonmanifold_vertex(), "non-manifold");
  expect_error(gen::flipped_face(), "oriented");
  expect_error(gen::repeated_vertex_face(), "repeat a vertex");
  expect_error(Mesh{}, "no triangles");
  Mesh nan = gen::tetrahedron();
  nan.positions[4] = std::nanf("");
  expect_error(nan, "non-finite");
  Mesh bad_index = gen::tetrahedron();
  bad_index.triangles[5] = 99;
  expect_error(bad_index, "vertex 99");
}

TEST(Codec, RejectsBadBitDepths) {
  EncodeOptions o;
  o.bits = 3;
  EXPECT_THROW(encode(gen::tetrahedron(), o), Error);
  o.bits = 25;
  EXPECT_THROW(encode(gen::tetrahedron(), o), Error);
}

TEST(Codec, DamagedFilesAreReportedNotMisdecoded) {
  const std::vector<uint8_t> file = encode(gen::icosphere(3));
  // Garbage and empty input.
  const std::vector<uint8_t> garbage(100, 0x5A);
  EXPECT_THROW(decode(garbage.data(), garbage.size()), Error);
  EXPECT_THROW(decode(file.data(), 0), Error);
  // Every truncation fails with an error.
  for (size_t n = 0; n < file.size(); n += std::max<size_t>(1, file.size() / 97))
    EXPECT_THROW(decode(file.data(), n), Error) << "truncated to " << n;
  // Every single-bit flip is caught (header, base block or level checksums).
  for (size_t i = 0; i < file.size(); i += std::max<size_t>(1, file.size() / 211)) {
    std::vector<uint8_t> copy = file;
    copy[i] ^= 0x10;
    EXPECT_THROW(decode(copy.data(), copy.size()), Error) << "flip at byte " << i;
  }
}

TEST(Codec, LevelOutOfRangeIsAnError) {
  const std::vector<uint8_t> file = encode(gen::icosphere(2));
  const FileInfo info = inspect(file.data(), file.size());
  EXPECT_THROW(decode(file.data(), file.size(), int(info.levels.size()) + 1), Error);
  EXPECT_THROW(decode(file.data(), file.size(), -2), Error);
}

// Decimation evaluates its candidates on several threads, and the clusters of a level are
// recorded on several threads (encode/clusters.cpp, more than one batch of clusters here):
// the file must not depend on how many (the mesh is large enough for every thread to get a
// slice), with attributes too.
TEST(Codec, FileDoesNotDependOnThreadCount) {
  const Mesh plain = gen::noisy_sphere(70000, 7);
  const Mesh coloured = with_attributes(gen::noisy_sphere(20000, 3), kColour | kNormals | kScalars);
  for (const Mesh *mesh : {&plain, &coloured}) {
    for (uint32_t clusters : {0u, 2500u}) {
      std::vector<uint8_t> files[3];
      const unsigned threads[3] = {1, 2, 7};
      for (int i = 0; i < 3; ++i) {
        EncodeOptions options;
        options.threads = threads[i];
        options.clusters = clusters;
        options.min_parallel_vertices = 0; // every clustered level on the threads
        files[i] = encode(*mesh, options);
        if (threads[i] == 2) { // and the default: the small levels on this thread
          EncodeOptions by_default = options;
          by_default.min_parallel_vertices = EncodeOptions().min_parallel_vertices;
          EXPECT_EQ(encode(*mesh, by_default), files[i]) << "clusters " << clusters;
        }
      }
      ASSERT_GT(inspect(files[0].data(), files[0].size()).clusters, 64u);
      EXPECT_EQ(files[0], files[1]) << "clusters " << clusters;
      EXPECT_EQ(files[0], files[2]) << "clusters " << clusters;
    }
  }
}

// encode(Mesh&&) frees a clean mesh once quantized: the file must be the one encode(const
// Mesh&) writes, for a clean mesh (also strict, with attributes) and for one the lossless
// stage cuts (given a mesh, it still reads it after the manifold encoder), and the mesh is
// left empty, also when the encoder refuses it.
TEST(Codec, EncodeTakingTheMeshWritesTheSameFile) {
  Mesh messy = gen::noisy_sphere(3000, 5);
  messy.triangles.insert(messy.triangles.end(), messy.triangles.begin(),
                         messy.triangles.begin() + 3); // a duplicate face: cut and recorded
  messy.positions.insert(messy.positions.end(), {0.5f, 0.5f, 0.5f}); // unreferenced
  const Mesh inputs[] = {gen::noisy_sphere(5000, 9),
                         with_attributes(gen::noisy_sphere(4000, 2), kColour | kNormals), messy};
  for (const Mesh &input : inputs)
    for (bool strict : {false, true}) {
      if (strict && &input == &inputs[2])
        continue;
      EncodeOptions options;
      options.strict = strict;
      EncodeReport given, taken;
      const std::vector<uint8_t> expected = encode(input, options, &given);
      Mesh copy = input;
      EXPECT_EQ(encode(std::move(copy), options, &taken), expected);
      EXPECT_EQ(copy.vertex_count(), 0u);
      EXPECT_TRUE(copy.triangles.empty() && copy.attributes.empty());
      EXPECT_EQ(taken.input_vertices, given.input_vertices);
      EXPECT_EQ(taken.unreferenced_vertices, given.unreferenced_vertices);
      EXPECT_EQ(taken.decoded_to_input, given.decoded_to_input);
    }
  Mesh refused = gen::nonmanifold_edge();
  EncodeOptions bad_bits;
  bad_bits.bits = 3;
  EXPECT_THROW(encode(std::move(refused), bad_bits), Error);
  EXPECT_EQ(refused.vertex_count(), 0u);
}

} // namespace
} // namespace pomar
