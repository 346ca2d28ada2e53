// Adaptive range coder (byte-wise renormalisation, carry propagation through a cached
// byte) plus the probability models the codec uses. Encoder and decoder are mirror images:
// every function of RangeEncoder has a counterpart in RangeDecoder that consumes exactly
// the same state changes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pomar {

constexpr uint32_t kRangeTop = 1u << 24; // renormalise when range drops below this
constexpr int kBitModelBits = 12;        // binary probabilities are 12-bit fixed point
constexpr int kBitModelShift = 5;        // adaptation speed of binary models

/// Adaptive probability of a binary event (probability of 0, 12-bit fixed point).
/// A frozen model keeps its probability (static model of a clustered level).
struct BitModel {
  uint16_t p0 = 1u << (kBitModelBits - 1);
  bool frozen = false;
  void update(int bit) {
    if (frozen)
      return;
    if (bit)
      p0 -= p0 >> kBitModelShift;
    else
      p0 += ((1u << kBitModelBits) - p0) >> kBitModelShift;
  }
};

/// Adaptive frequency model over a small alphabet (<= kMaxSymbols). Counts grow by
/// kIncrement per coded symbol and are halved when the total exceeds kMaxTotal, so the
/// model follows slow drifts in the statistics. A frozen model is static: it keeps the
/// frequencies it was given (symbols of frequency 0 cannot be coded).
class FrequencyModel {
public:
  static constexpr int kMaxSymbols = 64;
  static constexpr uint32_t kIncrement = 24;
  static constexpr uint32_t kMaxTotal = 1u << 16;

  explicit FrequencyModel(int symbols = 2);
  int symbols() const { return n_; }
  uint32_t total() const { return total_; }
  uint32_t freq(int s) const { return freq_[s]; }
  uint32_t cumulative(int s) const { // sum of freq of symbols < s
    if (frozen_)
      return cum_[s];
    uint32_t c = 0;
    for (int i = 0; i < s; ++i)
      c += freq_[i];
    return c;
  }
  /// Find the symbol whose cumulative interval holds `target` (< total()); sets its
  /// cumulative start. (A frozen model starts at the symbol of the target's bucket and
  /// scans its cumulative table, whose last entry, the total, stops the scan.)
  int find(uint32_t target, uint32_t *start) const {
    int s = 0;
    if (frozen_) {
      s = bucket_[target >> bucket_shift_];
      while (cum_[s + 1] <= target)
        ++s;
      *start = cum_[s];
      return s;
    }
    uint32_t c = 0;
    while (s < n_ - 1 && c + freq_[s] <= target)
      c += freq_[s++];
    *start = c;
    return s;
  }
  void update(int s) {
    if (frozen_)
      return;
    // In 32 bits: a dominant symbol can be at 65,512 or more, and 16-bit arithmetic used
    // to wrap it to 0..23 (0 halved stays 0: a symbol of frequency 0 empties the coder's
    // range and the encoder never stopped writing; found on a 100k-vertex mesh).
    const uint32_t f = uint32_t(freq_[s]) + kIncrement;
    total_ += kIncrement;
    if (total_ <= kMaxTotal)
      freq_[s] = static_cast<uint16_t>(f); // f < total_ <= 2^16: fits
    else
      halve(s, f);
  }
  /// Make the model static with frequencies proportional to `counts` (total about
  /// 2^kStaticBits, every counted symbol at least 1); all-zero counts give a uniform model.
  void freeze_from_counts(const uint32_t *counts);
  /// Make the model static with exactly these frequencies; false if they are unusable.
  bool freeze_with(const uint16_t *freq);
  bool frozen() const { return frozen_; }
  static constexpr int kStaticBits = 12;

private:
  void halve(int s, uint32_t f); // update() past kMaxTotal: symbol s at f, all halved
  void freeze();                 // frozen_ set, cum_ from freq_
  int n_;
  uint32_t total_;
  bool frozen_ = false;
  uint16_t freq_[kMaxSymbols];
  uint32_t cum_[kMaxSymbols + 1] =
      {}; // a frozen model's: cum_[s] = cumulative(s), cum_[n_] = total_
  // A frozen model's buckets: the targets [b << bucket_shift_, (b + 1) << bucket_shift_)
  // start at or after symbol bucket_[b], the symbol of target b << bucket_shift_.
  static constexpr int kBucketBits = 6;
  uint8_t bucket_shift_ = 0;
  uint8_t bucket_[1 << kBucketBits] = {};
};

// The per-symbol functions of both coders are defined in this header: they run a few
// times per coded vertex and inlining them into the traversal saves the calls; the rare
// paths (a byte out, a stream refill, a model rescale) stay in range_coder.cpp.

// (Cache-line aligned: the encoder codes clusters into neighbouring coders on several
// threads at once.)
class alignas(64) RangeEncoder {
public:
  explicit RangeEncoder(std::vector<uint8_t> *out) : out_(out) {}
  void encode(uint32_t start, uint32_t size, uint32_t total) {
    const uint32_t r = range_ / total;
    low_ += static_cast<uint64_t>(r) * start;
    range_ = r * size;
    normalize();
  }
  void encode(FrequencyModel &m, int symbol) {
    encode(m.cumulative(symbol), m.freq(symbol), m.total());
    m.update(symbol);
  }
  void encode_bit(BitModel &m, int bit) {
    const uint32_t bound = (range_ >> kBitModelBits) * m.p0;
    if (bit) {
      low_ += bound;
      range_ -= bound;
    } else {
      range_ = bound;
    }
    m.update(bit);
    normalize();
  }
  void encode_bypass(uint32_t value, int nbits); // nbits <= 24, equiprobable bits
  /// value in [0, total), all equally likely; total <= 2^16.
  void encode_uniform(uint32_t value, uint32_t total) { encode(value, 1, total); }
  /// Write the final bytes (as few as disambiguate the stream: 1 to 4); the stream is
  /// complete after this.
  void finish();

private:
  void normalize() {
    while (range_ < kRangeTop) {
      range_ <<= 8;
      shift_low();
    }
  }
  void shift_low();
  std::vector<uint8_t> *out_;
  uint64_t low_ = 0;
  uint32_t range_ = 0xFFFFFFFFu;
  uint8_t cache_ = 0;
  uint64_t pending_ = 1; // bytes held back: cache_ plus a run of 0xFF bytes
  bool first_ = true;    // the very first cached byte is always 0 and is not written
};

/// Supplies more bytes of a stream on demand (random access reads only what the decoder
/// consumes). Returns how many bytes are available in total now; the data pointer given
/// to the decoder must stay valid for all of them.
class StreamRefill {
public:
  virtual ~StreamRefill() = default;
  virtual size_t more(size_t needed) = 0;
};

class RangeDecoder {
public:
  RangeDecoder() = default;
  RangeDecoder(const uint8_t *data, size_t size) { reset(data, size); }
  /// Decode data[0..size); with `refill`, size may grow as the decoder needs bytes.
  void reset(const uint8_t *data, size_t size, StreamRefill *refill = nullptr);
  size_t consumed() const { return pos_; }
  int decode(FrequencyModel &m) {
    const uint32_t r = range_ / m.total();
    uint32_t target = code_ / r;
    if (target >= m.total())
      target = m.total() - 1; // only reachable on corrupt data
    uint32_t start;
    const int s = m.find(target, &start);
    code_ -= r * start;
    range_ = r * m.freq(s);
    m.update(s);
    normalize();
    return s;
  }
  int decode_bit(BitModel &m) {
    const uint32_t bound = (range_ >> kBitModelBits) * m.p0;
    int bit;
    if (code_ < bound) {
      range_ = bound;
      bit = 0;
    } else {
      code_ -= bound;
      range_ -= bound;
      bit = 1;
    }
    m.update(bit);
    normalize();
    return bit;
  }
  uint32_t decode_bypass(int nbits);
  /// decode_bypass(1), inline (a residual's sign).
  uint32_t decode_bypass_bit() {
    range_ >>= 1;
    const uint32_t bit = code_ >= range_;
    if (bit)
      code_ -= range_;
    normalize();
    return bit;
  }
  uint32_t decode_uniform(uint32_t total); ///< mirror of RangeEncoder::encode_uniform
  /// True when the decoder has asked for more bytes than the stream holds by more than
  /// the final flush can explain: the stream is truncated or corrupt.
  bool overrun() const { return overrun_ > 8; }

private:
  uint8_t next_byte() { return pos_ < size_ ? data_[pos_++] : byte_past_end(); }
  uint8_t byte_past_end(); // a refill, or 0 counted as an overrun
  void normalize() {
    while (range_ < kRangeTop) {
      range_ <<= 8;
      code_ = (code_ << 8) | next_byte();
    }
  }
  const uint8_t *data_ = nullptr;
  size_t size_ = 0, pos_ = 0;
  StreamRefill *refill_ = nullptr;
  uint32_t range_ = 0xFFFFFFFFu, code_ = 0;
  size_t overrun_ = 0;
};

} // namespace pomar
