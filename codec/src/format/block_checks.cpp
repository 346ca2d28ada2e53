// The BCHK section; see block_checks.h.
#include "format/block_checks.h"

namespace pomar {

namespace {

constexpr uint8_t kBlockChecksVersion = 1;
constexpr size_t kHeadBytes = 5;  // version, cluster count
constexpr size_t kEntryBytes = 3; // bits 8..31 of the block's XXH32

} // namespace

std::vector<uint8_t> write_block_checks(const std::vector<std::vector<uint8_t>> &blocks) {
  const uint32_t n = static_cast<uint32_t>(blocks.size());
  std::vector<uint8_t> body(kHeadBytes + kEntryBytes * size_t(n));
  body[0] = kBlockChecksVersion;
  for (int k = 0; k < 4; ++k)
    body[size_t(1 + k)] = static_cast<uint8_t>(n >> (8 * k));
  for (uint32_t c = 0; c < n; ++c) {
    const uint32_t high = checksum(blocks[c].data(), blocks[c].size()) >> 8;
    for (size_t k = 0; k < kEntryBytes; ++k)
      body[kHeadBytes + kEntryBytes * c + k] = static_cast<uint8_t>(high >> (8 * k));
  }
  return body;
}

void load_block_checks(const uint8_t *global, const FileLayout &layout, ClusterIndex &index) {
  const int i = find_section(layout, kBlockChecksTag);
  if (i < 0)
    return;
  const uint8_t *body = section_body(global, layout, size_t(i));
  const uint64_t bytes = layout.header.sections[size_t(i)].bytes;
  const uint32_t n = layout.header.clusters;
  uint32_t count = 0;
  if (bytes >= kHeadBytes)
    for (int k = 0; k < 4; ++k)
      count |= uint32_t(body[1 + k]) << (8 * k);
  if (!layout.header.clustered() || bytes != kHeadBytes + kEntryBytes * uint64_t(n) ||
      body[0] != kBlockChecksVersion || count != n || index.check.size() != n)
    throw Error(Error::Kind::DamagedFile,
                "damaged .pomar file: section 'BCHK' does not hold one check per cluster "
                "block this build reads (version 1, " +
                    std::to_string(n) + " clusters)");
  for (uint32_t c = 0; c < n; ++c) {
    const uint8_t *e = body + kHeadBytes + kEntryBytes * size_t(c);
    index.check[c] = (index.check[c] & 0xFFu) | uint32_t(e[0]) << 8 | uint32_t(e[1]) << 16 |
                     uint32_t(e[2]) << 24;
  }
  index.check_mask = 0xFFFFFFFFu;
}

} // namespace pomar
