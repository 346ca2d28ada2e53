#include "entropy/static_tables.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

#include "pomar/pomar.h"

namespace pomar {
namespace {

// Frequencies are stored on a logarithmic scale with 3 mantissa bits (at most 6% off):
// code q in 1..103 stands for ((8 + q%8) << (q/8)) >> 3; 0 is "never seen".
constexpr int kLogCodes = 104;

uint32_t log_frequency(uint32_t q) { return q == 0 ? 0 : ((8u + (q & 7)) << (q >> 3)) >> 3; }

/// log_frequency of every code, built once (non-decreasing in q: the small codes repeat 1).
const uint32_t *log_frequencies() {
  static const auto table = [] {
    std::array<uint32_t, kLogCodes> t{};
    for (uint32_t q = 0; q < uint32_t(kLogCodes); ++q)
      t[q] = log_frequency(q);
    return t;
  }();
  return table.data();
}

/// A binary model's probability in the tables: an 8-bit code.
uint32_t bit_code(uint32_t p0) { return std::min<uint32_t>(p0 >> 4, 255); }
uint16_t bit_probability(uint32_t code) { return static_cast<uint16_t>(code * 16 + 8); }
const uint32_t kHalfCode = bit_code(1u << (kBitModelBits - 1));
} // namespace

uint32_t log_code(uint32_t f) {
  // The smallest code whose frequency is nearest to f: binary search instead of trying all
  // 103 codes (the table writer and reader call this for every symbol of every model of
  // every level). Candidates: the first code at or above f, and the first code of the
  // value just below it (equal values: the smaller code wins, ties go to the lower value).
  const uint32_t *F = log_frequencies();
  const uint32_t hi = uint32_t(std::lower_bound(F + 1, F + kLogCodes, f) - F);
  if (hi == 1)
    return 1;
  const uint32_t lo = uint32_t(std::lower_bound(F + 1, F + kLogCodes, F[hi - 1]) - F);
  if (hi == uint32_t(kLogCodes))
    return lo;
  return f - F[lo] <= F[hi] - f ? lo : hi;
}

uint32_t log_code_reference(uint32_t f) {
  uint32_t best = 1;
  for (uint32_t q = 1; q < uint32_t(kLogCodes); ++q)
    if (std::abs(int64_t(log_frequency(q)) - int64_t(f)) <
        std::abs(int64_t(log_frequency(best)) - int64_t(f)))
      best = q;
  return best;
}

namespace {

/// Bits to code `counts` with frozen frequencies `freq` (infinite if a counted symbol
/// has frequency 0).
double data_bits(const uint32_t *counts, const uint16_t *freq, int n) {
  double total = 0, bits = 0;
  for (int s = 0; s < n; ++s)
    total += freq[s];
  for (int s = 0; s < n; ++s) {
    if (!counts[s])
      continue;
    if (!freq[s])
      return 1e300;
    bits += counts[s] * std::log2(total / freq[s]);
  }
  return bits;
}

/// What the table writer spends on a step from log code `b` to log code `a` (zigzagged, in
/// an adaptive model where most steps are 0): an estimate, the writer's models adapt.
double step_bits(uint32_t a, uint32_t b) {
  if (a == b)
    return 0.2;
  const uint32_t z = a > b ? 2 * (a - b) : 2 * (b - a) - 1;
  return z < 63 ? 2.0 + std::log2(double(z)) : 14.0;
}
uint32_t code_of(uint16_t freq) { return freq ? log_code(freq) : 0; }

/// The table bits of frequencies `x` after the previous level's `before` (steps from its
/// codes), or of a model the previous level did not use (`before` null: the first and last
/// non-zero symbols and the steps along the alphabet).
double table_bits(const uint16_t *x, const uint16_t *before, int n) {
  double bits = 2; // the "used" and "same as before" bits
  if (before) {
    for (int s = 0; s < n; ++s)
      bits += step_bits(code_of(x[s]), code_of(before[s]));
    return bits;
  }
  int first = 0, last = n - 1;
  while (first < last && x[first] == 0)
    ++first;
  while (last > first && x[last] == 0)
    --last;
  bits += 8;
  for (uint32_t s = uint32_t(first), ref = 48; s <= uint32_t(last); ++s) {
    bits += step_bits(code_of(x[s]), ref);
    ref = code_of(x[s]);
  }
  return bits;
}

/// Choose the frozen frequencies of a used model, `q` on entry the level's own (log-coded),
/// `before` the previous level's (null if it did not use the model): the one that codes the
/// level's `counts` with its table in the fewest bits of
/// - the previous level's frequencies as they are (one bit in the tables): returns 1;
/// - uniform frequencies (one bit: a model used a few times codes them cheaper so than its
///   table costs): returns 2, `q` all 1;
/// - the own frequencies, where there is a previous level each symbol keeping the previous
///   frequency when the data bits its own saves do not pay for storing its step (one
///   greedy pass in symbol order): returns 0, `q` those frequencies.
int choose_frequencies(const uint32_t *counts, const uint16_t *before, int n, uint16_t *q) {
  const auto valid = [&](const uint16_t *x) {
    uint32_t t = 0;
    for (int s = 0; s < n; ++s)
      t += x[s];
    return t != 0 && t <= FrequencyModel::kMaxTotal;
  };
  double best = data_bits(counts, q, n) + table_bits(q, before, n);
  if (before) {
    for (int s = 0; s < n; ++s) {
      if (q[s] == before[s])
        continue;
      const uint16_t own = q[s];
      q[s] = before[s];
      const double bits = valid(q) ? data_bits(counts, q, n) + table_bits(q, before, n) : 1e300;
      if (bits < best)
        best = bits;
      else
        q[s] = own;
    }
  }
  uint64_t events = 0;
  for (int s = 0; s < n; ++s)
    events += counts[s];
  const double reuse = before ? data_bits(counts, before, n) + 1 : 1e300;
  const double uniform = double(events) * std::log2(double(n)) + 1;
  if (reuse <= best && reuse <= uniform)
    return 1;
  if (uniform < best) {
    std::fill(q, q + n, uint16_t(1));
    return 2;
  }
  return 0;
}

/// The choice of the encoders that wrote versions 1-4 (LevelFreezer::fewest_bits_ false):
/// the previous level's frequencies when they code the level's counts within an estimate
/// of what storing the own ones costs (returns 1), else the own (0).
int reuse_previous_v4(const uint32_t *counts, const std::vector<uint16_t> &before, int n,
                      const uint16_t *q) {
  if (before.empty())
    return 0;
  int used_symbols = 0;
  for (int i = 0; i < n; ++i)
    used_symbols += q[i] != 0;
  return data_bits(counts, before.data(), n) <= data_bits(counts, q, n) + 1.5 * used_symbols + 2
             ? 1
             : 0;
}

} // namespace

ModelSlots::ModelSlots(Models &m) {
  // for_each_model visits each array's models one after the other: a model that does not
  // follow the previous one of its type starts a new array.
  auto add = [&](std::vector<Array> &arrays, void *model, size_t size, uint32_t symbols, bool bit) {
    const uintptr_t p = reinterpret_cast<uintptr_t>(model);
    const uint32_t slot = static_cast<uint32_t>(models_.size());
    Array *last = arrays.empty() ? nullptr : &arrays.back();
    if (last && p == last->begin + last->bytes && slot == last->first_slot + last->bytes / size)
      last->bytes += size;
    else
      arrays.push_back({p, size, slot});
    models_.push_back(model);
    is_bit_.push_back(bit);
    first_symbol_.push_back(symbols_);
    symbols_ += symbols;
  };
  for_each_model(
      m,
      [&](FrequencyModel &f) {
        add(frequency_arrays_, &f, sizeof(FrequencyModel), static_cast<uint32_t>(f.symbols()),
            false);
      },
      [&](BitModel &b) { add(bit_arrays_, &b, sizeof(BitModel), 2, true); });
}

void ModelSlots::outside_level() {
  throw Error(Error::Kind::Internal, "internal encoder error: a model outside its level");
}

void count_symbols(const SymbolRecorder &r, const ModelSlots &slots, uint32_t *counts) {
  for (const SymbolRecorder::Event &e : r.events)
    if (e.kind() != 2)
      ++counts[slots.first_symbol(e.model) + e.value()];
}

void LevelFreezer::freeze(Models &m, const ModelSlots &slots, std::vector<uint32_t> &&counted) {
  // Which models were used at all: those with a symbol counted (each event counts one).
  counts_ = std::move(counted);
  const std::vector<uint32_t> &counts = counts_;
  std::vector<uint8_t> used(slots.slots(), 0);
  for (uint32_t slot = 0; slot < slots.slots(); ++slot) {
    const uint32_t *c = &counts[slots.first_symbol(slot)];
    used[slot] = std::any_of(c, c + slots.symbols(slot), [](uint32_t n) { return n != 0; });
  }
  // Each used model: the frequencies that code this level's symbols with their table in
  // the fewest bits (choose_frequencies), or in versions 1-4 the previous level's when
  // they code them nearly as well as the own would (reuse_previous_v4).
  std::vector<std::vector<uint16_t>> &previous = previous_;
  if (previous.size() < slots.slots())
    previous.resize(slots.slots());
  uint32_t slot = 0;
  for_each_model(
      m,
      [&](FrequencyModel &f) {
        std::vector<uint16_t> &before = previous[slot];
        const uint32_t *c = &counts[slots.first_symbol(slot)];
        const bool in_use = used[slot++];
        const int n = f.symbols();
        f.freeze_from_counts(c);
        if (!in_use) {
          before.clear(); // unused: stays uniform, stored as such
          return;
        }
        uint16_t q[FrequencyModel::kMaxSymbols];
        for (int i = 0; i < n; ++i)
          q[i] = static_cast<uint16_t>(f.freq(i) ? log_frequency(log_code(f.freq(i))) : 0);
        const int choice =
            fewest_bits_ ? choose_frequencies(c, before.empty() ? nullptr : before.data(), n, q)
                         : reuse_previous_v4(c, before, n, q);
        if (choice == 1) {
          f.freeze_with(before.data());
          return;
        }
        f.freeze_with(q);
        if (choice == 2)
          before.clear(); // uniform: stored as unused
        else
          before.assign(q, q + n);
      },
      [&](BitModel &b) {
        std::vector<uint16_t> &before = previous[slot];
        const uint32_t *c = &counts[slots.first_symbol(slot)];
        const bool in_use = used[slot++];
        uint32_t p0 = 1u << (kBitModelBits - 1);
        if (in_use) {
          const uint64_t zeros = c[0], all = zeros + c[1];
          p0 = static_cast<uint32_t>((zeros << kBitModelBits) / all);
        }
        p0 = bit_probability(bit_code(p0)); // what the table keeps
        const uint32_t half = bit_probability(kHalfCode);
        if (in_use && !fewest_bits_ && !before.empty()) {
          auto bits = [&](double p) {
            return -(c[0] * std::log2(p / 4096.0) + c[1] * std::log2(1 - p / 4096.0));
          };
          if (bits(before[0]) <= bits(p0) + 6)
            p0 = before[0];
        } else if (in_use && fewest_bits_) {
          // The fewest bits of data and table: the level's own probability, the previous
          // level's ("same": one bit), or 1/2 (stored as unused: one bit).
          auto bits = [&](double p) {
            return -(c[0] * std::log2(p / 4096.0) + c[1] * std::log2(1 - p / 4096.0));
          };
          const uint32_t ref = before.empty() ? 128 : bit_code(before[0]);
          double best = bits(p0) + 2 + step_bits(bit_code(p0), ref);
          if (!before.empty() && bits(before[0]) + 2 <= best) {
            p0 = before[0];
            best = bits(before[0]) + 2;
          }
          if (double(c[0] + c[1]) + 1 < best)
            p0 = half;
        }
        b.p0 = static_cast<uint16_t>(p0);
        b.frozen = true;
        if (!in_use || (fewest_bits_ && p0 == half)) // (1/2 is stored as unused)
          before.clear();
        else
          before.assign(1, b.p0);
      });
}

std::vector<double> symbol_costs(const ModelSlots &slots, const std::vector<uint32_t> &counts) {
  std::vector<double> costs(slots.symbols(), 0.0);
  for (uint32_t slot = 0; slot < slots.slots(); ++slot) {
    const uint32_t first = slots.first_symbol(slot);
    for (uint32_t s = 0; s < slots.symbols(slot); ++s) {
      if (!counts[first + s])
        continue; // never looked up
      costs[first + s] =
          slots.is_bit(slot)
              ? cost_bits(*static_cast<const BitModel *>(slots.model(slot)), int(s))
              : cost_bits(*static_cast<const FrequencyModel *>(slots.model(slot)), int(s));
    }
  }
  return costs;
}

void add_recording_bits(const SymbolRecorder &r, const ModelSlots &slots,
                        const std::vector<double> &costs, double *bits) {
  for (const SymbolRecorder::Event &e : r.events)
    bits[e.stream()] +=
        e.kind() == 2 ? double(e.nbits()) : costs[slots.first_symbol(e.model) + e.value()];
}

void code_recording(const SymbolRecorder &r, const ModelSlots &slots, RangeEncoder &rc) {
  for (const SymbolRecorder::Event &e : r.events) {
    switch (e.kind()) {
    case 0:
      rc.encode(*static_cast<FrequencyModel *>(slots.model(e.model)), int(e.value()));
      break;
    case 1:
      rc.encode_bit(*static_cast<BitModel *>(slots.model(e.model)), int(e.value()));
      break;
    default:
      rc.encode_bypass(e.value(), int(e.nbits()));
    }
  }
}

// Table stream, level after level, each model in for_each_model order:
// - a "used" bit (adaptive; its context says whether the previous level used the model);
// - a frequency model used by the previous level: per symbol, the zigzagged step from that
//   level's log code (statistics drift slowly between levels); otherwise the first and last
//   non-zero symbols and the steps from one symbol's code to the next;
// - a binary model: its 8-bit probability code, as a step from the previous level's.
// Unused models are uniform (frequency models) or p0 = 1/2 (binary models).
namespace {

struct TableModels {
  BitModel used[4];
  BitModel same[2]; // "as in the previous level" (frequency / binary models)
  FrequencyModel index{FrequencyModel::kMaxSymbols};
  FrequencyModel along{FrequencyModel::kMaxSymbols};  // steps along an alphabet
  FrequencyModel across{FrequencyModel::kMaxSymbols}; // steps from the previous level
};

/// Per model slot: the previous level's codes (empty: unused there).
using History = std::vector<std::vector<uint32_t>>;

void put_step(RangeEncoder &rc, FrequencyModel &m, uint32_t q, uint32_t ref) {
  const int32_t d = int32_t(q) - int32_t(ref);
  const uint32_t z = d >= 0 ? uint32_t(2 * d) : uint32_t(-2 * d - 1);
  if (z < 63) {
    rc.encode(m, int(z));
  } else {
    rc.encode(m, 63);
    rc.encode_bypass(q, 8);
  }
}

uint32_t get_step(RangeDecoder &rc, FrequencyModel &m, uint32_t ref) {
  const int z = rc.decode(m);
  if (z == 63)
    return rc.decode_bypass(8);
  const int64_t q = int64_t(ref) + ((z & 1) ? -(z + 1) / 2 : z / 2);
  return q < 0 ? 0xFFFFFFFFu : uint32_t(q);
}

std::vector<uint32_t> &slot_history(History &h, size_t &slot) {
  if (h.size() <= slot)
    h.resize(slot + 1);
  return h[slot++];
}

} // namespace

std::vector<uint8_t> write_tables(std::vector<Models> &models) {
  std::vector<uint8_t> out;
  RangeEncoder rc(&out);
  TableModels t;
  History history;
  for (Models &m : models) {
    size_t slot = 0;
    for_each_model(
        m,
        [&](FrequencyModel &f) {
          std::vector<uint32_t> &before = slot_history(history, slot);
          const size_t n = size_t(f.symbols());
          bool uniform = true; // an unused model: stored as one bit, no codes needed
          for (size_t s = 0; s < n && uniform; ++s)
            uniform = f.freq(int(s)) == 1;
          rc.encode_bit(t.used[before.empty() ? 0 : 2], uniform ? 0 : 1);
          if (uniform) {
            before.clear();
            return;
          }
          std::vector<uint32_t> q(n);
          for (size_t s = 0; s < n; ++s)
            q[s] = f.freq(int(s)) ? log_code(f.freq(int(s))) : 0;
          if (!before.empty()) {
            const bool same = q == before;
            rc.encode_bit(t.same[0], same ? 1 : 0);
            if (same)
              return;
            for (size_t s = 0; s < n; ++s)
              put_step(rc, t.across, q[s], before[s]);
          } else {
            size_t first = 0, last = n - 1;
            while (first < last && q[first] == 0)
              ++first;
            while (last > first && q[last] == 0)
              --last;
            rc.encode(t.index, int(first));
            rc.encode(t.index, int(last));
            uint32_t ref = 48;
            for (size_t s = first; s <= last; ++s) {
              put_step(rc, t.along, q[s], ref);
              ref = q[s];
            }
          }
          before = q;
        },
        [&](BitModel &b) {
          std::vector<uint32_t> &before = slot_history(history, slot);
          const uint32_t code = bit_code(b.p0);
          rc.encode_bit(t.used[before.empty() ? 1 : 3], code != kHalfCode ? 1 : 0);
          if (code == kHalfCode) {
            before.clear();
            return;
          }
          if (!before.empty()) {
            rc.encode_bit(t.same[1], code == before[0] ? 1 : 0);
            if (code == before[0])
              return;
          }
          put_step(rc, t.across, code, before.empty() ? 128 : before[0]);
          before.assign(1, code);
        });
  }
  rc.finish();
  return out;
}

std::vector<Models> read_tables(const uint8_t *data, size_t size, size_t levels, bool patch_rank,
                                const std::vector<AttributeCodeModels> &attributes) {
  std::vector<Models> models(levels);
  for (Models &m : models) {
    m.conn.patch_rank = patch_rank;
    m.attr = attributes;
  }
  RangeDecoder rc(data, size);
  TableModels t;
  History history;
  auto bad = [] {
    throw Error(Error::Kind::DamagedFile, "damaged .pomar file: invalid static model tables");
  };
  for (Models &m : models) {
    size_t slot = 0;
    for_each_model(
        m,
        [&](FrequencyModel &f) {
          std::vector<uint32_t> &before = slot_history(history, slot);
          const size_t n = size_t(f.symbols());
          uint16_t freq[FrequencyModel::kMaxSymbols];
          if (!rc.decode_bit(t.used[before.empty() ? 0 : 2])) {
            for (size_t s = 0; s < n; ++s)
              freq[s] = 1;
            before.clear();
          } else {
            uint32_t q[FrequencyModel::kMaxSymbols] = {}; // no allocation per model
            if (!before.empty() && rc.decode_bit(t.same[0])) {
              std::copy(before.begin(), before.end(), q);
            } else if (!before.empty()) {
              for (size_t s = 0; s < n; ++s)
                q[s] = get_step(rc, t.across, before[s]);
            } else {
              const size_t first = size_t(rc.decode(t.index)), last = size_t(rc.decode(t.index));
              if (first > last || last >= n)
                bad();
              uint32_t ref = 48;
              for (size_t s = first; s <= last; ++s)
                ref = q[s] = get_step(rc, t.along, ref);
            }
            for (size_t s = 0; s < n; ++s) {
              if (q[s] >= kLogCodes)
                bad();
              freq[s] = static_cast<uint16_t>(log_frequency(q[s]));
            }
            before.assign(q, q + n);
          }
          if (!f.freeze_with(freq))
            bad();
        },
        [&](BitModel &b) {
          std::vector<uint32_t> &before = slot_history(history, slot);
          uint32_t code = kHalfCode;
          if (rc.decode_bit(t.used[before.empty() ? 1 : 3])) {
            if (!before.empty() && rc.decode_bit(t.same[1]))
              code = before[0];
            else
              code = get_step(rc, t.across, before.empty() ? 128 : before[0]);
            if (code > 255)
              bad();
            before.assign(1, code);
          } else {
            before.clear();
          }
          b.p0 = bit_probability(code);
          b.frozen = true;
        });
  }
  if (rc.overrun())
    bad();
  return models;
}

} // namespace pomar
