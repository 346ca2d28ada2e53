// Decimation (paper section 4): discrete levels of halfedge collapses.
//
// Each level ranks the collapsible halfedges v_from -> v_to by the length of v_to-v_ref
// (v_ref: the patch vertex farthest from v_to among those that get a new edge to v_to)
// and collapses greedily, shortest first. A collapse must keep the mesh manifold (link
// condition, boundary rules, no tetrahedron / lone triangle collapse) and must not turn
// any patch face normal by more than acos(0.7). Once a patch has been modified, no other
// collapse of the same level may touch its faces, and a vertex is v_to at most once per
// level: so the vertex splits of a level are independent and can be replayed in any order.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/corner_table.h"
#include "pomar/pomar.h"

namespace pomar {

/// One halfedge collapse, in input vertex ids. v_l / v_r are kNone on a boundary side.
struct Collapse {
  uint32_t v_from, v_to, v_l, v_r;
};

struct DecimationOptions {
  double normal_cosine = 0.7;        ///< reject collapses turning a patch face normal more
  double min_level_fraction = 0.002; ///< stop when a level removes fewer vertices than this
  uint32_t max_levels = 250;
  unsigned threads = 1; ///< threads evaluating the candidates (the result does not depend on it)
  /// Per vertex, optional: 1 = never v_from (the vertex stays to the base mesh; it may be
  /// v_to). Texture seams lock their vertices (lossless/seam_cut.h).
  const std::vector<uint8_t> *locked = nullptr;
  /// Per vertex, optional (with `origin`): the other copy of a vertex on a simple texture
  /// seam, or kNone. Twins collapse together or not at all: in one level, each along its
  /// side of the seam onto the copies of one vertex (origin[] says which vertices are copies
  /// of one: equal values), so both sides of the seam keep the same vertices.
  const std::vector<uint32_t> *twin = nullptr;
  const std::vector<uint32_t> *origin = nullptr;
};

struct Decimation {
  /// levels[0] is the first decimation level (applied to the input mesh); the encoder
  /// replays them backwards, levels.back() first.
  std::vector<std::vector<Collapse>> levels;
  std::vector<uint32_t> base_triangles; ///< surviving faces, input vertex ids
};

/// Decimate the mesh described by `ct` (consumed) with quantized positions `q` (xyz).
Decimation decimate(CornerTable ct, const std::vector<int32_t> &q, const DecimationOptions &options,
                    const Progress &progress);

} // namespace pomar
