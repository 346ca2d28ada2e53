// libFuzzer target: the .pomar decoders on arbitrary bytes.
// pomar::Error is the expected way to reject input; anything else (crash, sanitizer
// report, other exception, hang, OOM) is a finding.
#include <pomar/limits.h>
#include <pomar/pomar.h>
#include <pomar/random_access.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "format/file_format.h" // internal (pomar_internal): header layout, checksum()

namespace {

void put_u32(std::vector<uint8_t> &b, size_t at, uint32_t v) {
  for (int k = 0; k < 4; ++k)
    b[at + k] = static_cast<uint8_t>(v >> (8 * k));
}

// Recompute the XXH32 checksums of a (mutated) .pomar image: header, base block, global
// levels, tables and cluster index (not the 8-bit cluster checks, which are range coded
// inside the index). Without this almost every mutation dies at a checksum and the
// decoders proper are never reached. Returns false if the header does not parse.
// Field offsets: docs/format.md / file_format.cpp write_header().
bool repair_checksums(std::vector<uint8_t> &b) {
  try {
    const size_t hsize = pomar::header_size(b.data(), b.size());
    if (hsize < pomar::kFixedHeaderBytes + 4 || hsize > b.size())
      return false;
    put_u32(b, hsize - 4, pomar::checksum(b.data(), hsize - 4));
    const pomar::FileLayout L = pomar::read_layout(b.data(), b.size(), b.size());
    const pomar::FileHeader &h = L.header;
    auto fix = [&](size_t field, uint64_t offset, uint64_t n) {
      if (offset <= b.size() && n <= b.size() - offset)
        put_u32(b, field, pomar::checksum(b.data() + offset, n));
    };
    fix(56, L.base_offset, h.base_bytes);
    for (size_t i = 0; i < L.level_offset.size(); ++i)
      fix(pomar::kFixedHeaderBytes + pomar::kLevelEntryBytes * i + 16, L.level_offset[i],
          uint64_t(h.levels[i].connectivity_bytes) + h.levels[i].geometry_bytes);
    if (h.clustered()) {
      const size_t c = pomar::kFixedHeaderBytes + pomar::kLevelEntryBytes * h.levels.size();
      fix(c + 12, L.tables_offset, h.tables_bytes);
      fix(c + 20, L.index_offset, h.index_bytes);
      if (h.has_cluster_checksum) // version 3: all cluster data
        fix(c + 36, L.clusters_offset, h.cluster_bytes);
    }
    put_u32(b, hsize - 4, pomar::checksum(b.data(), hsize - 4));
    return true;
  } catch (const pomar::Error &) {
    return false;
  }
}

void run(const uint8_t *data, size_t size);

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  run(data, size);
  // Again with valid checksums, to get past them into the decoders.
  if (size >= pomar::kFixedHeaderBytes) {
    std::vector<uint8_t> fixed(data, data + size);
    if (repair_checksums(fixed) && !std::equal(fixed.begin(), fixed.end(), data))
      run(fixed.data(), fixed.size());
  }
  return 0;
}

namespace {
// An explicit memory limit (below libFuzzer's -rss_limit_mb=2048) rather than the automatic
// one: the same input is refused or decoded whatever memory the machine has free.
constexpr uint64_t kMemoryLimit = 1ull << 30;

void run(const uint8_t *data, size_t size) {
  try {
    pomar::inspect(data, size);
  } catch (const pomar::Error &) {
  }
  for (int level : {-1, 0, 1}) {
    try {
      pomar::decode(data, size, level, {}, kMemoryLimit);
    } catch (const pomar::Error &) {
    }
  }
  // Decoding around damage: must end with a valid mesh or pomar::Error, never loop.
  try {
    pomar::DecodeOptions o;
    o.skip_damaged = true;
    o.memory_limit = kMemoryLimit;
    pomar::DecodeReport r;
    (void)pomar::decode(data, size, o, &r);
    (void)pomar::check_blocks(data, size);
  } catch (const pomar::Error &) {
  }
  // (regressions/decoder-crash-da39a3ee...: the empty input used to reach memcpy with a
  // null pointer; fixed in MemorySource::read.)
  try {
    pomar::SelectiveOptions so;
    so.memory_limit = kMemoryLimit;
    pomar::SelectiveDecoder d(std::make_unique<pomar::MemorySource>(data, size), so);
    const uint32_t n = d.cluster_count();
    const int finest = d.finest_level();
    if (n > 0) {
      d.want_cluster(0, finest);
      if (n > 1)
        d.want_cluster(n / 2, d.base_clustered_level() + 1);
    }
    d.update();
    (void)d.mesh();
    d.want_all(finest);
    d.update();
    (void)d.mesh();
    (void)d.vertex_cluster();
    (void)d.vertex_level();
  } catch (const pomar::Error &) {
  }
}
} // namespace
