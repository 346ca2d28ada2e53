// pomar_core_bench: the codec's core in one process, next to Draco's library (when built
// with libdraco-dev): encode and decode from and to memory, repeated, so that neither the
// file formats, the process start nor the first touch of fresh pages is measured.
//
//   pomar_core_bench MESH [--runs N] [--threads T]
//
// MESH is read once (pomar's reader for pomar, Draco's for Draco), then each codec encodes
// it N times (pomar random access, 12 bits; Draco as `draco_encoder -qp 12 -cl 7`, bench.py's
// call: normals on 8 bits, texture coordinates on 10, other attributes on 8) and decodes its
// own file N times. Reported: the first run and the median of the others (glibc keeps the
// freed memory between runs, so these write warm pages: what a long-lived process, the
// Python module or a viewer, sees). bench/README.md ("The core in one process") explains
// why this differs from the whole-command ratios.
#include <pomar/mesh_io.h>
#include <pomar/pomar.h>

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#ifdef POMAR_BENCH_DRACO
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/io/mesh_io.h>
#endif

namespace {

struct Times {
  double first = 0, median = 0; // milliseconds
};

/// Run `f` `runs` times; the first run and the median of the others.
Times time_runs(int runs, const std::function<void()> &f) {
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const auto t1 = std::chrono::steady_clock::now();
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  Times t;
  t.first = ms[0];
  std::vector<double> rest(ms.begin() + (ms.size() > 1 ? 1 : 0), ms.end());
  std::sort(rest.begin(), rest.end());
  t.median = rest[rest.size() / 2];
  return t;
}

void row(const char *what, const Times &t, size_t vertices, const Times *draco) {
  std::printf("%-26s first %8.1f ms  median %8.1f ms  %6.3f us/vertex", what, t.first, t.median,
              1e3 * t.median / double(vertices));
  if (draco && draco->median > 0)
    std::printf("  x%.2f Draco", t.median / draco->median);
  std::printf("\n");
}

int usage() {
  std::fprintf(stderr, "usage: pomar_core_bench MESH [--runs N] [--threads T]\n"
                       "  encodes and decodes MESH N times in memory (default 9), pomar on T\n"
                       "  threads (default: 1 and the cores available), Draco alongside when\n"
                       "  built with libdraco-dev; prints first and median times.\n");
  return 2;
}

} // namespace

int main(int argc, char **argv) {
  if (argc < 2)
    return usage();
  std::string path;
  int runs = 9;
  std::vector<unsigned> thread_counts;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--runs") && i + 1 < argc)
      runs = std::max(2, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      thread_counts.push_back(unsigned(std::atoi(argv[++i])));
    else if (argv[i][0] == '-')
      return usage();
    else
      path = argv[i];
  }
  if (path.empty())
    return usage();
  if (thread_counts.empty())
    thread_counts = {1, 0};
  // Keep freed memory in the process (no unmapping, no trimming): every run after the
  // first reuses warm pages, for pomar and Draco alike.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);

  try {
    const pomar::Mesh mesh = pomar::load_mesh(path);
    const size_t nv = mesh.vertex_count();
    std::printf("%s: %zu vertices, %zu triangles, %d runs\n", path.c_str(), nv,
                mesh.triangle_count(), runs);
    Times draco_encode, draco_decode;
#ifdef POMAR_BENCH_DRACO
    {
      auto read = draco::ReadMeshFromFile(path);
      if (!read.ok()) {
        std::fprintf(stderr, "Draco cannot read %s: %s\n", path.c_str(), read.status().error_msg());
        return 1;
      }
      std::unique_ptr<draco::Mesh> dm = std::move(read).value();
      draco::Encoder encoder;
      encoder.SetSpeedOptions(10 - 7, 10 - 7); // -cl 7
      // draco_encoder -qp 12 -cl 7 (bench.py's call): its defaults for the rest.
      encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 12);
      encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, 8);
      encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 10);
      encoder.SetAttributeQuantization(draco::GeometryAttribute::GENERIC, 8);
      draco::EncoderBuffer buffer;
      draco_encode = time_runs(runs, [&] {
        buffer.Clear();
        if (!encoder.EncodeMeshToBuffer(*dm, &buffer).ok())
          throw std::runtime_error("Draco failed to encode");
      });
      size_t decoded = 0;
      draco_decode = time_runs(runs, [&] {
        draco::DecoderBuffer in;
        in.Init(buffer.data(), buffer.size());
        draco::Decoder decoder;
        auto out = decoder.DecodeMeshFromBuffer(&in);
        if (!out.ok())
          throw std::runtime_error("Draco failed to decode");
        decoded = out.value()->num_points();
      });
      row("Draco encode", draco_encode, nv, nullptr);
      row("Draco decode", draco_decode, nv, nullptr);
      std::printf("  (%zu bytes, %zu points decoded)\n", buffer.size(), decoded);
    }
    const Times *de = &draco_encode, *dd = &draco_decode;
#else
    const Times *de = nullptr, *dd = nullptr;
    std::printf("(built without libdraco-dev: pomar only)\n");
#endif
    for (unsigned threads : thread_counts) {
      pomar::EncodeOptions eo;
      eo.threads = threads;
      std::vector<uint8_t> file;
      const Times enc = time_runs(runs, [&] { file = pomar::encode(mesh, eo); });
      pomar::DecodeOptions dopt;
      dopt.threads = threads;
      size_t decoded = 0;
      const Times dec = time_runs(
          runs, [&] { decoded = pomar::decode(file.data(), file.size(), dopt).vertex_count(); });
      if (decoded != nv)
        throw std::runtime_error("pomar decoded " + std::to_string(decoded) + " vertices of " +
                                 std::to_string(nv));
      const std::string t = threads == 1 ? "1 thread"
                            : threads    ? std::to_string(threads) + " threads"
                                         : std::string("all threads");
      row(("pomar encode, " + t).c_str(), enc, nv, de);
      row(("pomar decode, " + t).c_str(), dec, nv, dd);
      std::printf("  (%zu bytes)\n", file.size());
    }
  } catch (const std::exception &e) {
    std::fprintf(stderr, "pomar_core_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
