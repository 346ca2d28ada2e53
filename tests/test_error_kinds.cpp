// pomar::Error kinds, paths and block locations, and DamagedBlock's integer fields: what
// callers (the tool, the plugins) act on instead of matching message text.
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/block_layout.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

using Kind = Error::Kind;

/// The error `f` throws (fails the test if it throws none).
Error error_of(const std::function<void()> &f) {
  try {
    f();
  } catch (const Error &e) {
    return e;
  }
  ADD_FAILURE() << "no pomar::Error thrown";
  return Error("none");
}

std::vector<uint8_t> clustered_file() {
  EncodeOptions o;
  o.cluster_ratio = 0.02;
  static const std::vector<uint8_t> file = encode(gen::icosphere(4), o);
  return file;
}

TEST(ErrorKinds, MessageOnlyErrorsHaveNoKindPathOrBlock) {
  const Error e("refused");
  EXPECT_EQ(e.kind(), Kind::Other);
  EXPECT_TRUE(e.path().empty());
  EXPECT_FALSE(e.in_block());
  EXPECT_STREQ(e.what(), "refused");
}

TEST(ErrorKinds, InvalidInputMeshes) {
  EncodeOptions strict; // (by default such meshes are encoded exactly: test_lossless.cpp)
  strict.strict = true;
  for (const Mesh &m : {gen::nonmanifold_edge(), gen::flipped_face(), gen::repeated_vertex_face()})
    EXPECT_EQ(error_of([&] { encode(m, strict); }).kind(), Kind::InvalidMesh);
  Mesh only_degenerate = gen::tetrahedron();
  only_degenerate.triangles = {0, 0, 1, 2, 3, 3};
  EXPECT_EQ(error_of([&] { encode(only_degenerate); }).kind(), Kind::InvalidMesh);
  Mesh nan = gen::tetrahedron();
  nan.positions[4] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(error_of([&] { encode(nan); }).kind(), Kind::InvalidMesh);
}

TEST(ErrorKinds, BadArgumentsAreUsageErrors) {
  EncodeOptions o;
  o.bits = 30;
  EXPECT_EQ(error_of([&] { encode(gen::tetrahedron(), o); }).kind(), Kind::Usage);
  const std::vector<uint8_t> file = clustered_file();
  const Error level = error_of([&] { decode(file.data(), file.size(), 999); });
  EXPECT_EQ(level.kind(), Kind::Usage);
  EXPECT_NE(std::string(level.what()).find("level 999 does not exist"), std::string::npos);
  EXPECT_EQ(error_of([] { check_level_exists(-1, 3); }).kind(), Kind::Usage);
  EXPECT_NO_THROW(check_level_exists(3, 3));
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()));
  EXPECT_EQ(error_of([&] { d.want_cluster(d.cluster_count(), 1); }).kind(), Kind::Usage);
  EXPECT_EQ(error_of([&] { d.want_all(d.finest_level() + 1); }).kind(), Kind::Usage);
}

TEST(ErrorKinds, MemoryLimit) {
  EncodeOptions o;
  o.memory_limit = 1024;
  EXPECT_EQ(error_of([&] { encode(gen::icosphere(4), o); }).kind(), Kind::MemoryLimit);
}

TEST(ErrorKinds, NotAPomarFile) {
  const std::vector<uint8_t> garbage(4096, 0x5A);
  const Error e = error_of([&] { decode(garbage.data(), garbage.size()); });
  EXPECT_EQ(e.kind(), Kind::DamagedFile);
  EXPECT_FALSE(e.in_block()); // nothing --skip-damaged could decode around
}

TEST(ErrorKinds, DamagedGlobalLevelNamesItsLevel) {
  EncodeOptions o;
  o.progressive = true;
  std::vector<uint8_t> file = encode(gen::icosphere(4), o);
  const FileInfo info = inspect(file.data(), file.size());
  ASSERT_GE(info.levels.size(), 2u);
  // The last level's block ends the file: damage its middle.
  const uint64_t last = info.levels.back().connectivity_bytes + info.levels.back().geometry_bytes;
  file[file.size() - last / 2 - 1] ^= 0x40;
  const int level = static_cast<int>(info.levels.size());
  const Error e = error_of([&] { decode(file.data(), file.size()); });
  EXPECT_EQ(e.kind(), Kind::DamagedFile);
  EXPECT_EQ(e.level(), level);
  EXPECT_EQ(e.cluster(), Error::kNoBlock);
  const std::vector<DamagedBlock> listed = check_blocks(file.data(), file.size());
  ASSERT_EQ(listed.size(), 1u);
  EXPECT_EQ(listed[0].level, level);
  EXPECT_EQ(listed[0].cluster, -1);
  EXPECT_EQ(listed[0].block, "level " + std::to_string(level));
}

TEST(ErrorKinds, DamagedAndMissingClusterBlocksNameTheirCluster) {
  const std::vector<uint8_t> intact = clustered_file();
  const FileInfo info = inspect(intact.data(), intact.size());
  ASSERT_GT(info.clusters, 2u);
  // Damage the cluster whose block ends the file (any block order).
  const uint32_t c = test::block_layout(intact).order.back();
  ASSERT_GT(info.cluster_block_bytes[c], 4u);
  std::vector<uint8_t> file = intact;
  file[file.size() - info.cluster_block_bytes[c] / 2 - 1] ^= 0x21;
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()));
  d.want_cluster(c, d.finest_level());
  const Error e = error_of([&] { d.update(); });
  EXPECT_EQ(e.kind(), Kind::DamagedFile);
  EXPECT_EQ(e.cluster(), int64_t(c));
  EXPECT_EQ(e.level(), Error::kNoBlock);

  // Truncated inside the cluster data: the missing blocks are TruncatedFile errors.
  const std::vector<uint8_t> cut(intact.begin(), intact.end() - info.cluster_block_bytes[c] / 2);
  const std::vector<DamagedBlock> listed = check_blocks(cut.data(), cut.size());
  ASSERT_FALSE(listed.empty());
  EXPECT_EQ(listed.back().cluster, int64_t(c));
  EXPECT_EQ(listed.back().level, -1);
  EXPECT_EQ(listed.back().block, "cluster " + std::to_string(c));
  const Error t = error_of([&] { decode(cut.data(), cut.size()); });
  EXPECT_EQ(t.kind(), Kind::TruncatedFile) << t.what();
}

TEST(ErrorKinds, MissingFileIsAnIoErrorNamingThePath) {
  const std::string path = "/nonexistent/pomar/dir/x.pomar";
  const Error e = error_of([&] { FileSource source(path); });
  EXPECT_EQ(e.kind(), Kind::Io);
  EXPECT_EQ(e.path(), path);
}

} // namespace
} // namespace pomar

namespace pomar {
namespace {

TEST(Printable, EscapesWhatATerminalWouldObey) {
  EXPECT_EQ(printable("quality"), "quality");
  EXPECT_EQ(printable("caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80"),
            "caf\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80"); // valid UTF-8 stays
  EXPECT_EQ(printable("a\x1b[31mred\x07"), "a\\x1b[31mred\\x07");
  EXPECT_EQ(printable("line\nbreak\ttab\x7f"), "line\\x0abreak\\x09tab\\x7f");
  EXPECT_EQ(printable("uality\x81\x8f"), "uality\\x81\\x8f"); // stray continuation bytes
  EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");             // overlong
  EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");    // a surrogate
  EXPECT_EQ(printable("\xe2\x82"), "\\xe2\\x82");             // cut short
  EXPECT_EQ(printable(std::string("nul\0byte", 8)), "nul\\x00byte");
}

} // namespace
} // namespace pomar
