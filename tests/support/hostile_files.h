// Hostile .pomar files made from valid ones: every header field that is a size, an offset
// source, a count or a version, set to values inside and beyond its valid range, with every
// checksum recomputed so the readers cannot stop at a checksum. Shared by the normal suite
// (tests/test_hostile_files.cpp, a systematic sweep) and the structure-aware fuzz target
// (tests/fuzz/fuzz_structure.cpp, random sequences of such edits).
// Field offsets: docs/format.md, "Fixed header", "Level table", "Version 2 and 3".
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <pomar/pomar.h>
#include <pomar/random_access.h>

#include "format/file_format.h" // internal (pomar_internal): header layout, checksum()

namespace pomar::hostile {

inline void put_le(std::vector<uint8_t> &b, size_t at, uint64_t v, int bytes) {
  for (int k = 0; k < bytes && at + k < b.size(); ++k)
    b[at + k] = static_cast<uint8_t>(v >> (8 * k));
}

inline uint64_t get_le(const std::vector<uint8_t> &b, size_t at, int bytes) {
  uint64_t v = 0;
  for (int k = 0; k < bytes && at + k < b.size(); ++k)
    v |= uint64_t(b[at + k]) << (8 * k);
  return v;
}

/// Where a version 4 header's section table (its count) starts; 0 if the image has none.
inline size_t section_table_at(const std::vector<uint8_t> &b) {
  if (b.size() < kFixedHeaderBytes || !(get_le(b, 10, 2) & kFlagSections))
    return 0;
  const uint64_t levels = std::min<uint64_t>(get_le(b, 48, 4), kMaxLevels);
  return kFixedHeaderBytes + kLevelEntryBytes * levels +
         ((get_le(b, 10, 2) & kFlagClustered) ? kClusterHeaderBytes : 0);
}

/// Recomputes the XXH32 checksums of a (mutated) image: header, base block, global levels,
/// tables, cluster index and (version 3) all cluster data, wherever the block lies inside the
/// image. Without this almost every mutation dies at a checksum and the decoders proper are
/// never reached. Returns false if the header does not parse.
inline bool repair_checksums(std::vector<uint8_t> &b) {
  try {
    const size_t hsize = header_size(b.data(), b.size());
    if (hsize < kFixedHeaderBytes + 4 || hsize > b.size())
      return false;
    put_le(b, hsize - 4, checksum(b.data(), hsize - 4), 4);
    // Strict first (as a decoder reads it), then lenient: fix what lies inside the image
    // even when the header announces more.
    FileLayout L;
    try {
      L = read_layout(b.data(), b.size(), b.size(), false);
    } catch (const Error &) {
      L = read_layout(b.data(), b.size(), b.size(), true);
    }
    const FileHeader &h = L.header;
    auto fix = [&](size_t field, uint64_t offset, uint64_t n) {
      if (offset <= b.size() && n <= b.size() - offset)
        put_le(b, field, checksum(b.data() + offset, n), 4);
    };
    fix(56, L.base_offset, h.base_bytes);
    const size_t table = section_table_at(b);
    for (size_t i = 0; i < L.section_offset.size(); ++i)
      fix(table + 4 + kSectionEntryBytes * i + 16, L.section_offset[i], h.sections[i].bytes);
    for (size_t i = 0; i < L.level_offset.size(); ++i)
      fix(kFixedHeaderBytes + kLevelEntryBytes * i + 16, L.level_offset[i],
          uint64_t(h.levels[i].connectivity_bytes) + h.levels[i].geometry_bytes);
    if (h.clustered()) {
      const size_t c = kFixedHeaderBytes + kLevelEntryBytes * h.levels.size();
      fix(c + 12, L.tables_offset, h.tables_bytes);
      fix(c + 20, L.index_offset, h.index_bytes);
      if (h.has_cluster_checksum)
        fix(c + 36, L.clusters_offset, h.cluster_bytes);
    }
    put_le(b, hsize - 4, checksum(b.data(), hsize - 4), 4);
    return true;
  } catch (const Error &) {
    return false;
  }
}

/// The image with its cluster index replaced by `index`'s sizes and checks (the header's
/// index size and every checksum made to match; the blocks stay where they are, so a size
/// changed moves where the decoder looks for every later block). `file` may be truncated
/// after its global part.
inline std::vector<uint8_t> with_cluster_index(const std::vector<uint8_t> &file,
                                               const ClusterIndex &index) {
  const FileLayout L = read_layout(file.data(), file.size(), file.size(), true);
  const std::vector<uint8_t> packed = pack_cluster_index(index);
  std::vector<uint8_t> b(file.begin(), file.begin() + long(L.index_offset));
  b.insert(b.end(), packed.begin(), packed.end());
  b.insert(b.end(), file.begin() + long(L.index_offset + L.header.index_bytes), file.end());
  const size_t c = kFixedHeaderBytes + kLevelEntryBytes * L.header.levels.size();
  put_le(b, c + 16, packed.size(), 4);
  repair_checksums(b);
  return b;
}

/// One header field: where it is, how wide, and whether it is a byte count.
struct Field {
  std::string name;
  size_t at = 0;
  int bytes = 4;
  bool is_size = false;
};

/// The fields of a valid image's header (sizes, counts, version, flags, bits, level table,
/// cluster header).
inline std::vector<Field> header_fields(const std::vector<uint8_t> &file) {
  std::vector<Field> f = {{"version", 8, 2},          {"flags", 10, 2},      {"bits", 12, 1},
                          {"extent", 28, 4},          {"vertices", 32, 4},   {"faces", 36, 4},
                          {"base_vertices", 40, 4},   {"base_faces", 44, 4}, {"levels", 48, 4},
                          {"base_bytes", 52, 4, true}};
  const uint32_t levels = uint32_t(std::min<uint64_t>(get_le(file, 48, 4), kMaxLevels));
  for (uint32_t i = 0; i < levels; ++i) {
    const size_t e = kFixedHeaderBytes + kLevelEntryBytes * i;
    const std::string l = "level " + std::to_string(i + 1) + " ";
    f.push_back({l + "vertices", e, 4});
    f.push_back({l + "faces", e + 4, 4});
    f.push_back({l + "connectivity_bytes", e + 8, 4, true});
    f.push_back({l + "geometry_bytes", e + 12, 4, true});
  }
  if (get_le(file, 10, 2) & kFlagClustered) {
    const size_t c = kFixedHeaderBytes + kLevelEntryBytes * levels;
    f.push_back({"global_levels", c, 4});
    f.push_back({"clusters", c + 4, 4});
    f.push_back({"tables_bytes", c + 8, 4, true});
    f.push_back({"index_bytes", c + 16, 4, true});
    f.push_back({"cluster_bytes", c + 24, 8, true});
    f.push_back({"cluster_connectivity_bytes", c + 32, 4, true});
  }
  if (const size_t t = section_table_at(file)) {
    f.push_back({"section count", t, 4});
    const uint32_t n = uint32_t(std::min<uint64_t>(get_le(file, t, 4), kMaxSections));
    for (uint32_t i = 0; i < n; ++i) {
      const size_t e = t + 4 + kSectionEntryBytes * i;
      const std::string name = "section " + std::to_string(i) + " ";
      f.push_back({name + "tag", e, 4});
      f.push_back({name + "flags", e + 4, 4});
      f.push_back({name + "bytes", e + 8, 8, true});
    }
  }
  return f;
}

/// Values worth trying in a field: the edges of its range, the file's size seen from the
/// field, and sizes that would make a 64-bit offset sum wrap back inside the file.
inline std::vector<uint64_t> interesting_values(const Field &f, const std::vector<uint8_t> &file) {
  const uint64_t cur = get_le(file, f.at, f.bytes);
  const uint64_t top = f.bytes == 8 ? ~uint64_t(0) : (uint64_t(1) << (8 * f.bytes)) - 1;
  const uint64_t n = file.size();
  std::vector<uint64_t> v = {0,     1, 2,     3,     cur - 1, cur + 1, cur * 2, cur / 2,
                             n - 1, n, n + 1, n * 2, top,     top - 1, top / 2, top / 2 + 1};
  if (f.bytes >= 4) {
    v.push_back(uint64_t(1) << 31);
    v.push_back(0xFFFFFFFFull);
  }
  if (f.bytes == 8) // wrap: offset + size == a small offset inside the file
    for (uint64_t back : {uint64_t(1), uint64_t(64), n / 2, n})
      v.push_back(~uint64_t(0) - back + 1);
  for (uint64_t &x : v)
    x &= top;
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

/// An explicit memory limit: the same input is refused or decoded whatever memory the
/// machine has free (below libFuzzer's -rss_limit_mb=2048).
constexpr uint64_t kMemoryLimit = 1ull << 30;

/// Every entry point a file's bytes reach: inspect, decode at several levels, decoding
/// around damage, the block check and the selective decoder (two regions, then all).
/// pomar::Error is the expected way to refuse; anything else escapes to the caller.
/// Returns how many of the calls succeeded.
inline int exercise_decoders(const uint8_t *data, size_t size) {
  int ok = 0;
  try {
    inspect(data, size);
    ++ok;
  } catch (const Error &) {
  }
  for (int level : {-1, 0, 1}) {
    try {
      (void)decode(data, size, level, {}, kMemoryLimit);
      ++ok;
    } catch (const Error &) {
    }
  }
  try {
    DecodeOptions o;
    o.skip_damaged = true;
    o.memory_limit = kMemoryLimit;
    DecodeReport r;
    (void)decode(data, size, o, &r);
    (void)check_blocks(data, size);
    ++ok;
  } catch (const Error &) {
  }
  try {
    SelectiveOptions so;
    so.memory_limit = kMemoryLimit;
    SelectiveDecoder d(std::make_unique<MemorySource>(data, size), so);
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
    ++ok;
  } catch (const Error &) {
  }
  return ok;
}

/// The layout promise: when the strict reader accepts an image, every block it names lies
/// inside the image (so no reader can be sent outside it). Returns the first block that does
/// not, or an empty string.
inline std::string layout_out_of_bounds(const std::vector<uint8_t> &b) {
  FileLayout L;
  try {
    L = read_layout(b.data(), b.size(), b.size(), false);
  } catch (const Error &) {
    return {};
  }
  const FileHeader &h = L.header;
  const uint64_t n = b.size();
  auto inside = [n](uint64_t offset, uint64_t bytes) { return offset <= n && bytes <= n - offset; };
  if (!inside(L.base_offset, h.base_bytes))
    return "base mesh block";
  for (size_t i = 0; i < L.section_offset.size(); ++i)
    if (!inside(L.section_offset[i], h.sections[i].bytes))
      return "section " + std::to_string(i);
  for (size_t i = 0; i < L.level_offset.size(); ++i)
    if (!inside(L.level_offset[i],
                uint64_t(h.levels[i].connectivity_bytes) + h.levels[i].geometry_bytes))
      return "level " + std::to_string(i + 1);
  if (h.clustered()) {
    if (!inside(L.tables_offset, h.tables_bytes))
      return "static model tables";
    if (!inside(L.index_offset, h.index_bytes))
      return "cluster index";
    if (!inside(L.clusters_offset, h.cluster_bytes))
      return "cluster data";
  }
  return {};
}

} // namespace pomar::hostile
