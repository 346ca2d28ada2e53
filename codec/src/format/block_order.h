// The BLKO section (required): cluster blocks stored in the Morton order of their roots,
// so that the blocks of one region of the model lie next to each other in the file
// (docs/format.md, "Section BLKO").
#pragma once

#include <cstdint>
#include <vector>

#include "format/file_format.h"

namespace pomar {

constexpr uint32_t kBlockOrderTag = section_tag("BLKO"); // required

/// The clusters in the order their blocks are stored: sorted by the Morton code of their
/// root's quantized position in the base clustered mesh (`q`: xyz per vertex, the first
/// `clusters` vertices are the roots; `bits` per coordinate, of which the top 21 count),
/// ties by cluster id.
std::vector<uint32_t> morton_block_order(const std::vector<int32_t> &q, uint32_t clusters,
                                         int bits);

std::vector<uint8_t> write_block_order();
/// Whether the file stores its blocks in Morton order (BLKO present and well formed;
/// throws a damaged-file error naming the section if it is not).
bool has_block_order(const uint8_t *global, const FileLayout &layout);
/// The offsets of `index` (sizes and checks in cluster id order) for blocks stored in
/// `order` from layout.clusters_offset on.
void place_blocks(ClusterIndex &index, const std::vector<uint32_t> &order,
                  const FileLayout &layout);

} // namespace pomar
