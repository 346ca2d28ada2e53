#include "refine/vertex_split.h"

namespace pomar {

void apply_split(CornerTable &ct, const SplitOp &op, uint32_t v_from) {
  using C = CornerTable;
  const uint32_t c_first = op.first_corner;
  // The corner of v_to in the last face of the range (v_to, w_k, v_r).
  uint32_t c_last = c_first;
  for (uint32_t t = 1; t < op.faces; ++t)
    c_last = ct.swing_ccw(c_last);
  // Faces across the two outer edges (v_to,v_l) and (v_r,v_to) of the range.
  const uint32_t across_l = ct.O[C::prev(c_first)];
  const uint32_t across_r = ct.O[C::next(c_last)];
  // Move the range to v_from.
  uint32_t c = c_first;
  for (uint32_t t = 0; t < op.faces; ++t) {
    ct.V[c] = v_from;
    if (t + 1 < op.faces)
      c = ct.swing_ccw(c);
  }
  ct.VC.push_back(c_first);
  uint32_t a2 = kNone, b2 = kNone;
  if (op.has_l) { // face (v_from, v_to, v_l)
    const uint32_t a0 = static_cast<uint32_t>(ct.V.size());
    const uint32_t v_l = ct.V[C::next(c_first)];
    ct.V.insert(ct.V.end(), {v_from, op.v_to, v_l});
    ct.O.insert(ct.O.end(), {kNone, kNone, kNone});
    ct.link(a0, across_l);
    ct.link(a0 + 1, C::prev(c_first));
    a2 = a0 + 2;
    ct.VC[op.v_to] = a0 + 1;
  }
  if (op.has_r) { // face (v_to, v_from, v_r)
    const uint32_t b0 = static_cast<uint32_t>(ct.V.size());
    const uint32_t v_r = ct.V[C::prev(c_last)];
    ct.V.insert(ct.V.end(), {op.v_to, v_from, v_r});
    ct.O.insert(ct.O.end(), {kNone, kNone, kNone});
    ct.link(b0, C::next(c_last));
    ct.link(b0 + 1, across_r);
    b2 = b0 + 2;
    ct.VC[op.v_to] = b0;
  }
  ct.link(a2, b2); // the split edge (v_from, v_to); a boundary edge if one face is missing
}

} // namespace pomar
