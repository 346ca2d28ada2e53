// Geometry prediction (paper section 5.1): where v_from is expected, and the local frame
// its residual is coded in. Shared by the encoder and the decoder through code_vertex
// (refine/level_traversal.h); inline, as the traversal is (it runs once per split).
#pragma once

#include <cstdint>
#include <vector>

#include "entropy/models.h"
#include "geometry/frenet_frame.h"
#include "geometry/normal_predictor.h"
#include "mesh/corner_table.h"
#include "refine/patch.h"

namespace pomar {

/// Prediction of v_from: the barycentre of its future neighbours (v_to and the patch ring
/// from v_l to v_r) plus, along the normal, a curvature term; residuals are expressed in
/// the Frenet frame built from edge v_to-v_ref and the normals of the (one or two) faces
/// along that edge. The curvature term: on a curved surface v_from sits off the plane of
/// its ring the same way v_to sits off its own ring, so half of v_to's umbrella vector
/// (the barycentre of v_to's ring minus v_to, along the normal) is subtracted; a level with
/// a linear NormalPredictor takes its combination of neighbours' heights instead.
struct Prediction {
  int32_t barycentre[3];
  FrenetFrame frame;
  int64_t offset[3];   // expected residual in the local frame
  int context;         // geometry model context (local edge length class)
  int64_t umbrella[3]; // v_to's umbrella vector (truncated mean of the spokes, global axes)
};

/// Integer normal of face k of the ring (v, n_k, n_k+1), from the spokes of v.
inline void add_face_normal(const Spoke *spokes, uint32_t m, uint32_t k, int64_t n[3]) {
  const int64_t *u = spokes[k].d, *w = spokes[(k + 1) % m].d;
  n[0] += u[1] * w[2] - u[2] * w[1];
  n[1] += u[2] * w[0] - u[0] * w[2];
  n[2] += u[0] * w[1] - u[1] * w[0];
}

/// The vectors of the linear normal predictor, offsets from v_to (integers, from what the
/// decoder knows): [0] the barycentre's, [1] v_ref's, [2] the sum of the two ring
/// neighbours of v_ref (on an open fan's end the one there is, twice), [3] v_to's umbrella
/// vector (Prediction::umbrella). `pred` is predict()'s.
inline void normal_vectors(const int32_t at[3], const Ring &ring, const Spoke *spokes,
                           const PatchRange &p, const Prediction &pred,
                           int64_t x[kNormalFeatures][3]) {
  const uint32_t m = ring.size(), j = p.j;
  const bool before = ring.closed || j > 0, after = ring.closed || j + 1 < m;
  const uint32_t a = before ? (j + m - 1) % m : after ? (j + 1) % m : j;
  const uint32_t b = after ? (j + 1) % m : a;
  for (int k = 0; k < 3; ++k) {
    x[0][k] = int64_t(pred.barycentre[k]) - at[k];
    x[1][k] = spokes[j].d[k];
    x[2][k] = spokes[a].d[k] + spokes[b].d[k];
    x[3][k] = pred.umbrella[k];
  }
}

/// The linear predictor's normal offset: the normal component, in the split's frame, of
/// sum c_k x_k (one frame map per split), divided by 2^kNormalShift and rounded (halves
/// up). About sum c_k h(x_k) / 2^kNormalShift, h(x_k) being the heights the encoder fits on.
inline void combine_normal_vectors(const NormalPredictor &np, const int64_t x[kNormalFeatures][3],
                                   int64_t v[3]) {
  for (int d = 0; d < 3; ++d)
    v[d] = int64_t(np.c[0]) * x[0][d] + int64_t(np.c[1]) * x[1][d] + int64_t(np.c[2]) * x[2][d] +
           int64_t(np.c[3]) * x[3][d];
}
inline int64_t linear_normal_offset(int64_t height) {
  return (height + (int64_t(1) << (kNormalShift - 1))) >> kNormalShift;
}
inline int64_t normal_offset(const NormalPredictor &np, const FrenetFrame &frame,
                             const int64_t x[kNormalFeatures][3]) {
  int64_t v[3];
  combine_normal_vectors(np, x, v);
  to_local(frame, v);
  return linear_normal_offset(v[2]);
}

/// Predict v_from for the split of `v_to` (at position `at`) with patch `p` of its ring,
/// whose spokes (refine/patch.h) give the neighbours' offsets from v_to; `np`: the level's
/// normal predictor. (Always inlined into code_vertex, as before the linear predictor made it
/// larger: called, it cost the decoder 3% more instructions.)
[[gnu::always_inline]] inline void predict(const int32_t at[3], const Ring &ring,
                                           const Spoke *spokes, const PatchRange &p,
                                           const NormalPredictor &np, Prediction &out) {
  const uint32_t m = ring.size();
  // Barycentre of v_to and the patch ring: sum = count * at + the spokes' offsets.
  int64_t sx = 0, sy = 0, sz = 0; // (components spelled out: the -O2 build kept the loops)
  for (uint32_t t = 0, i = p.first_face; t <= p.faces; ++t, i = i + 1 == m ? 0 : i + 1) {
    sx += spokes[i].d[0];
    sy += spokes[i].d[1];
    sz += spokes[i].d[2];
  }
  int64_t sum[3] = {sx, sy, sz};
  const int64_t count = int64_t(p.faces) + 2;
  for (int k = 0; k < 3; ++k) { // round to nearest; sums are non-negative
    sum[k] += count * at[k];
    out.barycentre[k] = static_cast<int32_t>((2 * sum[k] + count) / (2 * count));
  }
  int64_t normal[3] = {0, 0, 0};
  const uint32_t j = p.j;
  if (ring.closed || j < ring.faces())
    add_face_normal(spokes, m, j, normal);
  if (ring.closed || j > 0)
    add_face_normal(spokes, m, (j + m - 1) % m, normal);
  const int64_t *edge = spokes[j].d;
  out.frame = make_frenet_frame(normal, edge);
  out.context = geometry_context(spokes[j].len2);
  // v_to's umbrella vector (integer mean, truncated).
  int64_t ux = 0, uy = 0, uz = 0;
  for (uint32_t i = 0; i < m; ++i) {
    ux += spokes[i].d[0];
    uy += spokes[i].d[1];
    uz += spokes[i].d[2];
  }
  out.umbrella[0] = ux / int64_t(m);
  out.umbrella[1] = uy / int64_t(m);
  out.umbrella[2] = uz / int64_t(m);
  out.offset[0] = 0;
  out.offset[1] = 0;
  // One frame map either way: the umbrella vector's (curvature term) or the combination's.
  int64_t w[3] = {out.umbrella[0], out.umbrella[1], out.umbrella[2]};
  if (np.linear) {
    int64_t x[kNormalFeatures][3];
    normal_vectors(at, ring, spokes, p, out, x);
    combine_normal_vectors(np, x, w);
  }
  to_local(out.frame, w);
  out.offset[2] =
      np.linear ? linear_normal_offset(w[2]) : (1 - w[2]) >> 1; // round(-umbrella_n / 2)
}

} // namespace pomar
