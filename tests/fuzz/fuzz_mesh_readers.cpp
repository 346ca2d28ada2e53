// libFuzzer target: the mesh file readers (vcglib PLY/OFF/STL, binary STL, tinyobjloader
// OBJ) via pomar::load_mesh, then pomar::encode on whatever loads.
// pomar::Error is the expected way to reject input; anything else is a finding.
#include <pomar/limits.h>
#include <pomar/mesh_io.h>
#include <pomar/pomar.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <fcntl.h>
#include <unistd.h>
#include <vector>

namespace {

/// Memory limit for loading and encoding (see LLVMFuzzerTestOneInput).
constexpr uint64_t kMemoryLimit = 1ull << 30;

std::string temp_base() {
  const char *dir = std::getenv("TMPDIR");
  std::string base = std::string(dir && *dir ? dir : "/tmp") + "/pomar_fuzz_readers." +
                     std::to_string(static_cast<long>(getpid()));
  return base;
}
// The open file descriptors below 256 (a reader that leaks a FILE* adds one).
std::vector<int> open_fds() {
  std::vector<int> fds;
  for (int fd = 0; fd < 256; ++fd)
    if (fcntl(fd, F_GETFD) != -1) fds.push_back(fd);
  return fds;
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  if (size > 64 * 1024) return 0;
  static const std::string base = temp_base();
  for (const char *ext : {".ply", ".obj", ".off", ".stl"}) {
    const std::string path = base + ext;
    {
      std::FILE *f = std::fopen(path.c_str(), "wb");
      if (!f) {
        std::perror(path.c_str());
        std::abort();
      }
      if (size && std::fwrite(data, 1, size, f) != size) std::abort();
      std::fclose(f);
    }
    pomar::Mesh mesh;
    bool loaded = false;
    const std::vector<int> fds_before = open_fds();
    try {
      // An explicit memory limit (below -rss_limit_mb=2048), checked from the headers:
      // refusals do not depend on the machine's free memory.
      mesh = pomar::load_mesh(path, nullptr, [](uint64_t v, uint64_t f) {
        pomar::check_encode_memory(v, f, kMemoryLimit);
      });
      loaded = true;
    } catch (const pomar::Error &) {
    }
    std::remove(path.c_str());
    // A leaked FILE*/fd is a finding too: after `ulimit -n` inputs fopen fails (EMFILE).
    const std::vector<int> fds_after = open_fds();
    // (regressions/readers-crash-4401b907...: vcglib's ASCII STL reader leaks its FILE on a
    // malformed vertex; pomar reads ASCII STL itself.)
    if (fds_after != fds_before) {
      std::fprintf(stderr, "file descriptor leak: load_mesh(\"%s\") left %zu more open\n",
                   path.c_str(), fds_after.size() - fds_before.size());
      std::abort();
    }
    if (!loaded) continue;
    try {
      pomar::EncodeOptions opt;
      opt.memory_limit = kMemoryLimit;
      (void)pomar::encode(mesh, opt);
      if (mesh.vertex_count() >= 8) {
        opt.clusters = 2;
        (void)pomar::encode(mesh, opt);
      }
    } catch (const pomar::Error &) {
    }
  }
  return 0;
}
