// Morton (Z-order) keys of quantized positions: the encoder's vertex order
// (mesh/reorder.cpp) and the BLKO section's cluster block order (format/block_order.cpp).
#pragma once

#include <cstdint>

namespace pomar {

/// The low 21 bits of x spread to every third bit.
inline uint64_t spread3(uint64_t x) {
  x &= 0x1FFFFF;
  x = (x | x << 32) & 0x1F00000000FFFFull;
  x = (x | x << 16) & 0x1F0000FF0000FFull;
  x = (x | x << 8) & 0x100F00F00F00F00Full;
  x = (x | x << 4) & 0x10C30C30C30C30C3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

/// The Morton key of the low 21 bits of x, y and z (x in the lowest bit of each triple).
inline uint64_t morton_key(uint64_t x, uint64_t y, uint64_t z) {
  return spread3(x) | spread3(y) << 1 | spread3(z) << 2;
}

} // namespace pomar
