#include "entropy/range_coder.h"

#include <cassert>
#include <cmath>

#include "entropy/models.h"

namespace pomar {

// ---------------------------------------------------------------- FrequencyModel

FrequencyModel::FrequencyModel(int symbols) : n_(symbols), total_(0) {
  assert(symbols >= 2 && symbols <= kMaxSymbols);
  for (int i = 0; i < n_; ++i)
    freq_[i] = 1;
  total_ = static_cast<uint32_t>(n_);
}

void FrequencyModel::freeze_from_counts(const uint32_t *counts) {
  uint64_t sum = 0;
  for (int i = 0; i < n_; ++i)
    sum += counts[i];
  total_ = 0;
  for (int i = 0; i < n_; ++i) {
    uint32_t f = 1; // uniform when nothing was counted
    if (sum) {
      f = static_cast<uint32_t>((uint64_t(counts[i]) << kStaticBits) / sum);
      if (counts[i] && f == 0)
        f = 1;
    }
    freq_[i] = static_cast<uint16_t>(f);
    total_ += f;
  }
  freeze();
}

void FrequencyModel::freeze() {
  frozen_ = true;
  cum_[0] = 0;
  for (int i = 0; i < n_; ++i)
    cum_[i + 1] = cum_[i] + freq_[i];
  // The targets are below total_ <= 2^16: 2^kBucketBits buckets of 2^bucket_shift_.
  int shift = 0;
  while ((total_ - 1) >> shift >= (1u << kBucketBits))
    ++shift;
  bucket_shift_ = static_cast<uint8_t>(shift);
  int s = 0;
  for (uint32_t b = 0; b < (1u << kBucketBits); ++b) {
    const uint32_t target = b << shift;
    while (s < n_ - 1 && cum_[s + 1] <= target)
      ++s;
    bucket_[b] = static_cast<uint8_t>(s);
  }
}

bool FrequencyModel::freeze_with(const uint16_t *freq) {
  uint32_t total = 0;
  for (int i = 0; i < n_; ++i)
    total += freq[i];
  if (total == 0 || total > kMaxTotal)
    return false;
  for (int i = 0; i < n_; ++i)
    freq_[i] = freq[i];
  total_ = total;
  freeze();
  return true;
}

void FrequencyModel::halve(int s, uint32_t f) {
  total_ = 0;
  for (int i = 0; i < n_; ++i) {
    const uint32_t fi = i == s ? f : freq_[i];
    freq_[i] = static_cast<uint16_t>((fi + 1) >> 1);
    total_ += freq_[i];
  }
}

double cost_bits(const FrequencyModel &m, int s) {
  return std::log2(double(m.total()) / double(m.freq(s)));
}

double cost_bits(const BitModel &m, int bit) {
  const double p0 = double(m.p0) / double(1u << kBitModelBits);
  return -std::log2(bit ? 1.0 - p0 : p0);
}

// ---------------------------------------------------------------- RangeEncoder

void RangeEncoder::shift_low() {
  // Bytes are held back while they could still be changed by a carry: cache_ plus a run
  // of 0xFF bytes. Once the top of low_ is known, they are written (incremented on carry).
  if (static_cast<uint32_t>(low_) < 0xFF000000u || (low_ >> 32) != 0) {
    const uint8_t carry = static_cast<uint8_t>(low_ >> 32);
    uint8_t byte = cache_;
    do {
      if (!first_)
        out_->push_back(static_cast<uint8_t>(byte + carry));
      first_ = false;
      byte = 0xFF;
    } while (--pending_ != 0);
    cache_ = static_cast<uint8_t>(low_ >> 24);
  }
  ++pending_;
  low_ = (low_ & 0x00FFFFFFu) << 8;
}

void RangeEncoder::encode_bypass(uint32_t value, int nbits) {
  for (int i = nbits - 1; i >= 0; --i) {
    range_ >>= 1;
    if ((value >> i) & 1)
      low_ += range_;
    normalize();
  }
}

void RangeEncoder::finish() {
  // Emit as few bytes as possible: pick the value in [low, low + range) with the most
  // trailing zero bytes; the decoder reads zeros past the end of a stream.
  for (int keep = 1; keep <= 4; ++keep) {
    const uint64_t mask = (uint64_t(1) << (32 - 8 * keep)) - 1;
    const uint64_t value = (low_ + mask) & ~mask;
    if (value < low_ + range_) {
      low_ = value;
      for (int i = 0; i <= keep; ++i)
        shift_low();
      return;
    }
  }
  for (int i = 0; i < 5; ++i) // unreachable: keep = 4 always fits (range >= 2^24)
    shift_low();
}

// ---------------------------------------------------------------- RangeDecoder

void RangeDecoder::reset(const uint8_t *data, size_t size, StreamRefill *refill) {
  data_ = data;
  size_ = size;
  refill_ = refill;
  pos_ = 0;
  overrun_ = 0;
  range_ = 0xFFFFFFFFu;
  code_ = 0;
  for (int i = 0; i < 4; ++i)
    code_ = (code_ << 8) | next_byte();
}

uint8_t RangeDecoder::byte_past_end() {
  if (refill_) {
    size_ = refill_->more(pos_ + 1);
    if (pos_ < size_)
      return data_[pos_++];
  }
  ++overrun_;
  return 0;
}

uint32_t RangeDecoder::decode_uniform(uint32_t total) {
  const uint32_t r = range_ / total;
  uint32_t v = code_ / r;
  if (v >= total)
    v = total - 1; // only reachable on corrupt data
  code_ -= r * v;
  range_ = r;
  normalize();
  return v;
}

uint32_t RangeDecoder::decode_bypass(int nbits) {
  uint32_t v = 0;
  for (int i = 0; i < nbits; ++i) {
    range_ >>= 1;
    uint32_t bit = 0;
    if (code_ >= range_) {
      code_ -= range_;
      bit = 1;
    }
    v = (v << 1) | bit;
    normalize();
  }
  return v;
}

} // namespace pomar
