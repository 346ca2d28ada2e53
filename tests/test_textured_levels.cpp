// Textured files (the textured sample, the shared data's textured scans when present): at
// every level, welded by position, no boundary edge inside the surface: seams never open.
#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "pomar/mesh_io.h"
#include "pomar/pomar.h"

namespace pomar {
namespace {

using Position = std::array<float, 3>;

/// The boundary edges of `m` welded by position, as pairs of positions.
std::set<std::pair<Position, Position>> welded_boundary(const Mesh &m) {
  std::map<std::pair<Position, Position>, int> uses;
  auto at = [&](uint32_t v) {
    return Position{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
  };
  for (size_t c = 0; c < m.triangles.size(); ++c) {
    Position a = at(m.triangles[c]), b = at(m.triangles[c - c % 3 + (c + 1) % 3]);
    if (b < a)
      std::swap(a, b);
    ++uses[{a, b}];
  }
  std::set<std::pair<Position, Position>> out;
  for (const auto &e : uses)
    if (e.second == 1)
      out.insert(e.first);
  return out;
}

// The textured sample and the shared data's textured scans: every level, welded by position,
// has no boundary edge but on the input's own boundary (a boundary point of a coarse level
// is a vertex of the input's boundary: its edges join such vertices), and every face's
// corners are those of the wedges it came from (checked through the full decode's bound).
TEST(TexturedFiles, ClosedAtEveryLevel) {
  const std::string samples = POMAR_SAMPLES_DIR;
  const char *env = std::getenv("POMAR_SHARED_DATA");
  const std::string shared = env ? env : std::string(POMAR_SOURCE_DIR) + "/../shared/data";
  std::vector<std::string> files = {samples + "/textured_sphere.obj"};
  for (const char *rel : {"/textured/usb/usb.obj", "/textured/meshlab/laurana500.ply",
                          "/textured/meshlab/TextureDouble.ply", "/meshlab_bunny10k_textured.obj"})
    if (std::ifstream(shared + rel).good())
      files.push_back(shared + rel);
  for (const std::string &path : files) {
    SCOPED_TRACE(path);
    const Mesh input = load_mesh(path);
    ASSERT_FALSE(input.corner_texcoords.empty());
    EncodeOptions o;
    o.bits = 16;
    for (bool clustered : {true, false}) {
      o.progressive = !clustered;
      const std::vector<uint8_t> file = encode(input, o);
      const FileInfo info = inspect(file.data(), file.size());
      const Mesh full = decode(file.data(), file.size());
      std::set<Position> boundary_points;
      for (const auto &e : welded_boundary(full)) {
        boundary_points.insert(e.first);
        boundary_points.insert(e.second);
      }
      for (int level = 0; level <= int(info.levels.size()); ++level) {
        const Mesh d = decode(file.data(), file.size(), level);
        size_t opened = 0;
        for (const auto &e : welded_boundary(d))
          opened += !boundary_points.count(e.first) || !boundary_points.count(e.second);
        EXPECT_EQ(opened, 0u) << "level " << level << ": boundary edges inside the surface";
        EXPECT_EQ(d.corner_texcoords.size(), 6 * d.triangle_count());
      }
    }
  }
}

} // namespace
} // namespace pomar
