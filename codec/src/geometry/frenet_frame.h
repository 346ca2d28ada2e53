// Exact integer bijection between the global (x,y,z) frame and the local Frenet frame
// (t1, t2, n) of a vertex split (paper section 5.1, Figure 6).
//
// The rotation R^T that maps the global axes onto the local frame is written as three
// plane (Givens) rotations. Each one is a number of exact quarter turns followed by a
// residual rotation of at most 45 degrees, and that residual is applied as three integer
// lifting shears (x += round(T*y); y += round(S*x); x += round(T*y)). Every step is
// undone exactly by subtracting the same rounded value, so the map is a bijection on Z^3
// whatever the coefficients are. The coefficients are derived only from integer inputs
// with IEEE-754 basic operations (+ - * / sqrt, no FMA contraction) and then rounded to
// Q16 fixed point, so encoder and decoder rebuild them bit for bit.
#pragma once

#include <cstdint>

namespace pomar {

/// One plane rotation: `quarter_turns` times (x,y) -> (y,-x) on its plane's axes (x,y),
/// then shears (t = s = 0: none; the shears then add nothing).
struct Givens {
  uint8_t quarter_turns = 0;
  int64_t t = 0, s = 0; // Q16 shear coefficients
};

/// The local frame of one vertex split, as three Givens rotations, each in a fixed plane:
/// g[0] in (x,y), g[1] in (z,x), g[2] in (x,y) (kPlane; fixed planes let the maps keep the
/// three components in registers).
struct FrenetFrame {
  Givens g[3];
};
constexpr int kPlane[3][2] = {{0, 1}, {2, 0}, {0, 1}};

/// Build the frame whose third axis is along `normal` and whose first axis is along the
/// projection of `edge` (v_ref - v_to) on the tangent plane. Degenerate inputs (zero
/// normal, edge parallel to the normal) leave the corresponding rotations at identity.
FrenetFrame make_frenet_frame(const int64_t normal[3], const int64_t edge[3]);

// Integer only (defined here so that the traversal inlines them: they run once or twice
// per split); the floating-point part, the coefficients, is in frenet_frame.cpp.
namespace frenet_detail {
constexpr int kShift = 16;
constexpr int64_t kHalf = int64_t(1) << (kShift - 1);

/// round(c * y / 2^16) with floor semantics on the shifted sum, identical on both sides.
inline int64_t shear(int64_t c, int64_t y) { return (c * y + kHalf) >> kShift; }

/// `turns` quarter turns (x,y) -> (y,-x) at once: one turn swaps and negates, two negate
/// both (no loop: the count changes from split to split and a loop mispredicted).
template <class T> inline void quarter_turns(int turns, T &x, T &y) {
  if (turns & 1) {
    const T t = x;
    x = y;
    y = -t;
  }
  if (turns & 2) {
    x = -x;
    y = -y;
  }
}

template <int I, int J> inline void apply(const Givens &g, int64_t v[3]) {
  int64_t &x = v[I], &y = v[J];
  quarter_turns(g.quarter_turns, x, y);
  x += shear(g.t, y);
  y += shear(g.s, x);
  x += shear(g.t, y);
}

template <int I, int J> inline void unapply(const Givens &g, int64_t v[3]) {
  int64_t &x = v[I], &y = v[J];
  x -= shear(g.t, y);
  y -= shear(g.s, x);
  x -= shear(g.t, y);
  quarter_turns(4 - g.quarter_turns, x, y); // (4 - k turns undo k)
}
} // namespace frenet_detail

/// Global residual -> local (t1, t2, n) components. Exact inverse of to_global().
inline void to_local(const FrenetFrame &f, int64_t v[3]) {
  using namespace frenet_detail;
  apply<kPlane[0][0], kPlane[0][1]>(f.g[0], v);
  apply<kPlane[1][0], kPlane[1][1]>(f.g[1], v);
  apply<kPlane[2][0], kPlane[2][1]>(f.g[2], v);
}
/// Local components -> global residual.
inline void to_global(const FrenetFrame &f, int64_t v[3]) {
  using namespace frenet_detail;
  unapply<kPlane[2][0], kPlane[2][1]>(f.g[2], v);
  unapply<kPlane[1][0], kPlane[1][1]>(f.g[1], v);
  unapply<kPlane[0][0], kPlane[0][1]>(f.g[0], v);
}

} // namespace pomar
