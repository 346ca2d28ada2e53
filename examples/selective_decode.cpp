// Random access: decode one region of a .pomar file at full resolution, reading only the
// cluster blocks it needs.
#include <pomar/random_access.h>

#include <cstdio>
#include <memory>

int main(int argc, char **argv) try {
  if (argc != 2)
    return std::fprintf(stderr, "usage: %s IN.pomar\n", argv[0]), 2;
  pomar::SelectiveDecoder d(std::make_unique<pomar::FileSource>(argv[1]));
  const pomar::FileInfo &info = d.info();
  const float centre[3] = {info.bbox_min[0], info.bbox_min[1], info.bbox_min[2]};
  d.want_sphere(centre, 0.5f * info.grid.extent, d.finest_level()); // or want_cluster/box
  d.update();                  // completes the level map, reads only the blocks it needs
  pomar::Mesh part = d.mesh(); // + d.vertex_cluster(), d.vertex_level()
  std::printf("%zu vertices, %llu of %llu bytes read\n", part.vertex_count(),
              (unsigned long long)d.bytes_read(), (unsigned long long)info.total_bytes);
  d.want_all(d.finest_level());
  d.update(); // refines on top of the current state
  return d.mesh().vertex_count() == info.vertices ? 0 : 1;
} catch (const pomar::Error &e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
