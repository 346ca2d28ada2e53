#include "entropy/static_tables.h"

#include "pomar/pomar.h"

namespace pomar {

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
  FrequencyModel length{16};
};

void put_gamma(RangeEncoder &rc, FrequencyModel &length, uint32_t v) { // v < 2^15
  const int n = bit_length(v);
  rc.encode(length, n);
  if (n > 1)
    rc.encode_bypass(v & ((1u << (n - 1)) - 1), n - 1);
}

uint32_t get_gamma(RangeDecoder &rc, FrequencyModel &length) {
  const int n = rc.decode(length);
  uint32_t v = n == 0 ? 0 : 1;
  if (n > 1)
    v = (v << (n - 1)) | rc.decode_bypass(n - 1);
  return v;
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
          for (int s = first; s <= last; ++s)
            put_gamma(rc, t.length, f.freq(s));
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
            for (int s = first; s <= last; ++s) {
              const uint32_t v = get_gamma(rc, t.length);
              if (v > 0xFFFF)
                bad();
              freq[s] = static_cast<uint16_t>(v);
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
