// The threads of the codec's parallel steps: how many this process may use, and a small
// pool that runs the items of one step on all of them and returns when every item is done.
// Whatever runs on it must give the same result for any thread count (the steps write
// per-item results and join them in item order).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace pomar {

/// The cores this process may run on (its CPU affinity mask; at least 1; 1 in a
/// WebAssembly build without threads).
unsigned available_cores();

/// `threads` if non-zero, else available_cores() (the meaning of the options' 0).
unsigned resolve_threads(unsigned threads);

/// The decoder's threads for DecodeOptions/SelectiveOptions::threads: resolve_threads, at
/// most kMaxDecodeThreads (each thread holds claim stamps of 4 bytes per face,
/// pomar/limits.h decode_thread_memory; and applying the splits stays on one thread).
constexpr unsigned kMaxDecodeThreads = 8;
unsigned decode_threads(unsigned threads);

class ThreadPool {
public:
  /// `threads` threads in all, the caller's included (it works too); fewer if the system
  /// refuses to start more.
  explicit ThreadPool(unsigned threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool &) = delete;
  ThreadPool &operator=(const ThreadPool &) = delete;
  unsigned size() const { return static_cast<unsigned>(workers_.size()) + 1; }
  /// Run task(i, thread) for every i in [0, n) on the pool's threads (`thread` in
  /// [0, size()): one thread runs one item at a time), the items taken in increasing order;
  /// returns when all are done, rethrowing the first exception a task let out. The caller
  /// does not wait for workers that have not started (a busy machine): it takes their items.
  using Task = std::function<void(size_t item, unsigned thread)>;
  void run(size_t n, const Task &task);

private:
  void work(unsigned thread);
  void drain(unsigned thread, uint64_t generation);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  // The job, all under mutex_: an item is taken with the job's generation, so a worker
  // waking late never touches a later job's items with an earlier job's task.
  const Task *task_ = nullptr;
  size_t items_ = 0;
  size_t next_ = 0;         // next item to take
  size_t finished_ = 0;     // items done
  uint64_t generation_ = 0; // counts jobs
  bool stop_ = false;
  std::exception_ptr error_;
};

} // namespace pomar
