// The clusters of one clustered level decoded on several threads (paper section 5.2: each
// cluster has its own stream, so their traversals are independent), as a pipeline:
//
//   every thread   traverse clusters ahead, in any order, into per-cluster split lists
//   calling thread apply the traversed clusters one by one, in cluster order
//
// so that applying overlaps with traversing (the two-phase batches it replaces left the
// other threads idle while the calling thread applied a batch).
//
// Why a traversal may run while another cluster is applied. A cluster's traversal reads
// the fans of its own vertices only: faces with one of its vertices, and the lineage and
// positions of their vertices, which belong to the cluster or to clusters next to it in the
// cluster graph (clusters never become adjacent at finer levels: a split's new vertex v_from
// takes neighbours of its v_to). Applying cluster A writes faces that hold one of A's
// vertices, A's vertices' corner references and the entries of the vertices and faces it
// creates. So a traversal of B and the apply of A touch no common entry unless A and B are
// neighbours; the schedule never runs those together. Two more conditions: the mesh
// arrays must not move while traversals read them (an apply that would grow an array past
// its capacity waits until no traversal runs: `alone`), and a traversal must see no cluster
// after it applied (the claims of a damaged stream would then name the wrong cluster):
// applies go in cluster order and a cluster is traversed before it is applied.
//
// The result does not depend on the timing: each cluster's traversal reads the same
// level-(l-1) view whichever neighbours are applied (refine/level_step.h), and the applies
// run in cluster order on the calling thread.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <vector>

#include "decode/level_map.h"
#include "parallel/thread_pool.h"

namespace pomar {

class LevelSchedule {
public:
  struct Steps {
    /// Traverse index i (order[i]) on `thread`. What it throws is thrown when index i's
    /// turn to be applied comes, in place of apply(i).
    std::function<void(size_t i, unsigned thread)> traverse;
    /// Whether applying index i must run with no traversal at all (it grows the arrays).
    std::function<bool(size_t i)> alone;
    /// Apply index i (calling thread, increasing i); may throw.
    std::function<void(size_t i)> apply;
    /// After apply(i) (or the traversal of i) threw: index j > i was traversed and will not
    /// be applied (put its stream back). Called once the other threads have stopped.
    std::function<void(size_t j)> rewind;
    /// Optional: index i, traversed, is applied next after the current one (fetch what
    /// its apply reads first).
    std::function<void(size_t i)> prefetch;
  };

  /// Decode the clusters order[0..n) of one level (increasing ids, `graph`'s clusters) on
  /// `pool`'s threads, traversing at most `window` indices ahead of the next apply (the
  /// traversed clusters' splits wait in `window` slots: slot i % window). Rethrows what the first
  /// failing apply (or traversal, at its turn) threw, after rewinding the clusters
  /// traversed past it.
  void run(ThreadPool &pool, const ClusterGraph &graph, const uint32_t *order, size_t n,
           size_t window, const Steps &steps);

private:
  enum State : uint8_t { Untraversed, Traversing, Traversed, Applied };
  static constexpr uint32_t kAll = 0xFFFFFFFEu; // `applying`: an apply that must be alone

  void traverse_loop(unsigned thread);
  void apply_loop();
  bool take(size_t &i, bool applier);
  bool next_to_applying(uint32_t cluster) const;
  bool neighbour_traversing(uint32_t cluster) const;
  void traverse(size_t i, unsigned thread);
  void finish_traversal(size_t i);

  // The level being run (under mutex_).
  const ClusterGraph *graph_ = nullptr;
  const uint32_t *order_ = nullptr;
  const Steps *steps_ = nullptr;
  size_t n_ = 0, window_ = 0;
  std::vector<State> state_;                       // by index
  std::vector<std::exception_ptr> traverse_error_; // by index: what its traversal threw
  std::vector<uint8_t> traversed_now_;             // by cluster id: a thread is traversing it
  // The cluster being applied, or reserved for the next apply (no traversal next to it
  // starts); kAll: no traversal at all; 0xFFFFFFFF: none.
  uint32_t applying_ = 0xFFFFFFFFu;
  size_t next_apply_ = 0;     // the index applied next
  size_t scan_from_ = 0;      // no untraversed index below it
  size_t ahead_from_ = 0;     // nor in [next_apply_ + kAhead, ahead_from_) (other threads)
  size_t traversing_ = 0;     // traversals running
  bool stop_ = false;         // an apply threw: take no more
  size_t wake_at_ = 0;        // the waiting traversers want next_apply_ >= wake_at_
  int waiting_ = 0;           // traversers waiting in wait_
  bool main_waiting_ = false; // the applying thread waits in main_wait_
  std::mutex mutex_;
  std::condition_variable wait_, main_wait_;
};

} // namespace pomar
