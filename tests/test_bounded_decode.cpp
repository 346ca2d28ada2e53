// decode_to_ply_bounded (pomar/mesh_io.h): a full decode written region by region within a
// memory limit is the file a whole decode writes, byte for byte; what it cannot take is
// refused with the reason, and a limit below its smallest region names what it needs.
#include <pomar/limits.h>
#include <pomar/mesh_io.h>
#include <pomar/pomar.h>
#include <pomar/random_access.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support/mesh_gen.h"
#include "support/temp_dir.h"

namespace pomar {
namespace {

using BoundedDecodeTest = test::TempDirTest;

std::string read_bytes(const std::string &path) {
  const std::vector<uint8_t> b = read_file(path);
  return std::string(b.begin(), b.end());
}

/// Several components, holes (boundaries: splits that add one face) and a closed genus-2
/// surface.
Mesh scan_like() {
  Mesh m = gen::noisy_sphere(3000, 3);
  gen::append(m, gen::grid_with_holes(30, 3), 3.0);
  gen::append(m, gen::multi_torus(2, 12), -3.0);
  return m;
}

/// The limit that leaves room for about `fraction` of the whole mesh's decode beside the
/// fixed part of the estimate.
uint64_t limit_for(const std::string &file, double fraction, unsigned threads) {
  SelectiveDecoder d(std::make_unique<FileSource>(file));
  const std::vector<int> all(d.cluster_count(), d.finest_level());
  const std::vector<int> base(d.cluster_count(), d.base_clustered_level());
  const AttributeMask none = AttributeMask::none();
  const int g = d.base_clustered_level();
  const uint64_t whole = level_map_memory_estimate(d.info(), all, g, none, threads);
  const uint64_t least = level_map_memory_estimate(d.info(), base, g, none, threads);
  return least + uint64_t(fraction * double(whole - least));
}

TEST_F(BoundedDecodeTest, WritesTheWholeDecodesFileInRegions) {
  const Mesh input = scan_like();
  EncodeOptions eo;
  eo.cluster_ratio = 0.03;
  const std::vector<uint8_t> file = encode(input, eo);
  write_file_atomic(path("m.pomar"), file.data(), file.size());
  save_mesh(path("whole.ply"), decode(file.data(), file.size()));
  const std::string whole = read_bytes(path("whole.ply"));

  for (unsigned threads : {1u, 2u}) {
    for (double fraction : {0.75}) {
      BoundedDecodeOptions o;
      o.threads = threads;
      o.min_parallel_vertices = 0; // every level on the threads
      o.memory_limit = limit_for(path("m.pomar"), fraction, threads);
      std::vector<std::pair<double, std::string>> stages;
      o.progress = [&](double f, const char *stage) { stages.emplace_back(f, stage); };
      const BoundedDecodeReport r = decode_to_ply_bounded(path("m.pomar"), path("b.ply"), o);
      EXPECT_GT(r.regions, 1u) << fraction;
      EXPECT_LE(r.largest_region, o.memory_limit);
      EXPECT_EQ(r.vertices, input.vertex_count());
      EXPECT_EQ(r.faces, input.triangle_count());
      EXPECT_TRUE(read_bytes(path("b.ply")) == whole)
          << "threads " << threads << ", fraction " << fraction << ", " << r.regions << " regions";
      ASSERT_EQ(stages.size(), 2 * size_t(r.regions));
      EXPECT_EQ(stages.front().second, "count");
      EXPECT_EQ(stages.back().second, "write");
      EXPECT_DOUBLE_EQ(stages.back().first, 1.0);
    }
  }
  // A limit that holds everything: one region, the same file.
  BoundedDecodeOptions o;
  o.memory_limit = kNoMemoryLimit - 1;
  const BoundedDecodeReport r = decode_to_ply_bounded(path("m.pomar"), path("one.ply"), o);
  EXPECT_EQ(r.regions, 1u);
  EXPECT_TRUE(read_bytes(path("one.ply")) == whole);
  EXPECT_EQ(list_dir().size(), 4u) << "no temporary file left";
}

TEST_F(BoundedDecodeTest, ALimitBelowOneClusterNamesWhatItNeeds) {
  const std::vector<uint8_t> file = encode(gen::noisy_sphere(3000, 1));
  write_file_atomic(path("m.pomar"), file.data(), file.size());
  BoundedDecodeOptions o;
  o.memory_limit = 1 << 20;
  try {
    decode_to_ply_bounded(path("m.pomar"), path("b.ply"), o);
    FAIL() << "no error";
  } catch (const Error &e) {
    EXPECT_EQ(e.kind(), Error::Kind::MemoryLimit);
    const std::string what = e.what();
    EXPECT_NE(what.find("smallest region"), std::string::npos) << what;
    EXPECT_NE(what.find("in all; the limit is 1.0 MiB"), std::string::npos) << what;
  }
  EXPECT_EQ(list_dir().size(), 1u) << "no output, no temporary file";
}

TEST_F(BoundedDecodeTest, RefusesWhatItCannotWriteSayingWhy) {
  struct Case {
    const char *name;
    Mesh mesh;
    EncodeOptions options;
    const char *reason;
  };
  EncodeOptions progressive;
  progressive.progressive = true;
  Mesh coloured = gen::noisy_sphere(2000, 2);
  VertexAttribute colour;
  colour.kind = AttributeKind::Colour;
  colour.name = "colour";
  colour.components = 3;
  colour.colour.assign(3 * coloured.vertex_count(), 7);
  coloured.attributes.push_back(colour);
  std::vector<Case> cases;
  cases.push_back({"progressive", gen::noisy_sphere(2000, 2), progressive, "pure progressive"});
  cases.push_back({"attributes", coloured, {}, "per-vertex attributes"});
  Mesh unreferenced = gen::noisy_sphere(2000, 2);
  gen::detail::add_vertex(unreferenced, 5, 5, 5); // a vertex no face uses: the record keeps it
  cases.push_back({"lossless", unreferenced, {}, "lossless record"});
  for (const Case &c : cases) {
    const std::vector<uint8_t> file = encode(c.mesh, c.options);
    write_file_atomic(path("m.pomar"), file.data(), file.size());
    try {
      decode_to_ply_bounded(path("m.pomar"), path("b.ply"));
      ADD_FAILURE() << c.name << ": no error";
    } catch (const Error &e) {
      EXPECT_EQ(e.kind(), Error::Kind::Unsupported) << c.name;
      EXPECT_NE(std::string(e.what()).find(c.reason), std::string::npos) << e.what();
    }
  }
  try {
    decode_to_ply_bounded(path("m.pomar"), path("b.obj"));
    ADD_FAILURE() << "an OBJ output: no error";
  } catch (const Error &e) {
    EXPECT_EQ(e.kind(), Error::Kind::Usage);
  }
}

} // namespace
} // namespace pomar
