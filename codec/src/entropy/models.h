// Probability models of the POMAR symbols and how values are binarised onto them.
// One Models object lives for a whole decode (models adapt across levels).
//
//  s_v  split count of a vertex (0/1)  binary model, context: split neighbours & patch flag
//  s_e  rank of v_ref among v_to's edges (longest first)   17-symbol model (16 = escape)
//  s_l  steps from v_ref to v_l                            17-symbol model
//  s_r  steps from v_ref to v_r                            17-symbol model per min(s_l,8)
//  geometry residual components (t1,t2 share a model; n has its own), each coded as a
//  magnitude class (bit length) with a context from the local edge length, then sign and
//  mantissa bits (the top one modelled, the rest equiprobable).
#pragma once

#include <cstdint>
#include <vector>

#include "entropy/range_coder.h"

namespace pomar {

constexpr int kSvContexts = 6;
constexpr int kSmallSymbols = 16;         // values 0..15 coded directly, 16 = escape
constexpr int kSrContexts = 9;
constexpr int kGeomContexts = 26;         // edge-length classes
constexpr int kMagnitudeSymbols = 40;     // bit length of a residual component (<= 39)

inline int bit_length(uint64_t x) { return x ? 64 - __builtin_clzll(x) : 0; }

struct ConnectivityModels {
  BitModel sv[kSvContexts];
  FrequencyModel se{kSmallSymbols + 1};
  FrequencyModel sl{kSmallSymbols + 1};
  std::vector<FrequencyModel> sr{kSrContexts, FrequencyModel(kSmallSymbols + 1)};
};

struct GeometryModels {
  // [0] tangential (t1,t2), [1] normal
  std::vector<FrequencyModel> magnitude[2] = {
      std::vector<FrequencyModel>(kGeomContexts, FrequencyModel(kMagnitudeSymbols)),
      std::vector<FrequencyModel>(kGeomContexts, FrequencyModel(kMagnitudeSymbols))};
  BitModel mantissa[2][kMagnitudeSymbols];
};

struct Models {
  ConnectivityModels conn;
  GeometryModels geom;
};

/// Context of a geometry residual: the bit length of the squared v_to-v_ref length / 2,
/// i.e. roughly log2 of the local edge length.
inline int geometry_context(int64_t edge_length2) {
  const int c = bit_length(static_cast<uint64_t>(edge_length2)) / 2;
  return c < kGeomContexts ? c : kGeomContexts - 1;
}

// ---------------------------------------------------------------- encoding side

inline void put_small(RangeEncoder &rc, FrequencyModel &m, uint32_t v) {
  if (v < kSmallSymbols) {
    rc.encode(m, static_cast<int>(v));
    return;
  }
  rc.encode(m, kSmallSymbols);
  const uint32_t x = v - kSmallSymbols + 1; // >= 1
  const int n = bit_length(x);
  rc.encode_bypass(static_cast<uint32_t>(n), 6);
  if (n > 24) {
    rc.encode_bypass(x >> 24, n - 24);
    rc.encode_bypass(x & 0xFFFFFF, 24);
  } else {
    rc.encode_bypass(x, n);
  }
}

inline void put_residual(RangeEncoder &rc, GeometryModels &g, int kind, int ctx, int64_t v) {
  const uint64_t a = static_cast<uint64_t>(v < 0 ? -v : v);
  const int n = bit_length(a);
  rc.encode(g.magnitude[kind][ctx], n);
  if (n == 0)
    return;
  rc.encode_bypass(v < 0 ? 1 : 0, 1);
  if (n >= 2) {
    rc.encode_bit(g.mantissa[kind][n], static_cast<int>((a >> (n - 2)) & 1));
    const int rest = n - 2;
    const uint64_t bits = a & ((uint64_t(1) << rest) - 1);
    if (rest > 24) {
      rc.encode_bypass(static_cast<uint32_t>(bits >> 24), rest - 24);
      rc.encode_bypass(static_cast<uint32_t>(bits & 0xFFFFFF), 24);
    } else if (rest > 0) {
      rc.encode_bypass(static_cast<uint32_t>(bits), rest);
    }
  }
}

// ---------------------------------------------------------------- decoding side

inline uint32_t get_small(RangeDecoder &rc, FrequencyModel &m) {
  const int s = rc.decode(m);
  if (s < kSmallSymbols)
    return static_cast<uint32_t>(s);
  const int n = static_cast<int>(rc.decode_bypass(6));
  if (n < 1 || n > 32)
    return 0xFFFFFFFFu; // corrupt; callers range-check every symbol
  uint32_t x;
  if (n > 24) {
    x = rc.decode_bypass(n - 24) << 24;
    x |= rc.decode_bypass(24);
  } else {
    x = rc.decode_bypass(n);
  }
  const uint64_t v = uint64_t(x) + kSmallSymbols - 1;
  return v > 0xFFFFFFFEu ? 0xFFFFFFFFu : static_cast<uint32_t>(v);
}

inline int64_t get_residual(RangeDecoder &rc, GeometryModels &g, int kind, int ctx) {
  const int n = rc.decode(g.magnitude[kind][ctx]);
  if (n == 0)
    return 0;
  const bool negative = rc.decode_bypass(1) != 0;
  uint64_t a = 1;
  if (n >= 2) {
    a = (a << 1) | static_cast<uint64_t>(rc.decode_bit(g.mantissa[kind][n]));
    const int rest = n - 2;
    if (rest > 24) {
      a = (a << (rest - 24)) | rc.decode_bypass(rest - 24);
      a = (a << 24) | rc.decode_bypass(24);
    } else if (rest > 0) {
      a = (a << rest) | rc.decode_bypass(rest);
    }
  }
  return negative ? -static_cast<int64_t>(a) : static_cast<int64_t>(a);
}

} // namespace pomar
