// Attribute quantizers, checks and (with the encoder) round trips of every attribute kind.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <random>

#include "attributes/attribute_quantize.h"
#include "format/file_format.h"
#include "pomar/limits.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/mesh_attributes.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

double angle_degrees(const float a[3], const float b[3]) {
  // atan2 of |a x b| and a.b: acos of the dot loses small angles to float rounding.
  const double x = double(a[1]) * b[2] - double(a[2]) * b[1];
  const double y = double(a[2]) * b[0] - double(a[0]) * b[2];
  const double z = double(a[0]) * b[1] - double(a[1]) * b[0];
  const double dot = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
  return std::atan2(std::sqrt(x * x + y * y + z * z), dot) * 180.0 / M_PI;
}

/// Normals uniform on the sphere, plus the axes, the octahedron's edges and its folds.
std::vector<std::array<float, 3>> test_normals(size_t count, uint32_t seed) {
  std::vector<std::array<float, 3>> out;
  for (int a = 0; a < 3; ++a)
    for (float s : {-1.0f, 1.0f}) {
      std::array<float, 3> n = {0, 0, 0};
      n[a] = s;
      out.push_back(n);
    }
  std::mt19937 rng(seed);
  std::normal_distribution<float> g;
  std::uniform_real_distribution<float> u(-1, 1);
  while (out.size() < count) {
    std::array<float, 3> n = {g(rng), g(rng), g(rng)};
    if (out.size() % 7 == 0)
      n[out.size() % 3] = 0; // on a fold / an edge of the octahedron
    if (out.size() % 11 == 0)
      n = {u(rng), 1.0f - std::fabs(n[0]), 0.0f};
    if (n[0] == 0 && n[1] == 0 && n[2] == 0)
      continue;
    out.push_back(n);
  }
  return out;
}

TEST(AttributeQuantize, YCoCgRIsExactOnEveryColour) {
  for (int r = 0; r < 256; r += 1)
    for (int g = 0; g < 256; g += 3)
      for (int b = 0; b < 256; b += 5) {
        const uint8_t rgb[3] = {uint8_t(r), uint8_t(g), uint8_t(b)};
        int32_t c[3];
        rgb_to_ycocg(rgb, c);
        ASSERT_GE(c[0], 0);
        ASSERT_LE(c[0], 255);
        ASSERT_GE(c[1], -255);
        ASSERT_LE(c[2], 255);
        uint8_t back[3];
        ycocg_to_rgb(c, back);
        ASSERT_EQ(0, std::memcmp(rgb, back, 3)) << r << " " << g << " " << b;
      }
}

TEST(AttributeQuantize, FloatCodesAreOrderedAndExact) {
  const float values[] = {-std::numeric_limits<float>::infinity(),
                          -1e30f,
                          -1.0f,
                          -1e-40f,
                          -0.0f,
                          0.0f,
                          1e-45f,
                          1e-40f,
                          0.5f,
                          1.0f,
                          3e38f,
                          std::numeric_limits<float>::infinity()};
  for (size_t i = 0; i < sizeof(values) / sizeof(float); ++i) {
    const float back = code_float(float_code(values[i]));
    EXPECT_EQ(0, std::memcmp(&back, &values[i], 4)) << values[i];
    if (i) {
      EXPECT_LT(float_code(values[i - 1]), float_code(values[i]));
    }
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float back = code_float(float_code(nan));
  EXPECT_EQ(0, std::memcmp(&back, &nan, 4));
}

// The bound table (normal_error_bound) against measured errors; prints the measurement.
// (The table was measured with 2,000,000 samples: POMAR_NORMAL_SAMPLES=2000000.)
const size_t kNormalSamples =
    std::getenv("POMAR_NORMAL_SAMPLES") ? std::stoul(std::getenv("POMAR_NORMAL_SAMPLES")) : 200000;
TEST(AttributeQuantize, OctahedralNormalsStayWithinTheirBound) {
  const auto normals = test_normals(kNormalSamples, 7);
  for (int bits = 4; bits <= 16; ++bits) {
    double worst = 0;
    for (const auto &n : normals) {
      uint32_t u, v;
      octahedral_encode(n.data(), bits, u, v);
      ASSERT_LE(u, (1u << bits) - 2);
      ASSERT_LE(v, (1u << bits) - 2);
      float d[3];
      octahedral_decode(u, v, bits, d);
      worst = std::max(worst, angle_degrees(n.data(), d));
      ASSERT_NEAR(1.0, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 1e-6);
    }
    std::printf("normal bits %2d: max error %.5f degrees (bound %.4f)\n", bits, worst,
                normal_error_bound(bits));
    EXPECT_LE(worst, normal_error_bound(bits)) << bits;
    EXPECT_GT(worst, normal_error_bound(bits) / 4) << "bound too loose at " << bits;
  }
  EXPECT_LE(normal_error_bound(AttributeOptions().normal_bits), 0.5);
}

TEST(AttributeQuantize, RangeQuantizerWithinHalfAStep) {
  VertexAttribute a;
  a.kind = AttributeKind::TexCoord;
  a.name = "texcoord";
  a.components = 2;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.25f, 1.5f), w(0.0f, 0.001f);
  for (int i = 0; i < 5000; ++i) {
    a.values.push_back(u(rng));
    a.values.push_back(w(rng));
  }
  for (int bits : {1, 8, 12, 16, 24}) {
    AttributeOptions o;
    o.texcoord_bits = bits;
    const StoredAttribute s = describe(a, o);
    VertexAttribute out = a;
    for (size_t v = 0; v < a.vertex_count(); ++v) {
      int64_t codes[2];
      to_codes(s, a, v, codes);
      from_codes(s, codes, out, v);
    }
    double worst = 0;
    for (size_t i = 0; i < a.values.size(); ++i)
      worst = std::max(worst, std::fabs(double(out.values[i]) - a.values[i]));
    EXPECT_LE(worst, s.bound()) << bits;
    EXPECT_GT(worst, s.bound() / 4) << bits;
  }
}

Mesh triangle_with(VertexAttribute a) {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.triangles = {0, 1, 2};
  m.attributes.push_back(std::move(a));
  return m;
}

void expect_error(const Mesh &m, bool quantized, const char *fragment) {
  try {
    validate_attributes(m, quantized);
    ADD_FAILURE() << "no error, expected one containing: " << fragment;
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_EQ(e.kind(), Error::Kind::InvalidMesh) << e.what(); // (the tool's exit status 5)
  }
}

TEST(AttributeQuantize, ValidationNamesTheProblem) {
  VertexAttribute c;
  c.kind = AttributeKind::Colour;
  c.name = "colour";
  c.components = 3;
  c.colour = {1, 2, 3, 4, 5, 6};
  expect_error(triangle_with(c), false, "has 6 values, the mesh has 3 vertices x 3 = 9");
  c.components = 2;
  c.colour.assign(6, 0);
  expect_error(triangle_with(c), false, "colour needs 3 (RGB) or 4 (RGBA)");
  c.components = 4;
  c.colour.assign(12, 7);
  EXPECT_NO_THROW(validate_attributes(triangle_with(c), true));
  c.name.clear();
  expect_error(triangle_with(c), false, "a name of 1 to 255 bytes");

  VertexAttribute s;
  s.kind = AttributeKind::Scalar;
  s.name = "confidence";
  s.values = {0.5f, std::numeric_limits<float>::quiet_NaN(), 1.0f};
  expect_error(triangle_with(s), true, "scalar attribute 'confidence' of vertex 1 is NaN");
  EXPECT_NO_THROW(validate_attributes(triangle_with(s), false)); // exact mode keeps NaN
  Mesh two = triangle_with(s);
  two.attributes.push_back(s);
  expect_error(two, false, "two attributes are named 'confidence'");

  VertexAttribute n;
  n.kind = AttributeKind::Normal;
  n.name = "normal";
  n.components = 3;
  n.values = {0, 0, 1, 0, 0, 0, 1, 0, 0};
  EXPECT_NO_THROW(validate_attributes(triangle_with(n), true)); // zero-length: kept as (0, 0, 0)
  EXPECT_NO_THROW(validate_attributes(triangle_with(n), false));
  n.values[4] = std::numeric_limits<float>::quiet_NaN();
  expect_error(triangle_with(n), true, "normal attribute 'normal' of vertex 1 is NaN");
  n.values[4] = 0;
  n.values[8] = -std::numeric_limits<float>::infinity();
  expect_error(triangle_with(n), true, "normal attribute 'normal' of vertex 2 is infinite");
  EXPECT_NO_THROW(validate_attributes(triangle_with(n), false));
}

// A zero-length normal has the code one past the grid on both axes, only in an attribute
// whose descriptor says it holds some; it decodes to exactly (0, 0, 0).
TEST(AttributeQuantize, ZeroNormalsHaveTheirOwnCode) {
  VertexAttribute n;
  n.kind = AttributeKind::Normal;
  n.name = "normal";
  n.components = 3;
  n.values = {0, 0, 1, 0.3f, -0.2f, 0.9f};
  AttributeOptions o;
  for (int bits : {4, 9, 16}) {
    SCOPED_TRACE(bits);
    o.normal_bits = bits;
    StoredAttribute plain = describe(n, o);
    EXPECT_FALSE(plain.zero_normals); // no zero normal: codes and ranges as without the code
    int64_t lo, hi;
    code_range(plain, 1, lo, hi);
    EXPECT_EQ(hi, (int64_t(1) << bits) - 2);

    VertexAttribute z = n;
    z.values.insert(z.values.end(), {0.0f, -0.0f, 0.0f});
    const StoredAttribute s = describe(z, o);
    EXPECT_TRUE(s.zero_normals);
    for (uint32_t k = 0; k < 2; ++k) {
      code_range(s, k, lo, hi);
      EXPECT_EQ(lo, 0);
      EXPECT_EQ(hi, int64_t(octahedral_zero_code(bits)));
    }
    VertexAttribute out = z;
    std::fill(out.values.begin(), out.values.end(), 7.0f);
    for (size_t v = 0; v < 3; ++v) {
      int64_t c[2];
      to_codes(s, z, v, c);
      EXPECT_EQ(is_zero_normal(c[0], c[1], bits), v == 2);
      EXPECT_LE(c[0], int64_t(octahedral_zero_code(bits)) - (v == 2 ? 0 : 1));
      from_codes(s, c, out, v);
    }
    const float zero[3] = {0, 0, 0};
    EXPECT_EQ(0, std::memcmp(&out.values[6], zero, sizeof zero)); // +0, exactly
    EXPECT_LE(angle_degrees(&out.values[3], &z.values[3]), normal_error_bound(bits));
    const int64_t half[2] = {int64_t(octahedral_zero_code(bits)), 0};
    try {
      from_codes(s, half, out, 1);
      ADD_FAILURE() << "half of the zero code decoded";
    } catch (const Error &e) {
      EXPECT_EQ(e.kind(), Error::Kind::DamagedFile);
      EXPECT_NE(std::string(e.what()).find("vertex 1 has half of the zero-normal code"),
                std::string::npos)
          << e.what();
    }
  }
  o.exact = true; // exact normals keep the floats' bits: no code of their own
  n.values.insert(n.values.end(), {0.0f, 0.0f, 0.0f});
  EXPECT_FALSE(describe(n, o).zero_normals);
}

// ---------------------------------------------------------------- round trips

struct Coded {
  Mesh input;
  std::vector<uint8_t> file;
  EncodeReport report;
};

Coded encode_with(Mesh m, bool clustered, const AttributeOptions &attributes = {}) {
  Coded c;
  c.input = std::move(m);
  EncodeOptions o;
  o.bits = 16; // positions (nearly) unique: the tests match vertices by position
  o.progressive = !clustered;
  o.cluster_ratio = 0.02;
  o.attributes = attributes;
  c.file = encode(c.input, o, &c.report);
  return c;
}

/// Decoded attribute `got` of decoded vertex v against input vertex i.
void expect_close(const VertexAttribute &in, const VertexAttribute &got, size_t i, size_t v,
                  bool exact) {
  ASSERT_EQ(in.components, got.components);
  if (in.kind == AttributeKind::Colour) {
    for (uint32_t k = 0; k < in.components; ++k)
      ASSERT_EQ(in.colour[i * in.components + k], got.colour[v * in.components + k])
          << in.name << " vertex " << v;
    return;
  }
  const float *a = &in.values[i * in.components], *b = &got.values[v * in.components];
  if (exact) {
    ASSERT_EQ(0, std::memcmp(a, b, 4 * in.components)) << in.name << " vertex " << v;
    return;
  }
  if (in.kind == AttributeKind::Normal) {
    ASSERT_LE(angle_degrees(a, b), got.bound) << in.name << " vertex " << v;
    return;
  }
  for (uint32_t k = 0; k < in.components; ++k)
    ASSERT_LE(std::fabs(double(a[k]) - b[k]), got.bound) << in.name << " vertex " << v;
}

/// Every attribute of `out` (a full decode) against the input.
void expect_round_trip(const Coded &c, const Mesh &out, bool exact) {
  ASSERT_EQ(out.attributes.size(), c.input.attributes.size());
  EXPECT_EQ(out.texture_files, c.input.texture_files);
  for (const VertexAttribute &in : c.input.attributes) {
    const VertexAttribute *got = out.find(in.kind, in.name);
    ASSERT_NE(got, nullptr) << in.name;
    ASSERT_EQ(got->vertex_count(), out.vertex_count());
    if (exact || in.kind == AttributeKind::Colour) {
      EXPECT_EQ(got->bits, 0);
    }
    for (size_t v = 0; v < out.vertex_count(); ++v)
      expect_close(in, *got, c.report.decoded_to_input[v], v, exact);
  }
}

using Position = std::array<float, 3>;
Position position_of(const Mesh &m, size_t v) {
  return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}

/// `part` (an intermediate or selective decode) has, for each of its vertices, the
/// attributes the full decode `full` gives the vertex at the same position (a vertex keeps
/// its position from the level that creates it on).
void expect_same_as_full(const Mesh &part, const Mesh &full) {
  std::map<Position, size_t> at;
  for (size_t v = 0; v < full.vertex_count(); ++v)
    ASSERT_TRUE(at.emplace(position_of(full, v), v).second) << "positions must be unique";
  ASSERT_EQ(part.attributes.size(), full.attributes.size());
  for (size_t i = 0; i < full.attributes.size(); ++i) {
    const VertexAttribute &f = full.attributes[i], &p = part.attributes[i];
    ASSERT_EQ(p.name, f.name);
    ASSERT_EQ(p.vertex_count(), part.vertex_count());
    const uint32_t n = f.components;
    for (size_t v = 0; v < part.vertex_count(); ++v) {
      const auto it = at.find(position_of(part, v));
      ASSERT_NE(it, at.end());
      if (f.kind == AttributeKind::Colour)
        ASSERT_EQ(0, std::memcmp(&p.colour[v * n], &f.colour[it->second * n], n)) << f.name;
      else
        ASSERT_EQ(0, std::memcmp(&p.values[v * n], &f.values[it->second * n], 4 * n)) << f.name;
    }
  }
  EXPECT_EQ(part.texture_files, full.texture_files);
}

TEST(AttributeRoundTrip, EveryCombinationProgressiveAndClustered) {
  const Mesh sphere = gen::noisy_sphere(1500, 4, 0.1);
  for (int has :
       {int(kColour), kColour | kAlpha, int(kNormals), int(kScalars), int(kTexcoords), int(kAll)})
    for (bool clustered : {false, true}) {
      SCOPED_TRACE("attributes " + std::to_string(has) + (clustered ? " clustered" : ""));
      const Coded c = encode_with(with_attributes(sphere, has), clustered);
      const FileInfo info = inspect(c.file.data(), c.file.size());
      EXPECT_EQ(info.version, 5u);
      EXPECT_EQ(info.clustered(), clustered);
      EXPECT_EQ(info.attributes.size(), c.input.attributes.size());
      EXPECT_GT(info.attribute_bytes, 0u);
      expect_round_trip(c, decode(c.file.data(), c.file.size()), false);
    }
}

// Whatever the encoder writes, the readers take: every mix of attributes (texture file names
// with no coded attribute among them, the form a textured OBJ whose UVs are not kept has), in
// both layouts, through inspect, check_blocks, a full decode and every level.
TEST(AttributeRoundTrip, EveryEncodedMixReadsBack) {
  const Mesh sphere = gen::noisy_sphere(900, 4, 0.1);
  std::vector<Mesh> mixes;
  for (int has = 0; has <= kAll; ++has)
    if (!(has & kAlpha) || (has & kColour))
      mixes.push_back(with_attributes(sphere, has));
  Mesh names_only = sphere;
  names_only.texture_files = {"atlas_0.jpg", "atlas 1.png"};
  mixes.push_back(names_only);
  for (const Mesh &m : mixes)
    for (bool clustered : {false, true}) {
      SCOPED_TRACE(std::to_string(m.attributes.size()) + " attributes, " +
                   std::to_string(m.texture_files.size()) + " texture files" +
                   (clustered ? ", clustered" : ""));
      Coded c;
      ASSERT_NO_THROW(c = encode_with(m, clustered));
      FileInfo info;
      ASSERT_NO_THROW(info = inspect(c.file.data(), c.file.size()));
      EXPECT_EQ(info.attributes.size(), m.attributes.size());
      EXPECT_EQ(info.texture_files, m.texture_files);
      EXPECT_NO_THROW(check_blocks(c.file.data(), c.file.size()));
      const Mesh out = decode(c.file.data(), c.file.size());
      EXPECT_EQ(out.vertex_count(), m.vertex_count());
      expect_round_trip(c, out, false);
      for (int level = 0; level < int(info.levels.size()); level += 3)
        EXPECT_EQ(decode(c.file.data(), c.file.size(), level).texture_files, m.texture_files);
    }
}

TEST(AttributeRoundTrip, SeveralBitDepths) {
  const Mesh m = with_attributes(gen::noisy_sphere(800, 2, 0.1), kAll);
  for (int bits : {4, 8, 12, 16}) {
    SCOPED_TRACE(bits);
    AttributeOptions o;
    o.normal_bits = bits;
    o.scalar_bits = bits;
    o.texcoord_bits = bits;
    const Coded c = encode_with(m, true, o);
    const Mesh out = decode(c.file.data(), c.file.size());
    expect_round_trip(c, out, false);
    EXPECT_EQ(out.find(AttributeKind::Normal)->bits, bits);
    EXPECT_DOUBLE_EQ(out.find(AttributeKind::Normal)->bound, normal_error_bound(bits));
  }
}

TEST(AttributeRoundTrip, ExactModeIsBitExactWithSpecialValues) {
  Mesh m = with_attributes(gen::noisy_sphere(600, 3, 0.1), kAll);
  VertexAttribute &q = *m.find(AttributeKind::Scalar, "quality");
  q.values[0] = std::numeric_limits<float>::quiet_NaN();
  q.values[1] = -std::numeric_limits<float>::infinity();
  q.values[2] = 1e-42f; // denormal
  q.values[3] = -0.0f;
  VertexAttribute &n = *m.find(AttributeKind::Normal);
  n.values[3] = n.values[4] = n.values[5] = 0; // zero-length normal
  AttributeOptions o;
  o.exact = true;
  EXPECT_THROW(encode_with(m, false), Error); // quantized: NaN is an error
  for (bool clustered : {false, true}) {
    const Coded c = encode_with(m, clustered, o);
    expect_round_trip(c, decode(c.file.data(), c.file.size()), true);
  }
}

/// The first byte of the file's ATTR section body: its section version.
uint8_t attribute_section_version(const std::vector<uint8_t> &file) {
  const FileLayout layout = read_layout(file.data(), file.size());
  const int i = find_section(layout, section_tag("ATTR"));
  EXPECT_GE(i, 0);
  return i < 0 ? 0 : section_body(file.data(), layout, size_t(i))[0];
}

/// Whether normal v of `a` is exactly (+0, +0, +0).
bool is_plus_zero(const VertexAttribute &a, size_t v) {
  const float zero[3] = {0, 0, 0};
  return std::memcmp(&a.values[3 * v], zero, sizeof zero) == 0;
}

// Zero-length normals (scattered, and a whole patch of neighbours) are kept without
// --exact-attributes: exactly (0, 0, 0) in the full decode and in every level, the others
// within their bound, in both layouts; a mesh without them gets the descriptor of before.
TEST(AttributeRoundTrip, ZeroLengthNormalsComeBackAsZero) {
  const Mesh sphere = with_attributes(gen::noisy_sphere(1500, 4, 0.1), kAll);
  Mesh m = sphere;
  VertexAttribute &n = *m.find(AttributeKind::Normal);
  size_t zeros = 0;
  for (size_t v = 0; v < m.vertex_count(); ++v)
    if (v % 37 == 0 || m.positions[3 * v + 2] > 0.9f) { // (the cap: zero neighbours of zeros)
      n.values[3 * v] = v % 2 ? -0.0f : 0.0f;
      n.values[3 * v + 1] = n.values[3 * v + 2] = 0;
      ++zeros;
    }
  ASSERT_GT(zeros, 60u);
  for (bool clustered : {false, true}) {
    SCOPED_TRACE(clustered ? "clustered" : "progressive");
    const Coded plain = encode_with(sphere, clustered);
    EXPECT_EQ(attribute_section_version(plain.file), 1);
    const Coded c = encode_with(m, clustered);
    EXPECT_EQ(attribute_section_version(c.file), 2);
    const FileInfo info = inspect(c.file.data(), c.file.size());
    std::printf("%zu zero normals of %zu, %s: %zu bytes (without them: %zu)\n", zeros,
                m.vertex_count(), clustered ? "clustered" : "progressive", c.file.size(),
                plain.file.size());
    const Mesh full = decode(c.file.data(), c.file.size());
    expect_round_trip(c, full, false);
    const VertexAttribute &got = *full.find(AttributeKind::Normal);
    EXPECT_EQ(got.bits, 9);
    size_t decoded_zeros = 0;
    for (size_t v = 0; v < full.vertex_count(); ++v) {
      const size_t i = c.report.decoded_to_input[v];
      const bool zero =
          n.values[3 * i] == 0 && n.values[3 * i + 1] == 0 && n.values[3 * i + 2] == 0;
      ASSERT_EQ(is_plus_zero(got, v), zero) << "vertex " << v;
      decoded_zeros += zero;
    }
    EXPECT_EQ(decoded_zeros, zeros);
    for (int level = 0; level <= int(info.levels.size()); ++level) {
      SCOPED_TRACE("level " + std::to_string(level));
      expect_same_as_full(decode(c.file.data(), c.file.size(), level), full);
    }
    DecodeOptions without; // the normals left out, and all attributes left out
    without.attributes.normals = false;
    const Mesh no_normals = decode(c.file.data(), c.file.size(), without);
    EXPECT_EQ(no_normals.positions, full.positions);
    EXPECT_EQ(no_normals.find(AttributeKind::Normal), nullptr);
    EXPECT_EQ(no_normals.find(AttributeKind::Colour)->colour,
              full.find(AttributeKind::Colour)->colour);
    without.attributes = AttributeMask::none();
    EXPECT_EQ(decode(c.file.data(), c.file.size(), without).positions, full.positions);
  }
  // NaN and infinite normals stay an error naming the vertex.
  n.values[3 * 5 + 1] = std::numeric_limits<float>::quiet_NaN();
  try {
    encode_with(m, true);
    ADD_FAILURE() << "a NaN normal was encoded";
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("normal attribute 'normal' of vertex 5 is NaN"),
              std::string::npos)
        << e.what();
  }
}

TEST(AttributeRoundTrip, IntermediateLevelsHaveTheFullDecodesAttributes) {
  const Mesh m = with_attributes(gen::noisy_sphere(1200, 5, 0.1), kAll);
  for (bool clustered : {false, true}) {
    const Coded c = encode_with(m, clustered);
    const Mesh full = decode(c.file.data(), c.file.size());
    const FileInfo info = inspect(c.file.data(), c.file.size());
    for (int level = 0; level <= int(info.levels.size()); ++level) {
      SCOPED_TRACE("level " + std::to_string(level));
      expect_same_as_full(decode(c.file.data(), c.file.size(), level), full);
    }
  }
}

TEST(AttributeRoundTrip, SelectiveDecodesHaveTheFullDecodesAttributes) {
  const Coded c = encode_with(with_attributes(gen::noisy_sphere(3000, 6, 0.1), kAll), true);
  const Mesh full = decode(c.file.data(), c.file.size());
  SelectiveDecoder d(std::make_unique<MemorySource>(c.file.data(), c.file.size()));
  expect_same_as_full(d.mesh(), full); // base clustered mesh
  const float centre[3] = {1, 0, 0};
  d.want_sphere(centre, 0.5f, d.finest_level());
  d.update();
  EXPECT_GT(d.clusters_decoded(), 0u);
  EXPECT_LT(d.mesh().vertex_count(), full.vertex_count());
  expect_same_as_full(d.mesh(), full);
  const float other[3] = {-1, 0, 0};
  d.want_sphere(other, 0.5f, d.finest_level() - 1); // incremental
  d.update();
  expect_same_as_full(d.mesh(), full);
  d.clear_wanted(); // coarsening re-decodes
  d.want_cluster(3, d.finest_level());
  d.update();
  expect_same_as_full(d.mesh(), full);
}

TEST(AttributeRoundTrip, DropAndSkip) {
  const Mesh m = with_attributes(gen::noisy_sphere(500, 7, 0.1), kAll);
  AttributeOptions o;
  o.keep.colour = false;
  o.keep.texcoords = false;
  const Coded c = encode_with(m, true, o);
  Mesh out = decode(c.file.data(), c.file.size());
  EXPECT_EQ(out.find(AttributeKind::Colour), nullptr);
  EXPECT_EQ(out.find(AttributeKind::TexCoord), nullptr);
  EXPECT_TRUE(out.texture_files.empty());
  EXPECT_NE(out.find(AttributeKind::Normal), nullptr);
  EXPECT_EQ(out.attributes.size(), 3u);
  DecodeOptions none;
  none.attributes = AttributeMask::none();
  for (int level : {-1, 0, 2}) {
    none.level = level;
    EXPECT_TRUE(decode(c.file.data(), c.file.size(), none).attributes.empty());
  }
  DecodeOptions scalars_only;
  scalars_only.attributes = AttributeMask::none();
  scalars_only.attributes.scalars = true;
  out = decode(c.file.data(), c.file.size(), scalars_only);
  ASSERT_EQ(out.attributes.size(), 2u);
  EXPECT_EQ(out.attributes[1].name, "confidence");

  // Nothing kept: the file is the same as without attributes (version 1/3).
  AttributeOptions drop_all;
  drop_all.keep = AttributeMask::none();
  Mesh plain = m;
  plain.attributes.clear();
  plain.texture_files.clear();
  EXPECT_EQ(encode_with(m, true, drop_all).file, encode_with(plain, true).file);
  EXPECT_EQ(
      inspect(encode_with(plain, false).file.data(), encode_with(plain, false).file.size()).version,
      5u);
}

// A decode that returns no attribute reads past their codes (no prediction, no storage):
// the same positions and triangles as a full decode, at every level and in every selection.
TEST(AttributeRoundTrip, NoAttributesDecodesTheSameMesh) {
  const Mesh m = with_attributes(gen::noisy_sphere(2500, 12, 0.1), kAll);
  DecodeOptions none;
  none.attributes = AttributeMask::none();
  for (bool clustered : {false, true}) {
    SCOPED_TRACE(clustered ? "clustered" : "progressive");
    const Coded c = encode_with(m, clustered);
    const int levels = int(inspect(c.file.data(), c.file.size()).levels.size());
    for (int level : {-1, 0, 1, levels / 2, levels - 1}) {
      none.level = level;
      const Mesh full = decode(c.file.data(), c.file.size(), level);
      const Mesh plain = decode(c.file.data(), c.file.size(), none);
      EXPECT_EQ(plain.positions, full.positions) << "level " << level;
      EXPECT_EQ(plain.triangles, full.triangles) << "level " << level;
      EXPECT_TRUE(plain.attributes.empty());
      EXPECT_TRUE(plain.texture_files.empty());
    }
    if (!clustered)
      continue;
    SelectiveOptions so;
    so.attributes = AttributeMask::none();
    SelectiveDecoder with(std::make_unique<MemorySource>(c.file.data(), c.file.size()));
    SelectiveDecoder without(std::make_unique<MemorySource>(c.file.data(), c.file.size()), so);
    const float centre[3] = {1, 0, 0};
    for (SelectiveDecoder *d : {&with, &without}) { // a region, then more of the mesh
      d->want_sphere(centre, 0.6f, d->finest_level());
      d->update();
    }
    EXPECT_EQ(without.mesh().positions, with.mesh().positions);
    EXPECT_EQ(without.mesh().triangles, with.mesh().triangles);
    for (SelectiveDecoder *d : {&with, &without}) {
      d->want_cluster(0, d->finest_level());
      d->update();
    }
    const Mesh region = without.mesh();
    EXPECT_EQ(region.positions, with.mesh().positions);
    EXPECT_EQ(region.triangles, with.mesh().triangles);
    EXPECT_TRUE(region.attributes.empty());
    // Only the texture coordinates asked for: the attributes are decoded and returned.
    DecodeOptions uv;
    uv.attributes = AttributeMask::none();
    uv.attributes.texcoords = true;
    const Mesh only_uv = decode(c.file.data(), c.file.size(), uv);
    ASSERT_EQ(only_uv.attributes.size(), 1u);
    EXPECT_EQ(only_uv.attributes[0].kind, AttributeKind::TexCoord);
    EXPECT_EQ(only_uv.texture_files, m.texture_files);
  }
}

// The memory checks count the attributes: a limit that fits the mesh without them refuses
// it with them, and a decode that returns none of them needs no more than without.
TEST(AttributeRoundTrip, MemoryLimitsCountTheAttributes) {
  const Mesh plain = gen::noisy_sphere(3000, 13, 0.1);
  const Mesh m = with_attributes(plain, kAll);
  const uint64_t v = m.vertex_count(), f = m.triangle_count();
  const uint64_t per_vertex = encode_attribute_bytes_per_vertex(m, AttributeOptions());
  EXPECT_EQ(per_vertex, 16u + 34u * 10); // RGBA 4 + normal 2 + 2 scalars + UV 2 = 10 codes
  EncodeOptions o;
  o.threads = 1; // (each further thread adds decode_thread_memory: not what this tests)
  o.memory_limit = encode_memory_estimate(v, f) + v * per_vertex / 2;
  EXPECT_NO_THROW(encode(plain, o));
  try {
    encode(m, o);
    ADD_FAILURE() << "the attributes do not fit";
  } catch (const Error &e) {
    EXPECT_EQ(e.kind(), Error::Kind::MemoryLimit) << e.what();
  }
  o.attributes.keep = AttributeMask::none(); // dropped: not counted
  EXPECT_NO_THROW(encode(m, o));

  const Coded c = encode_with(m, true);
  const FileInfo info = inspect(c.file.data(), c.file.size());
  const uint64_t decode_extra = decode_attribute_bytes_per_vertex(info, AttributeMask());
  EXPECT_EQ(decode_extra, 16u + 8 * 10 + (4 + 12 + 8 + 8));
  EXPECT_EQ(decode_attribute_bytes_per_vertex(info, AttributeMask::none()), 0u);
  DecodeOptions d;
  d.threads = 1;
  d.memory_limit = decode_memory_estimate(v, f, true) + v * decode_extra / 2;
  try {
    decode(c.file.data(), c.file.size(), d);
    ADD_FAILURE() << "the attributes do not fit";
  } catch (const Error &e) {
    EXPECT_EQ(e.kind(), Error::Kind::MemoryLimit) << e.what();
  }
  d.attributes = AttributeMask::none();
  EXPECT_NO_THROW(decode(c.file.data(), c.file.size(), d));
  // The selective decoder checks the base clustered mesh (the rest is decoded on request).
  const uint32_t gl = info.global_levels;
  const uint64_t bv = gl ? info.levels[gl - 1].vertices : info.base_vertices;
  const uint64_t bf = gl ? info.levels[gl - 1].faces : info.base_faces;
  SelectiveOptions so;
  so.threads = 1;
  so.memory_limit = decode_memory_estimate(bv, bf, true) + bv * decode_extra / 2;
  EXPECT_THROW(SelectiveDecoder(std::make_unique<MemorySource>(c.file.data(), c.file.size()), so),
               Error);
  so.attributes = AttributeMask::none();
  EXPECT_NO_THROW(
      SelectiveDecoder(std::make_unique<MemorySource>(c.file.data(), c.file.size()), so));
}

TEST(AttributeRoundTrip, BadInputIsRefused) {
  Mesh m = with_attributes(gen::noisy_sphere(200, 8, 0.1), kColour | kScalars);
  m.attributes[0].colour.pop_back();
  EXPECT_THROW(encode(m), Error);
  m = with_attributes(gen::noisy_sphere(200, 8, 0.1), kScalars);
  m.attributes[0].values[5] = std::numeric_limits<float>::infinity();
  try {
    encode(m);
    ADD_FAILURE();
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("'quality' of vertex 5 is infinite"), std::string::npos)
        << e.what();
  }
  AttributeOptions dropped;
  dropped.keep.scalars = false; // a dropped attribute is not checked
  EncodeOptions o;
  o.attributes = dropped;
  EXPECT_NO_THROW(encode(m, o));
}

TEST(AttributeRoundTrip, DamagedSectionIsAClearError) {
  const Coded c = encode_with(with_attributes(gen::noisy_sphere(300, 9, 0.1), kColour), false);
  const FileInfo info = inspect(c.file.data(), c.file.size());
  std::vector<uint8_t> bad = c.file;
  bad[info.header_bytes + info.base_bytes + 3] ^= 0x10; // inside the ATTR body
  try {
    decode(bad.data(), bad.size());
    ADD_FAILURE();
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("ATTR"), std::string::npos) << e.what();
  }
  // The base mesh's codes are there: a decode without attributes needs them too (the other
  // vertices' codes are interleaved with their positions).
  DecodeOptions none;
  none.attributes = AttributeMask::none();
  EXPECT_THROW(decode(bad.data(), bad.size(), none), Error);
}

// Attributes are coded with the positions, in the level streams and cluster blocks: a
// selective decode reads only the blocks of its clusters, whose size grows with them.
TEST(AttributeRoundTrip, SelectiveDecodesReadOnlyTheirBlocks) {
  const Mesh plain = gen::noisy_sphere(3000, 10, 0.1);
  const Coded with = encode_with(with_attributes(plain, kAll), true);
  const Coded without = encode_with(plain, true);
  const FileInfo a = inspect(with.file.data(), with.file.size());
  const FileInfo b = inspect(without.file.data(), without.file.size());
  EXPECT_EQ(a.clusters, b.clusters);
  EXPECT_GT(a.cluster_bytes, b.cluster_bytes + 3000); // the attributes are in the blocks
  EXPECT_LT(a.attribute_bytes, a.total_bytes / 20);   // the section: base mesh only
  SelectiveDecoder d(std::make_unique<MemorySource>(with.file.data(), with.file.size()));
  d.want_cluster(0, d.base_clustered_level() + 2);
  d.update();
  EXPECT_LT(d.blocks_read(), a.clusters / 4);
  EXPECT_LT(d.bytes_read(), a.global_bytes + a.cluster_bytes / 4); // not the other blocks
  expect_same_as_full(d.mesh(), decode(with.file.data(), with.file.size()));
}

} // namespace
} // namespace pomar
