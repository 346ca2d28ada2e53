// What one traversal of a level marks (refine/level_traversal.h): per vertex, queued and
// split; per face, held by a patch of this traversal (a claim). Marks carry the stamp of
// the traversal that set them, so a new traversal starts without clearing anything.
//
// A global level walks the whole mesh and keeps its vertex marks in an array by vertex
// id (GlobalMarks). A cluster's traversal touches a few hundred vertices of a mesh of
// millions: an array by id missed the cache at almost every neighbour, so it keeps them
// by the vertex's rank in its cluster (ClusterMarks), and they stay in the core's cache.
// Claims are by face id in both. (A small hash set of a cluster's claimed faces, tried
// too, cost more in hashing than it saved in cache misses.)
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "memory/prefault.h"
#include "mesh/corner_table.h"
#include "refine/level_mesh.h"
#include "refine/patch.h"
#include "refine/patch_rank.h"

namespace pomar {

struct VertexMarks {
  uint32_t queued = 0, split = 0; // stamps; together: one cache line per vertex visit
};

/// The scratch of one traversal, reused from level to level (one per thread).
struct TraversalScratch {
  uint32_t stamp = 0;
  std::vector<VertexMarks> marks; // a global level's, by vertex id
  // A cluster's, by the vertex's rank in its cluster (LevelMesh::Lineage::local): as many
  // entries as the largest cluster has vertices.
  // (Its capacity is the room: read at every neighbour, kept beside the storage.)
  GrowArray<VertexMarks> local_marks;
  std::vector<uint32_t> claimed; // by face id: the stamp of the traversal that claimed it
  std::vector<uint32_t> claims;  // the faces this traversal's patches hold, in claim order
  // Leave LevelMesh::face_claim to the caller (clusters traversed in parallel: the caller
  // checks and writes their claims in cluster order, refine/level_step.h).
  bool defer_claims = false;
  GrowArray<std::pair<uint32_t, uint32_t>> queue; // (vertex, came from)
  Ring ring;
  std::vector<Spoke> spokes;    // of the split vertex being coded
  std::vector<uint32_t> ranked; // its ring's edges, longest first
  PatchPlacements placements;   // its patch's possible placements (version 5)
  /// Start a traversal of a mesh of `faces` faces, with marks by id for `vertices`
  /// vertices (a global level's; 0 for a cluster's traversal).
  void begin(uint32_t vertices, uint32_t faces) {
    if (marks.size() < vertices)
      marks.resize(vertices);
    if (claimed.size() < faces) {
      // Grown by doubling, the new room mapped in one call (memory/prefault.h): the zero
      // fill reaches it as the traversals meet more faces.
      if (claimed.capacity() < faces) {
        claimed.reserve(std::max<size_t>(faces, 2 * claimed.capacity()));
        prefault_room(claimed);
      }
      claimed.resize(faces, 0);
    }
    ++stamp;
    queue.clear();
    claims.clear();
  }
  /// The marks of the cluster vertex of rank `local` (grown on first use; new entries
  /// carry stamp 0, which no traversal has).
  VertexMarks &local_mark(uint32_t local) {
    if (local >= local_marks.capacity())
      local_marks.grow_to(std::max<size_t>(2 * local_marks.capacity(), size_t(local) + 64));
    return local_marks.data()[local];
  }
};

/// The claims of a traversal, by face id (both kinds of marks below).
struct FaceClaims {
  TraversalScratch &s;
  bool claimed(uint32_t f) const { return s.claimed[f] == s.stamp; }
  void claim(uint32_t f) const { s.claimed[f] = s.stamp; }
};

/// A global level's marks: by id (every vertex is visited).
struct GlobalMarks : FaceClaims {
  VertexMarks *vertex(uint32_t v) const { return &s.marks[v]; }
  /// f(v's marks) (every vertex has them).
  template <class F> void with_vertex(uint32_t v, F &&f) const { f(s.marks[v]); }
};

/// A cluster's marks: by rank in the cluster for the cluster's own vertices, nullptr for
/// the others (never queued nor split by this traversal).
struct ClusterMarks : FaceClaims {
  const LevelMesh::Lineage *lineage;
  uint32_t cluster;
  VertexMarks *vertex(uint32_t v) const {
    const LevelMesh::Lineage &l = lineage[v];
    return l.cluster == cluster ? &s.local_mark(l.local) : nullptr;
  }
  /// f(v's marks) if v is the cluster's, else nothing.
  template <class F> void with_vertex(uint32_t v, F &&f) const {
    const LevelMesh::Lineage &l = lineage[v];
    if (l.cluster == cluster)
      f(s.local_mark(l.local));
  }
};

} // namespace pomar
