// The mesh being refined level by level, with the lineage of every vertex.
#pragma once

#include <cstdint>
#include <vector>

#include "memory/prefault.h"
#include "mesh/corner_table.h"

namespace pomar {

/// The mesh being refined: what the decoder holds, and what the encoder replicates.
struct LevelMesh {
  CornerTable ct;
  std::vector<int32_t> q;  // quantized xyz per vertex
  uint32_t seed_faces = 0; // faces of the base mesh (traversal seeds, never removed)
  // Lineage of every vertex, one record per vertex (the walks read its fields together:
  // the view reads level and parent, a cluster's walk cluster and local): the level that
  // created it (0 = base mesh), its cluster (clustered levels: the base clustered mesh
  // vertex it descends from), its parent (the v_to it was split from; itself for base
  // vertices) and its rank of creation inside its cluster (0 before the clustered
  // levels). (cluster, local) names a vertex the same way whatever clusters were decoded
  // in whatever order.
  struct Lineage {
    uint32_t cluster = 0;
    uint32_t parent = 0;
    uint32_t local = 0;
    uint16_t level = 0;
  };
  std::vector<Lineage> lineage;
  std::vector<uint16_t> face_claim; // per face: last level whose patch held it
  // Per-vertex attributes (attributes/): `attr_codes` integer codes per vertex, each in
  // [attr_lo[k], attr_hi[k]]; a split vertex's codes are coded after its position.
  uint32_t attr_codes = 0;
  std::vector<int64_t> attr, attr_lo, attr_hi;
  // A decode that returns no attribute: the codes per split vertex read and dropped (the
  // residuals share the streams of the positions), with attr_codes = 0 and attr empty.
  uint32_t attr_skipped = 0;
  int normal_code = -1;   // first code of a quantized normal attribute (-1: none)
  int wedge_uv_code = -1; // first code of the seam cut's wedge texcoord (-1: none)
  // Per refinement level (the index; past the end: the last entry), whether it is
  // predicted from the positions there (attributes/wedge_prediction.h); empty: nowhere.
  std::vector<uint8_t> wedge_uv_positions;
  int normal_bits = 0;      // its octahedral bits
  bool normal_zero = false; // its codes may be the zero-length normal's (octahedral_zero_code)
  uint32_t vertex_count() const { return ct.vertex_count(); }
  bool wedge_from_positions(uint32_t level) const {
    return !wedge_uv_positions.empty() &&
           wedge_uv_positions[level < wedge_uv_positions.size() ? level
                                                                : wedge_uv_positions.size() - 1];
  }
  uint32_t level_of(uint32_t v) const { return lineage[v].level; }
  uint32_t cluster_of(uint32_t v) const { return lineage[v].cluster; }
  uint64_t key(uint32_t v) const { return (uint64_t(lineage[v].cluster) << 32) | lineage[v].local; }
  void init_lineage() {
    lineage.assign(vertex_count(), Lineage{});
    for (uint32_t v = 0; v < vertex_count(); ++v)
      lineage[v].parent = v;
    face_claim.assign(ct.face_count(), 0);
  }
  /// Room for the counts a decode will reach (from the level table), so that applying the
  /// splits appends without reallocating. A hint: counts no plausible file of
  /// `file_bytes` bytes reaches (a hostile header) reserve nothing.
  void reserve(uint64_t vertices, uint64_t faces, uint64_t file_bytes) {
    const uint64_t plausible = 64 * file_bytes + 1024;
    if (vertices > plausible || faces > 2 * plausible)
      return;
    reserve_counts(vertices, faces);
  }
  /// Room for these counts (the encoder's rebuild: the input's own, final counts), mapped
  /// a stretch ahead of each array's end (memory/prefault.h).
  void reserve_counts(uint64_t vertices, uint64_t faces) {
    for_each_array(*this, vertices, faces, [](auto &a, uint64_t n) {
      a.reserve(n);
      prefault_ahead_start(a);
    });
  }
  /// Grow the arrays to these counts, the new entries zero for the caller to write (the
  /// splits of a step: refine/level_step.h), keeping the room ahead of each end mapped
  /// (mapped before the zero fill when the room is there: a growth by many pages, a whole
  /// level's, then takes one call instead of a fault per page).
  void grow(uint64_t vertices, uint64_t faces) {
    for_each_array(*this, vertices, faces, [](auto &a, uint64_t n) {
      const size_t before = a.size();
      if (n <= a.capacity()) {
        prefault_ahead(a, before, n);
        a.resize(n);
      } else {
        a.resize(n);
        prefault_ahead(a, before);
      }
    });
  }
  /// Whether the arrays hold these counts without moving (within reserve_counts' room).
  bool has_room(uint64_t vertices, uint64_t faces) const {
    bool room = true;
    for_each_array(*this, vertices, faces,
                   [&](const auto &a, uint64_t n) { room = room && n <= a.capacity(); });
    return room;
  }
  /// The arrays the splits grow, each with its size for these counts: the one list that
  /// reserve_counts, grow and has_room go through.
  template <class Mesh, class F>
  static void for_each_array(Mesh &m, uint64_t vertices, uint64_t faces, const F &f) {
    f(m.ct.V, 3 * faces);
    f(m.ct.O, 3 * faces);
    f(m.ct.VC, vertices);
    f(m.q, 3 * vertices);
    f(m.attr, m.attr_codes * vertices);
    f(m.lineage, vertices);
    f(m.face_claim, faces);
  }
  /// Make the current mesh the base clustered mesh (paper section 5.2): each vertex
  /// roots the cluster with its id; vertices created later inherit their v_to's cluster.
  void root_clusters() {
    for (uint32_t c = 0; c < vertex_count(); ++c) {
      lineage[c].cluster = c;
      lineage[c].local = 0;
    }
  }
};

} // namespace pomar
