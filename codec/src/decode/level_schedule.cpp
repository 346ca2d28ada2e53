// The phased decoding of one clustered level; see level_schedule.h.
#include "decode/level_schedule.h"

#include <algorithm>
#include <atomic>
#include <memory>

namespace pomar {

std::vector<uint8_t> cluster_owners(const ClusterGraph &graph, unsigned threads) {
  const size_t n = graph.start.empty() ? 0 : graph.start.size() - 1;
  std::vector<uint8_t> owner(n, 0);
  if (threads <= 1 || n == 0)
    return owner;
  // Breadth-first order, each component from its smallest cluster id.
  std::vector<uint32_t> bfs;
  bfs.reserve(n);
  std::vector<uint8_t> seen(n, 0);
  for (uint32_t root = 0; root < n; ++root) {
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
  for (size_t r = 0; r < n; ++r)
    owner[bfs[r]] = static_cast<uint8_t>(r * threads / n);
  return owner;
}

size_t LevelSchedule::run(ThreadPool &pool, const ClusterGraph &graph,
                          const std::vector<uint8_t> &owner, const uint32_t *order, size_t n,
                          size_t window, const Steps &steps) {
  graph_ = &graph;
  owner_ = &owner;
  order_ = order;
  steps_ = &steps;
  window = std::max<size_t>(window, 1);
  const size_t clusters = graph.start.empty() ? 0 : graph.start.size() - 1;
  in_window_.assign(clusters, 0);
  for (size_t begin = 0; begin < n; begin += window) {
    const size_t end = std::min(n, begin + window);
    traverse_phase(pool, begin, end);
    size_t admitted = begin;
    while (admitted < end && steps.admit(admitted))
      ++admitted;
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

/// Phase 1 for indices [begin, end): item r of the pool traverses the indices whose cluster
/// role r owns, in increasing order, then takes the others' from the end of their lists.
void LevelSchedule::traverse_phase(ThreadPool &pool, size_t begin, size_t end) {
  const unsigned roles = pool.size();
  lists_.resize(roles);
  for (auto &l : lists_)
    l.clear();
  for (size_t i = begin; i < end; ++i)
    lists_[(*owner_)[order_[i]] % roles].push_back(static_cast<uint32_t>(i));
  const size_t count = end - begin;
  std::unique_ptr<std::atomic<uint8_t>[]> taken(new std::atomic<uint8_t>[count]);
  for (size_t i = 0; i < count; ++i)
    taken[i].store(0, std::memory_order_relaxed);
  by_.assign(count, 0);
  pool.run(roles, [&](size_t role, unsigned thread) {
    const auto take = [&](uint32_t i) {
      if (taken[i - begin].exchange(1, std::memory_order_relaxed))
        return;
      by_[i - begin] = static_cast<uint8_t>(role);
      steps_->traverse(i, thread);
    };
    for (uint32_t i : lists_[role])
      take(i);
    for (unsigned k = 1; k < roles; ++k) {
      const auto &other = lists_[(role + k) % roles];
      for (size_t j = other.size(); j-- > 0;)
        take(other[j]);
    }
  });
}

/// Phase 3 for the admitted indices [begin, end): item r of the pool applies those role r
/// traversed whose neighbours in the window role r traversed too; then this thread
/// applies the others, in order.
void LevelSchedule::apply_phase(ThreadPool &pool, size_t begin, size_t end) {
  if (begin == end)
    return;
  for (size_t i = begin; i < end; ++i)
    in_window_[order_[i]] = static_cast<uint32_t>(i - begin + 1);
  apply_later_.assign(end - begin, 0);
  for (size_t i = begin; i < end; ++i) {
    const uint32_t c = order_[i];
    for (uint32_t k = graph_->start[c]; k < graph_->start[c + 1]; ++k) {
      const uint32_t j = in_window_[graph_->adj[k]];
      if (j != 0 && by_[j - 1] != by_[i - begin]) {
        apply_later_[i - begin] = 1;
        break;
      }
    }
  }
  pool.run(pool.size(), [&](size_t role, unsigned thread) {
    for (size_t i = begin; i < end; ++i)
      if (by_[i - begin] == role && !apply_later_[i - begin])
        steps_->apply(i, thread);
  });
  for (size_t i = begin; i < end; ++i)
    if (apply_later_[i - begin])
      steps_->apply(i, 0);
  for (size_t i = begin; i < end; ++i)
    in_window_[order_[i]] = 0;
}

} // namespace pomar
