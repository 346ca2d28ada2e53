// The seam cut's wedge texture coordinate predicted from the positions (files whose ATTR
// descriptor of `pomar:corner texcoord` has the positions flag, docs/format.md "ATTR"): a
// vertex x near a known face (p0, p1, p2) of its chart is given the (u, v) that the face's
// affine map from positions to (u, v) gives x's projection onto the face's plane (its
// least-squares coordinates along the edges p1 - p0 and p2 - p0). A chart that maps its
// surface affinely (a projection, a flattened near-planar patch) is predicted exactly, and
// no orientation or scale of the chart is assumed. The predictions of several faces are
// averaged, each weighted by its Gram determinant (|e1 x e2|^2: a thin face says little).
//
// In doubles from integer codes and positions, with +, -, * and / only (each correctly
// rounded in IEEE 754), in one order: the encoder and every decoder get the same codes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "mesh/corner_table.h"
#include "refine/level_mesh.h"
#include "refine/patch.h"

namespace pomar {

/// Sums the predictions of one vertex's (u, v) codes from known faces.
class WedgeFromPositions {
public:
  explicit WedgeFromPositions(const int32_t x[3]) : x_(x) {}

  /// Known face (p0, p1, p2) with (u, v) codes u0, u1, u2.
  void add(const int32_t *p0, const int32_t *p1, const int32_t *p2, const int64_t *u0,
           const int64_t *u1, const int64_t *u2) {
    double e1[3], e2[3], d[3];
    for (int k = 0; k < 3; ++k) {
      e1[k] = double(p1[k]) - double(p0[k]);
      e2[k] = double(p2[k]) - double(p0[k]);
      d[k] = double(x_[k]) - double(p0[k]);
    }
    const double g11 = dot(e1, e1), g22 = dot(e2, e2), g12 = dot(e1, e2);
    const double r1 = dot(d, e1), r2 = dot(d, e2);
    const double det = g11 * g22 - g12 * g12;
    if (!(det > 0.0))
      return; // (a face without area)
    // x's coordinates along e1 and e2, times det.
    const double a1 = g22 * r1 - g12 * r2, a2 = g11 * r2 - g12 * r1;
    for (int j = 0; j < 2; ++j)
      sum_[j] += det * double(u0[j]) + a1 * (double(u1[j]) - double(u0[j])) +
                 a2 * (double(u2[j]) - double(u0[j]));
    weight_ += det;
  }

  /// The weighted mean, rounded and clamped to the codes' ranges; false if no face gave one.
  bool get(const int64_t lo[2], const int64_t hi[2], int64_t out[2]) const {
    if (!(weight_ > 0.0))
      return false;
    for (int j = 0; j < 2; ++j) {
      const double m = sum_[j] / weight_;
      out[j] = std::llround(std::min(std::max(m, double(lo[j])), double(hi[j])));
    }
    return true;
  }

private:
  static double dot(const double a[3], const double b[3]) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  }
  const int32_t *x_;
  double sum_[2] = {0.0, 0.0};
  double weight_ = 0.0;
};

/// The prediction of split vertex x's wedge texture coordinate (`pred`: its two codes) from
/// v_to's patch faces (v_to, n_i, n_i+1) of `ring` (v_to's ring as the level sees it), which
/// the split gives to x. False (pred untouched) if the patch faces have no area.
inline bool predict_wedge_from_positions(const LevelMesh &mesh, uint32_t v_to, const Ring &ring,
                                         const PatchRange &p, const int32_t x[3], int64_t *pred) {
  const uint32_t n = mesh.attr_codes, k = uint32_t(mesh.wedge_uv_code), m = ring.size();
  const auto uv = [&](uint32_t v) { return &mesh.attr[size_t(v) * n + k]; };
  const auto at = [&](uint32_t v) { return &mesh.q[3 * size_t(v)]; };
  WedgeFromPositions w(x);
  for (uint32_t t = 0, i = p.first_face; t < p.faces; ++t, i = (i + 1) % m) {
    const uint32_t a = ring.neighbour[i], b = ring.neighbour[(i + 1) % m];
    w.add(at(v_to), at(a), at(b), uv(v_to), uv(a), uv(b));
  }
  const int64_t lo[2] = {mesh.attr_lo[k], mesh.attr_lo[k + 1]};
  const int64_t hi[2] = {mesh.attr_hi[k], mesh.attr_hi[k + 1]};
  return w.get(lo, hi, pred);
}

} // namespace pomar
