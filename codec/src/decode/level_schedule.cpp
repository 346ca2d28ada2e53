// The pipelined decoding of one clustered level; see level_schedule.h.
#include "decode/level_schedule.h"

#include <algorithm>
#include <exception>

namespace pomar {

namespace {
constexpr uint32_t kNoCluster = 0xFFFFFFFFu;
// A traverser that found the window full waits for this many applies (one wake-up per
// cluster applied would cost more than the traversals it starts).
constexpr size_t kWakeAfter = 32;
// The other threads take clusters from this many past the next apply (see take()).
constexpr size_t kAhead = 128;
/// Lock `lock` (unlocked), spinning a little first: the critical sections here last well
/// under a microsecond and both threads take the lock every few microseconds, so a
/// blocking lock put a thread to sleep (a system call and a wake-up, several
/// microseconds) about once per ten clusters.
void spin_lock(std::unique_lock<std::mutex> &lock) {
  for (int i = 0; i < 2000; ++i) {
    if (lock.try_lock())
      return;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  lock.lock();
}
} // namespace

void LevelSchedule::run(ThreadPool &pool, const ClusterGraph &graph, const uint32_t *order,
                        size_t n, size_t window, const Steps &steps) {
  graph_ = &graph;
  order_ = order;
  steps_ = &steps;
  n_ = n;
  window_ = std::max<size_t>(window, 1);
  state_.assign(n, Untraversed);
  traverse_error_.assign(n, nullptr);
  const size_t clusters = graph.start.empty() ? 0 : graph.start.size() - 1;
  traversed_now_.assign(clusters, 0);
  applying_ = kNoCluster;
  next_apply_ = scan_from_ = ahead_from_ = traversing_ = 0;
  stop_ = false;
  wake_at_ = 0;
  waiting_ = 0;
  main_waiting_ = false;
  bool applier_ran = false; // (a pool whose threads did not start hands their items to us)
  std::exception_ptr error;
  pool.run(pool.size(), [&](size_t, unsigned thread) {
    if (thread != 0) {
      traverse_loop(thread);
    } else if (!applier_ran) {
      applier_ran = true;
      try {
        apply_loop();
      } catch (...) {
        error = std::current_exception();
      }
    }
  });
  if (error)
    std::rethrow_exception(error);
}

/// Under mutex_: index i (order_[i]) has a neighbour in the cluster graph being applied.
bool LevelSchedule::next_to_applying(uint32_t cluster) const {
  if (applying_ == kNoCluster)
    return false;
  if (applying_ == kAll || applying_ == cluster)
    return true;
  for (uint32_t k = graph_->start[cluster]; k < graph_->start[cluster + 1]; ++k)
    if (graph_->adj[k] == applying_)
      return true;
  return false;
}

/// Under mutex_: a neighbour of `cluster` is being traversed.
bool LevelSchedule::neighbour_traversing(uint32_t cluster) const {
  for (uint32_t k = graph_->start[cluster]; k < graph_->start[cluster + 1]; ++k)
    if (traversed_now_[graph_->adj[k]])
      return true;
  return false;
}

/// Under mutex_: take an untraversed index of the window that may be traversed now. The
/// applying thread (`applier`, not applying now: any index) takes the lowest; the other
/// threads the lowest from kAhead past the next apply, else the lowest below that: their
/// traversals then read other cache lines than the applies write, and the applying thread
/// applies the clusters it traversed itself. Sets wake_at_ for a thread that finds none.
bool LevelSchedule::take(size_t &i, bool applier) {
  while (scan_from_ < n_ && state_[scan_from_] != Untraversed)
    ++scan_from_;
  const size_t end = std::min(n_, next_apply_ + window_);
  bool blocked = false;
  const auto take_in = [&](size_t from, size_t to) {
    for (size_t j = from; j < to; ++j) {
      if (state_[j] != Untraversed)
        continue;
      if (!applier && next_to_applying(order_[j])) {
        blocked = true;
        continue;
      }
      state_[j] = Traversing;
      traversed_now_[order_[j]] = 1;
      ++traversing_;
      i = j;
      return true;
    }
    return false;
  };
  if (applier)
    return take_in(scan_from_, end);
  // (ahead_from_ only moves forward, past indices taken already: the scan stays short.)
  const size_t ahead = std::max(scan_from_, std::min(end, next_apply_ + kAhead));
  ahead_from_ = std::max(ahead_from_, ahead);
  while (ahead_from_ < end && state_[ahead_from_] != Untraversed)
    ++ahead_from_;
  if (take_in(ahead_from_, end) || take_in(scan_from_, ahead))
    return true;
  // Blocked by the apply: the next apply frees it; a full window: some applies later.
  const size_t want = next_apply_ + (blocked ? 1 : kWakeAfter);
  wake_at_ = waiting_ == 0 ? want : std::min(wake_at_, want);
  return false;
}

/// Traverse index i on `thread` (not under mutex_); what the traversal throws is kept for
/// index i's turn to be applied.
void LevelSchedule::traverse(size_t i, unsigned thread) {
  try {
    steps_->traverse(i, thread);
  } catch (...) {
    traverse_error_[i] = std::current_exception();
  }
}

/// Under mutex_: index i has been traversed.
void LevelSchedule::finish_traversal(size_t i) {
  state_[i] = Traversed;
  traversed_now_[order_[i]] = 0;
  --traversing_;
  if (main_waiting_)
    main_wait_.notify_one();
}

void LevelSchedule::traverse_loop(unsigned thread) {
  std::unique_lock<std::mutex> lock(mutex_, std::defer_lock);
  spin_lock(lock);
  for (;;) {
    if (stop_ || next_apply_ >= n_)
      return;
    size_t i;
    if (take(i, false)) {
      lock.unlock();
      traverse(i, thread);
      spin_lock(lock);
      finish_traversal(i);
      continue;
    }
    ++waiting_;
    wait_.wait(lock);
    --waiting_;
  }
}

void LevelSchedule::apply_loop() {
  std::unique_lock<std::mutex> lock(mutex_, std::defer_lock);
  spin_lock(lock);
  for (size_t a = 0; a < n_; ++a) {
    for (;;) {
      if (state_[a] == Traversed) {
        // Reserve the apply first (no new traversal next to it, or none at all), then
        // wait for the ones running to end, traversing meanwhile if there is work.
        if (applying_ == kNoCluster) {
          lock.unlock(); // (only this thread changes index a's state now, and applying_)
          const bool alone = steps_->alone(a);
          spin_lock(lock);
          applying_ = alone ? kAll : order_[a];
        }
        if (applying_ == kAll ? traversing_ == 0 : !neighbour_traversing(order_[a]))
          break;
      }
      size_t i;
      if (applying_ != kAll && take(i, true)) {
        lock.unlock();
        traverse(i, 0);
        spin_lock(lock);
        finish_traversal(i);
        continue;
      }
      main_waiting_ = true;
      main_wait_.wait(lock);
      main_waiting_ = false;
    }
    const bool next_ready = a + 1 < n_ && state_[a + 1] == Traversed;
    lock.unlock();
    if (next_ready && steps_->prefetch)
      steps_->prefetch(a + 1);
    try {
      if (traverse_error_[a])
        std::rethrow_exception(traverse_error_[a]);
      steps_->apply(a);
    } catch (...) {
      // Stop the traversers, wait for the running ones, then put back the streams of the
      // clusters traversed past a (the state they had before this level).
      spin_lock(lock);
      stop_ = true;
      applying_ = kNoCluster;
      wait_.notify_all();
      while (traversing_ > 0) {
        main_waiting_ = true;
        main_wait_.wait(lock);
        main_waiting_ = false;
      }
      lock.unlock();
      for (size_t j = a + 1; j < n_; ++j)
        if (state_[j] == Traversed)
          steps_->rewind(j);
      throw;
    }
    spin_lock(lock);
    state_[a] = Applied;
    applying_ = kNoCluster;
    next_apply_ = a + 1;
    if (waiting_ > 0 && (next_apply_ >= wake_at_ || next_apply_ == n_))
      wait_.notify_all();
  }
}

} // namespace pomar
