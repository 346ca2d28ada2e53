// Compress a mesh file, then decode it coarse and at full resolution.
#include <pomar/mesh_io.h>
#include <pomar/pomar.h>

#include <cstdio>

int main(int argc, char **argv) try {
  if (argc != 3)
    return std::fprintf(stderr, "usage: %s IN.ply OUT.pomar\n", argv[0]), 2;
  pomar::Mesh mesh = pomar::load_mesh(argv[1]); // .ply .obj .off .stl
  pomar::EncodeOptions options;
  options.bits = 12; // quantization grid: 2^12 steps per axis
  std::vector<uint8_t> file = pomar::encode(mesh, options);
  pomar::write_file_atomic(argv[2], file.data(), file.size());

  pomar::FileInfo info = pomar::inspect(file.data(), file.size());
  pomar::Mesh coarse = pomar::decode(file.data(), file.size(), 5); // after 5 levels
  pomar::Mesh full = pomar::decode(file.data(), file.size());      // all levels
  std::printf("pomar %s: %zu bytes, %zu levels; %zu -> %zu vertices\n", pomar::version(),
              file.size(), info.levels.size(), coarse.vertex_count(), full.vertex_count());
  return full.triangle_count() == mesh.triangle_count() ? 0 : 1;
} catch (const pomar::Error &e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
