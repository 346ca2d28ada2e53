// Probability models of the POMAR symbols and how values are binarised onto them.
// One Models object lives for a whole decode (models adapt across levels).
//
//  s_v  split count of a vertex (0/1): binary model; context: faces of the vertex already
//       held by this level's patches, split neighbours (see sv_context)
//  s_e  rank of v_ref among v_to's edges (longest first): 17-symbol model (16 = escape)
//       per valence of v_to
//  s_l, s_r  steps from v_ref to v_l / v_r, coded as their sum (the number of faces
//       that move to v_from; context: valence of v_to, open/closed fan), then s_l
//       (context: that sum); s_r follows.
//  rank (version 5, in place of s_e and s_l): the rank of the true patch placement among
//       those possible for s_l + s_r (refine/patch_rank.h), context: that sum and v_to's
//       valence (rank_context).
//  geometry residual components (t1,t2 share a model; n has its own), each coded as a
//  magnitude class (bit length) with a context from the local edge length, then sign and
//  mantissa bits (the top one modelled, the rest equiprobable).
#pragma once

#include <cstdint>
#include <type_traits>
#include <vector>

#include "entropy/range_coder.h"
#include "geometry/normal_predictor.h"

namespace pomar {

constexpr int kSvContexts = 48;      // 12 (held faces x split neighbours) x 4 valence classes
constexpr int kSmallSymbols = 16;    // values 0..15 coded directly, 16 = escape
constexpr int kValenceContexts = 16; // ring sizes 0..14, 15+
constexpr int kSlContexts = 12;
constexpr int kRankContexts = 40;     // 5 patch sizes x 8 fan classes
constexpr int kGeomContexts = 26;     // edge-length classes (octaves)
constexpr int kMagnitudeSymbols = 40; // bit length of a residual component (<= 39)

inline int bit_length(uint64_t x) { return x ? 64 - __builtin_clzll(x) : 0; }

/// Ideal code length in bits of coding `s` with model `m` in its current state (for the
/// encoder's per-symbol statistics; never part of the bitstream).
double cost_bits(const FrequencyModel &m, int s);
double cost_bits(const BitModel &m, int bit);

struct ConnectivityModels {
  /// Version 5: the patch is coded as s_l + s_r then a rank (`rank`); versions 1-4: s_e,
  /// s_l + s_r, s_l (`se`, `sl`). Set once per file; for_each_model visits the models the
  /// file's version uses only.
  bool patch_rank = false;
  BitModel sv[kSvContexts];
  std::vector<FrequencyModel> se{kValenceContexts, FrequencyModel(kSmallSymbols + 1)};
  std::vector<FrequencyModel> faces{2 * kValenceContexts, FrequencyModel(kSmallSymbols + 1)};
  std::vector<FrequencyModel> sl{kSlContexts, FrequencyModel(kSmallSymbols + 1)};
  std::vector<FrequencyModel> rank{kRankContexts, FrequencyModel(kSmallSymbols + 1)};
};

/// Contexts of the split symbols, from v_to's ring (known to the decoder).
inline int valence_context(uint32_t ring_size) {
  return static_cast<int>(ring_size < kValenceContexts ? ring_size : kValenceContexts - 1);
}
inline int faces_context(uint32_t ring_size, bool closed) {
  return valence_context(ring_size) * 2 + (closed ? 1 : 0);
}
inline int sl_context(uint32_t faces) {
  return static_cast<int>(faces < kSlContexts ? faces : kSlContexts - 1);
}
/// Context of the patch rank: s_l + s_r (1, 2, 3, 4, 5+) and the fan (open; closed of
/// valence <= 4, 5, 6, 7, 8, 9, 10+).
inline int rank_context(uint32_t faces, uint32_t ring_size, bool closed) {
  const uint32_t f = faces < 1 ? 0 : (faces > 5 ? 4 : faces - 1);
  const uint32_t fan = !closed ? 0 : ring_size <= 4 ? 1 : ring_size >= 10 ? 7 : ring_size - 3;
  return static_cast<int>(f * 8 + fan);
}

struct GeometryModels {
  // [0] tangential (t1,t2), [1] normal
  std::vector<FrequencyModel> magnitude[2] = {
      std::vector<FrequencyModel>(kGeomContexts, FrequencyModel(kMagnitudeSymbols)),
      std::vector<FrequencyModel>(kGeomContexts, FrequencyModel(kMagnitudeSymbols))};
  BitModel mantissa[2][kMagnitudeSymbols];
};

/// Residual models of one integer code of a per-vertex attribute (attributes/): a magnitude
/// class model per context (the bit length of the previous code's residual of the same
/// attribute, 0 for its first code) and the modelled bit under the leading one.
constexpr int kAttributeContexts = 6;
struct AttributeCodeModels {
  std::vector<FrequencyModel> classes =
      std::vector<FrequencyModel>(kAttributeContexts, FrequencyModel(kMagnitudeSymbols));
  BitModel top[kMagnitudeSymbols];
  bool first = true; // the first code of its attribute (context 0 always)
};

struct Models {
  ConnectivityModels conn;
  GeometryModels geom;
  /// The level's normal predictor (section GEOP; not a probability model: the static
  /// tables do not hold it, for_each_model does not visit it).
  NormalPredictor normal;
  /// One per attribute code of a vertex (empty for files without attributes).
  std::vector<AttributeCodeModels> attr;
};

/// Visit every model of a set in a fixed order (the order of the static tables).
template <class OnFrequency, class OnBit>
void for_each_model(Models &m, OnFrequency &&on_frequency, OnBit &&on_bit) {
  for (BitModel &b : m.conn.sv)
    on_bit(b);
  if (m.conn.patch_rank) {
    for (FrequencyModel &f : m.conn.faces)
      on_frequency(f);
    for (FrequencyModel &f : m.conn.rank)
      on_frequency(f);
  } else {
    for (FrequencyModel &f : m.conn.se)
      on_frequency(f);
    for (FrequencyModel &f : m.conn.faces)
      on_frequency(f);
    for (FrequencyModel &f : m.conn.sl)
      on_frequency(f);
  }
  for (auto &kind : m.geom.magnitude)
    for (FrequencyModel &f : kind)
      on_frequency(f);
  for (auto &kind : m.geom.mantissa)
    for (BitModel &b : kind)
      on_bit(b);
  for (AttributeCodeModels &a : m.attr) {
    for (FrequencyModel &f : a.classes)
      on_frequency(f);
    for (BitModel &b : a.top)
      on_bit(b);
  }
}

/// Context of an attribute code from the previous code's residual of the same attribute.
inline int attribute_context(const AttributeCodeModels &m, const int64_t *residual, uint32_t k) {
  if (m.first || k == 0)
    return 0;
  const int64_t r = residual[k - 1];
  const int n = bit_length(static_cast<uint64_t>(r < 0 ? -r : r));
  return n < kAttributeContexts - 1 ? n : kAttributeContexts - 1;
}

/// Context of a geometry residual: the bit length of the squared v_to-v_ref length / 2,
/// i.e. roughly log2 of the local edge length.
inline int geometry_context(int64_t edge_length2) {
  const int c = bit_length(static_cast<uint64_t>(edge_length2)) / 2;
  return c < kGeomContexts ? c : kGeomContexts - 1;
}

// ---------------------------------------------------------------- encoding side

/// Whether an encoder wants the ideal code lengths of what it is given. A symbol recorder
/// (Encoder::kRecorder) does not: its models are not frozen yet, so the lengths would mean
/// nothing; code_recording measures them when it codes the recording.
template <class Encoder, class = void> struct WantsBits : std::true_type {};
template <class Encoder>
struct WantsBits<Encoder, std::void_t<decltype(Encoder::kRecorder)>> : std::false_type {};

/// cost_bits(m, s) for an encoder that wants it, else 0 (no log2 per recorded symbol).
template <class Encoder, class Model> double bits_for(const Model &m, int s) {
  if constexpr (WantsBits<Encoder>::value)
    return cost_bits(m, s);
  else
    return 0.0;
}

/// `nbits` (0..48) raw, equiprobable bits of `value` (which has no higher bits set): the
/// range coder's bypass takes at most 24 at a time. get_raw reads them back.
template <class Encoder> void put_raw(Encoder &rc, uint64_t value, int nbits) {
  if (nbits > 24) {
    rc.encode_bypass(static_cast<uint32_t>(value >> 24), nbits - 24);
    rc.encode_bypass(static_cast<uint32_t>(value & 0xFFFFFF), 24);
  } else if (nbits > 0) {
    rc.encode_bypass(static_cast<uint32_t>(value), nbits);
  }
}

inline uint64_t get_raw(RangeDecoder &rc, int nbits) {
  if (nbits > 24) {
    const uint64_t high = rc.decode_bypass(nbits - 24);
    return (high << 24) | rc.decode_bypass(24);
  }
  return nbits > 0 ? rc.decode_bypass(nbits) : 0;
}

/// Each put_* returns the ideal number of bits it spent (statistics only; 0 for the models
/// of a recorder, see WantsBits).
template <class Encoder> double put_small(Encoder &rc, FrequencyModel &m, uint32_t v) {
  double bits;
  if (v < kSmallSymbols) {
    bits = bits_for<Encoder>(m, static_cast<int>(v));
    rc.encode(m, static_cast<int>(v));
    return bits;
  }
  bits = bits_for<Encoder>(m, kSmallSymbols);
  rc.encode(m, kSmallSymbols);
  const uint32_t x = v - kSmallSymbols + 1; // >= 1
  const int n = bit_length(x);
  bits += 6 + n;
  rc.encode_bypass(static_cast<uint32_t>(n), 6);
  put_raw(rc, x, n);
  return bits;
}

/// A signed value as its magnitude class (bit length, model `classes`), a sign bit, the bit
/// under the leading one (modelled by top[class] if `top` is given) and the rest raw.
template <class Encoder>
double put_signed(Encoder &rc, FrequencyModel &classes, BitModel *top, int64_t v) {
  const uint64_t a = static_cast<uint64_t>(v < 0 ? -v : v);
  const int n = bit_length(a);
  double bits = bits_for<Encoder>(classes, n);
  rc.encode(classes, n);
  if (n == 0)
    return bits;
  rc.encode_bypass(v < 0 ? 1 : 0, 1);
  bits += 1;
  int rest = n - 1;
  if (top && n >= 2) {
    const int bit = static_cast<int>((a >> (n - 2)) & 1);
    bits += bits_for<Encoder>(top[n], bit);
    rc.encode_bit(top[n], bit);
    --rest;
  }
  bits += rest;
  put_raw(rc, a & ((uint64_t(1) << rest) - 1), rest);
  return bits;
}

template <class Encoder>
double put_residual(Encoder &rc, GeometryModels &g, int kind, int ctx, int64_t v) {
  return put_signed(rc, g.magnitude[kind][ctx], g.mantissa[kind], v);
}

// ---------------------------------------------------------------- decoding side

inline uint32_t get_small(RangeDecoder &rc, FrequencyModel &m) {
  const int s = rc.decode(m);
  if (s < kSmallSymbols)
    return static_cast<uint32_t>(s);
  const int n = static_cast<int>(rc.decode_bypass(6));
  if (n < 1 || n > 32)
    return 0xFFFFFFFFu; // corrupt; callers range-check every symbol
  const uint64_t v = get_raw(rc, n) + kSmallSymbols - 1;
  return v > 0xFFFFFFFEu ? 0xFFFFFFFFu : static_cast<uint32_t>(v);
}

/// (Always inlined: it runs three times per split, and its callers' loops (the position's
/// components, the attribute codes) hold one copy each.)
[[gnu::always_inline]] inline int64_t get_signed(RangeDecoder &rc, FrequencyModel &classes,
                                                 BitModel *top) {
  const int n = rc.decode(classes);
  if (n == 0)
    return 0;
  const bool negative = rc.decode_bypass_bit() != 0;
  uint64_t a = 1;
  int rest = n - 1;
  if (top && n >= 2) {
    a = (a << 1) | static_cast<uint64_t>(rc.decode_bit(top[n]));
    --rest;
  }
  a = (a << rest) | get_raw(rc, rest);
  return negative ? -static_cast<int64_t>(a) : static_cast<int64_t>(a);
}

inline int64_t get_residual(RangeDecoder &rc, GeometryModels &g, int kind, int ctx) {
  return get_signed(rc, g.magnitude[kind][ctx], g.mantissa[kind]);
}

} // namespace pomar
