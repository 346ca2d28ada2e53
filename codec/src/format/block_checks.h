// The BCHK section (optional): the 24 bits of each cluster block's XXH32 that the cluster
// index's 8-bit check leaves out, so that every block is checked against its whole XXH32
// (docs/format.md, "Section BCHK").
#pragma once

#include <cstdint>
#include <vector>

#include "format/file_format.h"

namespace pomar {

constexpr uint32_t kBlockChecksTag = section_tag("BCHK"); // optional (flags 0)

/// The section's body for the cluster blocks `blocks` (in cluster id order).
std::vector<uint8_t> write_block_checks(const std::vector<std::vector<uint8_t>> &blocks);
/// With a BCHK section, completes `index.check` to each block's whole XXH32 and sets
/// `index.check_mask` to all 32 bits; without one, leaves the 8-bit checks. Throws a
/// damaged-file error naming the section if it does not match the cluster header.
void load_block_checks(const uint8_t *global, const FileLayout &layout, ClusterIndex &index);

} // namespace pomar
