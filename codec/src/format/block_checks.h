// The BCHK section (optional): bits of each cluster block's XXH32 beyond the 8 the cluster
// index's check holds, so that every block is checked against 16 bits (version 2, one byte
// per block) or its whole XXH32 (version 1, three bytes per block) (docs/format.md,
// "Section BCHK").
#pragma once

#include <cstdint>
#include <vector>

#include "format/file_format.h"

namespace pomar {

constexpr uint32_t kBlockChecksTag = section_tag("BCHK"); // optional (flags 0)

/// The section's body (version 2) for the cluster blocks `blocks` (in cluster id order).
std::vector<uint8_t> write_block_checks(const std::vector<std::vector<uint8_t>> &blocks);
/// The same, version 1 (bits 8..31 of each XXH32), as earlier encoders wrote it.
std::vector<uint8_t> write_block_checks_v1(const std::vector<std::vector<uint8_t>> &blocks);
/// Completes `index.check` with the section body `body` (`bytes` long; version 1: to each
/// block's whole XXH32, check_mask all 32 bits; version 2: to its low 16 bits, check_mask
/// 0xFFFF). Throws a damaged-file error naming the section if it does not match the
/// cluster header.
void apply_block_checks(const uint8_t *body, uint64_t bytes, const FileLayout &layout,
                        ClusterIndex &index);
/// apply_block_checks with the file's BCHK section, if it has one (without one, leaves the
/// 8-bit checks). `global` holds the file's global part.
void load_block_checks(const uint8_t *global, const FileLayout &layout, ClusterIndex &index);

} // namespace pomar
