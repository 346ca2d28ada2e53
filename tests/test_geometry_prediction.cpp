// Format version 5's per-level normal predictor (section GEOP, geometry/predict.h): files
// that use it decode to their input, whole and cluster by cluster; the section is required
// and checked; files without it (version 5 as written before it) decode as they did.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "format/file_format.h"
#include "format/geometry_prediction.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/mesh_compare.h"
#include "support/stored_files.h"

namespace pomar {
namespace {

namespace fs = std::filesystem;
using test::on_grid;
using test::read_bytes;
const fs::path &kLegacy = test::kLegacyDir;

bool has_section(const FileInfo &info, const std::string &name, bool required) {
  for (const auto &s : info.sections)
    if (s.name == name && s.required == required)
      return true;
  return false;
}

/// samples/bunny.ply, positions and triangles (what the predictor is about).
const Mesh &bunny() {
  static const Mesh m = [] {
    Mesh b = load_mesh(std::string(POMAR_SAMPLES_DIR) + "/bunny.ply");
    b.attributes.clear();
    return b;
  }();
  return m;
}

const std::vector<uint8_t> &bunny_file(bool progressive) {
  static const std::vector<uint8_t> files[2] = {[] {
                                                  EncodeOptions o;
                                                  return encode(bunny(), o);
                                                }(),
                                                [] {
                                                  EncodeOptions o;
                                                  o.progressive = true;
                                                  return encode(bunny(), o);
                                                }()};
  return files[progressive ? 1 : 0];
}

TEST(GeometryPrediction, LinearLevelsDecodeToTheInput) {
  for (const bool progressive : {true, false}) {
    SCOPED_TRACE(progressive ? "progressive" : "random access");
    const std::vector<uint8_t> &file = bunny_file(progressive);
    const FileInfo info = inspect(file.data(), file.size());
    EXPECT_EQ(info.version, 5u);
    ASSERT_TRUE(has_section(info, "GEOP", true));
    const FileLayout layout = read_layout(file.data(), file.size());
    const std::vector<NormalPredictor> levels = load_geometry_prediction(file.data(), layout);
    ASSERT_EQ(levels.size(), layout.header.levels.size());
    // The finest levels, global in the progressive file, clustered in the other.
    EXPECT_TRUE(levels.back().linear);
    const auto expected = test::canonical(on_grid(bunny(), info.grid));
    EXPECT_TRUE(test::canonical(decode(file.data(), file.size())) == expected);
    if (progressive)
      continue;
    // Cluster by cluster (each clustered level's predictor from the global part).
    SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()));
    d.want_all(d.finest_level());
    d.update();
    EXPECT_TRUE(test::canonical(d.mesh()) == expected);
  }
}

TEST(GeometryPrediction, CostsLessThanTheCurvatureTermOrIsNotWritten) {
  // The encoder before the normal predictor (tests/data/legacy/README.md), same meshes and
  // options: the bunny's file is smaller; the bumpy sphere's levels would not repay the
  // section, which is then not written (the progressive bytes are the earlier encoder's;
  // the clustered file's model tables are chosen in fewer bits than that encoder's).
  EXPECT_LT(bunny_file(true).size(), read_bytes(kLegacy / "v5_bunny.pomar").size());
  const Mesh input = load_mesh((kLegacy / "bumpy_sphere.off").string());
  EncodeOptions o;
  o.progressive = true;
  EXPECT_EQ(encode(input, o), read_bytes(kLegacy / "v5.pomar"));
  o.progressive = false;
  o.clusters = 8;
  o.cluster_errors = false; // (the sections the earlier encoder did not write)
  o.spatial_layout = false;
  o.block_checks = false;
  const std::vector<uint8_t> clustered = encode(input, o);
  const FileLayout layout = read_layout(clustered.data(), clustered.size());
  EXPECT_LT(find_section(layout, kGeometryPredictionTag), 0);
  EXPECT_LT(clustered.size(), read_bytes(kLegacy / "v5_clustered.pomar").size());
  EXPECT_TRUE(test::canonical(decode(clustered.data(), clustered.size())) ==
              test::canonical(on_grid(input, layout.header.grid)));
}

TEST(GeometryPrediction, SectionRoundTrip) {
  const std::vector<uint8_t> &file = bunny_file(true);
  const FileLayout layout = read_layout(file.data(), file.size());
  const std::vector<NormalPredictor> levels = load_geometry_prediction(file.data(), layout);
  const int i = find_section(layout, kGeometryPredictionTag);
  ASSERT_GE(i, 0);
  const uint8_t *body = section_body(file.data(), layout, size_t(i));
  EXPECT_EQ(write_geometry_prediction(levels),
            std::vector<uint8_t>(body, body + layout.header.sections[size_t(i)].bytes));
}

TEST(GeometryPrediction, FileWithoutTheSectionPredictsByCurvature) {
  // Version 5 as written before the section: decodes to its input as it did.
  const std::vector<uint8_t> file = read_bytes(kLegacy / "v5_bunny.pomar");
  const FileLayout layout = read_layout(file.data(), file.size());
  EXPECT_LT(find_section(layout, kGeometryPredictionTag), 0);
  for (const NormalPredictor &p : load_geometry_prediction(file.data(), layout))
    EXPECT_FALSE(p.linear);
  EXPECT_TRUE(test::canonical(decode(file.data(), file.size())) ==
              test::canonical(on_grid(bunny(), layout.header.grid)));
}

TEST(GeometryPrediction, MalformedSectionIsDamageNamingIt) {
  // Added to a version 5 file without one, with valid checksums: a wrong level count, a
  // body that ends early, an unknown version.
  const std::vector<uint8_t> file = read_bytes(kLegacy / "v5.pomar");
  const FileLayout layout = read_layout(file.data(), file.size());
  std::vector<NormalPredictor> levels(layout.header.levels.size());
  levels.back().linear = true;
  std::vector<uint8_t> good = write_geometry_prediction(levels);
  std::vector<uint8_t> wrong_count = good, short_body = good, bad_version = good;
  wrong_count[4] ^= 1;
  short_body.pop_back();
  bad_version[0] = 9;
  for (const auto &body : {wrong_count, short_body, bad_version}) {
    const std::vector<uint8_t> bad =
        with_sections(file.data(), file.size(), {{kGeometryPredictionTag, kSectionRequired, body}});
    try {
      decode(bad.data(), bad.size());
      ADD_FAILURE() << "decoded a file with a malformed GEOP section";
    } catch (const Error &e) {
      EXPECT_EQ(e.kind(), Error::Kind::DamagedFile);
      EXPECT_NE(std::string(e.what()).find("'GEOP'"), std::string::npos) << e.what();
    }
  }
  // Well formed: it is read (the last level's coefficients, all zero, predict no offset).
  const std::vector<uint8_t> ok =
      with_sections(file.data(), file.size(), {{kGeometryPredictionTag, kSectionRequired, good}});
  const FileLayout ok_layout = read_layout(ok.data(), ok.size());
  EXPECT_TRUE(load_geometry_prediction(ok.data(), ok_layout).back().linear);
}

} // namespace
} // namespace pomar
