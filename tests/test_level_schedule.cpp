// The pipelined schedule of a clustered level (decode/level_schedule.h) with stand-in
// steps that record what ran when, on random cluster graphs with random delays: what the
// decoder's correctness rests on must hold for every interleaving the threads produce.
//   - every cluster is traversed once, before it is applied; the applies run in order on
//     the calling thread;
//   - no traversal runs next to (or on) the cluster being applied, none at all during an
//     apply that must be alone;
//   - no traversal starts more than `window` indices past the next apply;
//   - an apply that throws: run() rethrows it, nothing after it is applied, and exactly the
//     clusters traversed past it are rewound; a traversal that throws: the same at its
//     turn to be applied.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "decode/level_schedule.h"

namespace pomar {
namespace {

/// A random graph of `clusters` clusters: a ring (neighbouring ids are adjacent, as in
/// real files) plus random chords.
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
  std::vector<std::atomic<int>> traversing;     // by cluster
  std::vector<std::atomic<int>> traversals;     // by index: times traversed
  std::vector<std::atomic<int>> traversed_done; // by index: traversal finished
  std::atomic<int> running{0};                  // traversals running
  std::atomic<uint32_t> applying{kNone};        // cluster being applied
  std::atomic<bool> applying_alone{false};
  std::atomic<size_t> applied{0}; // applies done
  std::atomic<int> violations{0};
  std::mutex messages_lock;
  std::vector<std::string> messages;

  Recorder(const ClusterGraph &g, std::vector<uint32_t> o, size_t w)
      : graph(g), order(std::move(o)), window(w), traversing(g.start.size() - 1),
        traversals(order.size()), traversed_done(order.size()) {}

  void fail(const std::string &what) {
    ++violations;
    const std::lock_guard<std::mutex> lock(messages_lock);
    if (messages.size() < 5)
      messages.push_back(what);
  }
  bool next_to(uint32_t a, uint32_t b) const {
    if (a == b)
      return true;
    for (uint32_t k = graph.start[a]; k < graph.start[a + 1]; ++k)
      if (graph.adj[k] == b)
        return true;
    return false;
  }
  void check_traversal(size_t i) {
    const uint32_t c = order[i], now = applying.load();
    if (applying_alone.load())
      fail("traversal of index " + std::to_string(i) + " during an apply that must be alone");
    if (now != kNone && next_to(c, now))
      fail("traversal of cluster " + std::to_string(c) + " next to applied cluster " +
           std::to_string(now));
  }
};

struct ScheduleRun {
  size_t applied = 0;
  std::vector<int> rewound;
  bool threw = false;
};

ScheduleRun run_schedule(Recorder &r, ThreadPool &pool, uint32_t seed, size_t throw_at,
                         const std::vector<bool> &alone, size_t traverse_throws_at = kNone) {
  LevelSchedule schedule;
  std::vector<std::mt19937> rngs;
  for (unsigned t = 0; t < pool.size(); ++t)
    rngs.emplace_back(seed * 31 + t);
  const std::thread::id caller = std::this_thread::get_id();
  ScheduleRun out;
  out.rewound.assign(r.order.size(), 0);
  LevelSchedule::Steps steps;
  steps.traverse = [&](size_t i, unsigned thread) {
    if (i >= r.applied.load() + r.window)
      r.fail("index " + std::to_string(i) + " traversed outside the window");
    const uint32_t c = r.order[i];
    ++r.running;
    ++r.traversing[c];
    ++r.traversals[i];
    r.check_traversal(i);
    spin(rngs[thread]);
    r.check_traversal(i);
    --r.traversing[c];
    --r.running;
    r.traversed_done[i] = 1;
    if (i == traverse_throws_at)
      throw std::runtime_error("damaged block");
  };
  steps.alone = [&](size_t i) { return bool(alone[i]); };
  steps.apply = [&](size_t i) {
    if (std::this_thread::get_id() != caller)
      r.fail("apply off the calling thread");
    if (i != r.applied.load())
      r.fail("apply of index " + std::to_string(i) + " out of order");
    if (!r.traversed_done[i].load())
      r.fail("apply of index " + std::to_string(i) + " before its traversal");
    const uint32_t c = r.order[i];
    r.applying = c;
    r.applying_alone = bool(alone[i]);
    if (alone[i] && r.running.load() != 0)
      r.fail("apply that must be alone while traversals run");
    for (uint32_t k = r.graph.start[c]; k < r.graph.start[c + 1]; ++k)
      if (r.traversing[r.graph.adj[k]].load())
        r.fail("apply of cluster " + std::to_string(c) + " while a neighbour is traversed");
    spin(rngs[0]);
    r.applying_alone = false;
    r.applying = kNone;
    if (i == throw_at)
      throw std::runtime_error("damaged");
    r.applied = i + 1;
  };
  steps.rewind = [&](size_t j) {
    if (j <= std::min(throw_at, traverse_throws_at))
      r.fail("rewind of index " + std::to_string(j) + ", not past the failed apply");
    ++out.rewound[j];
  };
  try {
    schedule.run(pool, r.graph, r.order.data(), r.order.size(), r.window, steps);
  } catch (const std::runtime_error &) {
    out.threw = true;
  }
  out.applied = r.applied.load();
  return out;
}

TEST(LevelSchedule, TraversalsNeverMeetTheApplyAndAppliesStayInOrder) {
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
      std::vector<bool> alone(order.size());
      for (size_t i = 0; i < order.size(); ++i)
        alone[i] = rng() % 9 == 0;
      const size_t window = 1 + rng() % 64;
      Recorder r(graph, order, window);
      const ScheduleRun run = run_schedule(r, pool, seed, kNone, alone);
      const std::string where = std::to_string(threads) + " threads, seed " + std::to_string(seed);
      EXPECT_FALSE(run.threw) << where;
      EXPECT_EQ(run.applied, order.size()) << where;
      for (size_t i = 0; i < order.size(); ++i)
        EXPECT_EQ(r.traversals[i].load(), 1) << where << ", index " << i;
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

/// A level of `n` clusters whose apply (or traversal: `in_traversal`) of one index throws:
/// run() rethrows, the indices before it are applied (each traversed once), not it nor any
/// after it, and exactly the indices past it that were traversed are rewound.
void expect_stops_at_the_failure(ThreadPool &pool, uint32_t seed, uint32_t n, bool in_traversal) {
  std::mt19937 rng(seed);
  const ClusterGraph graph = random_graph(n, rng);
  const size_t fails = rng() % n, window = 1 + rng() % 80;
  Recorder r(graph, all_clusters(n), window);
  const ScheduleRun run = run_schedule(r, pool, seed, in_traversal ? kNone : fails,
                                       std::vector<bool>(n, false), in_traversal ? fails : kNone);
  const std::string where = "seed " + std::to_string(seed);
  EXPECT_TRUE(run.threw) << where;
  EXPECT_EQ(run.applied, fails) << where;
  for (size_t j = 0; j < n; ++j) {
    const int traversed = r.traversals[j].load();
    EXPECT_LE(traversed, 1) << where << ", index " << j;
    if (j <= fails) {
      EXPECT_EQ(traversed, 1) << where << ", index " << j;
    }
    EXPECT_EQ(run.rewound[j], j > fails ? traversed : 0) << where << ", index " << j;
  }
  EXPECT_EQ(r.violations.load(), 0) << where << ": " << (r.messages.empty() ? "" : r.messages[0]);
}

TEST(LevelSchedule, AFailedApplyStopsTheLevelAndRewindsWhatWasTraversedPastIt) {
  ThreadPool pool(3);
  for (uint32_t seed = 101; seed <= 112; ++seed)
    expect_stops_at_the_failure(pool, seed, 300, false);
}

TEST(LevelSchedule, AFailedTraversalFailsAtItsTurnToBeApplied) {
  ThreadPool pool(2);
  for (uint32_t seed = 201; seed <= 208; ++seed)
    expect_stops_at_the_failure(pool, seed, 200, true);
}

TEST(LevelSchedule, APoolOfOneThreadDoesEverythingOnTheCaller) {
  ThreadPool pool(1);
  std::mt19937 rng(7);
  const ClusterGraph graph = random_graph(50, rng);
  Recorder r(graph, all_clusters(50), 4);
  const ScheduleRun run = run_schedule(r, pool, 7, kNone, std::vector<bool>(50, true));
  EXPECT_EQ(run.applied, 50u);
  for (size_t i = 0; i < 50; ++i)
    EXPECT_EQ(r.traversals[i].load(), 1);
  EXPECT_EQ(r.violations.load(), 0) << (r.messages.empty() ? "" : r.messages[0]);
}

} // namespace
} // namespace pomar
