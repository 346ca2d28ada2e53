// Format version 4: sections in the global part (docs/format.md, "Version 4: sections").
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>

#include "format/file_format.h"
#include "pomar/limits.h"
#include "pomar/random_access.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

/// A file of `m` whose only sections are those the tests add: version 5 random-access
/// files otherwise carry BLKO and CERR (FormatSections.Version5RandomAccessFilesHaveTheir
/// SectionsByDefault).
std::vector<uint8_t> file_of(const Mesh &m, bool progressive, int format_version = 5) {
  EncodeOptions o;
  o.progressive = progressive;
  o.clusters = progressive ? 0 : 8;
  o.memory_limit = kNoMemoryLimit;
  o.format_version = format_version;
  o.spatial_layout = false;
  o.cluster_errors = false;
  return encode(m, o);
}

const Section kOptional{section_tag("TST1"), 0, {10, 20, 30}};
const Section kRequired{section_tag("TST2"), kSectionRequired, {1}};

TEST(FormatSections, TheVersion4LayoutWithoutSectionsKeepsVersion1And3) {
  const std::vector<uint8_t> p = file_of(gen::icosphere(2), true, 4);
  EXPECT_EQ(inspect(p.data(), p.size()).version, 1u);
  const std::vector<uint8_t> c = file_of(gen::icosphere(2), false, 4);
  EXPECT_EQ(inspect(c.data(), c.size()).version, 3u);
  // Re-assembling without sections gives back the same bytes.
  EXPECT_EQ(with_sections(c.data(), c.size(), {}), c);
  EXPECT_EQ(with_sections(p.data(), p.size(), {}), p);
  // Both decode to what version 5 files of the same mesh decode to.
  for (bool progressive : {true, false}) {
    const std::vector<uint8_t> old = progressive ? p : c,
                               v5 = file_of(gen::icosphere(2), progressive);
    EXPECT_EQ(inspect(v5.data(), v5.size()).version, 5u);
    const Mesh a = decode(old.data(), old.size()), b = decode(v5.data(), v5.size());
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.triangles, b.triangles);
  }
}

TEST(FormatSections, Version5FilesHaveASectionTableAndKeepTheirVersion) {
  for (bool progressive : {true, false}) {
    const std::vector<uint8_t> f = file_of(gen::icosphere(2), progressive);
    const FileLayout layout = read_layout(f.data(), f.size());
    EXPECT_EQ(layout.header.version, kPatchRankFormatVersion);
    EXPECT_TRUE(layout.header.flags & kFlagSections);
    // No section but, in a random-access file, the blocks' 32-bit checks.
    ASSERT_EQ(layout.header.sections.size(), progressive ? 0u : 1u);
    if (!progressive) {
      EXPECT_EQ(layout.header.sections[0].tag, section_tag("BCHK"));
    }
    EXPECT_EQ(with_sections(f.data(), f.size(), {}), f);
    const std::vector<uint8_t> g = with_sections(f.data(), f.size(), {kOptional});
    EXPECT_EQ(inspect(g.data(), g.size()).version, 5u);
    EXPECT_EQ(g.size(), f.size() + kSectionEntryBytes + 3);
    EXPECT_EQ(decode(g.data(), g.size()).triangles, decode(f.data(), f.size()).triangles);
  }
}

TEST(FormatSections, Version5RandomAccessFilesHaveTheirSectionsByDefault) {
  EncodeOptions o;
  o.clusters = 8;
  const Mesh m = gen::icosphere(2);
  const std::vector<uint8_t> f = encode(m, o);
  const FileInfo info = inspect(f.data(), f.size());
  ASSERT_EQ(info.version, 5u);
  ASSERT_EQ(info.sections.size(), 3u);
  std::vector<std::string> names;
  for (const FileInfo::Section &s : info.sections)
    names.push_back(s.name);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"BCHK", "BLKO", "CERR"}));
  for (const FileInfo::Section &s : info.sections)
    EXPECT_EQ(s.required, s.name == "BLKO");
  // Off, one by one; the mesh is the same.
  o.block_checks = false;
  for (const bool errors : {false, true}) {
    o.cluster_errors = errors;
    o.spatial_layout = !errors;
    const std::vector<uint8_t> g = encode(m, o);
    const FileInfo gi = inspect(g.data(), g.size());
    ASSERT_EQ(gi.sections.size(), 1u);
    EXPECT_EQ(gi.sections[0].name, errors ? "CERR" : "BLKO");
    EXPECT_EQ(decode(g.data(), g.size()).triangles, decode(f.data(), f.size()).triangles);
  }
  o.cluster_errors = o.spatial_layout = false;
  o.block_checks = true;
  const std::vector<uint8_t> checks_only = encode(m, o);
  const FileInfo ci = inspect(checks_only.data(), checks_only.size());
  ASSERT_EQ(ci.sections.size(), 1u);
  EXPECT_EQ(ci.sections[0].name, "BCHK");
  // Format version 4 writes none (its readers would refuse BLKO): version 3, no table.
  o.cluster_errors = o.spatial_layout = true;
  o.format_version = 4;
  const std::vector<uint8_t> v4 = encode(m, o);
  EXPECT_EQ(inspect(v4.data(), v4.size()).version, 3u);
  EXPECT_TRUE(inspect(v4.data(), v4.size()).sections.empty());
}

TEST(FormatSections, TheEncoderRefusesAnUnknownFormatVersion) {
  for (int version : {1, 3, 6}) {
    try {
      file_of(gen::icosphere(1), true, version);
      ADD_FAILURE() << "version " << version << " accepted";
    } catch (const Error &e) {
      EXPECT_EQ(e.kind(), Error::Kind::Usage);
      EXPECT_NE(std::string(e.what()).find("format version 4 or 5"), std::string::npos);
    }
  }
}

TEST(FormatSections, SectionsAreListedAndTheMeshDecodesUnchanged) {
  for (bool progressive : {true, false}) {
    const Mesh m = gen::torus(16, 10);
    const std::vector<uint8_t> plain = file_of(m, progressive, 4);
    const std::vector<uint8_t> v4 = with_sections(plain.data(), plain.size(), {kOptional});
    const FileInfo info = inspect(v4.data(), v4.size());
    EXPECT_EQ(info.version, 4u);
    EXPECT_EQ(info.clustered(), !progressive);
    ASSERT_EQ(info.sections.size(), 1u);
    EXPECT_EQ(info.sections[0].name, "TST1");
    EXPECT_EQ(info.sections[0].bytes, 3u);
    EXPECT_FALSE(info.sections[0].required);
    EXPECT_EQ(v4.size(), plain.size() + 4 + kSectionEntryBytes + 3);
    const Mesh a = decode(plain.data(), plain.size()), b = decode(v4.data(), v4.size());
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_EQ(a.triangles, b.triangles);
    for (int level : {0, 2})
      EXPECT_EQ(decode(plain.data(), plain.size(), level).triangles,
                decode(v4.data(), v4.size(), level).triangles);
    // The selective decoder reads the longer header in steps and decodes the same.
    SelectiveDecoder d(std::make_unique<MemorySource>(v4.data(), v4.size()));
    d.want_all(d.finest_level());
    d.update();
    EXPECT_EQ(d.mesh().triangles, a.triangles);
    // The body reads back, and a second with_sections replaces it by tag.
    const FileLayout L = read_layout(v4.data(), v4.size());
    const int i = find_section(L, kOptional.tag);
    ASSERT_GE(i, 0);
    const uint8_t *body = section_body(v4.data(), L, size_t(i));
    EXPECT_EQ(std::vector<uint8_t>(body, body + 3), kOptional.body);
    const Section other{kOptional.tag, 0, std::vector<uint8_t>(1, 7)};
    const std::vector<uint8_t> again = with_sections(v4.data(), v4.size(), {other});
    const FileInfo info2 = inspect(again.data(), again.size());
    ASSERT_EQ(info2.sections.size(), 1u);
    EXPECT_EQ(info2.sections[0].bytes, 1u);
  }
}

TEST(FormatSections, AnUnknownRequiredSectionIsRefusedByName) {
  const std::vector<uint8_t> plain = file_of(gen::icosphere(2), false);
  const std::vector<uint8_t> v4 = with_sections(plain.data(), plain.size(), {kOptional, kRequired});
  EXPECT_EQ(inspect(v4.data(), v4.size()).sections.size(),
            inspect(plain.data(), plain.size()).sections.size() + 2); // info still works
  try {
    (void)decode(v4.data(), v4.size());
    FAIL() << "decoded a file with an unknown required section";
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("'TST2'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SelectiveDecoder(std::make_unique<MemorySource>(v4.data(), v4.size())), Error);
}

TEST(FormatSections, ADamagedSectionBodyIsNamed) {
  const std::vector<uint8_t> plain = file_of(gen::icosphere(2), true);
  std::vector<uint8_t> v4 = with_sections(plain.data(), plain.size(), {kOptional});
  const FileLayout L = read_layout(v4.data(), v4.size());
  v4[L.section_offset[0] + 1] ^= 0x40;
  try {
    section_body(v4.data(), L, 0);
    FAIL() << "a damaged section passed its checksum";
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("section 'TST1'"), std::string::npos) << e.what();
  }
  // A file cut inside the sections is truncated before anything can be decoded.
  EXPECT_THROW(read_layout(v4.data(), L.section_offset[0] + 1, L.section_offset[0] + 1, true),
               Error);
}

} // namespace
} // namespace pomar
