#include "geometry/frenet_frame.h"

#include <cmath>
#include <cstdlib>

// This translation unit must be compiled without floating-point contraction or fast-math
// (see codec/CMakeLists.txt): the coefficients below are part of the bitstream.

namespace pomar {
namespace {

using frenet_detail::apply;

/// floor(x * 2^16 + 0.5) as an integer, for |x| <= 1 (the coefficients: a tangent of at
/// most 45 degrees, a sine): truncation toward zero, one down if that went up, is floor
/// exactly, without libm's call.
int64_t fixed_round(double x) {
  const double y = x * 65536.0 + 0.5;
  const int64_t t = static_cast<int64_t>(y);
  return static_cast<double>(t) > y ? t - 1 : t;
}

/// Rotation in its plane (x,y) that maps direction (a,b) onto the positive x axis. (Always
/// inlined: make_frenet_frame calls it three times per split.)
[[gnu::always_inline]] inline Givens givens_from_pair(double a, double b) {
  Givens g;
  if (a == 0.0 && b == 0.0)
    return g;
  // Quarter turns bring the direction within 45 degrees of +i.
  int k;
  if (std::fabs(a) >= std::fabs(b))
    k = a >= 0 ? 0 : 2;
  else
    k = b > 0 ? 1 : 3;
  frenet_detail::quarter_turns(k, a, b); // (in doubles: exact, sign changes and a swap)
  g.quarter_turns = static_cast<uint8_t>(k);
  if (b == 0.0)
    return g;
  const double r = std::sqrt(a * a + b * b);
  g.t = fixed_round(b / (r + a)); // tan(beta/2)
  g.s = fixed_round(-b / r);      // -sin(beta)
  return g;
}

} // namespace

FrenetFrame make_frenet_frame(const int64_t normal[3], const int64_t edge[3]) {
  FrenetFrame f;
  const double nx = static_cast<double>(normal[0]);
  const double ny = static_cast<double>(normal[1]);
  const double nz = static_cast<double>(normal[2]);
  // 1) about z: bring the normal into the xz half-plane x >= 0.
  f.g[0] = givens_from_pair(nx, ny);
  // 2) in the (z,x) plane: bring it onto +z. After step 1 it is (hypot(nx,ny), 0, nz).
  f.g[1] = givens_from_pair(nz, std::sqrt(nx * nx + ny * ny));
  // 3) about the new z: bring the edge's tangential part onto +x (integer-rotated edge).
  int64_t e[3] = {edge[0], edge[1], edge[2]};
  apply<kPlane[0][0], kPlane[0][1]>(f.g[0], e);
  apply<kPlane[1][0], kPlane[1][1]>(f.g[1], e);
  f.g[2] = givens_from_pair(static_cast<double>(e[0]), static_cast<double>(e[1]));
  return f;
}

} // namespace pomar
