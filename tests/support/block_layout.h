// Where each cluster block of a file lies, whatever order the file stores the blocks in
// (cluster id order, or the Morton order of a BLKO section): tests that damage, cut or
// read a block find it here instead of summing the sizes of the clusters before it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <numeric>
#include <vector>

#include "pomar/limits.h"
#include "pomar/random_access.h"

namespace pomar::test {

struct BlockLayout {
  std::vector<uint64_t> offset; // per cluster: its block's first byte in the file
  std::vector<uint32_t> size;   // per cluster: its block's bytes
  std::vector<uint32_t> order;  // the clusters in the order their blocks are stored
  uint64_t end(uint32_t c) const { return offset[c] + size[c]; }
};

inline BlockLayout block_layout(const std::vector<uint8_t> &file) {
  SelectiveOptions o;
  o.memory_limit = kNoMemoryLimit;
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()), o);
  BlockLayout b;
  const uint32_t n = d.cluster_count();
  for (uint32_t c = 0; c < n; ++c) {
    b.offset.push_back(d.block_offset(c));
    b.size.push_back(d.block_size(c));
  }
  b.order.resize(n);
  std::iota(b.order.begin(), b.order.end(), 0u);
  std::stable_sort(b.order.begin(), b.order.end(),
                   [&](uint32_t x, uint32_t y) { return b.offset[x] < b.offset[y]; });
  return b;
}

} // namespace pomar::test
