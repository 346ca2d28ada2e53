// The phased schedule of a clustered level (decode/level_schedule.h) with stand-in steps
// that record what ran when, on random cluster graphs with random delays: what the
// decoder's correctness rests on must hold for every interleaving the threads produce.
//   - every cluster is traversed once; no apply runs while a traversal does (the phases);
//   - admits run one at a time in index order, each once the indices up to it are
//     traversed; the window's grow (calling thread) and applies after its admits;
//   - every admitted index is applied once; two neighbouring clusters are never applied at
//     the same time; `applied` is called in index order on the calling thread after the
//     window's applies;
//   - no traversal starts more than `window` indices past the applied ones;
//   - an admit that fails: run() returns its index, nothing from it on is applied, and
//     exactly the indices past it that were traversed are rewound.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "decode/level_schedule.h"

namespace pomar {
namespace {

/// A random graph of `clusters` clusters: a ring plus random chords.
ClusterGraph random_graph(uint32_t clusters, std::mt19937 &rng) {
  std::vector<std::vector<uint32_t>> adj(clusters);
  const auto link = [&](uint32_t a, uint32_t b) {
    if (a == b)
      return;
    for (uint32_t x : adj[a])
      if (x == b)
        return;
    adj[a].push_back(b);
    adj[b].push_back(a);
  };
  for (uint32_t c = 0; c + 1 < clusters; ++c)
    link(c, c + 1);
  std::uniform_int_distribution<uint32_t> any(0, clusters - 1);
  for (uint32_t k = 0; k < clusters; ++k)
    link(any(rng), any(rng));
  ClusterGraph g;
  g.start.push_back(0);
  for (const auto &a : adj) {
    g.adj.insert(g.adj.end(), a.begin(), a.end());
    g.start.push_back(static_cast<uint32_t>(g.adj.size()));
  }
  return g;
}

void spin(std::mt19937 &rng) { // a few microseconds, sometimes a yield
  std::uniform_int_distribution<int> d(0, 40);
  const int n = d(rng);
  if (n > 36)
    std::this_thread::yield();
  volatile int x = 0;
  for (int i = 0; i < n * 50; ++i)
    x = x + i;
}

struct Recorder {
  const ClusterGraph &graph;
  std::vector<uint32_t> order;
  size_t window;
  std::vector<std::atomic<int>> applying;   // by cluster: applies running
  std::vector<std::atomic<int>> traversals; // by index: times traversed
  std::vector<std::atomic<int>> applies;    // by index: times applied
  std::vector<std::atomic<int>> traversed;  // by index: its traversal ended
  std::atomic<int> admitting{0};            // admits running
  std::vector<int> admitted;                // by index (calling thread only)
  std::atomic<int> traversing{0};           // traversals running
  std::atomic<int> applies_running{0};
  std::atomic<size_t> applied_upto{0}; // indices below it are applied ("applied" called)
  size_t admit_next = 0;               // the index admitted next (calling thread)
  bool grown = false;                  // the grow after the last admits ran
  std::atomic<int> violations{0};
  std::mutex messages_lock;
  std::vector<std::string> messages;

  Recorder(const ClusterGraph &g, std::vector<uint32_t> o, size_t w)
      : graph(g), order(std::move(o)), window(w), applying(g.start.size() - 1),
        traversals(order.size()), applies(order.size()), traversed(order.size()),
        admitted(order.size(), 0) {}

  void fail(const std::string &what) {
    ++violations;
    const std::lock_guard<std::mutex> lock(messages_lock);
    if (messages.size() < 5)
      messages.push_back(what);
  }
};

struct ScheduleRun {
  size_t failed = 0; // what run() returned
  std::vector<int> rewound;
};

/// Run the schedule; the admit of `fails_at` (kNone: none) fails.
ScheduleRun run_schedule(Recorder &r, ThreadPool &pool, uint32_t seed, size_t fails_at) {
  LevelSchedule schedule;
  std::vector<std::mt19937> rngs;
  for (unsigned t = 0; t < pool.size(); ++t)
    rngs.emplace_back(seed * 31 + t);
  std::mt19937 caller_rng(seed);
  const std::thread::id caller = std::this_thread::get_id();
  const std::vector<uint32_t> rank = breadth_first_ranks(r.graph);
  ScheduleRun out;
  out.rewound.assign(r.order.size(), 0);
  const auto on_caller = [&](const char *what) {
    if (std::this_thread::get_id() != caller)
      r.fail(std::string(what) + " off the calling thread");
  };
  LevelSchedule::Steps steps;
  steps.traverse = [&](size_t i, unsigned thread) {
    if (i >= r.applied_upto.load() + r.window)
      r.fail("index " + std::to_string(i) + " traversed outside the window");
    ++r.traversing;
    ++r.traversals[i];
    if (r.applies_running.load() != 0)
      r.fail("traversal of index " + std::to_string(i) + " while an apply runs");
    spin(rngs[thread]);
    if (r.applies_running.load() != 0)
      r.fail("traversal of index " + std::to_string(i) + " while an apply runs");
    r.traversed[i] = 1;
    --r.traversing;
  };
  steps.admit = [&](size_t i) {
    if (++r.admitting != 1)
      r.fail("two admits at once");
    if (i != r.admit_next)
      r.fail("admit of index " + std::to_string(i) + " out of order");
    for (size_t j = i - i % r.window; j <= i; ++j)
      if (!r.traversed[j].load())
        r.fail("admit of index " + std::to_string(i) + " before index " + std::to_string(j) +
               " was traversed");
    spin(caller_rng);
    r.admit_next = i + 1;
    r.grown = false;
    --r.admitting;
    if (i == fails_at)
      return false;
    r.admitted[i] = 1;
    return true;
  };
  steps.grow = [&] {
    on_caller("grow");
    r.grown = true;
  };
  steps.apply = [&](size_t i, unsigned thread) {
    if (!r.admitted[i] || !r.grown)
      r.fail("apply of index " + std::to_string(i) + " before its admit and the grow");
    if (r.traversing.load() != 0)
      r.fail("apply of index " + std::to_string(i) + " while a traversal runs");
    const uint32_t c = r.order[i];
    ++r.applies_running;
    ++r.applies[i];
    ++r.applying[c];
    for (uint32_t k = r.graph.start[c]; k < r.graph.start[c + 1]; ++k)
      if (r.applying[r.graph.adj[k]].load())
        r.fail("apply of cluster " + std::to_string(c) + " while a neighbour is applied");
    spin(rngs[thread]);
    --r.applying[c];
    --r.applies_running;
  };
  steps.applied = [&](size_t i) {
    on_caller("applied");
    if (i != r.applied_upto.load() || r.applies[i].load() != 1 || r.applies_running.load())
      r.fail("applied(" + std::to_string(i) + ") out of order or before its apply ended");
    r.applied_upto = i + 1;
    spin(caller_rng);
  };
  steps.rewind = [&](size_t j) {
    on_caller("rewind");
    if (j <= fails_at && fails_at != kNone)
      r.fail("rewind of index " + std::to_string(j) + ", not past the failed admit");
    ++out.rewound[j];
  };
  out.failed = schedule.run(pool, r.graph, rank, r.order.data(), r.order.size(), r.window, steps);
  return out;
}

TEST(LevelSchedule, PhasesNeverOverlapAndNeighboursAreNeverAppliedTogether) {
  for (unsigned threads : {2u, 3u, 7u}) {
    ThreadPool pool(threads);
    for (uint32_t seed = 1; seed <= 12; ++seed) {
      std::mt19937 rng(seed);
      const uint32_t clusters = 40 + seed * 23;
      const ClusterGraph graph = random_graph(clusters, rng);
      // A level refines a subset of the clusters (increasing ids).
      std::vector<uint32_t> order;
      for (uint32_t c = 0; c < clusters; ++c)
        if (rng() % 4 != 0)
          order.push_back(c);
      const size_t window = 1 + rng() % 64;
      Recorder r(graph, order, window);
      const ScheduleRun run = run_schedule(r, pool, seed, kNone);
      const std::string where = std::to_string(threads) + " threads, seed " + std::to_string(seed);
      EXPECT_EQ(run.failed, order.size()) << where;
      EXPECT_EQ(r.applied_upto.load(), order.size()) << where;
      for (size_t i = 0; i < order.size(); ++i) {
        EXPECT_EQ(r.traversals[i].load(), 1) << where << ", index " << i;
        EXPECT_EQ(r.applies[i].load(), 1) << where << ", index " << i;
        EXPECT_EQ(run.rewound[i], 0) << where << ", index " << i;
      }
      EXPECT_EQ(r.violations.load(), 0)
          << where << ": " << (r.messages.empty() ? "" : r.messages[0]);
    }
  }
}

std::vector<uint32_t> all_clusters(uint32_t n) {
  std::vector<uint32_t> order(n);
  for (uint32_t c = 0; c < n; ++c)
    order[c] = c;
  return order;
}

/// A level of `n` clusters whose admit of one index fails: run() returns it, the indices
/// before it are applied (each traversed once), not it nor any after it, and exactly the
/// indices past it that were traversed (the rest of its window) are rewound.
void expect_stops_at_the_failure(ThreadPool &pool, uint32_t seed, uint32_t n) {
  std::mt19937 rng(seed);
  const ClusterGraph graph = random_graph(n, rng);
  const size_t fails = rng() % n, window = 1 + rng() % 80;
  Recorder r(graph, all_clusters(n), window);
  const ScheduleRun run = run_schedule(r, pool, seed, fails);
  const std::string where = "seed " + std::to_string(seed);
  EXPECT_EQ(run.failed, fails) << where;
  EXPECT_EQ(r.applied_upto.load(), fails) << where;
  const size_t window_end = std::min<size_t>(n, (fails / window + 1) * window);
  for (size_t j = 0; j < n; ++j) {
    EXPECT_EQ(r.traversals[j].load(), j < window_end ? 1 : 0) << where << ", index " << j;
    EXPECT_EQ(r.applies[j].load(), j < fails ? 1 : 0) << where << ", index " << j;
    EXPECT_EQ(run.rewound[j], j > fails && j < window_end ? 1 : 0) << where << ", index " << j;
  }
  EXPECT_EQ(r.violations.load(), 0) << where << ": " << (r.messages.empty() ? "" : r.messages[0]);
}

TEST(LevelSchedule, AFailedAdmitStopsTheLevelAndRewindsWhatWasTraversedPastIt) {
  ThreadPool pool(3);
  for (uint32_t seed = 101; seed <= 112; ++seed)
    expect_stops_at_the_failure(pool, seed, 300);
}

TEST(LevelSchedule, APoolOfOneThreadDoesEverythingOnTheCaller) {
  ThreadPool pool(1);
  std::mt19937 rng(7);
  const ClusterGraph graph = random_graph(50, rng);
  Recorder r(graph, all_clusters(50), 4);
  const ScheduleRun run = run_schedule(r, pool, 7, kNone);
  EXPECT_EQ(run.failed, 50u);
  EXPECT_EQ(r.applied_upto.load(), 50u);
  for (size_t i = 0; i < 50; ++i) {
    EXPECT_EQ(r.traversals[i].load(), 1);
    EXPECT_EQ(r.applies[i].load(), 1);
  }
  EXPECT_EQ(r.violations.load(), 0) << (r.messages.empty() ? "" : r.messages[0]);
}

TEST(LevelSchedule, BreadthFirstRanksNumberEveryClusterOnceComponentAfterComponent) {
  // Two components: a path 0-2-4 and a triangle 1-3-5.
  ClusterGraph g;
  const std::vector<std::vector<uint32_t>> adj = {{2}, {3, 5}, {0, 4}, {1, 5}, {2}, {1, 3}};
  g.start.push_back(0);
  for (const auto &a : adj) {
    g.adj.insert(g.adj.end(), a.begin(), a.end());
    g.start.push_back(static_cast<uint32_t>(g.adj.size()));
  }
  EXPECT_EQ(breadth_first_ranks(g), (std::vector<uint32_t>{0, 3, 1, 4, 2, 5}));
}

} // namespace
} // namespace pomar
