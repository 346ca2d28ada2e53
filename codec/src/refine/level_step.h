// The per-level step (paper section 5.1, Figure 3), the one place where the encoder, the
// decoder of global levels and the selective decoder refine the mesh:
//
//   traverse -> check -> apply the splits
//
// 1. traverse: a global level walks the whole mesh (traverse_level), a clustered level one
//    cluster on the level-(l-1) view (traverse_cluster); the Codec policy codes or reads
//    s_v, the split symbols and, per split vertex, the data of v_from (NewVertex);
// 2. check: the caller's check sees the counts the mesh will have and may throw (a stream
//    that ended early, a level table that disagrees);
// 3. apply: the splits are applied in the order they were coded; the i-th split coded
//    creates vertex vertex_count() + i (what the encoder numbers its vertices by).
//
// The step owns the face claims its traversal makes: when the traversal or the check
// throws, it releases them before the exception leaves, and the mesh is exactly as before
// the step (damage never half-applies; the other clusters of the level can still claim
// those faces).
#pragma once

#include <cstdint>
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

class LevelStep {
public:
  /// Refine the whole mesh by global level `level` (vertices get cluster 0).
  template <class Codec, class Check = NoCheck>
  void global_level(LevelMesh &mesh, Codec &codec, uint32_t level, const Check &check = {}) {
    traverse_and_check(mesh, level, check,
                       [&] { traverse_level(mesh, codec, scratch_, level, splits_); });
    apply_splits(mesh, level, 0, nullptr);
  }

  /// Refine one cluster by one clustered level; `next_local` is the cluster's counter of
  /// created vertices (LevelMesh::local), advanced by the splits.
  template <class Codec, class Check = NoCheck>
  void cluster_level(LevelMesh &mesh, Codec &codec, const ClusterLevel &where, uint32_t &next_local,
                     const Check &check = {}) {
    const LevelView view{where.level, where.older_than};
    traverse_and_check(mesh, where.level, check, [&] {
      traverse_cluster(mesh, codec, scratch_, where.cluster, view, splits_);
    });
    apply_splits(mesh, where.level, where.cluster, &next_local);
  }

private:
  template <class Check, class Traverse>
  void traverse_and_check(LevelMesh &mesh, uint32_t level, const Check &check,
                          const Traverse &traverse) {
    scratch_.begin(mesh.vertex_count(), mesh.ct.face_count());
    splits_.clear();
    try {
      traverse();
      StepCounts n{mesh.vertex_count() + splits_.size(), mesh.ct.face_count()};
      for (const PendingSplit &ps : splits_)
        n.faces += uint64_t(ps.op.has_l) + uint64_t(ps.op.has_r);
      check(n);
    } catch (...) {
      release_claims(mesh, level);
      throw;
    }
  }

  /// Undo the face claims of this step's traversal of `level`.
  void release_claims(LevelMesh &mesh, uint32_t level) const {
    for (uint32_t f = 0; f < mesh.face_claim.size(); ++f)
      if (scratch_.claimed[f] == scratch_.stamp && mesh.face_claim[f] == level)
        mesh.face_claim[f] = static_cast<uint16_t>(level - 1);
  }

  /// Apply the splits in traversal order; new vertices get consecutive ids. A cluster's
  /// new vertices are numbered inside the cluster by `next_local`.
  void apply_splits(LevelMesh &mesh, uint32_t level, uint32_t cluster, uint32_t *next_local) {
    for (const PendingSplit &ps : splits_) {
      const uint32_t v_from = mesh.vertex_count();
      apply_split(mesh.ct, ps.op, v_from);
      mesh.q.insert(mesh.q.end(), ps.v_from.position, ps.v_from.position + 3);
      mesh.attr.insert(mesh.attr.end(), ps.v_from.attr, ps.v_from.attr + mesh.attr_codes);
      mesh.tag.push_back({cluster, static_cast<uint16_t>(level)});
      mesh.parent.push_back(ps.op.v_to);
      if (next_local)
        mesh.local.push_back((*next_local)++);
    }
    mesh.face_claim.resize(mesh.ct.face_count(), 0);
  }

  TraversalScratch scratch_;
  std::vector<PendingSplit> splits_;
};

} // namespace pomar
