// entropy/static_tables: the clustered levels' frozen models, chosen by LevelFreezer and
// stored by write_tables. Version 5 files choose each model's frequencies for the fewest
// bits of data and table; whatever is chosen, read_tables gives back exactly the models the
// blocks were coded with.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "entropy/models.h"
#include "entropy/static_tables.h"

namespace pomar {
namespace {

/// Counts of `levels` clustered levels for every model of a version 5 set: frequency models
/// with geometric-looking statistics that drift slowly from level to level (more events
/// each level), some models used only a few times, some not at all; binary models likewise.
std::vector<std::vector<uint32_t>> drifting_counts(int levels, uint32_t seed) {
  Models m;
  m.conn.patch_rank = true;
  ModelSlots slots(m);
  std::mt19937 rng(seed);
  std::vector<std::vector<uint32_t>> all;
  for (int l = 0; l < levels; ++l) {
    std::vector<uint32_t> counts(slots.symbols(), 0);
    const double events = 200.0 * std::pow(1.33, l);
    for (uint32_t slot = 0; slot < slots.slots(); ++slot) {
      const uint32_t kind = slot % 5; // 0, 1: busy; 2: a few events; 3, 4: unused
      if (kind >= 3)
        continue;
      const double n = kind == 2 ? 2 + double(rng() % 3) : events / (1 + slot % 7);
      const double decay = 0.45 + 0.02 * double(l % 3) + 0.05 * double(slot % 4);
      uint32_t *c = &counts[slots.first_symbol(slot)];
      double p = 1 - decay;
      for (uint32_t s = 0; s < slots.symbols(slot); ++s, p *= decay)
        c[s] = uint32_t(std::lround(n * p * (0.9 + 0.2 * double(rng() % 100) / 100)));
      if (kind == 2) {
        for (uint32_t s = 0; s < slots.symbols(slot); ++s)
          c[s] = 0;
        c[rng() % slots.symbols(slot)] = uint32_t(n);
      }
    }
    all.push_back(std::move(counts));
  }
  return all;
}

struct Frozen {
  std::vector<Models> levels;
  double data_bits = 0; // the counted symbols coded with the frozen models
};

Frozen freeze_levels(const std::vector<std::vector<uint32_t>> &counts, bool fewest_bits) {
  Frozen out;
  out.levels.resize(counts.size());
  LevelFreezer freezer(fewest_bits);
  for (size_t l = 0; l < counts.size(); ++l) {
    Models &m = out.levels[l];
    m.conn.patch_rank = true;
    ModelSlots slots(m);
    freezer.freeze(m, slots, std::vector<uint32_t>(counts[l]));
    const std::vector<double> costs = symbol_costs(slots, freezer.counts());
    for (size_t s = 0; s < costs.size(); ++s)
      out.data_bits += counts[l][s] * costs[s];
  }
  return out;
}

/// Every model of `a` and `b` has the same frozen frequencies (binary: probability).
void expect_same_models(std::vector<Models> &a, std::vector<Models> &b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t l = 0; l < a.size(); ++l) {
    std::vector<const FrequencyModel *> fa, fb;
    std::vector<uint16_t> pa, pb;
    for_each_model(
        a[l], [&](FrequencyModel &f) { fa.push_back(&f); },
        [&](BitModel &m) { pa.push_back(m.p0); });
    for_each_model(
        b[l], [&](FrequencyModel &f) { fb.push_back(&f); },
        [&](BitModel &m) { pb.push_back(m.p0); });
    ASSERT_EQ(fa.size(), fb.size());
    EXPECT_EQ(pa, pb) << "level " << l;
    for (size_t i = 0; i < fa.size(); ++i) {
      ASSERT_EQ(fa[i]->symbols(), fb[i]->symbols());
      for (int s = 0; s < fa[i]->symbols(); ++s)
        ASSERT_EQ(fa[i]->freq(s), fb[i]->freq(s)) << "level " << l << " model " << i;
    }
  }
}

TEST(ModelTables, WhatIsChosenIsWhatIsRead) {
  for (bool fewest_bits : {true, false}) {
    Frozen f = freeze_levels(drifting_counts(12, 7), fewest_bits);
    const std::vector<uint8_t> table = write_tables(f.levels);
    std::vector<Models> read = read_tables(table.data(), table.size(), f.levels.size(), true);
    expect_same_models(f.levels, read);
  }
}

TEST(ModelTables, FewestBitsCostLessThanVersion4sChoice) {
  // Data and table together, over levels whose statistics drift: the version 5 choice is
  // smaller, mostly in the tables (steps the data do not repay are not stored).
  for (uint32_t seed : {1u, 2u, 3u}) {
    const auto counts = drifting_counts(14, seed);
    Frozen v5 = freeze_levels(counts, true), v4 = freeze_levels(counts, false);
    const double t5 = 8.0 * double(write_tables(v5.levels).size());
    const double t4 = 8.0 * double(write_tables(v4.levels).size());
    EXPECT_LT(t5 + v5.data_bits, t4 + v4.data_bits) << "seed " << seed;
    EXPECT_LT(t5, 0.8 * t4) << "seed " << seed;
  }
}

TEST(ModelTables, AModelUsedAFewTimesIsUniform) {
  // Two events of a 17-symbol model cost 8.2 bits with uniform frequencies, less than its
  // table; a busy model keeps frequencies of its own.
  Models m;
  m.conn.patch_rank = true;
  ModelSlots slots(m);
  std::vector<uint32_t> counts(slots.symbols(), 0);
  const uint32_t rare = slots.slot(&m.conn.rank[3]), busy = slots.slot(&m.conn.rank[4]);
  counts[slots.first_symbol(rare) + 5] = 2;
  for (uint32_t s = 0; s < 6; ++s)
    counts[slots.first_symbol(busy) + s] = 4000 >> (2 * s);
  LevelFreezer freezer;
  freezer.freeze(m, slots, std::move(counts));
  for (int s = 0; s < m.conn.rank[3].symbols(); ++s)
    EXPECT_EQ(m.conn.rank[3].freq(s), 1);
  EXPECT_GT(m.conn.rank[4].freq(0), 16 * m.conn.rank[4].freq(3));
  EXPECT_EQ(m.conn.rank[4].freq(10), 0);
}

} // namespace
} // namespace pomar
