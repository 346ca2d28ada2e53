// pomar::Error kinds and paths from the mesh file readers and writers.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <functional>
#include <string>

#include "pomar/mesh_io.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

using Kind = Error::Kind;

Error error_of(const std::function<void()> &f) {
  try {
    f();
  } catch (const Error &e) {
    return e;
  }
  ADD_FAILURE() << "no pomar::Error thrown";
  return Error("none");
}

std::string temp_path(const char *name) { return testing::TempDir() + "pomar_kinds_" + name; }

TEST(MeshIoKinds, MissingFileIsAnIoErrorNamingThePath) {
  const std::string path = temp_path("missing.ply");
  std::remove(path.c_str());
  const Error e = error_of([&] { load_mesh(path); });
  EXPECT_EQ(e.kind(), Kind::Io);
  EXPECT_EQ(e.path(), path);
  EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u); // the message starts with the path
}

TEST(MeshIoKinds, MalformedFileIsAnInvalidMesh) {
  const std::string path = temp_path("bad.off");
  std::ofstream(path) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"; // index 7 of 3 vertices
  const Error e = error_of([&] { load_mesh(path); });
  EXPECT_EQ(e.kind(), Kind::InvalidMesh) << e.what();
  EXPECT_EQ(e.path(), path);
  std::remove(path.c_str());
}

TEST(MeshIoKinds, UnknownExtensionIsAUsageError) {
  const Error e = error_of([&] { save_mesh(temp_path("mesh.xyz"), gen::tetrahedron()); });
  EXPECT_EQ(e.kind(), Kind::Usage);
}

TEST(MeshIoKinds, UnwritableDestinationIsAnIoError) {
  const std::string path = "/nonexistent/pomar/dir/out.ply";
  const Error e = error_of([&] { save_mesh(path, gen::tetrahedron()); });
  EXPECT_EQ(e.kind(), Kind::Io);
  EXPECT_EQ(e.path(), path);
}

TEST(MeshIoKinds, SizeCheckKeepsItsKind) {
  const std::string path = temp_path("tetra.off");
  save_mesh(path, gen::tetrahedron());
  const Error e = error_of([&] {
    load_mesh(path, nullptr,
              [](uint64_t, uint64_t) { throw Error(Kind::MemoryLimit, "not enough memory"); });
  });
  EXPECT_EQ(e.kind(), Kind::MemoryLimit);
  EXPECT_EQ(e.path(), path);
  std::remove(path.c_str());
}

} // namespace
} // namespace pomar
