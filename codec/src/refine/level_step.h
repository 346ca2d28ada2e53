// The per-level step (paper section 5.1, Figure 3), the one place where the encoder, the
// decoder of global levels and the selective decoder refine the mesh:
//
//   traverse -> check -> apply the splits
//
// 1. traverse: a global level walks the whole mesh (traverse_level), a clustered level one
//    cluster on the level-(l-1) view (traverse_cluster); the Codec policy codes or reads
//    s_v, the split symbols and, per split vertex, the data of v_from (SplitList);
// 2. check: the caller's check sees the counts the mesh will have and may throw (a stream
//    that ended early, a level table that disagrees);
// 3. apply: the splits are applied in the order they were coded; the i-th split coded
//    creates vertex vertex_count() + i (what the encoder numbers its vertices by).
//
// The step owns the face claims its traversal makes: when the traversal or the check
// throws, it releases them before the exception leaves, and the mesh is exactly as before
// the step (damage never half-applies; the other clusters of the level can still claim
// those faces).
//
// The clusters of one clustered level can also be refined in phases (the selective
// decoder's threads): traverse_cluster_level runs step 1 and 2 of several clusters at once,
// each on its own LevelStep, without touching the mesh (face claims included); then
// admit_cluster_level, in cluster order, checks each cluster's claims against the clusters
// admitted before it and makes them; apply_admitted applies a cluster's splits with the
// vertex and face ids it gets in cluster order (decode/level_schedule.h applies clusters
// that are not neighbours at once). A cluster's traversal does not depend on the splits of
// other clusters of its level (the level-(l-1) view), so this gives the mesh, the vertex
// numbering and the errors of cluster_level called in cluster order.
#pragma once

#include <algorithm>
#include <cstdint>
#include <exception>
#include <vector>

#include "refine/level_traversal.h"

namespace pomar {

/// The sizes the mesh will have once a step's splits are applied, for the caller's check.
struct StepCounts {
  uint64_t vertices = 0;
  uint64_t faces = 0;
};

/// Which cluster a clustered step refines, to which level.
struct ClusterLevel {
  uint32_t cluster;    // also its root: the base clustered mesh vertex with that id
  uint32_t level;      // the clustered level decoded (its data: one level of the cluster)
  uint32_t older_than; // vertices below this id are older than `level` (0: not known)
};

/// A check that accepts everything (the encoder knows its data is right).
struct NoCheck {
  void operator()(const StepCounts &) const {}
};

/// A cluster traversed but not yet applied (traverse_cluster_level -> apply_cluster_level).
/// Cache-line aligned, as LevelStep: the threads of a level fill neighbouring ones.
struct alignas(64) TraversedCluster {
  SplitList splits;
  std::vector<uint32_t> claims; // the faces its patches hold, in claim order
  StepCounts adds;              // the vertices and faces its splits add
  std::exception_ptr error;     // what its traversal or check threw (nothing to apply)
};

// (Cache-line aligned: with threads, each runs its own step and writes its scratch at every
// vertex; two steps sharing a cache line slowed both down.)
class alignas(64) LevelStep {
public:
  /// Refine the whole mesh by global level `level` (vertices get cluster 0).
  template <class Codec, class Check = NoCheck>
  void global_level(LevelMesh &mesh, Codec &codec, uint32_t level, const Check &check = {}) {
    traverse_and_check(mesh, level, true, now(mesh), mesh.ct.face_count(), check,
                       [&] { traverse_level(mesh, codec, scratch_, level, splits_); });
    apply_splits(mesh, splits_, level, 0, nullptr);
  }

  /// Refine one cluster by one clustered level; `next_local` is the cluster's counter of
  /// created vertices (LevelMesh::local), advanced by the splits.
  template <class Codec, class Check = NoCheck>
  void cluster_level(LevelMesh &mesh, Codec &codec, const ClusterLevel &where, uint32_t &next_local,
                     const Check &check = {}) {
    const LevelView view{where.level, where.older_than};
    traverse_and_check(mesh, where.level, false, now(mesh), mesh.ct.face_count(), check, [&] {
      traverse_cluster(mesh, codec, scratch_, where.cluster, view, splits_);
    });
    apply_splits(mesh, splits_, where.level, where.cluster, &next_local);
  }

  /// Steps 1 and 2 of cluster_level, leaving the mesh as it is (other LevelSteps may
  /// traverse other clusters of the level on the same mesh at the same time): the splits,
  /// the claims and what the traversal or the check threw go to `out`. Another thread may
  /// meanwhile apply clusters that are not next to this one (decode/level_schedule.h),
  /// within the arrays' capacity: this reads no array's size, and the check sees the
  /// counts this cluster's splits add (from zero).
  template <class Codec, class Check = NoCheck>
  void traverse_cluster_level(LevelMesh &mesh, Codec &codec, const ClusterLevel &where,
                              const Check &check, TraversedCluster &out) {
    const LevelView view{where.level, where.older_than};
    scratch_.defer_claims = true;
    out.error = nullptr;
    out.adds = {};
    // (The face ids it meets are below the corner table's capacity, which only changes
    // while no traversal runs.)
    const uint32_t face_room = static_cast<uint32_t>(mesh.ct.V.capacity() / 3);
    try {
      out.adds = traverse_and_check(mesh, where.level, false, StepCounts{}, face_room, check, [&] {
        traverse_cluster(mesh, codec, scratch_, where.cluster, view, splits_);
      });
    } catch (...) {
      out.error = std::current_exception();
    }
    scratch_.defer_claims = false;
    out.splits.swap(splits_);
    out.claims.swap(scratch_.claims);
  }

  /// Step 3 of a cluster traversed by traverse_cluster_level, the clusters of the level
  /// taken in cluster order: a patch face an earlier cluster holds is damage (reported
  /// first: cluster_level would have stopped there), then the traversal's error is
  /// rethrown, else the claims are made and the splits applied. Throws with the mesh as it
  /// was.
  template <class Codec>
  void apply_cluster_level(LevelMesh &mesh, Codec &codec, const ClusterLevel &where,
                           uint32_t &next_local, TraversedCluster &in) {
    admit_cluster_level(mesh, codec, where, in);
    apply_splits(mesh, in.splits, where.level, where.cluster, &next_local);
  }

  /// Step 3 in two parts, for clusters applied out of order (decode/level_schedule.h).
  /// First, in cluster order: the checks of apply_cluster_level and the claims; throws
  /// with the mesh as it was.
  template <class Codec>
  static void admit_cluster_level(LevelMesh &mesh, Codec &codec, const ClusterLevel &where,
                                  const TraversedCluster &in) {
    for (uint32_t f : in.claims)
      if (mesh.face_claim[f] == where.level)
        codec.corrupt(kSharedFace);
    if (in.error)
      std::rethrow_exception(in.error);
    for (uint32_t f : in.claims)
      mesh.face_claim[f] = static_cast<uint16_t>(where.level);
  }
  /// Then, in any order once the arrays hold every admitted cluster (LevelMesh::grow): the
  /// splits of an admitted cluster, its new vertices from `first_vertex` and its new faces
  /// from `first_face` (the counts the clusters before it reach).
  static void apply_admitted(LevelMesh &mesh, const ClusterLevel &where, uint32_t &next_local,
                             const TraversedCluster &in, uint32_t first_vertex,
                             uint32_t first_face) {
    apply_splits_at(mesh, in.splits, where.level, where.cluster, &next_local, first_vertex,
                    first_face);
  }

private:
  static StepCounts now(const LevelMesh &mesh) {
    return {mesh.vertex_count(), mesh.ct.face_count()};
  }

  /// Returns the counts checked. (`by_id`: a global level, whose traversal marks vertices
  /// by id, TraversalScratch::begin; `now`: the counts the check adds the splits to; face
  /// ids met are below `face_room`.)
  template <class Check, class Traverse>
  StepCounts traverse_and_check(LevelMesh &mesh, uint32_t level, bool by_id, StepCounts now,
                                uint32_t face_room, const Check &check, const Traverse &traverse) {
    scratch_.begin(by_id ? mesh.vertex_count() : 0, face_room);
    splits_.clear();
    try {
      traverse();
      StepCounts n{now.vertices + splits_.size(), now.faces};
      for (const PendingSplit &ps : splits_.split)
        n.faces += uint64_t(ps.op.has_l) + uint64_t(ps.op.has_r);
      check(n);
      return n;
    } catch (...) {
      release_claims(mesh, level);
      throw;
    }
  }

  /// Undo the face claims of this step's traversal of `level` (none were made if deferred).
  void release_claims(LevelMesh &mesh, uint32_t level) const {
    if (scratch_.defer_claims)
      return;
    for (uint32_t f : scratch_.claims)
      if (mesh.face_claim[f] == level)
        mesh.face_claim[f] = static_cast<uint16_t>(level - 1);
  }

  /// Apply the splits in traversal order; new vertices get consecutive ids, new faces
  /// too. A cluster's new vertices are numbered inside the cluster by `next_local`. The
  /// arrays are sized once for the whole step, each split writes its entries in place.
  static void apply_splits(LevelMesh &mesh, const SplitList &splits, uint32_t level,
                           uint32_t cluster, uint32_t *next_local) {
    const uint32_t v0 = mesh.vertex_count(), f0 = mesh.ct.face_count();
    uint32_t new_faces = 0;
    for (const PendingSplit &ps : splits.split)
      new_faces += uint32_t(ps.op.has_l) + uint32_t(ps.op.has_r);
    mesh.grow(size_t(v0) + splits.size(), size_t(f0) + new_faces);
    apply_splits_at(mesh, splits, level, cluster, next_local, v0, f0);
  }

  /// apply_splits into arrays already sized: split i creates vertex v0 + i, the new faces
  /// follow from face f0.
  static void apply_splits_at(LevelMesh &mesh, const SplitList &splits, uint32_t level,
                              uint32_t cluster, uint32_t *next_local, uint32_t v0, uint32_t f0) {
    CornerTable &ct = mesh.ct;
    const uint32_t n = static_cast<uint32_t>(splits.size());
    uint32_t face = f0;
    const uint32_t codes = mesh.attr_codes;
    for (uint32_t i = 0; i < n; ++i) {
      prefetch_split(ct, splits, i, n);
      const PendingSplit &ps = splits.split[i];
      const uint32_t v_from = v0 + i;
      face += apply_split(ct, ps.op, v_from, face);
      std::copy(ps.position, ps.position + 3, &mesh.q[3 * size_t(v_from)]);
      const int64_t *codes_i = splits.attr.data() + size_t(i) * codes;
      std::copy(codes_i, codes_i + codes, mesh.attr.data() + size_t(v_from) * codes);
      mesh.lineage[v_from] = {cluster, ps.op.v_to, next_local ? (*next_local)++ : 0,
                              static_cast<uint16_t>(level)};
    }
  }

  /// Applying the splits is memory bound (with threads, another core traversed their
  /// faces): fetch the first face of the split 4 ahead, and 2 ahead the faces the split
  /// reads next from there, the second of its range and the one across its left edge.
  /// (Always inlined: see CornerTable::prefetch.)
  [[gnu::always_inline]] static void prefetch_split(const CornerTable &ct, const SplitList &splits,
                                                    uint32_t i, uint32_t n) {
    if (i + 4 < n)
      ct.prefetch(splits.split[i + 4].op.first_corner);
    if (i + 2 < n) {
      const uint32_t c = splits.split[i + 2].op.first_corner;
      ct.prefetch(ct.O[CornerTable::next(c)]);
      const uint32_t left = ct.O[CornerTable::prev(c)];
      if (left != kNone)
        __builtin_prefetch(&ct.O[left]);
    }
  }

  TraversalScratch scratch_;
  SplitList splits_;
};

} // namespace pomar
