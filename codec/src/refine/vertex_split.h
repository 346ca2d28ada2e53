// The vertex split, inverse of the halfedge collapse (paper Figure 2), on a CornerTable.
#pragma once

#include <cstdint>

#include "mesh/corner_table.h"

namespace pomar {

/// A split of v_to: the `faces` consecutive faces of v_to's fan starting (counter-
/// clockwise) at corner `first_corner` move to the new vertex v_from. They run from v_l to
/// v_r; has_l / has_r say whether the new faces (v_from, v_to, v_l) and (v_to, v_from, v_r)
/// exist (false on a boundary side).
struct SplitOp {
  uint32_t v_to;
  uint32_t first_corner;
  uint32_t faces;
  bool has_l, has_r;
};

/// Apply `op` in place: vertex `v_from` and the new faces, `face` then `face + 1`
/// (has_l's first), are already in the arrays (refine/level_step.h sizes them once for
/// all the splits of a step); their entries are written here. Returns the number of
/// faces created (has_l + has_r). Valid as long as the op's faces were not touched by
/// other splits.
uint32_t apply_split(CornerTable &ct, const SplitOp &op, uint32_t v_from, uint32_t face);

} // namespace pomar
