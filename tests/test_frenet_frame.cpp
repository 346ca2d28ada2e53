// The integer Frenet-frame map is an exact bijection and close to a true rotation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/frenet_frame.h"

namespace pomar {
namespace {

TEST(FrenetFrame, ExactlyInvertibleOnRandomFramesAndVectors) {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int64_t> coord(-(int64_t(1) << 25), int64_t(1) << 25);
  std::uniform_int_distribution<int64_t> big(-(int64_t(1) << 51), int64_t(1) << 51);
  for (int t = 0; t < 20000; ++t) {
    const int64_t n[3] = {big(rng) >> (rng() % 50), big(rng) >> (rng() % 50),
                          big(rng) >> (rng() % 50)};
    const int64_t e[3] = {coord(rng), coord(rng), coord(rng)};
    const FrenetFrame f = make_frenet_frame(n, e);
    const int64_t r[3] = {coord(rng) >> (rng() % 24), coord(rng) >> (rng() % 24),
                          coord(rng) >> (rng() % 24)};
    int64_t v[3] = {r[0], r[1], r[2]};
    to_local(f, v);
    to_global(f, v);
    ASSERT_EQ(v[0], r[0]);
    ASSERT_EQ(v[1], r[1]);
    ASSERT_EQ(v[2], r[2]);
  }
}

TEST(FrenetFrame, DegenerateInputsStayInvertible) {
  const int64_t zero[3] = {0, 0, 0};
  const int64_t along[3] = {0, 0, 5};
  for (const int64_t *n : {zero, along}) {
    for (const int64_t *e : {zero, along}) {
      const FrenetFrame f = make_frenet_frame(n, e);
      int64_t v[3] = {7, -3, 11};
      to_local(f, v);
      to_global(f, v);
      EXPECT_EQ(v[0], 7);
      EXPECT_EQ(v[1], -3);
      EXPECT_EQ(v[2], 11);
    }
  }
}

TEST(FrenetFrame, MapsNormalToZAndEdgeToX) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0, 1);
  for (int t = 0; t < 2000; ++t) {
    const double nx = g(rng), ny = g(rng), nz = g(rng);
    const int64_t n[3] = {int64_t(nx * 1e6), int64_t(ny * 1e6), int64_t(nz * 1e6)};
    const int64_t e[3] = {int64_t(g(rng) * 1e4), int64_t(g(rng) * 1e4), int64_t(g(rng) * 1e4)};
    const FrenetFrame f = make_frenet_frame(n, e);
    // The (scaled) normal lands on +z up to rounding.
    const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
    int64_t v[3] = {n[0] >> 8, n[1] >> 8, n[2] >> 8};
    to_local(f, v);
    EXPECT_NEAR(double(v[2]), len / 256.0, 8.0 + len / 256.0 * 1e-3);
    EXPECT_NEAR(double(v[0]), 0.0, 8.0 + len / 256.0 * 1e-3);
    EXPECT_NEAR(double(v[1]), 0.0, 8.0 + len / 256.0 * 1e-3);
    // The edge's tangential part lands on +x: y stays near zero.
    int64_t w[3] = {e[0], e[1], e[2]};
    to_local(f, w);
    EXPECT_NEAR(double(w[1]), 0.0, 8.0);
    EXPECT_GE(double(w[0]), -8.0);
    // Lengths are preserved up to the lifting roundings.
    int64_t r[3] = {int64_t(g(rng) * 1000), int64_t(g(rng) * 1000), int64_t(g(rng) * 1000)};
    const double before = std::sqrt(double(r[0]) * r[0] + double(r[1]) * r[1] + double(r[2]) * r[2]);
    to_local(f, r);
    const double after = std::sqrt(double(r[0]) * r[0] + double(r[1]) * r[1] + double(r[2]) * r[2]);
    EXPECT_NEAR(after, before, 6.0 + before * 1e-3);
  }
}

} // namespace
} // namespace pomar
