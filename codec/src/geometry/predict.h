// Geometry prediction (paper section 5.1): where v_from is expected, and the local frame
// its residual is coded in. Shared by the encoder and the decoder through code_vertex
// (refine/level_traversal.h).
#pragma once

#include <cstdint>
#include <vector>

#include "geometry/frenet_frame.h"
#include "mesh/corner_table.h"
#include "refine/patch.h"

namespace pomar {

/// Prediction of v_from: the barycentre of its future neighbours (v_to and the patch ring
/// from v_l to v_r) plus, along the normal, a curvature term; residuals are expressed in
/// the Frenet frame built from edge v_to-v_ref and the normals of the (one or two) faces
/// along that edge. The curvature term: on a curved surface v_from sits off the plane of
/// its ring the same way v_to sits off its own ring, so half of v_to's umbrella vector
/// (the barycentre of v_to's ring minus v_to, along the normal) is subtracted.
struct Prediction {
  int32_t barycentre[3];
  FrenetFrame frame;
  int64_t offset[3]; // expected residual in the local frame
  int context;       // geometry model context (local edge length class)
};

/// Predict v_from for the split of `v_to` with patch `p` of its ring (positions `q`).
void predict(const std::vector<int32_t> &q, uint32_t v_to, const Ring &ring, const PatchRange &p,
             Prediction &out);

} // namespace pomar
