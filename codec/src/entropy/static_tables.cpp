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
double data_bits(const std::vector<uint32_t> &counts, const uint16_t *freq, int n) {
  double total = 0, bits = 0;
  for (int s = 0; s < n; ++s)
    total += freq[s];
  for (int s = 0; s < n; ++s) {
    if (!counts[size_t(s)])
      continue;
    if (!freq[s])
      return 1e300;
    bits += counts[size_t(s)] * std::log2(total / freq[s]);
  }
  return bits;
}

} // namespace

ModelAddresses::ModelAddresses(Models &m) {
  auto add = [&](const void *begin, size_t bytes) {
    const uintptr_t b = reinterpret_cast<uintptr_t>(begin);
    if (bytes)
      ranges_.push_back({b, b + bytes});
  };
  auto add_vector = [&](const std::vector<FrequencyModel> &v) {
    add(v.data(), v.size() * sizeof(FrequencyModel));
  };
  add(&m, sizeof(Models)); // the models held in the struct itself (sv, mantissa)
  add_vector(m.conn.se);
  add_vector(m.conn.faces);
  add_vector(m.conn.sl);
  for (const auto &kind : m.geom.magnitude)
    add_vector(kind);
  add(m.attr.data(), m.attr.size() * sizeof(AttributeCodeModels)); // their `top` models
  for (const AttributeCodeModels &a : m.attr)
    add_vector(a.classes);
  std::sort(ranges_.begin(), ranges_.end());
  if (ranges_.size() > 256)
    throw Error(Error::Kind::Internal, "internal encoder error: too many model arrays");
}

uint32_t ModelAddresses::name(const void *model) const {
  const uintptr_t p = reinterpret_cast<uintptr_t>(model);
  auto it = std::upper_bound(ranges_.begin(), ranges_.end(), std::make_pair(p, ~uintptr_t(0)));
  if (it == ranges_.begin() || p >= (it - 1)->second || p - (it - 1)->first > 0xFFFFFFu)
    throw Error(Error::Kind::Internal, "internal encoder error: a model outside its level");
  --it;
  return uint32_t(it - ranges_.begin()) << 24 | uint32_t(p - it->first);
}

void LevelFreezer::freeze(Models &m, const std::vector<SymbolRecorder> &recordings) {
  std::unordered_map<const void *, std::vector<uint32_t>> counts;
  for (const SymbolRecorder &r : recordings)
    for (const SymbolRecorder::Event &e : r.events) {
      if (e.kind() == 2)
        continue;
      void *model = r.model(e);
      auto &c = counts[model];
      const size_t n = e.kind() == 0 ? size_t(static_cast<FrequencyModel *>(model)->symbols()) : 2;
      c.resize(n, 0);
      ++c[e.value()];
    }
  // A model whose previous-level table codes this level's symbols nearly as well as its
  // own would (within what storing its own costs) reuses it.
  std::vector<std::vector<uint16_t>> &previous = previous_;
  {
    size_t slot = 0;
    auto prev_of = [&]() -> std::vector<uint16_t> & {
      if (previous.size() <= slot)
        previous.resize(slot + 1);
      return previous[slot++];
    };
    for_each_model(
        m,
        [&](FrequencyModel &f) {
          std::vector<uint16_t> &before = prev_of();
          const int n = f.symbols();
          auto it = counts.find(&f);
          std::vector<uint32_t> c(size_t(n), 0);
          if (it != counts.end())
            c = it->second;
          f.freeze_from_counts(c.data());
          if (it == counts.end()) {
            before.clear(); // unused: stays uniform, stored as such
            return;
          }
          uint16_t q[FrequencyModel::kMaxSymbols];
          for (int i = 0; i < n; ++i)
            q[i] = static_cast<uint16_t>(f.freq(i) ? log_frequency(log_code(f.freq(i))) : 0);
          if (!before.empty()) {
            int used = 0;
            for (int i = 0; i < n; ++i)
              used += q[i] != 0;
            const double own = data_bits(c, q, n) + 1.5 * used + 2;
            if (data_bits(c, before.data(), n) <= own) {
              f.freeze_with(before.data());
              return;
            }
          }
          f.freeze_with(q);
          before.assign(q, q + n);
        },
        [&](BitModel &b) {
          std::vector<uint16_t> &before = prev_of();
          auto it = counts.find(&b);
          uint32_t p0 = 1u << (kBitModelBits - 1);
          if (it != counts.end()) {
            const uint64_t zeros = it->second[0], all = zeros + it->second[1];
            p0 = static_cast<uint32_t>((zeros << kBitModelBits) / all);
          }
          p0 = std::min<uint32_t>(p0 >> 4, 255) * 16 + 8; // the 8-bit code the table keeps
          if (it != counts.end() && !before.empty()) {
            auto bits = [&](double p) {
              return -(it->second[0] * std::log2(p / 4096.0) +
                       it->second[1] * std::log2(1 - p / 4096.0));
            };
            if (bits(before[0]) <= bits(p0) + 6)
              p0 = before[0];
          }
          b.p0 = static_cast<uint16_t>(p0);
          b.frozen = true;
          if (it == counts.end())
            before.clear();
          else
            before.assign(1, b.p0);
        });
  }
}

void code_recording(const SymbolRecorder &r, RangeEncoder &rc, double *bits) {
  for (const SymbolRecorder::Event &e : r.events) {
    switch (e.kind()) {
    case 0: {
      auto &m = *static_cast<FrequencyModel *>(r.model(e));
      bits[e.stream()] += cost_bits(m, int(e.value()));
      rc.encode(m, int(e.value()));
      break;
    }
    case 1: {
      auto &m = *static_cast<BitModel *>(r.model(e));
      bits[e.stream()] += cost_bits(m, int(e.value()));
      rc.encode_bit(m, int(e.value()));
      break;
    }
    default:
      bits[e.stream()] += e.nbits();
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

uint32_t bit_code(uint32_t p0) { return std::min<uint32_t>(p0 >> 4, 255); }
uint16_t bit_probability(uint32_t code) { return static_cast<uint16_t>(code * 16 + 8); }
const uint32_t kHalfCode = bit_code(1u << (kBitModelBits - 1));

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

std::vector<Models> read_tables(const uint8_t *data, size_t size, size_t levels,
                                const std::vector<AttributeCodeModels> &attributes) {
  std::vector<Models> models(levels);
  for (Models &m : models)
    m.attr = attributes;
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
