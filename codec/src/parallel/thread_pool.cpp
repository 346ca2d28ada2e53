// The codec's threads; see thread_pool.h.
#include "parallel/thread_pool.h"

#include <algorithm>
#include <system_error>

#ifdef __linux__
#include <sched.h>
#endif

namespace pomar {

unsigned available_cores() {
#if defined(__EMSCRIPTEN__) && !defined(__EMSCRIPTEN_PTHREADS__)
  return 1;
#else
#ifdef __linux__
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
    return static_cast<unsigned>(CPU_COUNT(&set));
#endif
  return std::max(1u, std::thread::hardware_concurrency());
#endif
}

unsigned resolve_threads(unsigned threads) { return threads ? threads : available_cores(); }

unsigned decode_threads(unsigned threads) {
  return std::min(resolve_threads(threads), kMaxDecodeThreads);
}

ThreadPool::ThreadPool(unsigned threads) {
  for (unsigned t = 1; t < threads; ++t) {
    try {
      workers_.emplace_back([this, t] { work(t); });
    } catch (const std::system_error &) {
      break; // no more threads: the ones started do the work
    }
  }
}

ThreadPool::~ThreadPool() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread &w : workers_)
    w.join();
}

void ThreadPool::run(size_t n, const Task &task) {
  if (n == 0)
    return;
  uint64_t generation;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    task_ = &task;
    items_ = n;
    next_ = 0;
    finished_ = 0;
    error_ = nullptr;
    generation = ++generation_;
  }
  if (!workers_.empty())
    wake_.notify_all();
  drain(0, generation);
  std::exception_ptr error;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return finished_ == items_; });
    task_ = nullptr;
    std::swap(error, error_);
  }
  if (error)
    std::rethrow_exception(error);
}

void ThreadPool::work(unsigned thread) {
  uint64_t seen = 0;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_)
        return;
      seen = generation_;
    }
    drain(thread, seen);
  }
}

void ThreadPool::drain(unsigned thread, uint64_t generation) {
  for (;;) {
    size_t i;
    const Task *task;
    {
      // One lock per item: the items are large (a cluster's traversal).
      const std::lock_guard<std::mutex> lock(mutex_);
      if (generation_ != generation || next_ >= items_)
        return;
      i = next_++;
      task = task_;
    }
    std::exception_ptr error;
    try {
      (*task)(i, thread);
    } catch (...) {
      error = std::current_exception();
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    if (error && !error_)
      error_ = error;
    if (++finished_ == items_)
      done_.notify_all();
  }
}

} // namespace pomar
