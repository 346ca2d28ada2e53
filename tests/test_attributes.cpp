// Attribute quantizers, checks and (with the encoder) round trips of every attribute kind.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>

#include "attributes/attribute_quantize.h"
#include "pomar/pomar.h"

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
  const float values[] = {-std::numeric_limits<float>::infinity(), -1e30f, -1.0f, -1e-40f, -0.0f,
                          0.0f, 1e-45f, 1e-40f, 0.5f, 1.0f, 3e38f,
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
  expect_error(triangle_with(n), true, "of vertex 1 has length 0");
  EXPECT_NO_THROW(validate_attributes(triangle_with(n), false));
}

} // namespace
} // namespace pomar
