// Little-endian byte and bit packing with bounds-checked reading.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

class ByteWriter {
public:
  explicit ByteWriter(std::vector<uint8_t> &out) : out_(out) {}
  void u8(uint8_t v) { out_.push_back(v); }
  void u16(uint16_t v) { put(v, 2); }
  void u32(uint32_t v) { put(v, 4); }
  void f32(float f) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    put(v, 4);
  }
  void bytes(const uint8_t *p, size_t n) {
    for (size_t i = 0; i < n; ++i) // (vector::insert here trips a GCC 12 false warning)
      out_.push_back(p[i]);
  }

private:
  void put(uint32_t v, int n) {
    for (int i = 0; i < n; ++i)
      out_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  std::vector<uint8_t> &out_;
};

/// Reads from [data, data+size); any read past the end throws Error("<what>: truncated").
class ByteReader {
public:
  ByteReader(const uint8_t *data, size_t size, const char *what)
      : p_(data), size_(size), what_(what) {}
  uint8_t u8() { return static_cast<uint8_t>(get(1)); }
  uint16_t u16() { return static_cast<uint16_t>(get(2)); }
  uint32_t u32() { return get(4); }
  float f32() {
    const uint32_t v = get(4);
    float f;
    std::memcpy(&f, &v, 4);
    return f;
  }
  size_t position() const { return pos_; }
  void skip(size_t n) {
    if (pos_ > size_ || size_ - pos_ < n)
      throw Error(Error::Kind::DamagedFile, std::string(what_) + " is truncated");
    pos_ += n;
  }

private:
  uint32_t get(int n) {
    if (size_ - pos_ < size_t(n) || pos_ > size_)
      throw Error(Error::Kind::DamagedFile, std::string(what_) + " is truncated");
    uint32_t v = 0;
    for (int i = 0; i < n; ++i)
      v |= uint32_t(p_[pos_ + i]) << (8 * i);
    pos_ += n;
    return v;
  }
  const uint8_t *p_;
  size_t size_, pos_ = 0;
  const char *what_;
};

class BitWriter {
public:
  explicit BitWriter(std::vector<uint8_t> &out) : out_(out) {}
  void put(uint32_t v, int nbits) { // nbits <= 32
    for (int i = 0; i < nbits; ++i) {
      acc_ |= ((v >> i) & 1u) << fill_;
      if (++fill_ == 8) {
        out_.push_back(static_cast<uint8_t>(acc_));
        acc_ = 0;
        fill_ = 0;
      }
    }
  }
  void flush() {
    if (fill_)
      out_.push_back(static_cast<uint8_t>(acc_));
    acc_ = 0;
    fill_ = 0;
  }

private:
  std::vector<uint8_t> &out_;
  uint32_t acc_ = 0;
  int fill_ = 0;
};

class BitReader {
public:
  BitReader(const uint8_t *data, size_t size) : p_(data), size_(size) {}
  uint32_t get(int nbits) {
    uint32_t v = 0;
    for (int i = 0; i < nbits; ++i, ++bit_) {
      if (bit_ / 8 >= size_)
        throw Error(Error::Kind::DamagedFile, "base mesh block is truncated");
      v |= uint32_t((p_[bit_ / 8] >> (bit_ % 8)) & 1u) << i;
    }
    return v;
  }

private:
  const uint8_t *p_;
  size_t size_, bit_ = 0;
};

} // namespace pomar
