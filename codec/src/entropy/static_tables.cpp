#include "entropy/static_tables.h"

#include <cstdlib>

#include "pomar/pomar.h"

namespace pomar {
namespace {

// Frequencies are stored on a logarithmic scale with 3 mantissa bits (at most 6% off):
// code q in 1..103 stands for ((8 + q%8) << (q/8)) >> 3; 0 is "never seen".
constexpr int kLogCodes = 104;

uint32_t log_frequency(uint32_t q) { return q == 0 ? 0 : ((8u + (q & 7)) << (q >> 3)) >> 3; }

uint32_t log_code(uint32_t f) { // the code whose frequency is nearest to f (f >= 1)
  uint32_t best = 1;
  for (uint32_t q = 1; q < kLogCodes; ++q)
    if (std::abs(int64_t(log_frequency(q)) - int64_t(f)) <
        std::abs(int64_t(log_frequency(best)) - int64_t(f)))
      best = q;
  return best;
}

} // namespace

void freeze_on_recordings(std::vector<Models> &models,
                          const std::vector<SymbolRecorder> &recordings) {
  std::unordered_map<const void *, std::vector<uint32_t>> counts;
  for (const SymbolRecorder &r : recordings)
    for (const SymbolRecorder::Event &e : r.events) {
      if (e.kind == 2)
        continue;
      auto &c = counts[e.model];
      const size_t n = e.kind == 0 ? size_t(static_cast<FrequencyModel *>(e.model)->symbols()) : 2;
      c.resize(n, 0);
      ++c[e.value];
    }
  for (Models &m : models)
    for_each_model(
        m,
        [&](FrequencyModel &f) {
          std::vector<uint32_t> c(size_t(f.symbols()), 0);
          auto it = counts.find(&f);
          if (it != counts.end())
            c = it->second;
          f.freeze_from_counts(c.data());
          if (it == counts.end())
            return; // unused: stays uniform, stored as such
          uint16_t q[FrequencyModel::kMaxSymbols];
          for (int i = 0; i < f.symbols(); ++i)
            q[i] = static_cast<uint16_t>(f.freq(i) ? log_frequency(log_code(f.freq(i))) : 0);
          f.freeze_with(q);
        },
        [&](BitModel &b) {
          auto it = counts.find(&b);
          uint32_t p0 = 1u << (kBitModelBits - 1);
          if (it != counts.end()) {
            const uint64_t zeros = it->second[0], all = zeros + it->second[1];
            p0 = static_cast<uint32_t>((zeros << kBitModelBits) / all);
            p0 = std::min(std::max(p0, 1u), (1u << kBitModelBits) - 1);
          }
          b.p0 = static_cast<uint16_t>(p0);
          b.frozen = true;
        });
}

std::vector<uint8_t> code_recording(const SymbolRecorder &r, double bits[2]) {
  std::vector<uint8_t> out;
  RangeEncoder rc(&out);
  for (const SymbolRecorder::Event &e : r.events) {
    switch (e.kind) {
    case 0: {
      auto &m = *static_cast<FrequencyModel *>(e.model);
      bits[e.stream] += cost_bits(m, int(e.value));
      rc.encode(m, int(e.value));
      break;
    }
    case 1: {
      auto &m = *static_cast<BitModel *>(e.model);
      bits[e.stream] += cost_bits(m, int(e.value));
      rc.encode_bit(m, int(e.value));
      break;
    }
    default:
      bits[e.stream] += e.nbits;
      rc.encode_bypass(e.value, e.nbits);
    }
  }
  rc.finish();
  return out;
}

// Table stream: for each model in for_each_model order, a "used" bit (adaptive); a used
// frequency model gives its first and last non-zero symbols and the frequencies between
// (adaptive Elias-gamma); a used binary model gives its 12-bit probability.
namespace {

struct TableCoder {
  BitModel used[2];
  FrequencyModel index{FrequencyModel::kMaxSymbols};
  FrequencyModel delta{FrequencyModel::kMaxSymbols}; // zigzag step between log codes
};

// Log codes of a model's symbols change slowly from one symbol to the next: code the
// zigzagged step (escape 63 + 7 raw bits for big jumps).
void put_code(RangeEncoder &rc, TableCoder &t, uint32_t q, uint32_t &prev) {
  const int32_t d = int32_t(q) - int32_t(prev);
  const uint32_t z = d >= 0 ? uint32_t(2 * d) : uint32_t(-2 * d - 1);
  if (z < 63) {
    rc.encode(t.delta, int(z));
  } else {
    rc.encode(t.delta, 63);
    rc.encode_bypass(q, 7);
  }
  prev = q;
}

uint32_t get_code(RangeDecoder &rc, TableCoder &t, uint32_t &prev) {
  const int z = rc.decode(t.delta);
  uint32_t q;
  if (z < 63)
    q = uint32_t(int32_t(prev) + ((z & 1) ? -(z + 1) / 2 : z / 2));
  else
    q = rc.decode_bypass(7);
  prev = q;
  return q;
}

} // namespace

std::vector<uint8_t> write_tables(std::vector<Models> &models) {
  std::vector<uint8_t> out;
  RangeEncoder rc(&out);
  TableCoder t;
  for (Models &m : models)
    for_each_model(
        m,
        [&](FrequencyModel &f) {
          int first = 0, last = f.symbols() - 1;
          while (first < f.symbols() && f.freq(first) == 0)
            ++first;
          while (last >= 0 && f.freq(last) == 0)
            --last;
          // A model nobody used was frozen uniform: all ones.
          bool uniform = true;
          for (int s = 0; s < f.symbols(); ++s)
            uniform = uniform && f.freq(s) == 1;
          rc.encode_bit(t.used[0], uniform ? 0 : 1);
          if (uniform)
            return;
          rc.encode(t.index, first);
          rc.encode(t.index, last);
          uint32_t prev = 48;
          for (int s = first; s <= last; ++s)
            put_code(rc, t, f.freq(s) ? log_code(f.freq(s)) : 0, prev);
        },
        [&](BitModel &b) {
          const bool used = b.p0 != (1u << (kBitModelBits - 1));
          rc.encode_bit(t.used[1], used ? 1 : 0);
          if (used)
            rc.encode_bypass(b.p0, kBitModelBits);
        });
  rc.finish();
  return out;
}

std::vector<Models> read_tables(const uint8_t *data, size_t size, size_t levels) {
  std::vector<Models> models(levels);
  RangeDecoder rc(data, size);
  TableCoder t;
  auto bad = [] { throw Error("damaged .pomar file: invalid static model tables"); };
  for (Models &m : models)
    for_each_model(
        m,
        [&](FrequencyModel &f) {
          uint16_t freq[FrequencyModel::kMaxSymbols];
          for (int s = 0; s < f.symbols(); ++s)
            freq[s] = 1;
          if (rc.decode_bit(t.used[0])) {
            const int first = rc.decode(t.index), last = rc.decode(t.index);
            if (first > last || last >= f.symbols())
              bad();
            for (int s = 0; s < f.symbols(); ++s)
              freq[s] = 0;
            uint32_t prev = 48;
            for (int s = first; s <= last; ++s) {
              const uint32_t q = get_code(rc, t, prev);
              if (q >= kLogCodes)
                bad();
              freq[s] = static_cast<uint16_t>(log_frequency(q));
            }
          }
          if (!f.freeze_with(freq))
            bad();
        },
        [&](BitModel &b) {
          b.p0 = 1u << (kBitModelBits - 1);
          if (rc.decode_bit(t.used[1])) {
            const uint32_t p = rc.decode_bypass(kBitModelBits);
            if (p == 0)
              bad();
            b.p0 = static_cast<uint16_t>(p);
          }
          b.frozen = true;
        });
  if (rc.overrun())
    bad();
  return models;
}

} // namespace pomar
