// Per-corner texture coordinates and face materials: kept on a full decode, and at every
// level and in every selection the seams stay closed and every face's corners lie in one
// chart of its material.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "attributes/attribute_section.h"
#include "attributes/material_section.h"
#include "format/file_format.h"
#include "lossless/seam_cut.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/mesh_attributes.h"
#include "support/mesh_gen.h"
#include "support/stored_files.h"

namespace pomar {
namespace {

constexpr int kCellsU = kCubeMapCellsU,
              kCellsV = kCubeMapCellsV; // the atlas: a chart per cube face
Mesh cube_mapped(Mesh m) { return with_cube_map_texture(std::move(m)); }

/// The chart (atlas cell) a texture coordinate falls in.
int chart_of(const float *uv) {
  const int i = std::min(kCellsU - 1, std::max(0, int(std::floor(uv[0] * kCellsU))));
  const int j = std::min(kCellsV - 1, std::max(0, int(std::floor(uv[1] * kCellsV))));
  return j * kCellsU + i;
}

using Position = std::array<float, 3>;
using Edge = std::pair<uint32_t, uint32_t>;

/// The mesh's edges used by one face only, its vertices welded by position.
size_t welded_boundary_edges(const Mesh &m) {
  std::map<Position, uint32_t> id;
  std::vector<uint32_t> weld(m.vertex_count());
  for (size_t v = 0; v < m.vertex_count(); ++v)
    weld[v] =
        id.emplace(Position{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]},
                   uint32_t(id.size()))
            .first->second;
  std::map<Edge, int> uses;
  for (size_t c = 0; c < m.triangles.size(); ++c) {
    const uint32_t a = weld[m.triangles[c]], b = weld[m.triangles[c - c % 3 + (c + 1) % 3]];
    ++uses[{std::min(a, b), std::max(a, b)}];
  }
  size_t boundary = 0;
  for (const auto &e : uses)
    boundary += e.second == 1;
  return boundary;
}

/// Every face's corners in one chart, and that chart of the face's material.
void expect_faces_in_one_chart(const Mesh &m, const std::string &what) {
  ASSERT_EQ(m.corner_texcoords.size(), 6 * m.triangle_count()) << what;
  ASSERT_EQ(m.face_materials.size(), m.triangle_count()) << what;
  size_t wrong = 0;
  for (size_t f = 0; f < m.triangle_count(); ++f) {
    const int c0 = chart_of(&m.corner_texcoords[6 * f]);
    const bool same = c0 == chart_of(&m.corner_texcoords[6 * f + 2]) &&
                      c0 == chart_of(&m.corner_texcoords[6 * f + 4]);
    wrong += !same || m.face_materials[f] != (c0 < 3 ? 0u : 1u);
  }
  EXPECT_EQ(wrong, 0u) << what << ": faces whose corners leave their chart";
}

struct Coded {
  Mesh input;
  std::vector<uint8_t> file;
  EncodeReport report;
};

Coded encode_textured(const Mesh &m, bool clustered, bool exact = false) {
  Coded c;
  c.input = m;
  EncodeOptions o;
  o.bits = 16; // positions (nearly) unique: the checks weld by position
  o.progressive = !clustered;
  o.cluster_ratio = 0.02;
  o.attributes.exact = exact;
  c.file = encode(c.input, o, &c.report);
  return c;
}

/// A full decode against the input: the same faces (through the report's vertex map), each
/// corner's texture coordinate within the bound (or exact), the same material.
void expect_corners_kept(const Coded &c, const Mesh &out, bool exact) {
  ASSERT_EQ(out.triangle_count(), c.input.triangle_count());
  ASSERT_EQ(out.vertex_count(), c.input.vertex_count()); // the seam copies welded back
  EXPECT_EQ(out.materials.size(), c.input.materials.size());
  for (size_t i = 0; i < out.materials.size(); ++i) {
    EXPECT_EQ(out.materials[i].name, c.input.materials[i].name);
    EXPECT_EQ(out.materials[i].texture, c.input.materials[i].texture);
    EXPECT_EQ(out.materials[i].properties, c.input.materials[i].properties);
  }
  EXPECT_EQ(out.texture_files, c.input.texture_files);
  if (exact) {
    EXPECT_EQ(out.corner_texcoord_bits, 0);
  } else {
    EXPECT_EQ(out.corner_texcoord_bits, 12);
    EXPECT_GT(out.corner_texcoord_bound, 0.0);
    EXPECT_LE(out.corner_texcoord_bound, 1.0 / 4095); // half a step over a range of at most 2
  }
  // Input faces by their rotation starting at the smallest vertex: (face, rotation).
  std::map<std::array<uint32_t, 3>, std::pair<size_t, int>> input_faces;
  auto rotation = [](const uint32_t *t) {
    int s = 0;
    for (int k = 1; k < 3; ++k)
      if (t[k] < t[s])
        s = k;
    return s;
  };
  for (size_t f = 0; f < c.input.triangle_count(); ++f) {
    const uint32_t *t = &c.input.triangles[3 * f];
    const int s = rotation(t);
    input_faces[{t[s], t[(s + 1) % 3], t[(s + 2) % 3]}] = {f, s};
  }
  const std::vector<uint32_t> &to_input = c.report.decoded_to_input;
  ASSERT_EQ(to_input.size(), out.vertex_count());
  size_t corners_off = 0, materials_off = 0;
  for (size_t f = 0; f < out.triangle_count(); ++f) {
    const uint32_t t[3] = {to_input[out.triangles[3 * f]], to_input[out.triangles[3 * f + 1]],
                           to_input[out.triangles[3 * f + 2]]};
    const int s = rotation(t);
    const auto it = input_faces.find({t[s], t[(s + 1) % 3], t[(s + 2) % 3]});
    ASSERT_NE(it, input_faces.end()) << "decoded face " << f << " is not an input face";
    const auto [g, gs] = it->second;
    materials_off += out.face_materials[f] != c.input.face_materials[g];
    for (int k = 0; k < 3; ++k) { // decoded corner (s + k) is input corner (gs + k)
      const float *a = &out.corner_texcoords[6 * f + 2 * ((s + k) % 3)];
      const float *b = &c.input.corner_texcoords[6 * g + 2 * ((gs + k) % 3)];
      for (int j = 0; j < 2; ++j)
        corners_off += exact ? std::memcmp(a + j, b + j, 4) != 0
                             : std::fabs(double(a[j]) - b[j]) > out.corner_texcoord_bound;
    }
  }
  EXPECT_EQ(corners_off, 0u) << "corner texture coordinates off their input's";
  EXPECT_EQ(materials_off, 0u) << "faces with another material";
}

TEST(TextureSeams, CornersAndMaterialsAreKept) {
  const Mesh m = cube_mapped(gen::noisy_sphere(3000, 3, 0.05));
  for (bool clustered : {false, true})
    for (bool exact : {false, true}) {
      SCOPED_TRACE(std::string(clustered ? "clustered" : "progressive") + (exact ? ", exact" : ""));
      const Coded c = encode_textured(m, clustered, exact);
      EXPECT_GT(c.report.lossless.seam_edges, 50u);
      EXPECT_GT(c.report.lossless.wedge_copies, 50u);
      expect_corners_kept(c, decode(c.file.data(), c.file.size()), exact);
    }
}

/// How many of the file's refinement levels predict the wedge texture coordinate from the
/// positions (the descriptor's positions flag: all of them; else its level mask).
size_t levels_from_positions(const std::vector<uint8_t> &file) {
  const StoredAttribute s = test::wedge_descriptor(file);
  const FileInfo info = inspect(file.data(), file.size());
  if (s.from_positions)
    return info.levels.size();
  EXPECT_LE(s.level_positions.size(), info.levels.size());
  return size_t(std::count(s.level_positions.begin(), s.level_positions.end(), uint8_t(1)));
}

// The wedge texture coordinates are predicted from the positions where the charts map the
// surface affinely (the cube map's projections) and by the neighbours' mean where they do
// not (the same mesh, each wedge moved at random by up to 40 grid steps): the encoder
// chooses level by level, from its estimates of both on the level before, and either way
// the corners come back.
TEST(TextureSeams, WedgePredictionFollowsTheCharts) {
  const Mesh m = cube_mapped(gen::noisy_sphere(3000, 3, 0.05));
  Mesh jittered = m;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> offset(-0.01f, 0.01f);
  std::map<std::tuple<uint32_t, float, float>, std::pair<float, float>> moved; // per wedge
  for (size_t c = 0; c < m.triangles.size(); ++c) {
    const float *uv = &m.corner_texcoords[2 * c];
    const auto key = std::make_tuple(m.triangles[c], uv[0], uv[1]);
    auto it = moved.find(key);
    if (it == moved.end())
      it = moved.emplace(key, std::make_pair(offset(rng), offset(rng))).first;
    jittered.corner_texcoords[2 * c] = uv[0] + it->second.first;
    jittered.corner_texcoords[2 * c + 1] = uv[1] + it->second.second;
  }
  const Coded affine = encode_textured(m, true), noisy = encode_textured(jittered, true);
  EXPECT_EQ(affine.report.lossless.wedge_copies, noisy.report.lossless.wedge_copies);
  const size_t levels = inspect(affine.file.data(), affine.file.size()).levels.size();
  EXPECT_GT(levels, 5u);
  EXPECT_GE(levels_from_positions(affine.file), levels - 1); // (the first: the base mesh's)
  // (The jittered wedges leave residuals of about the jitter either way: the estimates
  // choose level by level, and the corners come back whichever they take.)
  expect_corners_kept(affine, decode(affine.file.data(), affine.file.size()), false);
  expect_corners_kept(noisy, decode(noisy.file.data(), noisy.file.size()), false);
}

// The ATTR section's level mask (version 4): which levels predict the wedge texture
// coordinate from the positions, a bit a level over two bytes here; a bit past the level
// count, or the mask with the every-level positions flag, is a damaged section.
TEST(TextureSeams, LevelMaskOfTheWedgePredictor) {
  AttributeTable t;
  StoredAttribute s;
  s.kind = AttributeKind::TexCoord;
  s.name = kWedgeTexcoord;
  s.components = 2;
  s.bits = 12;
  s.lo = {0.f, 0.f};
  s.hi = {1.f, 1.f};
  s.level_positions = {1, 0, 0, 1, 1, 0, 0, 0, 1, 0};
  t.stored.push_back(s);
  t.estimated_bytes = {0};
  t.codes = 2;
  t.wedge_uv = 0;
  const std::vector<uint8_t> body = write_attributes(t, 0);
  EXPECT_EQ(body[0], kAttributeSectionLevelsVersion);
  const AttributeTable back = read_attributes(body.data(), body.size(), 0);
  ASSERT_EQ(back.stored.size(), 1u);
  EXPECT_EQ(back.stored[0].level_positions, s.level_positions);
  EXPECT_FALSE(back.stored[0].from_positions);
  // version, count; kind, components, bits, flags, name length, name; 2 x (lo, hi); mask
  const size_t mask = 2 + 5 + s.name.size() + 16;
  ASSERT_EQ(body[mask] | body[mask + 1] << 8, 10);
  EXPECT_EQ(body[mask + 2], 0x19); // levels 1, 4, 5
  EXPECT_EQ(body[mask + 3], 0x01); // level 9
  std::vector<uint8_t> past = body;
  past[mask + 3] |= 0x04; // level 11 of 10
  try {
    read_attributes(past.data(), past.size(), 0);
    ADD_FAILURE() << "a mask bit past the level count was taken";
  } catch (const Error &e) {
    EXPECT_EQ(e.kind(), Error::Kind::DamagedFile);
    EXPECT_NE(std::string(e.what()).find("level mask past its level count"), std::string::npos)
        << e.what();
  }
  std::vector<uint8_t> both = body;
  both[2 + 3] |= 2; // the descriptor's flags: the every-level positions flag as well
  EXPECT_THROW(read_attributes(both.data(), both.size(), 0), Error);
}

TEST(TextureSeams, EveryLevelIsClosedAndInItsCharts) {
  const Mesh m = cube_mapped(gen::noisy_sphere(4000, 5, 0.05));
  ASSERT_EQ(welded_boundary_edges(m), 0u);
  for (bool clustered : {false, true}) {
    SCOPED_TRACE(clustered ? "clustered" : "progressive");
    const Coded c = encode_textured(m, clustered);
    const FileInfo info = inspect(c.file.data(), c.file.size());
    ASSERT_GT(info.levels.size(), 3u);
    for (int level = 0; level <= int(info.levels.size()); ++level) {
      const Mesh d = decode(c.file.data(), c.file.size(), level);
      const std::string what = "level " + std::to_string(level);
      EXPECT_EQ(welded_boundary_edges(d), 0u) << what << ": a seam opened";
      expect_faces_in_one_chart(d, what);
    }
  }
}

TEST(TextureSeams, SelectionsAreClosedAndInTheirCharts) {
  const Mesh m = cube_mapped(gen::noisy_sphere(4000, 7, 0.05));
  const Coded c = encode_textured(m, true);
  for (unsigned threads : {1u, 2u}) {
    SelectiveOptions so;
    so.threads = threads;
    SelectiveDecoder d(std::make_unique<MemorySource>(c.file.data(), c.file.size()), so);
    const int finest = d.finest_level(), base = d.base_clustered_level();
    ASSERT_GT(finest, base + 2);
    std::vector<uint32_t> link_start, link;
    d.cluster_links(link_start, link);
    EXPECT_GT(link.size(), 0u) << "the copies of seam vertices are linked";
    // Random levels per cluster (smooth transitions raise their neighbours as needed): the
    // whole surface at mixed levels, welded, has no boundary edge.
    std::mt19937 rng(threads);
    for (int round = 0; round < 4; ++round) {
      d.clear_wanted();
      for (uint32_t k = 0; k < d.cluster_count(); ++k)
        d.want_cluster(k, base + int(rng() % uint32_t(finest - base + 1)));
      d.update();
      const Mesh mixed = d.mesh();
      const std::string what =
          "round " + std::to_string(round) + ", " + std::to_string(threads) + " threads";
      EXPECT_EQ(welded_boundary_edges(mixed), 0u) << what << ": a seam opened";
      expect_faces_in_one_chart(mixed, what);
      for (uint32_t k = 0; k < d.cluster_count(); ++k)
        for (uint32_t i = link_start[k]; i < link_start[k + 1]; ++i)
          ASSERT_EQ(d.levels()[k], d.levels()[link[i]]) << what << ": linked clusters apart";
    }
    const float centre[3] = {1, 0, 0};
    d.clear_wanted();
    d.want_sphere(centre, 0.5f, finest);
    d.update();
    EXPECT_EQ(welded_boundary_edges(d.mesh()), 0u) << "a region: a seam opened";
    expect_faces_in_one_chart(d.mesh(), "a region");
  }
}

TEST(TextureSeams, DroppingTextureCoordinatesDropsCornersAndMaterials) {
  const Mesh m = cube_mapped(gen::noisy_sphere(1500, 3, 0.05));
  EncodeOptions o;
  o.attributes.keep.texcoords = false;
  const std::vector<uint8_t> file = encode(m, o);
  const Mesh out = decode(file.data(), file.size());
  EXPECT_TRUE(out.corner_texcoords.empty());
  EXPECT_TRUE(out.face_materials.empty());
  EXPECT_EQ(out.vertex_count(), m.vertex_count());
  // Kept in the file, left out by the decoder.
  const std::vector<uint8_t> kept = encode(m, EncodeOptions());
  DecodeOptions dropping;
  dropping.attributes.texcoords = false;
  const Mesh without = decode(kept.data(), kept.size(), dropping);
  EXPECT_TRUE(without.corner_texcoords.empty());
  EXPECT_TRUE(without.attributes.empty());
  EXPECT_EQ(without.vertex_count(), m.vertex_count());
}

TEST(TextureSeams, EmbeddedImagesComeBackBitForBit) {
  Mesh m = cube_mapped(gen::noisy_sphere(800, 3, 0.05));
  m.texture_images = {std::vector<uint8_t>{0x89, 'P', 'N', 'G', 0, 1, 2, 255}, {}};
  for (bool clustered : {false, true}) {
    const Coded c = encode_textured(m, clustered);
    const FileInfo info = inspect(c.file.data(), c.file.size());
    EXPECT_EQ(info.embedded_texture_bytes, (std::vector<uint64_t>{8, 0}));
    EXPECT_EQ(decode(c.file.data(), c.file.size()).texture_images, m.texture_images);
    EXPECT_EQ(decode(c.file.data(), c.file.size(), 1).texture_images, m.texture_images);
    DecodeOptions no_uv;
    no_uv.attributes.texcoords = false;
    EXPECT_TRUE(decode(c.file.data(), c.file.size(), no_uv).texture_images.empty());
  }
  Mesh plain = m; // per-vertex data only (no corners): the images still go in
  plain.corner_texcoords.clear();
  plain.face_materials.clear();
  plain.materials.clear();
  const std::vector<uint8_t> file = encode(plain, EncodeOptions());
  EXPECT_EQ(decode(file.data(), file.size()).texture_images, m.texture_images);
  Mesh too_many = m;
  too_many.texture_images.resize(3);
  too_many.texture_images[2] = {1};
  EXPECT_THROW(encode(too_many, EncodeOptions()), Error);
}

TEST(TextureSeams, CheckBlocksReadsTheSections) {
  const Mesh m = cube_mapped(gen::noisy_sphere(600, 3, 0.05));
  const std::vector<uint8_t> file = encode(m, EncodeOptions());
  EXPECT_TRUE(check_blocks(file.data(), file.size()).empty());
  // A MATL section whose material names a texture the file does not have (checksums right):
  // check_blocks refuses it as a decode does, instead of calling the file whole.
  MaterialTable bad;
  bad.corner_texcoords = bad.face_materials = true;
  bad.materials = {{"front", 0, ""}, {"back", 7, ""}};
  const std::vector<uint8_t> hurt = with_sections(
      file.data(), file.size(), {{kMaterialSectionTag, kSectionRequired, write_materials(bad)}});
  for (const auto &run : {std::function<void()>([&] { check_blocks(hurt.data(), hurt.size()); }),
                          std::function<void()>([&] { decode(hurt.data(), hurt.size()); })}) {
    try {
      run();
      ADD_FAILURE() << "the damaged MATL section was not refused";
    } catch (const Error &e) {
      EXPECT_EQ(e.kind(), Error::Kind::DamagedFile) << e.what();
      EXPECT_NE(std::string(e.what()).find("MATL section"), std::string::npos) << e.what();
    }
  }
}

TEST(TextureSeams, BadCornerValuesAreNamed) {
  Mesh m = cube_mapped(gen::noisy_sphere(500, 3, 0.05));
  auto expect_refused = [](const Mesh &bad, const std::string &words) {
    try {
      encode(bad, EncodeOptions());
      ADD_FAILURE() << "not refused: " << words;
    } catch (const Error &e) {
      EXPECT_EQ(e.kind(), Error::Kind::InvalidMesh) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  Mesh nan = m;
  nan.corner_texcoords[6 * 7 + 3] = std::nanf("");
  expect_refused(nan, "corner 1 of face 7 is NaN");
  Mesh material = m;
  material.face_materials[4] = 2;
  expect_refused(material, "face 4 has material 2");
  Mesh sizes = m;
  sizes.corner_texcoords.pop_back();
  expect_refused(sizes, "per-corner texture coordinates");
  EncodeOptions exact;
  exact.attributes.exact = true; // NaN kept bit for bit
  const std::vector<uint8_t> file = encode(nan, exact);
  const Mesh out = decode(file.data(), file.size());
  size_t nans = 0;
  for (float x : out.corner_texcoords)
    nans += std::isnan(x);
  EXPECT_EQ(nans, 1u);
}

} // namespace
} // namespace pomar
