// The phased decoding of one clustered level; see level_schedule.h.
#include "decode/level_schedule.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <thread>

namespace pomar {

std::vector<uint32_t> breadth_first_ranks(const ClusterGraph &graph) {
  const size_t n = graph.start.empty() ? 0 : graph.start.size() - 1;
  std::vector<uint32_t> bfs;
  bfs.reserve(n);
  std::vector<uint8_t> seen(n, 0);
  for (uint32_t root = 0; root < n; ++root) { // (each component from its smallest id)
    if (seen[root])
      continue;
    seen[root] = 1;
    bfs.push_back(root);
    for (size_t head = bfs.size() - 1; head < bfs.size(); ++head) {
      const uint32_t c = bfs[head];
      for (uint32_t k = graph.start[c]; k < graph.start[c + 1]; ++k)
        if (!seen[graph.adj[k]]) {
          seen[graph.adj[k]] = 1;
          bfs.push_back(graph.adj[k]);
        }
    }
  }
  std::vector<uint32_t> rank(n);
  for (size_t r = 0; r < n; ++r)
    rank[bfs[r]] = static_cast<uint32_t>(r);
  return rank;
}

size_t LevelSchedule::run(ThreadPool &pool, const ClusterGraph &graph,
                          const std::vector<uint32_t> &rank, const uint32_t *order, size_t n,
                          size_t window, const Steps &steps) {
  graph_ = &graph;
  rank_ = &rank;
  order_ = order;
  steps_ = &steps;
  window = std::max<size_t>(window, 1);
  const size_t clusters = graph.start.empty() ? 0 : graph.start.size() - 1;
  in_window_.assign(clusters, 0);
  for (size_t begin = 0; begin < n; begin += window) {
    const size_t end = std::min(n, begin + window);
    begin_ = admitted_ = begin;
    admit_failed_ = false;
    traverse_phase(pool, begin, end, begin == 0);
    admit_traversed(end); // (the rest: every index is traversed now)
    const size_t admitted = admitted_;
    steps.grow();
    apply_phase(pool, begin, admitted);
    for (size_t i = begin; i < admitted; ++i)
      steps.applied(i);
    if (admitted < end) { // index `admitted` failed
      for (size_t j = admitted + 1; j < end; ++j)
        steps.rewind(j);
      return admitted;
    }
  }
  return n;
}

/// Phase 1 for indices [begin, end): item r of the pool traverses the indices of its part of
/// the window (its r-th run by breadth-first rank), in increasing order, then takes the
/// others' from the end of their lists. (`first`: the level's first window; item 0 runs
/// Steps::early first.)
void LevelSchedule::traverse_phase(ThreadPool &pool, size_t begin, size_t end, bool first) {
  const unsigned roles = pool.size();
  lists_.resize(roles);
  for (auto &l : lists_)
    l.clear();
  // The window's clusters by their breadth-first rank, cut into `roles` equal runs.
  by_rank_.clear();
  for (size_t i = begin; i < end; ++i)
    by_rank_.push_back({(*rank_)[order_[i]], static_cast<uint32_t>(i)});
  std::sort(by_rank_.begin(), by_rank_.end());
  const size_t count = end - begin;
  for (size_t r = 0; r < count; ++r)
    lists_[r * roles / count].push_back(by_rank_[r].second);
  for (auto &l : lists_)
    std::sort(l.begin(), l.end());
  if (state_room_ < count) {
    state_.reset(new std::atomic<uint8_t>[count]);
    state_room_ = count;
  }
  for (size_t i = 0; i < count; ++i)
    state_[i].store(kUntaken, std::memory_order_relaxed);
  by_.assign(count, 0);
  pool.run(roles, [&](size_t role, unsigned thread) {
    const auto take = [&](uint32_t i) {
      uint8_t untaken = kUntaken;
      if (!state_[i - begin].compare_exchange_strong(untaken, kTaken, std::memory_order_relaxed))
        return;
      by_[i - begin] = static_cast<uint8_t>(role);
      steps_->traverse(i, thread);
      state_[i - begin].store(kTraversed, std::memory_order_release);
      if (role == 0) // (the admits trail the traversals: hidden behind the others')
        admit_traversed(end);
    };
    if (first && role == 0 && steps_->early)
      steps_->early();
    for (uint32_t i : lists_[role])
      take(i);
    for (unsigned k = 1; k < roles; ++k) {
      const auto &other = lists_[(role + k) % roles];
      for (size_t j = other.size(); j-- > 0;)
        take(other[j]);
    }
  });
}

/// Admit the indices from admitted_ on that are traversed, in order, up to `end` or the
/// first one that fails. Role 0 of the traversal phase calls it between its traversals,
/// the calling thread after the phase: one thread at a time.
void LevelSchedule::admit_traversed(size_t end) {
  while (!admit_failed_ && admitted_ < end &&
         state_[admitted_ - begin_].load(std::memory_order_acquire) == kTraversed) {
    if (steps_->admit(admitted_))
      ++admitted_;
    else
      admit_failed_ = true;
  }
}

/// Phase 3 for the admitted indices [begin, end). A cluster next to one another role
/// traversed (in the window) is a border cluster; the others are interior. Item r of the
/// pool applies the indices role r traversed, in order: role 0 its border clusters first,
/// then its interior ones; any other role its interior ones first, then, once the roles
/// before it have applied theirs, its border ones. So no two border clusters are applied
/// at once, and an interior cluster is next to no cluster another role applies.
void LevelSchedule::apply_phase(ThreadPool &pool, size_t begin, size_t end) {
  if (begin == end)
    return;
  for (size_t i = begin; i < end; ++i)
    in_window_[order_[i]] = static_cast<uint32_t>(i - begin + 1);
  border_.assign(end - begin, 0);
  for (size_t i = begin; i < end; ++i) {
    const uint32_t c = order_[i];
    for (uint32_t k = graph_->start[c]; k < graph_->start[c + 1]; ++k) {
      const uint32_t j = in_window_[graph_->adj[k]];
      if (j != 0 && by_[j - 1] != by_[i - begin]) {
        border_[i - begin] = 1;
        break;
      }
    }
  }
  for (size_t i = begin; i < end; ++i)
    in_window_[order_[i]] = 0;
  std::atomic<size_t> borders_done{0}; // roles 0..borders_done-1 applied their border clusters
  pool.run(pool.size(), [&](size_t role, unsigned thread) {
    const auto apply = [&](bool border) {
      for (size_t i = begin; i < end; ++i)
        if (by_[i - begin] == role && border_[i - begin] == border)
          steps_->apply(i, thread);
    };
    if (role > 0)
      apply(false);
    // (Items are taken in increasing order, so the roles waited for are running.)
    for (int spin = 0; borders_done.load(std::memory_order_acquire) != role; ++spin)
      if (spin > 64)
        std::this_thread::yield();
    apply(true);
    borders_done.store(role + 1, std::memory_order_release);
    if (role == 0)
      apply(false);
  });
}

} // namespace pomar
