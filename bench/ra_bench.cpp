// pomar_ra_bench: what random access costs (file size) and what it buys (bytes and time to
// get one cluster at full resolution). Used by bench/bench.py; see bench/README.md.
//
//   pomar_ra_bench curve MESH [--bits N]
//       Encodes MESH in pure progressive mode and with several cluster ratios; prints a
//       markdown table of size (total/connectivity/geometry bpv, tables, index), overhead
//       against the progressive file and encode time.
//
//   pomar_ra_bench one MESH [--bits N] [--clusters N | --ratio R] [--repeat K] [--verbose]
//       Encodes MESH (default: the codec's default ratio) to a temporary .pomar file, then decodes
//       K (default 20) evenly spaced clusters at the finest level, each with a fresh
//       SelectiveDecoder over a FileSource; prints min/median/max times, bytes and blocks
//       read, and the same for the constructor alone and for a full decode. --verbose
//       prints one line per cluster on stderr.
//
// Times: std::chrono::steady_clock around the library calls only (no mesh loading, no
// mesh() conversion). Exit status 0 on success, 1 on a pomar::Error or I/O failure, 2 on
// bad arguments.
#include <pomar/mesh_io.h>
#include <pomar/pomar.h>
#include <pomar/random_access.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <unistd.h>

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

double bpv(uint64_t bytes, uint32_t vertices) {
  return vertices ? 8.0 * double(bytes) / double(vertices) : 0.0;
}

template <class T> T median(std::vector<T> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  if (n == 0)
    return T();
  if (n % 2)
    return v[n / 2];
  return static_cast<T>((v[n / 2 - 1] + v[n / 2]) / 2);
}

std::string with_commas(uint64_t v) {
  std::string s = std::to_string(v);
  for (int i = int(s.size()) - 3; i > 0; i -= 3)
    s.insert(size_t(i), ",");
  return s;
}

std::string base_name(const std::string &path) {
  return std::filesystem::path(path).filename().string();
}

[[noreturn]] void usage(const char *msg = nullptr) {
  if (msg)
    std::fprintf(stderr, "pomar_ra_bench: %s\n", msg);
  std::fprintf(stderr,
               "usage: pomar_ra_bench curve MESH [--bits N]\n"
               "       pomar_ra_bench one MESH [--bits N] [--clusters N | --ratio R] "
               "[--repeat K] [--verbose]\n"
               "       pomar_ra_bench view FILE.pomar PIXELS CAMERA(23 numbers) [LEVELS]\n"
               "       pomar_ra_bench encode MESH OUT.pomar [RATIO]  (with CERR and BLKO)\n");
  std::exit(2);
}

struct Args {
  std::string mode, mesh;
  int bits = 12;
  uint32_t clusters = 0;
  double ratio = pomar::EncodeOptions{}.cluster_ratio;
  bool ratio_given = false;
  int repeat = 20;
  bool verbose = false;
};

Args parse(int argc, char **argv) {
  if (argc < 3)
    usage();
  Args a;
  a.mode = argv[1];
  a.mesh = argv[2];
  if (a.mode != "curve" && a.mode != "one")
    usage(("unknown mode '" + a.mode + "'").c_str());
  for (int i = 3; i < argc; ++i) {
    const std::string opt = argv[i];
    if (opt == "--verbose" && a.mode == "one") {
      a.verbose = true;
      continue;
    }
    if (i + 1 >= argc)
      usage((opt + " needs a value").c_str());
    const char *val = argv[++i];
    char *end = nullptr;
    if (opt == "--bits") {
      a.bits = int(std::strtol(val, &end, 10));
      if (*end || a.bits < 4 || a.bits > 24)
        usage("--bits must be an integer in 4..24");
    } else if (opt == "--clusters" && a.mode == "one") {
      const long n = std::strtol(val, &end, 10);
      if (*end || n < 1 || n > 0x7fffffffL)
        usage("--clusters must be a positive integer");
      a.clusters = uint32_t(n);
    } else if (opt == "--ratio" && a.mode == "one") {
      a.ratio = std::strtod(val, &end);
      if (*end || !(a.ratio > 0 && a.ratio <= 1))
        usage("--ratio must be a number in (0, 1]");
      a.ratio_given = true;
    } else if (opt == "--repeat" && a.mode == "one") {
      a.repeat = int(std::strtol(val, &end, 10));
      if (*end || a.repeat < 1)
        usage("--repeat must be a positive integer");
    } else {
      usage(("unknown option '" + opt + "' for mode " + a.mode).c_str());
    }
  }
  if (a.clusters && a.ratio_given)
    usage("--clusters and --ratio are exclusive");
  return a;
}

// ------------------------------------------------------------------------------- curve

int run_curve(const Args &a) {
  const pomar::Mesh mesh = pomar::load_mesh(a.mesh);
  struct Row {
    double ratio = 0; // 0 = progressive
    pomar::FileInfo info;
    double encode_s = 0;
  };
  std::vector<Row> rows;
  auto run = [&](bool progressive, double ratio) {
    pomar::EncodeOptions o;
    o.bits = a.bits;
    o.progressive = progressive;
    o.cluster_ratio = ratio;
    const auto t0 = Clock::now();
    const std::vector<uint8_t> file = pomar::encode(mesh, o);
    Row r;
    r.encode_s = seconds_since(t0);
    r.ratio = progressive ? 0 : ratio;
    r.info = pomar::inspect(file.data(), file.size());
    rows.push_back(r);
  };
  run(true, 0);
  for (double ratio : {0.005, 0.01, 0.02, 0.04, 0.06, 0.08, 0.10}) {
    std::fprintf(stderr, "pomar_ra_bench: %s ratio %.3f ...\n", base_name(a.mesh).c_str(), ratio);
    run(false, ratio);
  }

  const pomar::FileInfo &prog = rows.front().info;
  std::printf("#### cluster-ratio curve: %s (%s vertices, %d-bit, %zu levels)\n\n",
              base_name(a.mesh).c_str(), with_commas(prog.vertices).c_str(), a.bits,
              prog.levels.size());
  std::printf("| ratio | clusters | global levels | total bpv | conn bpv | geom bpv | tables bytes "
              "| index bytes | overhead vs progressive | encode s |\n");
  std::printf("|:--|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n");
  for (const Row &r : rows) {
    const pomar::FileInfo &i = r.info;
    char ratio[32];
    if (r.ratio == 0)
      std::snprintf(ratio, sizeof ratio, "progressive");
    else
      std::snprintf(ratio, sizeof ratio, "%.3f%s", r.ratio,
                    r.ratio == pomar::EncodeOptions{}.cluster_ratio ? " (default)" : "");
    const double overhead = 100.0 * (double(i.total_bytes) / double(prog.total_bytes) - 1.0);
    std::printf("| %s | %s | %u | %.2f | %.2f | %.2f | %s | %s | %+.1f%% | %.3f |\n", ratio,
                with_commas(i.clusters).c_str(), i.global_levels, bpv(i.total_bytes, i.vertices),
                bpv(i.connectivity_bytes, i.vertices), bpv(i.geometry_bytes, i.vertices),
                with_commas(i.tables_bytes).c_str(), with_commas(i.index_bytes).c_str(), overhead,
                r.encode_s);
  }
  return 0;
}

// ------------------------------------------------------------------------------- one

/// Removes the temporary file however run_one ends.
struct TempFile {
  std::string path;
  ~TempFile() {
    if (!path.empty()) {
      std::error_code ec;
      std::filesystem::remove(path, ec);
    }
  }
};

struct Stats {
  std::vector<double> ms;
  std::vector<uint64_t> bytes;
  std::vector<uint32_t> blocks;
  std::vector<size_t> vertices;
};

int run_one(const Args &a) {
  const pomar::Mesh mesh = pomar::load_mesh(a.mesh);
  pomar::EncodeOptions o;
  o.bits = a.bits;
  o.clusters = a.clusters;
  o.cluster_ratio = a.ratio;
  auto t0 = Clock::now();
  const std::vector<uint8_t> data = pomar::encode(mesh, o);
  const double encode_s = seconds_since(t0);
  const pomar::FileInfo info = pomar::inspect(data.data(), data.size());
  if (!info.clustered())
    throw pomar::Error("the encoded file has no clusters");

  std::error_code ec;
  std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
  if (ec)
    dir = "/tmp";
  TempFile tmp;
  tmp.path = (dir / ("pomar_ra_bench." + std::to_string(::getpid()) + ".pomar")).string();
  pomar::write_file_atomic(tmp.path, data.data(), data.size());
  const uint64_t file_bytes = data.size();

  const uint32_t n = info.clusters;
  const uint32_t k = std::min<uint32_t>(uint32_t(a.repeat), n);
  std::vector<uint32_t> ids(k);
  for (uint32_t i = 0; i < k; ++i) // centres of k equal slices of 0..n-1
    ids[i] = uint32_t((uint64_t(2 * i + 1) * n) / (2 * uint64_t(k)));

  Stats ctor, one, full;
  int finest = 0, global_levels = 0;
  auto decode_one = [&](uint32_t c, bool record) {
    const auto s = Clock::now();
    pomar::SelectiveDecoder d(std::make_unique<pomar::FileSource>(tmp.path));
    const double ctor_ms = 1e3 * seconds_since(s);
    const uint64_t ctor_bytes = d.bytes_read();
    d.want_cluster(c, d.finest_level());
    d.update();
    const double total_ms = 1e3 * seconds_since(s);
    finest = d.finest_level();
    global_levels = d.base_clustered_level();
    if (!record)
      return;
    ctor.ms.push_back(ctor_ms);
    ctor.bytes.push_back(ctor_bytes);
    ctor.blocks.push_back(0);
    ctor.vertices.push_back(0);
    one.ms.push_back(total_ms);
    one.bytes.push_back(d.bytes_read());
    one.blocks.push_back(d.blocks_read());
    one.vertices.push_back(d.mesh().vertex_count()); // untimed
    if (a.verbose)
      std::fprintf(stderr,
                   "cluster %u: %.2f ms (constructor %.2f), %llu bytes, %u blocks, %u clusters "
                   "refined, %zu vertices\n",
                   c, total_ms, ctor_ms, static_cast<unsigned long long>(d.bytes_read()),
                   d.blocks_read(), d.clusters_decoded(), one.vertices.back());
  };
  decode_one(ids[0], false); // warm-up: page cache, allocator
  for (uint32_t c : ids)
    decode_one(c, true);

  const int full_runs = 3;
  for (int r = 0; r < full_runs; ++r) {
    const auto s = Clock::now();
    pomar::SelectiveDecoder d(std::make_unique<pomar::FileSource>(tmp.path));
    d.want_all(d.finest_level());
    d.update();
    full.ms.push_back(1e3 * seconds_since(s));
    full.bytes.push_back(d.bytes_read());
    full.blocks.push_back(d.blocks_read());
    full.vertices.push_back(d.mesh().vertex_count());
  }
  const size_t full_vertices = full.vertices.front();

  char how[64];
  if (a.clusters)
    std::snprintf(how, sizeof how, "--clusters %u", a.clusters);
  else
    std::snprintf(how, sizeof how, "ratio %g", a.ratio);
  std::printf("#### one cluster at full resolution: %s (%s vertices, %d-bit)\n\n",
              base_name(a.mesh).c_str(), with_commas(info.vertices).c_str(), a.bits);
  std::printf("- file: %s bytes (%.2f bpv), %s clusters (%s), global levels 0..%d of %d, "
              "global part %s bytes (%.1f%%), encode %.3f s\n",
              with_commas(file_bytes).c_str(), bpv(file_bytes, info.vertices),
              with_commas(n).c_str(), how, global_levels, finest,
              with_commas(info.global_bytes).c_str(),
              100.0 * double(info.global_bytes) / double(file_bytes), encode_s);
  std::printf("- %u clusters (ids evenly spaced: %u, %u, ..., %u), each with a fresh "
              "SelectiveDecoder(FileSource), after one untimed warm-up; full decode: %d runs\n\n",
              k, ids.front(), k > 1 ? ids[1] : ids.front(), ids.back(), full_runs);
  std::printf("| measurement | min ms | median ms | max ms | median bytes read | %% of file "
              "| median blocks read | median vertices decoded |\n");
  std::printf("|:--|--:|--:|--:|--:|--:|--:|--:|\n");
  auto line = [&](const char *what, const Stats &s, bool show_vertices) {
    const auto [lo, hi] = std::minmax_element(s.ms.begin(), s.ms.end());
    const uint64_t b = median(s.bytes);
    std::printf("| %s | %.2f | %.2f | %.2f | %s | %.1f%% | %s | %s |\n", what, *lo, median(s.ms),
                *hi, with_commas(b).c_str(), 100.0 * double(b) / double(file_bytes),
                with_commas(median(s.blocks)).c_str(),
                show_vertices ? with_commas(median(s.vertices)).c_str() : "-");
  };
  line("constructor only (header, global levels, tables, index)", ctor, false);
  line("constructor + want_cluster(c, finest) + update()", one, true);
  line("full: constructor + want_all(finest) + update()", full, true);
  if (full_vertices != info.vertices)
    std::printf("\nWARNING: the full selective decode has %zu vertices, the file %u\n",
                full_vertices, info.vertices);
  return 0;
}

} // namespace

/// `view FILE.pomar PIXELS CAMERA [LEVELS]`: SelectiveDecoder::view_levels for a camera given
/// as 23 comma-separated numbers (eye xyz, view-projection 16 column-major, vertical fov,
/// width, height, near: the web client's viewOf), after decoding the level map LEVELS
/// (comma-separated, one per cluster; default the base clustered mesh); prints the levels,
/// then after want_view + update the bytes read. The web tests compare the WebAssembly
/// decoder's selection with it.
int run_view(int argc, char **argv) {
  if (argc < 5)
    usage("view needs FILE.pomar PIXELS CAMERA [LEVELS]");
  const auto numbers = [](const std::string &text) {
    std::vector<double> out;
    size_t at = 0;
    while (at <= text.size()) {
      const size_t end = std::min(text.find(',', at), text.size());
      out.push_back(std::stod(text.substr(at, end - at)));
      at = end + 1;
    }
    return out;
  };
  const std::vector<double> cam = numbers(argv[4]);
  if (cam.size() != 23)
    usage("the camera is 23 numbers");
  pomar::ViewCamera camera;
  for (int k = 0; k < 3; ++k)
    camera.eye[k] = float(cam[size_t(k)]);
  for (int k = 0; k < 16; ++k)
    camera.view_proj[k] = float(cam[size_t(3 + k)]);
  camera.fov_y = float(cam[19]);
  camera.width = float(cam[20]);
  camera.height = float(cam[21]);
  camera.near_distance = float(cam[22]);
  pomar::SelectiveDecoder d(std::make_unique<pomar::FileSource>(argv[2]));
  if (argc > 5) {
    std::vector<int> levels;
    for (double l : numbers(argv[5]))
      levels.push_back(int(l));
    d.set_wanted(levels);
    d.update();
  }
  const std::vector<int> levels = d.view_levels(camera, std::stof(argv[3]));
  std::printf("levels:");
  for (int l : levels)
    std::printf(" %d", l);
  d.want_view(camera, std::stof(argv[3]));
  d.update();
  std::printf("\nbytes read: %llu of %llu\n", (unsigned long long)d.bytes_read(),
              (unsigned long long)d.info().total_bytes);
  return 0;
}

/// `encode MESH OUT.pomar [RATIO]`: a random-access file with a stored error per cluster and
/// level (CERR) and its blocks in spatial order (BLKO), as the view benches and tests use
/// (what `pomar encode` writes by default, with RATIO as --cluster-ratio).
int run_encode(int argc, char **argv) {
  if (argc < 4)
    usage("encode needs MESH OUT.pomar [RATIO]");
  pomar::EncodeOptions o;
  o.spatial_layout = true;
  o.cluster_errors = true;
  if (argc > 4)
    o.cluster_ratio = std::stod(argv[4]);
  const std::vector<uint8_t> file = pomar::encode(pomar::load_mesh(argv[2]), o);
  std::FILE *f = std::fopen(argv[3], "wb");
  if (!f || std::fwrite(file.data(), 1, file.size(), f) != file.size() || std::fclose(f) != 0)
    throw std::runtime_error(std::string("cannot write ") + argv[3]);
  std::printf("%s: %zu bytes\n", argv[3], file.size());
  return 0;
}

int main(int argc, char **argv) {
  if (argc > 1 && std::string(argv[1]) == "encode") {
    try {
      return run_encode(argc, argv);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "pomar_ra_bench: %s\n", e.what());
      return 1;
    }
  }
  if (argc > 1 && std::string(argv[1]) == "view") {
    try {
      return run_view(argc, argv);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "pomar_ra_bench: %s\n", e.what());
      return 1;
    }
  }
  const Args a = parse(argc, argv);
  try {
    return a.mode == "curve" ? run_curve(a) : run_one(a);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "pomar_ra_bench: %s\n", e.what());
    return 1;
  }
}
