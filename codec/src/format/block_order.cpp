// The BLKO section; see block_order.h.
#include "format/block_order.h"
#include "mesh/morton.h"

#include <algorithm>
#include <numeric>

namespace pomar {

namespace {

constexpr uint8_t kBlockOrderVersion = 1;
constexpr uint8_t kMortonOfRoots = 1;

} // namespace

std::vector<uint32_t> morton_block_order(const std::vector<int32_t> &q, uint32_t clusters,
                                         int bits) {
  const int shift = std::max(0, bits - 21);
  std::vector<uint64_t> key(clusters);
  for (uint32_t c = 0; c < clusters; ++c)
    key[c] =
        morton_key(uint32_t(q[3 * size_t(c)]) >> shift, uint32_t(q[3 * size_t(c) + 1]) >> shift,
                   uint32_t(q[3 * size_t(c) + 2]) >> shift);
  std::vector<uint32_t> order(clusters);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](uint32_t a, uint32_t b) { return key[a] != key[b] ? key[a] < key[b] : a < b; });
  return order;
}

std::vector<uint8_t> write_block_order() { return {kBlockOrderVersion, kMortonOfRoots}; }

bool has_block_order(const uint8_t *global, const FileLayout &layout) {
  const int i = find_section(layout, kBlockOrderTag);
  if (i < 0)
    return false;
  const uint8_t *body = section_body(global, layout, size_t(i));
  const uint64_t n = layout.header.sections[size_t(i)].bytes;
  if (!layout.header.clustered() || n != 2 || body[0] != kBlockOrderVersion ||
      body[1] != kMortonOfRoots)
    throw Error(Error::Kind::DamagedFile,
                "damaged .pomar file: section 'BLKO' does not describe a block order this "
                "build reads (version 1, Morton order of the cluster roots, in a clustered file)");
  return true;
}

void place_blocks(ClusterIndex &index, const std::vector<uint32_t> &order,
                  const FileLayout &layout) {
  uint64_t offset = layout.clusters_offset;
  for (uint32_t c : order) {
    index.offset[c] = offset;
    offset += index.size[c];
  }
}

} // namespace pomar
