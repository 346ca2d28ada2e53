// The BCHK section; see block_checks.h.
#include "format/block_checks.h"

namespace pomar {

namespace {

constexpr size_t kHeadBytes = 5; // version, cluster count

/// Version 1: bits 8..31 of the block's XXH32 (3 bytes); version 2: bits 8..15 (1 byte).
size_t entry_bytes(uint8_t version) { return version == 1 ? 3 : 1; }

std::vector<uint8_t> write(const std::vector<std::vector<uint8_t>> &blocks, uint8_t version) {
  const uint32_t n = static_cast<uint32_t>(blocks.size());
  const size_t entry = entry_bytes(version);
  std::vector<uint8_t> body(kHeadBytes + entry * size_t(n));
  body[0] = version;
  for (int k = 0; k < 4; ++k)
    body[size_t(1 + k)] = static_cast<uint8_t>(n >> (8 * k));
  for (uint32_t c = 0; c < n; ++c) {
    const uint32_t high = checksum(blocks[c].data(), blocks[c].size()) >> 8;
    for (size_t k = 0; k < entry; ++k)
      body[kHeadBytes + entry * c + k] = static_cast<uint8_t>(high >> (8 * k));
  }
  return body;
}

} // namespace

std::vector<uint8_t> write_block_checks(const std::vector<std::vector<uint8_t>> &blocks) {
  return write(blocks, 2);
}
std::vector<uint8_t> write_block_checks_v1(const std::vector<std::vector<uint8_t>> &blocks) {
  return write(blocks, 1);
}

void apply_block_checks(const uint8_t *body, uint64_t bytes, const FileLayout &layout,
                        ClusterIndex &index) {
  const uint32_t n = layout.header.clusters;
  const uint8_t version = bytes > 0 ? body[0] : 0;
  uint32_t count = 0;
  if (bytes >= kHeadBytes)
    for (int k = 0; k < 4; ++k)
      count |= uint32_t(body[1 + k]) << (8 * k);
  const size_t entry = entry_bytes(version);
  if (!layout.header.clustered() || (version != 1 && version != 2) ||
      bytes != kHeadBytes + entry * uint64_t(n) || count != n || index.check.size() != n)
    throw Error(Error::Kind::DamagedFile,
                "damaged .pomar file: section 'BCHK' does not hold one check per cluster "
                "block this build reads (version 1 or 2, " +
                    std::to_string(n) + " clusters)");
  for (uint32_t c = 0; c < n; ++c) {
    const uint8_t *e = body + kHeadBytes + entry * size_t(c);
    uint32_t high = 0;
    for (size_t k = 0; k < entry; ++k)
      high |= uint32_t(e[k]) << (8 * k);
    index.check[c] = (index.check[c] & 0xFFu) | high << 8;
  }
  index.check_mask = version == 1 ? 0xFFFFFFFFu : 0xFFFFu;
}

void load_block_checks(const uint8_t *global, const FileLayout &layout, ClusterIndex &index) {
  const int i = find_section(layout, kBlockChecksTag);
  if (i < 0)
    return;
  apply_block_checks(section_body(global, layout, size_t(i)),
                     layout.header.sections[size_t(i)].bytes, layout, index);
}

} // namespace pomar
