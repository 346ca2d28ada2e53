// Inputs the fuzzers (tests/fuzz/) found, replayed through the public API in the normal
// suite (and under ASan + UBSan by scripts/test.sh).
#include <gtest/gtest.h>

#include <fstream>

#include <dirent.h>
#include <filesystem>
#include <memory>

#include "pomar/mesh_io.h"
#include "pomar/random_access.h"

namespace pomar {
namespace {

namespace fs = std::filesystem;
const fs::path kRegressions = fs::path(POMAR_SOURCE_DIR) / "tests" / "fuzz" / "regressions";

size_t open_descriptors() {
  size_t n = 0;
  if (DIR *d = opendir("/proc/self/fd")) {
    while (readdir(d))
      ++n;
    closedir(d);
  }
  return n;
}

TEST(FuzzRegressions, EmptyInputIsAClearErrorForEveryDecoder) {
  const std::vector<uint8_t> empty;
  EXPECT_THROW(inspect(empty.data(), 0), Error);
  EXPECT_THROW(decode(empty.data(), 0), Error);
  EXPECT_THROW(SelectiveDecoder(std::make_unique<MemorySource>(empty.data(), 0)), Error);
}

TEST(FuzzRegressions, MalformedAsciiStlIsRefusedWithoutLeakingAFile) {
  const fs::path input = kRegressions / "readers-crash-4401b907a1f8de537c2abb1f6b764df01fb4ad75";
  ASSERT_TRUE(fs::exists(input));
  const fs::path stl = fs::path(::testing::TempDir()) / "pomar_fuzz_regression.stl";
  fs::copy_file(input, stl, fs::copy_options::overwrite_existing);
  const size_t before = open_descriptors();
  for (int i = 0; i < 20; ++i)
    EXPECT_THROW(load_mesh(stl.string()), Error);
  EXPECT_EQ(open_descriptors(), before);
  fs::remove(stl);
}

/// The message load_mesh refuses regression file `name` with, read as an OFF file (empty,
/// and a test failure, if it loads).
std::string off_refusal(const char *name) {
  const fs::path input = kRegressions / name;
  EXPECT_TRUE(fs::exists(input)) << name;
  const fs::path off = fs::path(::testing::TempDir()) / "pomar_fuzz_regression.off";
  fs::copy_file(input, off, fs::copy_options::overwrite_existing);
  std::string message;
  try {
    load_mesh(off.string());
    ADD_FAILURE() << name << " was accepted";
  } catch (const Error &e) {
    message = e.what();
  }
  fs::remove(off);
  return message;
}

TEST(FuzzRegressions, OffColourMapIndexOutOfRangeIsRefused) {
  // A COFF vertex with one colour value (a colour map index) of 255: vcglib's importer
  // indexed its 148-entry map with it (undefined behaviour found by fuzz_mesh_readers).
  const std::string e =
      off_refusal("readers-ub-off-colormap-6395a3bbed1ac736d4e77c2f3808ef9e5cb09a1d");
  EXPECT_NE(e.find("colour map index"), std::string::npos) << e;
}

TEST(FuzzRegressions, OffFloatColourOutOfRangeIsRefused) {
  // A COFF vertex whose RGB, read as floats by vcglib (a dot in the first value), holds
  // 2.0: vcglib converted 2 x 255 to a byte (undefined behaviour found by
  // fuzz_mesh_readers). The walk refuses float colours outside 0..1 first.
  const std::string e =
      off_refusal("readers-ub-off-float-colour-50a9851dafe258d90841ea5feab775dd68571450");
  EXPECT_NE(e.find("outside 0..1"), std::string::npos) << e;
  // In range, the same file shape loads: floats 0..1 are what OFF colours in floats are.
  const fs::path good = fs::path(::testing::TempDir()) / "pomar_colour_ok.off";
  {
    std::ofstream out(good);
    out << "COFF\n3 1 0\n0 0 0 0.5 1.0 0.0\n1 0 0 0.25 0.5 1\n0 1 0 0. 0 1\n3 0 1 2\n";
  }
  const Mesh m = load_mesh(good.string());
  const VertexAttribute *c = m.find(AttributeKind::Colour);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->colour[0], 127); // (unsigned char)(0.5 x 255)
  fs::remove(good);
}

TEST(FuzzRegressions, TristripPlyLoadsOrFailsCleanly) {
  const fs::path input = kRegressions / "readers-leak-fb23e152d22760b7390a120c0738d301e73bd637";
  ASSERT_TRUE(fs::exists(input));
  const fs::path ply = fs::path(::testing::TempDir()) / "pomar_fuzz_regression.ply";
  fs::copy_file(input, ply, fs::copy_options::overwrite_existing);
  try {
    const Mesh m = load_mesh(ply.string());
    EXPECT_GT(m.triangle_count(), 0u);
  } catch (const Error &) {
  }
  fs::remove(ply);
}

} // namespace
} // namespace pomar
