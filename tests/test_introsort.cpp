// mesh/introsort.h: the sort whose order of equal elements is part of the bitstream (the
// edge ranking of split vertices with more than 16 edges, the encoder's face order). With
// GCC's standard library (what files were written with) it must leave equal elements
// exactly where std::sort does; on any library it must sort.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "mesh/introsort.h"

namespace pomar {
namespace {

struct Item {
  uint32_t key, id; // sorted by key alone: equal keys tie, `id` shows where they went
  bool operator==(const Item &o) const { return key == o.key && id == o.id; }
};
const auto by_key = [](const Item &a, const Item &b) { return a.key < b.key; };

std::vector<Item> items(const std::vector<uint32_t> &keys) {
  std::vector<Item> v(keys.size());
  for (size_t i = 0; i < keys.size(); ++i)
    v[i] = {keys[i], uint32_t(i)};
  return v;
}

/// Inputs of `n` keys: random over a small range (many ties) or a large one, sorted,
/// reversed, all equal, organ pipe, sawtooth.
std::vector<std::vector<uint32_t>> inputs(size_t n, std::mt19937 &rng) {
  std::vector<std::vector<uint32_t>> out;
  for (uint32_t range : {2u, 5u, uint32_t(n / 4 + 1), 1000000u}) {
    std::vector<uint32_t> k(n);
    for (uint32_t &x : k)
      x = rng() % range;
    out.push_back(k);
  }
  std::vector<uint32_t> up(n), down(n), equal(n, 7), pipe(n), saw(n);
  for (size_t i = 0; i < n; ++i) {
    up[i] = uint32_t(i / 3);
    down[i] = uint32_t((n - i) / 3);
    pipe[i] = uint32_t(std::min(i, n - i));
    saw[i] = uint32_t(i % 11);
  }
  for (auto *k : {&up, &down, &equal, &pipe, &saw})
    out.push_back(*k);
  return out;
}

void expect_sorted(const std::vector<Item> &v) {
  EXPECT_TRUE(std::is_sorted(v.begin(), v.end(), by_key));
}

TEST(Introsort, SortsAndLeavesTiesWhereGccsStdSortDoes) {
  std::mt19937 rng(12345);
  size_t compared = 0, ties_moved = 0;
  std::vector<size_t> sizes;
  for (size_t n = 0; n <= 70; ++n)
    sizes.push_back(n);
  for (size_t n : {100, 257, 1000, 4099, 100000})
    sizes.push_back(n);
  for (size_t n : sizes)
    for (const std::vector<uint32_t> &keys : inputs(n, rng)) {
      std::vector<Item> ours = items(keys), reference = ours;
      introsort(ours.data(), ours.data() + ours.size(), by_key);
      expect_sorted(ours);
#ifdef __GLIBCXX__
      std::sort(reference.begin(), reference.end(), by_key);
      ASSERT_EQ(ours, reference) << n << " keys";
      ++compared;
      std::vector<Item> stable = items(keys);
      std::stable_sort(stable.begin(), stable.end(), by_key);
      ties_moved += ours != stable;
#endif
    }
#ifdef __GLIBCXX__
  EXPECT_EQ(compared, sizes.size() * 9);
  // The comparison means something: std::sort moved ties in many of these inputs.
  EXPECT_GT(ties_moved, compared / 4);
#endif
}

TEST(Introsort, HeapSortIsGccsPartialSortOfTheWholeRange) {
  std::mt19937 rng(777);
  for (size_t n : {0, 1, 2, 3, 16, 17, 33, 64, 1000, 12345})
    for (const std::vector<uint32_t> &keys : inputs(n, rng)) {
      std::vector<Item> ours = items(keys), reference = ours;
      introsort_detail::heap_sort(ours.data(), ours.data() + ours.size(), by_key);
      expect_sorted(ours);
#ifdef __GLIBCXX__
      std::partial_sort(reference.begin(), reference.end(), reference.end(), by_key);
      ASSERT_EQ(ours, reference) << n << " keys";
#endif
    }
}

TEST(Introsort, AnAdversarialInputTakesTheHeapPathAsGccsStdSortDoes) {
  // McIlroy's adversary ("A killer adversary for quicksort", 1999) fixes the values
  // lazily, during a sort, so that every partition is as lopsided as it can be: on its
  // input the partitions pass the depth limit and the heap sort finishes the range (an
  // instrumented build counted one heap sort per sort of these inputs). Its values, halved
  // so that pairs tie, are then sorted again by both sorts.
  for (int n : {100, 1000, 5000}) {
    const int gas = n; // not fixed yet
    std::vector<int> val(n, gas), idx(n);
    int fixed = 0, candidate = 0;
    for (int i = 0; i < n; ++i)
      idx[i] = i;
    introsort(idx.data(), idx.data() + n, [&](int x, int y) {
      if (val[x] == gas && val[y] == gas)
        val[x == candidate ? x : y] = fixed++;
      if (val[x] == gas)
        candidate = x;
      else if (val[y] == gas)
        candidate = y;
      return val[x] < val[y];
    });
    std::vector<uint32_t> keys(n);
    for (int i = 0; i < n; ++i)
      keys[i] = uint32_t((val[i] == gas ? fixed++ : val[i]) / 2);
    std::vector<Item> ours = items(keys), reference = ours;
    size_t ours_compared = 0, reference_compared = 0;
    introsort(ours.data(), ours.data() + ours.size(), [&](const Item &a, const Item &b) {
      ++ours_compared;
      return a.key < b.key;
    });
    expect_sorted(ours);
#ifdef __GLIBCXX__
    std::sort(reference.begin(), reference.end(), [&](const Item &a, const Item &b) {
      ++reference_compared;
      return a.key < b.key;
    });
    ASSERT_EQ(ours, reference) << n << " keys";
    EXPECT_EQ(ours_compared, reference_compared); // the same steps, comparison for comparison
#endif
  }
}

TEST(Introsort, RingsOfSeventeenToFortyEdgesWithATie) {
  // What the edge ranking sorts: ring indices by (squared length descending, key), one
  // neighbour named twice (same length and key).
  std::mt19937 rng(99);
  for (int trial = 0; trial < 20000; ++trial) {
    const uint32_t m = 17 + rng() % 24;
    std::vector<int64_t> len(m);
    std::vector<uint64_t> key(m);
    for (uint32_t i = 0; i < m; ++i) {
      len[i] = rng() % 1000;
      key[i] = rng();
    }
    const uint32_t a = rng() % m, b = rng() % m;
    len[b] = len[a];
    key[b] = key[a];
    const auto before = [&](uint32_t x, uint32_t y) {
      return len[x] != len[y] ? len[x] > len[y] : key[x] < key[y];
    };
    std::vector<uint32_t> ours(m), reference(m);
    for (uint32_t i = 0; i < m; ++i)
      ours[i] = reference[i] = i;
    introsort(ours.data(), ours.data() + m, before);
    ASSERT_TRUE(std::is_sorted(ours.begin(), ours.end(), before));
#ifdef __GLIBCXX__
    std::sort(reference.begin(), reference.end(), before);
    ASSERT_EQ(ours, reference) << "ring of " << m;
#endif
  }
}

} // namespace
} // namespace pomar
