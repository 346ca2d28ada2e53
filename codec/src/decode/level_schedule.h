// The clusters of one clustered level decoded on several threads (paper section 5.2: each
// cluster has its own stream, so their traversals are independent), a window of clusters
// at a time, in three phases:
//
//   1. traverse  every thread traverses the window's clusters it owns, then helps with the
//                others' (from the end of their lists): per-cluster split lists;
//   2. admit     one thread at a time, in cluster order: checks each cluster (its claims
//                against the clusters before it, its traversal's error) and numbers its
//                new vertices and faces after the clusters before it; stops at a failure.
//                Thread 0 admits as far as the traversals allow between its own, the
//                calling thread the rest after them;
//   3. apply     every thread applies the admitted clusters it traversed; those next to
//                another thread's (border clusters) one thread after the other.
//
// Why the owners. Each thread keeps the same clusters level after level (a spatial part of
// the window: its clusters by breadth-first rank in the cluster graph, cut into one run
// per thread; a level's windows hold the same clusters as the level before's when the
// whole mesh is refined): the faces and vertices a thread reads in its traversals
// are the ones it wrote when it applied its clusters at the level before, so they stay in
// its core's cache. (When one thread applied every cluster, the others read lines that
// core had written: on a machine whose cores do not share a cache that doubles their cost
// per split; bench/README.md, "Threads".)
//
// Why the result does not depend on the threads. A traversal reads the level-(l-1) view,
// the same whichever clusters of the level are applied (refine/level_step.h); during phase 1
// nothing is applied anyway (what runs alongside the traversals writes only what they do
// not read: the admits LevelMesh::face_claim, Steps::early the arrays past their ends,
// within their capacity). Phase 2 gives every cluster the vertex and face ids it gets
// when the clusters are applied one by one in cluster order, and the same first error.
// In phase 3 two clusters applied at once are not neighbours in the cluster graph, so no
// face holds vertices of both (a face's vertices are pairwise adjacent): their splits write
// disjoint entries. A split's new faces link to whatever lies across its outer edges when it
// is applied; two splits on either side of one edge give the same two faces in the same
// order whichever goes first, so the apply order does not change the corner table.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "decode/level_map.h"
#include "parallel/thread_pool.h"

namespace pomar {

/// Each cluster's rank in a breadth-first order of the cluster graph (component after
/// component): a window's clusters sorted by it and cut into runs are spatial parts.
std::vector<uint32_t> breadth_first_ranks(const ClusterGraph &graph);

class LevelSchedule {
public:
  struct Steps {
    /// Traverse index i (order[i]) on `thread`; keeps what it throws for admit.
    std::function<void(size_t i, unsigned thread)> traverse;
    /// One thread at a time, increasing i, once indices <= i are traversed (alongside
    /// the traversals of higher ones): check index i and number its splits after the
    /// indices admitted before it; false: it failed (then nothing after it is admitted).
    std::function<bool(size_t i)> admit;
    /// Optional: run by one thread at the start of the level's first traversal phase,
    /// alongside the others' traversals (making room ahead, within the arrays' capacity).
    std::function<void()> early;
    /// Calling thread, after the window's admits: make room for what they add.
    std::function<void()> grow;
    /// Apply admitted index i on `thread` (parallel with non-neighbours); does not throw.
    std::function<void(size_t i, unsigned thread)> apply;
    /// Calling thread, increasing i: index i has been applied.
    std::function<void(size_t i)> applied;
    /// Calling thread, after a failure: index j, traversed and not admitted, will not be
    /// applied (put its stream back).
    std::function<void(size_t j)> rewind;
  };

  /// Decode the clusters order[0..n) of one level (increasing ids, `graph`'s clusters) on
  /// `pool`'s threads, `window` indices at a time; `rank`: breadth_first_ranks(graph).
  /// Returns the first index that failed to be admitted (n: none); the indices
  /// before it are applied, the others are as they were (traversed ones rewound).
  size_t run(ThreadPool &pool, const ClusterGraph &graph, const std::vector<uint32_t> &rank,
             const uint32_t *order, size_t n, size_t window, const Steps &steps);

private:
  void traverse_phase(ThreadPool &pool, size_t begin, size_t end, bool first);
  void admit_traversed(size_t end);
  void apply_phase(ThreadPool &pool, size_t begin, size_t end);

  const ClusterGraph *graph_ = nullptr;
  const std::vector<uint32_t> *rank_ = nullptr;
  const uint32_t *order_ = nullptr;
  const Steps *steps_ = nullptr;
  std::vector<std::pair<uint32_t, uint32_t>> by_rank_; // the window's (rank, index)
  std::vector<std::vector<uint32_t>> lists_;           // per thread: the window's indices it owns
  std::vector<uint8_t> by_; // by index in the window: the thread that traversed it
  // By index in the window: untaken, taken by a thread, traversed.
  enum : uint8_t { kUntaken, kTaken, kTraversed };
  std::unique_ptr<std::atomic<uint8_t>[]> state_;
  size_t state_room_ = 0;           // state_'s length
  size_t begin_ = 0;                // the window's first index
  size_t admitted_ = 0;             // indices below it are admitted
  bool admit_failed_ = false;       // index admitted_ failed
  std::vector<uint32_t> in_window_; // by cluster id: index in the window + 1 (0: not in it)
  std::vector<uint8_t> border_;     // by index in the window: next to another role's
};

} // namespace pomar
