#include "refine/vertex_split.h"

namespace pomar {

uint32_t apply_split(CornerTable &ct, const SplitOp &op, uint32_t v_from, uint32_t face) {
  using C = CornerTable;
  const uint32_t c_first = op.first_corner;
  // Move the range to v_from, swinging to the corner of v_to in the last face of the
  // range (v_to, w_k, v_r). (Swings read O only: moving V on the way changes nothing.)
  uint32_t c_last = c_first;
  ct.V[c_first] = v_from;
  for (uint32_t t = 1; t < op.faces; ++t) {
    c_last = ct.swing_ccw(c_last);
    ct.V[c_last] = v_from;
  }
  // Faces across the two outer edges (v_to,v_l) and (v_r,v_to) of the range.
  const uint32_t across_l = ct.O[C::prev(c_first)];
  const uint32_t across_r = ct.O[C::next(c_last)];
  ct.VC[v_from] = c_first;
  uint32_t a2 = kNone, b2 = kNone;
  if (op.has_l) { // face (v_from, v_to, v_l)
    const uint32_t a0 = 3 * face++;
    ct.V[a0] = v_from;
    ct.V[a0 + 1] = op.v_to;
    ct.V[a0 + 2] = ct.V[C::next(c_first)]; // v_l
    ct.link(a0, across_l);
    ct.link(a0 + 1, C::prev(c_first));
    a2 = a0 + 2;
    ct.VC[op.v_to] = a0 + 1;
  }
  if (op.has_r) { // face (v_to, v_from, v_r)
    const uint32_t b0 = 3 * face;
    ct.V[b0] = op.v_to;
    ct.V[b0 + 1] = v_from;
    ct.V[b0 + 2] = ct.V[C::prev(c_last)]; // v_r
    ct.link(b0, C::next(c_last));
    ct.link(b0 + 1, across_r);
    b2 = b0 + 2;
    ct.VC[op.v_to] = b0;
  }
  ct.link(a2, b2); // the split edge (v_from, v_to); a boundary edge if one face is missing
  return uint32_t(op.has_l) + uint32_t(op.has_r);
}

} // namespace pomar
