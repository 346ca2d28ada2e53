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

/// Tiers of clustered levels (docs/format.md, "Version 5", part 1): the rounds grouped into
/// tiers of `rounds`, finest first, each tier with a grid of cells of side 2^k quantized units
/// (k chosen at the tier's start so that the occupied cells hold about `cell_vertices`
/// vertices; the grid shifted by half a cell on odd tiers). During a tier's rounds a vertex
/// with a neighbour in another cell (a border vertex) is locked, never v_from nor v_to, so
/// every collapse stays inside one cell and the border vertices are the same at both ends
/// of the tier. No tier starts on `until_vertices` vertices or fewer.
struct DecimationTiers {
  uint32_t rounds = 0; ///< rounds per tier; 0 = no tiers
  uint32_t cell_vertices = 1024;
  uint32_t until_vertices = 0;
  int bits = 12; ///< of the quantized positions (cells of side 2^k, 0 < k <= bits)
};

/// One tier of a decimation in tiers.
struct DecimationTier {
  uint32_t first_round = 0, rounds = 0; ///< decimation rounds (levels[first_round ...])
  int cell_bits = 0;                    ///< k: cells of side 2^k
  bool shifted = false;                 ///< the grid shifted by 2^(k-1) on every axis
  /// At the tier's start: the vertices, the occupied cells, the border vertices, the
  /// longest edge (quantized units).
  uint32_t vertices = 0, cells = 0, border = 0;
  double longest_edge = 0;
};

/// The cell of tier `t` holding quantized position `q` (xyz): three 21-bit cell coordinates.
uint64_t tier_cell(const DecimationTier &t, const int32_t *q);

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
  /// Optional: decimate in tiers (off by default).
  const DecimationTiers *tiers = nullptr;
};

struct Decimation {
  /// levels[0] is the first decimation level (applied to the input mesh); the encoder
  /// replays them backwards, levels.back() first.
  std::vector<std::vector<Collapse>> levels;
  std::vector<uint32_t> base_triangles; ///< surviving faces, input vertex ids
  std::vector<DecimationTier> tiers;    ///< with options.tiers: the tiers, finest first
};

/// Decimate the mesh described by `ct` (consumed) with quantized positions `q` (xyz).
Decimation decimate(CornerTable ct, const std::vector<int32_t> &q, const DecimationOptions &options,
                    const Progress &progress);

} // namespace pomar
