// The BCHK section (format version 5): every cluster block is checked against 16 bits of
// its XXH32 (section version 2; version 1, the whole XXH32), so a damaged block or a
// misaligned cluster index never decodes to a wrong mesh without an error or a damage
// report, in a full decode and in a region decode alike. A SelectiveDecoder reads the
// section before the first block it reads, not at open.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "format/block_checks.h"
#include "format/block_order.h"
#include "format/file_format.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/block_layout.h"
#include "support/hostile_files.h"
#include "support/mesh_compare.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

using test::canonical;

struct Encoded {
  std::vector<uint8_t> file;
  FileLayout layout;
  ClusterIndex index; // with the section's checks, as a decoder reads them
};

Encoded encode_sphere(int format_version, bool spatial_layout = false) {
  EncodeOptions o;
  o.cluster_ratio = 0.02;
  o.format_version = format_version;
  // Blocks in cluster id order, so that a misaligned index shifts every block after the
  // damage (the default spatial order is checked by the first test).
  o.spatial_layout = spatial_layout;
  Encoded e;
  e.file = encode(gen::icosphere(5), o);
  e.layout = read_layout(e.file.data(), e.file.size());
  e.index = read_cluster_index(e.file.data() + e.layout.index_offset, e.layout);
  load_block_checks(e.file.data(), e.layout, e.index);
  return e;
}

const Encoded &sphere() {
  static const Encoded e = encode_sphere(5);
  return e;
}

std::unique_ptr<SelectiveDecoder> open(const std::vector<uint8_t> &file, bool skip) {
  SelectiveOptions options;
  options.skip_damaged = skip;
  return std::make_unique<SelectiveDecoder>(
      std::make_unique<MemorySource>(file.data(), file.size()), options);
}

/// The mesh an intact file gives for the level map `levels`.
Mesh intact_at(const std::vector<int> &levels) {
  auto d = open(sphere().file, false);
  d->set_wanted(levels);
  d->update();
  EXPECT_EQ(d->levels(), levels);
  return d->mesh();
}

/// What a tolerant decode of a damaged file must be: every report names a cluster (none is
/// a caution that damage could not be located) and the mesh is exactly the intact file's at
/// the level map the damage left.
void expect_no_wrong_mesh(const SelectiveDecoder &d, const std::string &what) {
  for (const DamagedBlock &b : d.damaged()) {
    EXPECT_GE(b.level_kept, 0) << what << ": " << b.block << ": " << b.problem;
    EXPECT_EQ(b.block.rfind("cluster ", 0), 0u) << what << ": " << b.block;
  }
  EXPECT_EQ(canonical(d.mesh()), canonical(intact_at(d.levels()))) << what;
}

TEST(BlockChecks, VersionFiveFilesHoldSixteenBitsOfTheChecksumOfEveryBlock) {
  const Encoded &e = sphere();
  const uint32_t n = e.layout.header.clusters;
  ASSERT_GT(n, 100u);
  const int i = find_section(e.layout, kBlockChecksTag);
  ASSERT_GE(i, 0);
  EXPECT_EQ(e.layout.header.sections[size_t(i)].flags, 0u); // optional
  EXPECT_EQ(e.layout.header.sections[size_t(i)].bytes, 5u + n);
  EXPECT_EQ(e.index.check_mask, 0xFFFFu);
  for (uint32_t c = 0; c < n; ++c)
    EXPECT_EQ(e.index.check[c],
              checksum(e.file.data() + e.index.offset[c], e.index.size[c]) & 0xFFFFu);
  // The same with the blocks in the spatial order (BLKO, the default): the checks stay in
  // cluster id order, each the whole XXH32 of its cluster's block wherever it lies.
  const Encoded spatial = encode_sphere(5, true);
  ASSERT_GE(find_section(spatial.layout, kBlockOrderTag), 0);
  const test::BlockLayout blocks = test::block_layout(spatial.file);
  EXPECT_NE(blocks.order.front(), 0u);
  for (uint32_t c = 0; c < spatial.layout.header.clusters; ++c)
    EXPECT_EQ(spatial.index.check[c],
              checksum(spatial.file.data() + blocks.offset[c], blocks.size[c]) & 0xFFFFu);
  // Format version 4 writes no such section: its blocks keep their 8-bit checks.
  const Encoded v4 = encode_sphere(4);
  EXPECT_EQ(find_section(v4.layout, kBlockChecksTag), -1);
  EXPECT_EQ(v4.index.check_mask, 0xFFu);
  EXPECT_EQ(v4.layout.header.version, kClusteredFormatVersion);
}

TEST(BlockChecks, FlipsThatPassTheEightBitCheckAreNamedNeverDecoded) {
  const Encoded &e = sphere();
  const uint32_t n = e.layout.header.clusters, G = e.layout.header.global_levels;
  const int finest = int(e.layout.header.levels.size());
  int tried = 0;
  for (uint32_t i = 0; i < n && tried < 16; ++i) {
    const uint32_t c = (i * 7919u + n / 3) % n;
    const uint64_t at = e.index.offset[c], size = e.index.size[c];
    if (size < 8)
      continue;
    for (uint32_t k = 0; k < 4096; ++k) {
      std::vector<uint8_t> file = e.file;
      file[at + k % size] ^= uint8_t(1 + k / size);
      if ((checksum(file.data() + at, size) & 0xFF) != (e.index.check[c] & 0xFF))
        continue; // (what the 8-bit check alone catches)
      ++tried;
      const std::string what = "cluster " + std::to_string(c) + ", k " + std::to_string(k);
      try {
        decode(file.data(), file.size());
        ADD_FAILURE() << what << ": a strict decode succeeded";
      } catch (const Error &err) {
        EXPECT_NE(std::string(err.what()).find("cluster " + std::to_string(c)), std::string::npos)
            << what << ": " << err.what();
      }
      const std::vector<DamagedBlock> listed = check_blocks(file.data(), file.size());
      ASSERT_EQ(listed.size(), 1u) << what;
      EXPECT_EQ(listed[0].block, "cluster " + std::to_string(c)) << what;
      // The whole mesh: exactly the damaged cluster reported, kept at the base clustered level.
      auto d = open(file, true);
      d->want_all(finest);
      d->update();
      ASSERT_EQ(d->damaged().size(), 1u) << what;
      EXPECT_EQ(d->damaged()[0].block, "cluster " + std::to_string(c));
      EXPECT_EQ(d->levels()[c], int(G));
      expect_no_wrong_mesh(*d, what);
      // A region around it: the same.
      auto r = open(file, true);
      r->want_cluster(c, finest);
      r->update();
      ASSERT_EQ(r->damaged().size(), 1u) << what;
      expect_no_wrong_mesh(*r, what + ", region");
      // Strict, the region needs the block whole: an error naming it.
      auto s = open(file, false);
      s->want_cluster(c, finest);
      EXPECT_THROW(s->update(), Error) << what;
      break;
    }
  }
  EXPECT_GE(tried, 12);
}

TEST(BlockChecks, AMisalignedIndexNeverDecodesWrongData) {
  const Encoded &e = sphere();
  const uint32_t n = e.layout.header.clusters;
  const int finest = int(e.layout.header.levels.size());
  ClusterIndex plain = read_cluster_index(e.file.data() + e.layout.index_offset, e.layout);
  for (const uint32_t k : {3u, n / 2, n - 12}) {
    ClusterIndex shifted = plain;
    ++shifted.size[k]; // every later block is read one byte off
    --shifted.size[n - 1];
    const std::vector<uint8_t> file = hostile::with_cluster_index(e.file, shifted);
    const std::string what = "misaligned after cluster " + std::to_string(k);
    EXPECT_THROW(decode(file.data(), file.size()), Error) << what;
    const std::vector<DamagedBlock> listed = check_blocks(file.data(), file.size());
    size_t moved = 0;
    for (uint32_t c = k; c < n; ++c)
      moved += plain.size[c] > 0;
    EXPECT_GE(listed.size(), moved - 1) << what; // (an empty block reads the same anywhere)
    for (const DamagedBlock &b : listed) {
      ASSERT_EQ(b.block.rfind("cluster ", 0), 0u) << what << ": " << b.block;
      EXPECT_GE(std::stoul(b.block.substr(8)), k) << what;
    }
    auto d = open(file, true);
    d->want_all(finest);
    d->update();
    EXPECT_FALSE(d->damaged().empty()) << what;
    expect_no_wrong_mesh(*d, what);
    DecodeOptions o;
    o.skip_damaged = true;
    DecodeReport report;
    const Mesh m = decode(file.data(), file.size(), o, &report);
    EXPECT_EQ(canonical(m), canonical(d->mesh())) << what;
    // Regions on both sides of the misalignment.
    for (const uint32_t c : {k / 2, (k + n) / 2}) {
      auto r = open(file, true);
      r->want_cluster(c, finest);
      r->update();
      expect_no_wrong_mesh(*r, what + ", region of cluster " + std::to_string(c));
    }
  }
}

TEST(BlockChecks, VersionOneSectionsStillCheckTheWholeChecksum) {
  const Encoded &e = sphere();
  const uint32_t n = e.layout.header.clusters;
  std::vector<std::vector<uint8_t>> blocks(n);
  for (uint32_t c = 0; c < n; ++c)
    blocks[c].assign(e.file.begin() + long(e.index.offset[c]),
                     e.file.begin() + long(e.index.offset[c] + e.index.size[c]));
  const std::vector<uint8_t> v1 = with_sections(
      e.file.data(), e.file.size(), {{kBlockChecksTag, 0, write_block_checks_v1(blocks)}});
  const FileLayout layout = read_layout(v1.data(), v1.size());
  EXPECT_EQ(layout.header.sections[size_t(find_section(layout, kBlockChecksTag))].bytes,
            5u + 3u * n);
  ClusterIndex index = read_cluster_index(v1.data() + layout.index_offset, layout);
  load_block_checks(v1.data(), layout, index);
  EXPECT_EQ(index.check_mask, 0xFFFFFFFFu);
  for (uint32_t c = 0; c < n; ++c)
    EXPECT_EQ(index.check[c], checksum(blocks[c].data(), blocks[c].size()));
  // It decodes as the file with the version 2 section does; a block damaged where the
  // version 2 check would pass but the whole checksum fails is still caught.
  auto a = open(v1, false), b = open(e.file, false);
  a->want_all(a->finest_level());
  b->want_all(b->finest_level());
  a->update();
  b->update();
  EXPECT_EQ(canonical(a->mesh()), canonical(b->mesh()));
}

TEST(BlockChecks, ReadOnlyWhenTheFirstBlockIsRead) {
  const Encoded &e = sphere();
  const int i = find_section(e.layout, kBlockChecksTag);
  ASSERT_GE(i, 0);
  const uint64_t section = e.layout.header.sections[size_t(i)].bytes;
  const int cerr = find_section(e.layout, section_tag("CERR"));
  ASSERT_GE(cerr, 0);
  const uint64_t errors = e.layout.header.sections[size_t(cerr)].bytes;
  auto d = open(e.file, false);
  // Open: the global part without the two per-cluster sections.
  EXPECT_EQ(d->bytes_read(), e.layout.global_bytes - section - errors);
  d->update(); // nothing wanted past the base clustered mesh: still nothing read
  EXPECT_EQ(d->bytes_read(), e.layout.global_bytes - section - errors);
  d->want_cluster(3, d->finest_level());
  d->update();
  // The blocks and the checks, not the stored errors (no view asked for them).
  EXPECT_GT(d->blocks_read(), 0u);
  const uint64_t after_region = d->bytes_read();
  EXPECT_GE(after_region, e.layout.global_bytes - errors);
  EXPECT_LT(after_region, e.file.size());
  EXPECT_GT(d->cluster_error(3, d->base_clustered_level()), 0.0); // reads CERR
  EXPECT_EQ(d->bytes_read(), after_region + errors);
  d->cluster_error(4, d->base_clustered_level()); // once
  EXPECT_EQ(d->bytes_read(), after_region + errors);
}

TEST(BlockChecks, ADamagedSectionIsNamed) {
  const Encoded &e = sphere();
  const int i = find_section(e.layout, kBlockChecksTag);
  ASSERT_GE(i, 0);
  // A wrong cluster count, the section's checksum right: refused, naming the section.
  std::vector<uint8_t> file = e.file;
  file[e.layout.section_offset[size_t(i)] + 1] ^= 1;
  ASSERT_TRUE(hostile::repair_checksums(file));
  for (const bool skip : {false, true}) {
    // Opened (the section is read with the first block), refused at the first block.
    auto d = open(file, skip);
    d->want_cluster(0, d->finest_level());
    try {
      d->update();
      ADD_FAILURE() << "decoded a block";
    } catch (const Error &err) {
      EXPECT_EQ(err.kind(), Error::Kind::DamagedFile);
      EXPECT_NE(std::string(err.what()).find("BCHK"), std::string::npos) << err.what();
    }
  }
  EXPECT_THROW(check_blocks(file.data(), file.size()), Error);
  EXPECT_THROW(inspect(file.data(), file.size()), Error); // pomar info: exit 4
  // A flipped byte, the section's checksum left as it was: named too.
  std::vector<uint8_t> flipped = e.file;
  flipped[e.layout.section_offset[size_t(i)] + 7] ^= 0x10;
  try {
    inspect(flipped.data(), flipped.size());
    ADD_FAILURE() << "inspect accepted a damaged BCHK section";
  } catch (const Error &err) {
    EXPECT_NE(std::string(err.what()).find("BCHK"), std::string::npos) << err.what();
  }
  auto d = open(flipped, true);
  d->want_all(d->finest_level());
  try {
    d->update();
    ADD_FAILURE() << "decoded with a damaged BCHK section";
  } catch (const Error &err) {
    EXPECT_NE(std::string(err.what()).find("BCHK"), std::string::npos) << err.what();
  }
}

} // namespace
} // namespace pomar
