#include "format/file_format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>

// xxhash compiled into this file (Debian's xxhash.h carries the implementation): no call
// into the uninstrumented libxxhash.so, so ASan and the fuzzers see every byte a checksum
// reads, and a file's bytes reach no code that sanitizers cannot check.
#define XXH_INLINE_ALL
#include <xxhash.h>

#include "entropy/models.h"
#include "entropy/range_coder.h"
#include "format/bit_io.h"

namespace pomar {

uint32_t checksum(const uint8_t *data, size_t size) { return XXH32(data, size, 0); }

uint32_t checksum(const std::vector<const std::vector<uint8_t> *> &blocks) {
  XXH32_state_t *state = XXH32_createState();
  if (!state)
    throw std::bad_alloc();
  XXH32_reset(state, 0);
  for (const std::vector<uint8_t> *b : blocks)
    if (!b->empty())
      XXH32_update(state, b->data(), b->size());
  const uint32_t h = XXH32_digest(state);
  XXH32_freeState(state);
  return h;
}

namespace {

void write_header(const FileHeader &h, std::vector<uint8_t> &out) {
  ByteWriter w(out);
  w.bytes(kMagic, 8);
  w.u16(h.version);
  w.u16(h.flags);
  w.u8(static_cast<uint8_t>(h.grid.bits));
  w.u8(0);
  w.u8(0);
  w.u8(0);
  for (int k = 0; k < 3; ++k)
    w.f32(h.grid.origin[k]);
  w.f32(h.grid.extent);
  w.u32(h.vertices);
  w.u32(h.faces);
  w.u32(h.base_vertices);
  w.u32(h.base_faces);
  w.u32(static_cast<uint32_t>(h.levels.size()));
  w.u32(h.base_bytes);
  w.u32(h.base_checksum);
  for (const LevelEntry &e : h.levels) {
    w.u32(e.vertices);
    w.u32(e.faces);
    w.u32(e.connectivity_bytes);
    w.u32(e.geometry_bytes);
    w.u32(e.checksum);
  }
  if (h.clustered()) {
    w.u32(h.global_levels);
    w.u32(h.clusters);
    w.u32(h.tables_bytes);
    w.u32(h.tables_checksum);
    w.u32(h.index_bytes);
    w.u32(h.index_checksum);
    w.u32(static_cast<uint32_t>(h.cluster_bytes));
    w.u32(static_cast<uint32_t>(h.cluster_bytes >> 32));
    // Version 3: the informative connectivity share in 32 bits (saturated), then the
    // checksum of the cluster data.
    w.u32(static_cast<uint32_t>(std::min<uint64_t>(h.cluster_connectivity_bytes, 0xFFFFFFFFu)));
    w.u32(h.cluster_checksum);
  }
  if (h.flags & kFlagSections) {
    w.u32(static_cast<uint32_t>(h.sections.size()));
    for (const SectionEntry &e : h.sections) {
      w.u32(e.tag);
      w.u32(e.flags);
      w.u32(static_cast<uint32_t>(e.bytes));
      w.u32(static_cast<uint32_t>(e.bytes >> 32));
      w.u32(e.checksum);
    }
  }
  w.u32(checksum(out.data(), out.size()));
}

struct SizeModels {
  FrequencyModel length{33};
  BitModel top[33][2];
};

} // namespace

/// The cluster index: block sizes (adaptive Elias-gamma) and check bytes, range coded.
std::vector<uint8_t> pack_cluster_index(const ClusterIndex &index) {
  std::vector<uint8_t> out;
  RangeEncoder rc(&out);
  SizeModels m;
  for (size_t c = 0; c < index.size.size(); ++c) {
    const uint32_t n = index.size[c];
    const int nb = bit_length(n);
    rc.encode(m.length, nb);
    // The two bits under the leading one are modelled (sizes cluster around a mean).
    for (int i = nb - 2, k = 0; i >= 0; --i, ++k) {
      const int bit = (n >> i) & 1;
      if (k < 2)
        rc.encode_bit(m.top[nb][k], bit);
      else
        rc.encode_bypass(uint32_t(bit), 1);
    }
    rc.encode_bypass(index.check[c] & 0xFF, 8);
  }
  rc.finish();
  return out;
}

namespace {

[[noreturn]] void bad(const std::string &what) {
  throw Error(Error::Kind::DamagedFile, "not a valid .pomar file: " + what);
}

// No .pomar file is this large: every size read from a header is checked against it before
// it takes part in a sum, so offsets computed from sizes can never wrap (2^48 bytes leaves
// room for 2^15 such sizes in a 64-bit sum).
constexpr uint64_t kMaxFileBytes = uint64_t(1) << 48;

/// offset += bytes, refusing a size no file can have (a hostile header must not make an
/// offset wrap around and land back inside the buffer).
void advance(uint64_t &offset, uint64_t bytes, const char *what) {
  if (bytes > kMaxFileBytes || offset > kMaxFileBytes - bytes)
    bad(std::string(what) + " size " + std::to_string(bytes) +
        " is impossible (more than 2^48 bytes)");
  offset += bytes;
}

} // namespace

// The base mesh block is one range-coded stream: positions as differences to the previous
// vertex (the encoder orders vertices along a Morton curve, so they are small), then the
// faces, each rotated to start at its smallest index and sorted, as the step from the
// previous face's first index and the two other indices relative to the first. Every
// value is a magnitude class (adaptive) followed by sign and mantissa bits.
namespace {

struct BaseModels {
  FrequencyModel coord[3] = {FrequencyModel(kMagnitudeSymbols), FrequencyModel(kMagnitudeSymbols),
                             FrequencyModel(kMagnitudeSymbols)};
  FrequencyModel first{kMagnitudeSymbols}, other{kMagnitudeSymbols};
};

} // namespace

void canonical_faces(std::vector<uint32_t> &t) {
  const size_t nf = t.size() / 3;
  std::vector<std::array<uint32_t, 3>> f(nf);
  for (size_t i = 0; i < nf; ++i) {
    std::array<uint32_t, 3> x = {t[3 * i], t[3 * i + 1], t[3 * i + 2]};
    std::rotate(x.begin(), std::min_element(x.begin(), x.end()), x.end());
    f[i] = x;
  }
  std::sort(f.begin(), f.end());
  for (size_t i = 0; i < nf; ++i)
    std::copy(f[i].begin(), f[i].end(), &t[3 * i]);
}

std::vector<uint8_t> pack_base_mesh(const BaseMesh &base, int bits) {
  (void)bits;
  std::vector<uint8_t> out;
  RangeEncoder rc(&out);
  BaseModels m;
  int32_t prev[3] = {0, 0, 0};
  for (size_t i = 0; i < base.q.size(); ++i) {
    put_signed(rc, m.coord[i % 3], nullptr, int64_t(base.q[i]) - prev[i % 3]);
    prev[i % 3] = base.q[i];
  }
  uint32_t prev_first = 0;
  for (size_t f = 0; f < base.triangles.size(); f += 3) {
    const uint32_t a = base.triangles[f];
    put_signed(rc, m.first, nullptr, int64_t(a) - prev_first);
    put_signed(rc, m.other, nullptr, int64_t(base.triangles[f + 1]) - a);
    put_signed(rc, m.other, nullptr, int64_t(base.triangles[f + 2]) - a);
    prev_first = a;
  }
  rc.finish();
  return out;
}

namespace {

/// The file image from its parts; `header`'s clustered fields already describe `index` and
/// `cluster_data` (the blocks, in file order).
std::vector<uint8_t> assemble(FileHeader header, const std::vector<uint8_t> &base_block,
                              const std::vector<std::vector<uint8_t>> &level_blocks,
                              const std::vector<uint8_t> &tables, const std::vector<uint8_t> &index,
                              const std::vector<const uint8_t *> &data,
                              const std::vector<size_t> &data_bytes,
                              const std::vector<Section> &sections) {
  if (sections.size() > kMaxSections)
    throw Error(Error::Kind::Internal,
                "internal error: more than " + std::to_string(kMaxSections) + " sections");
  // Version 5 (the header says so: its level streams rank patches) always has a section
  // table; the older ones only when there are sections.
  const bool v5 = header.ranks_patches();
  header.version = v5                   ? kPatchRankFormatVersion
                   : !sections.empty()  ? kSectionsFormatVersion
                   : header.clustered() ? kClusteredFormatVersion
                                        : kFormatVersion;
  header.flags = static_cast<uint16_t>((header.flags & kFlagClustered) |
                                       (sections.empty() && !v5 ? 0 : kFlagSections));
  header.sections.clear();
  for (const Section &sec : sections)
    header.sections.push_back(
        {sec.tag, sec.flags, sec.body.size(), checksum(sec.body.data(), sec.body.size())});
  header.base_bytes = static_cast<uint32_t>(base_block.size());
  header.base_checksum = checksum(base_block.data(), base_block.size());
  for (size_t i = 0; i < level_blocks.size(); ++i)
    header.levels[i].checksum = checksum(level_blocks[i].data(), level_blocks[i].size());
  if (header.clustered()) {
    header.tables_bytes = static_cast<uint32_t>(tables.size());
    header.tables_checksum = checksum(tables.data(), tables.size());
    header.index_bytes = static_cast<uint32_t>(index.size());
    header.index_checksum = checksum(index.data(), index.size());
  }
  std::vector<uint8_t> out;
  write_header(header, out);
  out.insert(out.end(), base_block.begin(), base_block.end());
  for (const Section &sec : sections)
    out.insert(out.end(), sec.body.begin(), sec.body.end());
  for (const auto &b : level_blocks)
    out.insert(out.end(), b.begin(), b.end());
  if (header.clustered()) {
    out.insert(out.end(), tables.begin(), tables.end());
    out.insert(out.end(), index.begin(), index.end());
    for (size_t i = 0; i < data.size(); ++i)
      out.insert(out.end(), data[i], data[i] + data_bytes[i]);
  }
  return out;
}

} // namespace

std::vector<uint8_t> write_file(FileHeader header, const std::vector<uint8_t> &base_block,
                                const std::vector<std::vector<uint8_t>> &level_blocks,
                                const std::vector<uint8_t> &tables,
                                const std::vector<std::vector<uint8_t>> &cluster_blocks,
                                const std::vector<Section> &sections,
                                const std::vector<uint32_t> *block_order) {
  std::vector<uint8_t> index;
  std::vector<const uint8_t *> data;
  std::vector<size_t> data_bytes;
  if (header.clustered()) {
    header.clusters = static_cast<uint32_t>(cluster_blocks.size());
    ClusterIndex entries; // sizes and checks in cluster id order
    for (const auto &b : cluster_blocks) {
      entries.size.push_back(static_cast<uint32_t>(b.size()));
      entries.check.push_back(static_cast<uint8_t>(checksum(b.data(), b.size()) & 0xFF));
    }
    index = pack_cluster_index(entries);
    header.cluster_bytes = 0;
    std::vector<const std::vector<uint8_t> *> blocks; // in file order
    for (size_t i = 0; i < cluster_blocks.size(); ++i) {
      const auto &b = cluster_blocks[block_order ? (*block_order).at(i) : i];
      header.cluster_bytes += b.size();
      blocks.push_back(&b);
      data.push_back(b.data());
      data_bytes.push_back(b.size());
    }
    header.has_cluster_checksum = true;
    header.cluster_checksum = checksum(blocks);
  }
  return assemble(header, base_block, level_blocks, tables, index, data, data_bytes, sections);
}

size_t header_size(const uint8_t *data, size_t size) {
  if (size < kFixedHeaderBytes)
    return kFixedHeaderBytes;
  ByteReader r(data, size, "the .pomar header");
  for (int i = 0; i < 10; ++i)
    r.u8();
  const uint16_t flags = r.u16();
  ByteReader c(data + 48, 4, "the .pomar header");
  const uint64_t levels = std::min<uint32_t>(c.u32(), kMaxLevels);
  size_t bytes = kFixedHeaderBytes + kLevelEntryBytes * levels +
                 ((flags & kFlagClustered) ? kClusterHeaderBytes : 0);
  if (flags & kFlagSections) { // version 4: the section count, then the table
    if (size < bytes + 4)
      return bytes + 4;
    ByteReader n(data + bytes, 4, "the .pomar section table");
    bytes += 4 + kSectionEntryBytes * std::min<uint32_t>(n.u32(), kMaxSections);
  }
  return bytes + 4;
}

namespace {

// read_layout's steps, in the order of the header's fields.

/// The fixed header after the signature: version, flags, grid, counts, base block size;
/// returns the level count (checked against kMaxLevels).
uint32_t read_fixed_header(ByteReader &r, FileHeader &h) {
  h.version = r.u16();
  if (h.version < kFormatVersion || h.version > kPatchRankFormatVersion)
    throw Error(Error::Kind::Unsupported, "unsupported .pomar version " +
                                              std::to_string(h.version) +
                                              " (this build reads versions 1 to 5)");
  h.flags = r.u16();
  const bool v4 = h.version >= kSectionsFormatVersion; // (4 and 5: a section table)
  const bool flags_ok =
      v4 ? (h.flags & ~(kFlagClustered | kFlagSections)) == 0 && (h.flags & kFlagSections)
         : (h.flags & ~kFlagClustered) == 0 && (h.version != kFormatVersion) == h.clustered();
  if (!flags_ok)
    bad("unknown flags " + std::to_string(h.flags) + " for version " + std::to_string(h.version));
  h.grid.bits = r.u8();
  r.u8();
  r.u8();
  r.u8();
  for (int k = 0; k < 3; ++k)
    h.grid.origin[k] = r.f32();
  h.grid.extent = r.f32();
  h.vertices = r.u32();
  h.faces = r.u32();
  h.base_vertices = r.u32();
  h.base_faces = r.u32();
  const uint32_t levels = r.u32();
  h.base_bytes = r.u32();
  h.base_checksum = r.u32();
  if (levels > kMaxLevels)
    bad("level count " + std::to_string(levels) + " exceeds " + std::to_string(kMaxLevels));
  return levels;
}

/// The header's size (fixed part, level table, cluster header, the section table of versions 4 and
/// 5, checksum) into L.header_bytes, and its checksum checked; returns the section count.
uint32_t check_header_bytes(const uint8_t *data, size_t size, uint32_t levels, FileLayout &L) {
  const FileHeader &h = L.header;
  const bool v4 = h.version >= kSectionsFormatVersion; // (4 and 5: a section table)
  const size_t table_at =
      kFixedHeaderBytes + kLevelEntryBytes * levels + (h.clustered() ? kClusterHeaderBytes : 0);
  uint32_t sections = 0;
  if (v4) {
    if (size < table_at + 4)
      bad("header is truncated");
    ByteReader n(data + table_at, 4, "the .pomar section table");
    sections = n.u32();
    if (sections > kMaxSections)
      bad("section count " + std::to_string(sections) + " exceeds " + std::to_string(kMaxSections));
  }
  L.header_bytes = table_at + (v4 ? 4 + kSectionEntryBytes * sections : 0) + 4;
  if (size < L.header_bytes)
    bad("header is truncated");
  ByteReader c(data + L.header_bytes - 4, 4, "header checksum");
  if (checksum(data, L.header_bytes - 4) != c.u32())
    bad("header checksum mismatch (the file is damaged)");
  return sections;
}

void read_level_table(ByteReader &r, uint32_t levels, FileHeader &h) {
  h.levels.resize(levels);
  for (LevelEntry &e : h.levels) {
    e.vertices = r.u32();
    e.faces = r.u32();
    e.connectivity_bytes = r.u32();
    e.geometry_bytes = r.u32();
    e.checksum = r.u32();
  }
}

/// Versions 2 and 3: the cluster header, its counts checked against the level table.
void read_cluster_header(ByteReader &r, FileHeader &h) {
  h.global_levels = r.u32();
  h.clusters = r.u32();
  h.tables_bytes = r.u32();
  h.tables_checksum = r.u32();
  h.index_bytes = r.u32();
  h.index_checksum = r.u32();
  h.cluster_bytes = r.u32();
  h.cluster_bytes |= uint64_t(r.u32()) << 32;
  h.cluster_connectivity_bytes = r.u32();
  if (h.version == kClusteredFormatVersion2) {
    h.cluster_connectivity_bytes |= uint64_t(r.u32()) << 32;
  } else {
    h.has_cluster_checksum = true;
    h.cluster_checksum = r.u32();
  }
  if (h.cluster_connectivity_bytes > h.cluster_bytes)
    bad("cluster connectivity share exceeds the cluster data");
  if (h.global_levels >= h.levels.size())
    bad("no clustered level after " + std::to_string(h.global_levels) + " global levels");
  const uint32_t base_clustered =
      h.global_levels == 0 ? h.base_vertices : h.levels[h.global_levels - 1].vertices;
  if (h.clusters != base_clustered)
    bad("cluster count differs from the base clustered mesh's vertex count");
}

/// Version 4: the section table (its count, read by check_header_bytes, skipped).
void read_section_table(ByteReader &r, uint32_t sections, FileHeader &h) {
  r.u32();
  for (uint32_t i = 0; i < sections; ++i) {
    SectionEntry e;
    e.tag = r.u32();
    e.flags = r.u32();
    e.bytes = r.u32();
    e.bytes |= uint64_t(r.u32()) << 32;
    e.checksum = r.u32();
    if (e.flags & ~kSectionRequired)
      bad("section " + section_name(e.tag) + " has unknown flags " + std::to_string(e.flags));
    for (const SectionEntry &o : h.sections)
      if (o.tag == e.tag)
        bad("section " + section_name(e.tag) + " appears twice");
    h.sections.push_back(e);
  }
}

/// The counts' sanity, before anybody allocates from them.
void check_counts(const FileHeader &h) {
  if (h.grid.bits < 1 || h.grid.bits > 24)
    bad("quantization bits " + std::to_string(h.grid.bits) + " outside 1..24");
  if (!std::isfinite(h.grid.extent) || h.grid.extent < 0 || !std::isfinite(h.grid.origin[0]) ||
      !std::isfinite(h.grid.origin[1]) || !std::isfinite(h.grid.origin[2]))
    bad("bounding box is not finite");
  if (h.base_faces == 0 || h.base_vertices < 3 || h.base_vertices > h.vertices ||
      h.base_faces > h.faces || h.vertices > (1u << 31) || h.faces > (1u << 31))
    bad("inconsistent vertex/face counts");
  uint32_t nv = h.base_vertices, nf = h.base_faces;
  for (const LevelEntry &e : h.levels) {
    if (e.vertices <= nv || e.vertices > 2 * uint64_t(nv) || e.faces < nf)
      bad("level table counts do not grow like vertex splits");
    nv = e.vertices;
    nf = e.faces;
  }
  if (nv != h.vertices || nf != h.faces)
    bad("level table does not end at the announced vertex/face counts");
  if (h.base_bytes == 0)
    bad("empty base mesh block");
  // The base block bounds the base counts: a face's two other corners differ from its first
  // (build_corner_table refuses repeats), so each costs at least a sign bit, two bits a face,
  // and a stream of n bytes holds at most 8 (n + 9) + 32 bits (the decoder reads up to 8
  // zero bytes past its end); every base vertex is used by a face (the encoder codes no
  // unreferenced vertex), so there are at most three per face. A header claiming more is
  // refused before anything is sized from it.
  if (h.base_faces > 4 * uint64_t(h.base_bytes) + 64)
    bad(std::to_string(h.base_faces) + " base faces cannot be coded in a base mesh block of " +
        std::to_string(h.base_bytes) + " bytes");
  if (h.base_vertices > 3 * uint64_t(h.base_faces))
    bad(std::to_string(h.base_vertices) + " base vertices for " + std::to_string(h.base_faces) +
        " base faces: more than three per face");
}

/// Every block's offset, each addition checked (advance; nothing subtracts sizes); returns
/// the offset of the end of the file the header announces.
uint64_t place_blocks(FileLayout &L) {
  const FileHeader &h = L.header;
  uint64_t offset = L.header_bytes;
  L.base_offset = offset;
  advance(offset, h.base_bytes, "base mesh block");
  for (const SectionEntry &e : h.sections) {
    L.section_offset.push_back(offset);
    advance(offset, e.bytes, "section");
  }
  const size_t global = h.clustered() ? h.global_levels : h.levels.size();
  for (size_t i = 0; i < global; ++i) {
    L.level_offset.push_back(offset);
    advance(offset, uint64_t(h.levels[i].connectivity_bytes) + h.levels[i].geometry_bytes,
            "global level block");
  }
  for (size_t i = global; i < h.levels.size(); ++i)
    if (h.levels[i].connectivity_bytes || h.levels[i].geometry_bytes)
      bad("a clustered level has global data");
  if (h.clustered()) {
    L.tables_offset = offset;
    advance(offset, h.tables_bytes, "static model tables");
    L.index_offset = offset;
    advance(offset, h.index_bytes, "cluster index");
    L.clusters_offset = offset;
    L.global_bytes = offset;
    advance(offset, h.cluster_bytes, "cluster data");
  } else {
    L.global_bytes = offset;
  }
  return offset;
}

/// With allow_truncated, only what every decode needs must be present; a strict reader
/// needs every byte the header announces (`end`).
void check_present(const FileLayout &L, uint64_t end, bool allow_truncated) {
  const FileHeader &h = L.header;
  const uint64_t needed = !allow_truncated         ? end
                          : h.clustered()          ? L.global_bytes
                          : L.level_offset.empty() ? L.global_bytes
                                                   : L.level_offset[0]; // base + sections
  if (needed > L.file_size)
    throw Error(Error::Kind::TruncatedFile,
                "truncated .pomar file: " + std::to_string(L.file_size) +
                    " bytes, the header announces " + std::to_string(end));
  if (h.vertices > 512 * uint64_t(L.file_size) + 64)
    bad("the announced vertex count is implausible for the file size");
}

} // namespace

FileLayout read_layout(const uint8_t *data, size_t size, uint64_t file_size, bool allow_truncated) {
  if (file_size == 0)
    file_size = size;
  if (size < 8 || std::memcmp(data, kMagic, 8) != 0)
    bad("the file does not start with the POMAR signature");
  ByteReader r(data, size, "the .pomar header");
  for (int i = 0; i < 8; ++i)
    r.u8();
  FileLayout L;
  FileHeader &h = L.header;
  const uint32_t levels = read_fixed_header(r, h);
  const uint32_t sections = check_header_bytes(data, size, levels, L);
  read_level_table(r, levels, h);
  if (h.clustered())
    read_cluster_header(r, h);
  if (h.version >= kSectionsFormatVersion) // (4 and 5)
    read_section_table(r, sections, h);
  check_counts(h);
  const uint64_t end = place_blocks(L);
  L.file_size = file_size;
  check_present(L, end, allow_truncated);
  return L;
}

BaseMesh read_base_mesh(const uint8_t *data, const FileLayout &L, bool keep) {
  const FileHeader &h = L.header;
  const uint8_t *p = data + L.base_offset;
  if (checksum(p, h.base_bytes) != h.base_checksum)
    throw Error(Error::Kind::DamagedFile, "damaged .pomar file: base mesh checksum mismatch");
  auto bad = [](const char *what) {
    throw Error(Error::Kind::DamagedFile, std::string("damaged .pomar file: base mesh ") + what);
  };
  BaseMesh b;
  RangeDecoder rc(p, h.base_bytes);
  BaseModels m;
  const int64_t top = (int64_t(1) << h.grid.bits) - 1;
  // (The counts are bounded by the block's size, read_layout; a stream that runs past its
  // block stops at once.)
  const size_t nq = size_t(h.base_vertices) * 3, nt = size_t(h.base_faces) * 3;
  if (keep)
    b.q.resize(nq);
  int64_t prev[3] = {0, 0, 0};
  for (size_t i = 0; i < nq; ++i) {
    const int64_t v = prev[i % 3] + get_signed(rc, m.coord[i % 3], nullptr);
    if (v < 0 || v > top)
      bad("position outside the quantization grid");
    if (rc.overrun())
      bad("data ends too early");
    if (keep)
      b.q[i] = static_cast<int32_t>(v);
    prev[i % 3] = v;
  }
  if (keep)
    b.triangles.resize(nt);
  int64_t prev_first = 0;
  for (size_t f = 0; f < nt; f += 3) {
    const int64_t a = prev_first + get_signed(rc, m.first, nullptr);
    const int64_t x = a + get_signed(rc, m.other, nullptr),
                  y = a + get_signed(rc, m.other, nullptr);
    for (int64_t i : {a, x, y})
      if (i < 0 || i >= int64_t(h.base_vertices))
        bad("face refers to a missing vertex");
    if (x == a || y == a || x == y)
      bad("face repeats a vertex");
    if (rc.overrun())
      bad("data ends too early");
    if (keep) {
      b.triangles[f] = uint32_t(a);
      b.triangles[f + 1] = uint32_t(x);
      b.triangles[f + 2] = uint32_t(y);
    }
    prev_first = a;
  }
  return b;
}

void check_level(const uint8_t *data, const FileLayout &L, size_t i) {
  const LevelEntry &e = L.header.levels[i];
  const size_t n = size_t(e.connectivity_bytes) + e.geometry_bytes;
  if (L.level_offset[i] + n > L.file_size)
    throw Error(Error::Kind::TruncatedFile, "truncated .pomar file: level " +
                                                std::to_string(i + 1) + " ends at byte " +
                                                std::to_string(L.level_offset[i] + n) +
                                                ", the file has " + std::to_string(L.file_size))
        .in_block(int(i + 1));
  if (checksum(data + L.level_offset[i], n) != e.checksum)
    throw Error(Error::Kind::DamagedFile, "damaged .pomar file: checksum mismatch in level " +
                                              std::to_string(i + 1) + " block")
        .in_block(int(i + 1));
}

ClusterIndex read_cluster_index(const uint8_t *data, const FileLayout &L) {
  const FileHeader &h = L.header;
  check_block(data, h.index_bytes, h.index_checksum, "cluster index");
  ClusterIndex index;
  // Each entry ends with its 8-bit check (8 bits the stream must hold): the index block
  // bounds the count (read_base_mesh: at most 8 (n + 9) + 32 bits in n bytes).
  if (h.clusters > uint64_t(h.index_bytes) + 16)
    throw Error(Error::Kind::DamagedFile, "damaged .pomar file: " + std::to_string(h.clusters) +
                                              " clusters cannot be indexed in " +
                                              std::to_string(h.index_bytes) + " bytes");
  RangeDecoder rc(data, h.index_bytes);
  SizeModels m;
  uint64_t offset = L.clusters_offset, total = 0;
  index.offset.resize(h.clusters);
  index.size.resize(h.clusters);
  index.check.resize(h.clusters);
  for (uint32_t c = 0; c < h.clusters; ++c) {
    const int nb = rc.decode(m.length);
    uint32_t n = nb == 0 ? 0 : 1u;
    for (int i = nb - 2, k = 0; i >= 0; --i, ++k)
      n = (n << 1) | uint32_t(k < 2 ? rc.decode_bit(m.top[nb][k]) : int(rc.decode_bypass(1)));
    index.offset[c] = offset;
    index.size[c] = n;
    index.check[c] = static_cast<uint8_t>(rc.decode_bypass(8));
    offset += n;
    total += n;
    if (total > h.cluster_bytes)
      throw Error(Error::Kind::DamagedFile,
                  "damaged .pomar file: cluster index exceeds the cluster data");
  }
  if (total != h.cluster_bytes || rc.overrun())
    throw Error(Error::Kind::DamagedFile,
                "damaged .pomar file: cluster index does not match the cluster data");
  return index;
}

std::string section_name(uint32_t tag) {
  std::string name;
  for (int k = 0; k < 4; ++k) {
    const char ch = static_cast<char>(tag >> (8 * k));
    if (ch < 0x20 || ch > 0x7E) {
      char hex[16];
      std::snprintf(hex, sizeof hex, "0x%08X", tag);
      return hex;
    }
    name += ch;
  }
  return "'" + name + "'";
}

int find_section(const FileLayout &L, uint32_t tag) {
  for (size_t i = 0; i < L.header.sections.size(); ++i)
    if (L.header.sections[i].tag == tag)
      return static_cast<int>(i);
  return -1;
}

const uint8_t *section_body(const uint8_t *data, const FileLayout &L, size_t i) {
  const SectionEntry &e = L.header.sections.at(i);
  if (L.section_offset[i] + e.bytes > L.file_size)
    throw Error(Error::Kind::TruncatedFile, "truncated .pomar file: section " +
                                                section_name(e.tag) + " ends at byte " +
                                                std::to_string(L.section_offset[i] + e.bytes) +
                                                ", the file has " + std::to_string(L.file_size));
  const uint8_t *p = data + L.section_offset[i];
  if (checksum(p, e.bytes) != e.checksum)
    throw Error(Error::Kind::DamagedFile,
                "damaged .pomar file: checksum mismatch in section " + section_name(e.tag));
  return p;
}

const std::vector<uint32_t> &known_sections() {
  // The sections this build's decoders honour.
  static const std::vector<uint32_t> known = {
      section_tag("ATTR"), kLosslessTag,        section_tag("MATL"), section_tag("TEXI"),
      section_tag("CERR"), section_tag("BLKO"), section_tag("GEOP"), section_tag("BCHK")};
  return known;
}

void require_known_sections(const FileLayout &L, const std::vector<uint32_t> &known) {
  for (const SectionEntry &e : L.header.sections)
    if ((e.flags & kSectionRequired) && std::find(known.begin(), known.end(), e.tag) == known.end())
      throw Error(Error::Kind::Unsupported, "this build of pomar cannot read the file's section " +
                                                section_name(e.tag) +
                                                ", which it needs (written by a newer pomar?)");
}

std::vector<uint8_t> with_sections(const uint8_t *file, size_t size,
                                   const std::vector<Section> &add) {
  const FileLayout L = read_layout(file, size);
  FileHeader h = L.header;
  auto bytes = [file](uint64_t offset, uint64_t n) {
    return std::vector<uint8_t>(file + offset, file + offset + n);
  };
  const std::vector<uint8_t> base = bytes(L.base_offset, h.base_bytes);
  std::vector<Section> sections;
  for (size_t i = 0; i < h.sections.size(); ++i) {
    const SectionEntry &e = h.sections[i];
    if (std::none_of(add.begin(), add.end(), [&](const Section &s) { return s.tag == e.tag; }))
      sections.push_back({e.tag, e.flags, bytes(L.section_offset[i], e.bytes)});
  }
  sections.insert(sections.end(), add.begin(), add.end());
  std::vector<std::vector<uint8_t>> levels;
  for (size_t i = 0; i < L.level_offset.size(); ++i)
    levels.push_back(bytes(L.level_offset[i],
                           uint64_t(h.levels[i].connectivity_bytes) + h.levels[i].geometry_bytes));
  // The clustered part is copied as it is (tables, index, the blocks in their file order,
  // which a BLKO section defines from the decoded roots: never re-derived here).
  std::vector<uint8_t> tables, index;
  std::vector<const uint8_t *> data;
  std::vector<size_t> data_bytes;
  if (h.clustered()) {
    tables = bytes(L.tables_offset, h.tables_bytes);
    index = bytes(L.index_offset, h.index_bytes);
    read_cluster_index(index.data(), L); // checked before it is copied
    data.push_back(file + L.clusters_offset);
    data_bytes.push_back(h.cluster_bytes);
  }
  return assemble(h, base, levels, tables, index, data, data_bytes, sections);
}

void check_block(const uint8_t *data, size_t size, uint32_t expected, const char *what) {
  if (checksum(data, size) != expected)
    throw Error(Error::Kind::DamagedFile,
                std::string("damaged .pomar file: ") + what + " checksum mismatch");
}

FileInfo file_info(const FileLayout &L, uint64_t file_size) {
  const FileHeader &h = L.header;
  FileInfo info;
  info.version = h.version;
  info.bits = h.grid.bits;
  info.grid = h.grid;
  for (int k = 0; k < 3; ++k) {
    info.bbox_min[k] = h.grid.origin[k];
    info.bbox_max[k] = static_cast<float>(double(h.grid.origin[k]) + h.grid.extent);
  }
  info.vertices = h.vertices;
  info.faces = h.faces;
  info.base_vertices = h.base_vertices;
  info.base_faces = h.base_faces;
  for (const LevelEntry &e : h.levels) {
    info.levels.push_back({e.vertices, e.faces, e.connectivity_bytes, e.geometry_bytes});
    info.connectivity_bytes += e.connectivity_bytes;
    info.geometry_bytes += e.geometry_bytes;
  }
  if (h.clustered()) {
    info.global_levels = h.global_levels;
    info.clusters = h.clusters;
    info.tables_bytes = h.tables_bytes;
    info.index_bytes = h.index_bytes;
    info.cluster_bytes = h.cluster_bytes;
    info.connectivity_bytes += h.cluster_connectivity_bytes;
    info.geometry_bytes += h.cluster_bytes - h.cluster_connectivity_bytes;
  } else {
    info.global_levels = static_cast<uint32_t>(h.levels.size());
  }
  info.global_bytes = L.global_bytes;
  info.total_bytes = file_size;
  info.header_bytes = L.header_bytes;
  info.base_bytes = h.base_bytes;
  for (const SectionEntry &e : h.sections) {
    std::string name;
    for (int k = 0; k < 4; ++k)
      name += static_cast<char>(e.tag >> (8 * k));
    info.sections.push_back({name, e.bytes, (e.flags & kSectionRequired) != 0});
    if (e.tag == section_tag("ATTR"))
      info.attribute_bytes += e.bytes;
    if (e.tag == kLosslessTag)
      info.lossless_bytes += e.bytes;
  }
  info.input_vertices = h.vertices; // inspect() reads a lossless record's counts
  info.input_faces = h.faces;
  return info;
}

} // namespace pomar
