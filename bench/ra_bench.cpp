// pomar_ra_bench: what random access costs (file size) and what it buys (bytes and time to
// get one cluster at full resolution). Used by bench/bench.py; see bench/README.md.
//
//   pomar_ra_bench curve MESH [--bits N]
//       Encodes MESH in pure progressive mode and with several cluster ratios; prints a
//       markdown table of size (total/connectivity/geometry bpv, tables, index), overhead
//       against the progressive file and encode time.
//
//   pomar_ra_bench tiers MESH [--rounds 3,4,5] [--cells 256,1024,4096] [--centres K]
//       Encodes MESH with the clustered levels decimated in tiers (EncodeOptions::tier_rounds)
//       and prints file size and levels against the default, and the bytes a tiered
//       decoder would read for a close-up against the level map on the default file.
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
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <unordered_map>
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
  std::fprintf(stderr, "usage: pomar_ra_bench curve MESH [--bits N]\n"
                       "       pomar_ra_bench one MESH [--bits N] [--clusters N | --ratio R] "
                       "[--repeat K] [--verbose]\n"
                       "       pomar_ra_bench view FILE.pomar PIXELS CAMERA(23 numbers) [LEVELS]\n"
                       "       pomar_ra_bench encode MESH OUT.pomar [RATIO]  (with CERR and BLKO)\n"
                       "       pomar_ra_bench tiers MESH [--rounds 3,4,5] [--cells 256,1024,4096] "
                       "[--centres K] [--bits N]\n");
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

namespace {

// ------------------------------------------------------------------------------- tiers

/// One encode of `tiers`: the file, its report and, from a full selective decode, every
/// vertex's grid position, cluster and level.
struct TierFile {
  std::string name;
  uint32_t rounds = 0, cell_vertices = 0;
  std::vector<uint8_t> data;
  pomar::EncodeReport report;
  std::vector<uint32_t> q; // xyz grid indices
  std::vector<uint32_t> cluster, level;
  uint32_t global = 0, clustered_levels = 0;
  double encode_s = 0;
};

TierFile encode_tiered(const pomar::Mesh &mesh, int bits, uint32_t rounds, uint32_t cell_vertices) {
  TierFile f;
  f.rounds = rounds;
  f.cell_vertices = cell_vertices;
  pomar::EncodeOptions o;
  o.bits = bits;
  o.tier_rounds = rounds;
  o.tier_cell_vertices = cell_vertices;
  const auto t0 = Clock::now();
  f.data = pomar::encode(mesh, o, &f.report);
  f.encode_s = seconds_since(t0);
  const pomar::FileInfo &info = f.report.info;
  if (!info.clustered())
    throw pomar::Error("the encoded file has no clusters");
  f.global = info.global_levels;
  f.clustered_levels = uint32_t(info.levels.size()) - f.global;
  pomar::SelectiveDecoder d(std::make_unique<pomar::MemorySource>(f.data.data(), f.data.size()));
  d.want_all(d.finest_level());
  d.update();
  const pomar::Mesh m = d.mesh();
  f.cluster = d.vertex_cluster();
  f.level = d.vertex_level();
  f.q.resize(m.positions.size());
  for (size_t i = 0; i < m.positions.size(); ++i)
    f.q[i] = info.grid.quantize(int(i % 3), m.positions[i]);
  return f;
}

/// A box of grid units, [lo, hi] per axis.
struct Box {
  double lo[3], hi[3];
  bool meets(const Box &b, double grow = 0) const {
    for (int a = 0; a < 3; ++a)
      if (lo[a] > b.hi[a] + grow || b.lo[a] > hi[a] + grow)
        return false;
    return true;
  }
};

/// The bytes of every block prefix: of cluster c up to clustered level j.
struct Prefixes {
  const TierFile &f;
  uint64_t upto(uint32_t c, uint32_t j) const {
    return f.report.cluster_level_ends[size_t(c) * f.clustered_levels + j];
  }
  uint64_t level(uint32_t c, uint32_t j) const { return upto(c, j) - (j ? upto(c, j - 1) : 0); }
};

/// Every cluster's root position (its vertex of the base clustered mesh).
std::vector<const uint32_t *> cluster_roots(const TierFile &f) {
  std::vector<const uint32_t *> root(f.report.info.clusters, nullptr);
  for (size_t v = 0; v < f.cluster.size(); ++v)
    if (f.level[v] <= f.global && f.cluster[v] < root.size() && !root[f.cluster[v]])
      root[f.cluster[v]] = &f.q[3 * v];
  return root;
}

/// Today's level map on `f` for the region: the clusters whose roots lie in `region`
/// wanted at the finest level, the SelectiveDecoder completing the map (one ring of raised
/// neighbours per level). Returns {bytes read past the constructor's, the prefix model:
/// the same map read as exact level prefixes, the region's own blocks alone}.
struct TodayRead {
  uint64_t open = 0, read = 0, whole = 0, prefix = 0, region = 0;
  uint32_t region_clusters = 0, raised = 0;
};

TodayRead read_today(const TierFile &f, const Box &region) {
  TodayRead t;
  const std::vector<const uint32_t *> root = cluster_roots(f);
  pomar::SelectiveDecoder d(std::make_unique<pomar::MemorySource>(f.data.data(), f.data.size()));
  t.open = d.bytes_read();
  std::vector<int> wanted(root.size(), d.base_clustered_level());
  const Prefixes p{f};
  for (uint32_t c = 0; c < root.size(); ++c) {
    if (!root[c])
      continue;
    bool in = true;
    for (int a = 0; a < 3; ++a)
      in = in && root[c][a] >= region.lo[a] && root[c][a] <= region.hi[a];
    if (in) {
      wanted[c] = d.finest_level();
      ++t.region_clusters;
      t.region += p.upto(c, f.clustered_levels - 1);
    }
  }
  d.set_wanted(wanted);
  d.update();
  t.read = d.bytes_read() - t.open;
  const std::vector<int> &map = d.levels();
  for (uint32_t c = 0; c < map.size(); ++c)
    if (map[c] > int(f.global)) {
      ++t.raised;
      t.whole += p.upto(c, f.clustered_levels - 1);
      t.prefix += p.upto(c, uint32_t(map[c]) - f.global - 1);
    }
  return t;
}

/// The tiered decoder's read on a tiered file, modelled: the cells of the finest tier
/// meeting the region, then per coarser tier the cells meeting a selected cell of the
/// tier before grown by this tier's longest edge (the mesh's longest edge once its levels
/// are decoded), each cell read for all its levels of the tier. A cell's bytes: each
/// cluster-level prefix difference shared evenly among that cluster's splits of the level,
/// each split counted in the cell (of its level's tier) holding its position (a cluster
/// level without a split: in the cell of the cluster's root).
struct TierRead {
  uint64_t read = 0;
  uint32_t cells = 0;
  std::vector<uint32_t> per_tier_cells;
  std::vector<uint64_t> per_tier_bytes;
};

struct TierCells {
  // per tier: cell key -> bytes of its levels of the tier
  std::vector<std::vector<std::pair<uint64_t, double>>> bytes;
  uint64_t uncovered = 0; // clustered-level bytes outside every tier
};

uint64_t cell_of(const pomar::EncodeReport::Tier &t, const uint32_t *q) {
  const uint32_t shift = t.shifted ? 1u << (t.cell_bits - 1) : 0;
  uint64_t key = 0;
  for (int a = 0; a < 3; ++a)
    key = key << 21 | (((q[a] + shift) >> t.cell_bits) & 0x1FFFFF);
  return key;
}

Box cell_box(const pomar::EncodeReport::Tier &t, uint64_t key) {
  const double side = double(1u << t.cell_bits), shift = t.shifted ? side / 2 : 0;
  Box b;
  for (int a = 0; a < 3; ++a) {
    const double k = double((key >> (21 * (2 - a))) & 0x1FFFFF);
    b.lo[a] = k * side - shift;
    b.hi[a] = b.lo[a] + side;
  }
  return b;
}

TierCells tier_cells(const TierFile &f) {
  const auto &tiers = f.report.tiers;
  TierCells out;
  out.bytes.resize(tiers.size());
  const uint32_t C = f.report.info.clusters, J = f.clustered_levels;
  std::vector<uint32_t> splits(size_t(C) * J, 0);
  for (size_t v = 0; v < f.level.size(); ++v)
    if (f.level[v] > f.global)
      ++splits[size_t(f.cluster[v]) * J + (f.level[v] - f.global - 1)];
  const auto tier_of = [&](uint32_t level) -> int {
    for (size_t t = 0; t < tiers.size(); ++t)
      if (int(level) >= tiers[t].first_level && int(level) < tiers[t].first_level + tiers[t].levels)
        return int(t);
    return -1;
  };
  const Prefixes p{f};
  std::vector<std::unordered_map<uint64_t, double>> cells(tiers.size());
  const auto add = [&](uint32_t level, const uint32_t *q, double bytes) {
    const int t = tier_of(level);
    if (t < 0)
      out.uncovered += uint64_t(bytes + 0.5);
    else
      cells[size_t(t)][cell_of(tiers[size_t(t)], q)] += bytes;
  };
  for (size_t v = 0; v < f.level.size(); ++v)
    if (f.level[v] > f.global) {
      const uint32_t c = f.cluster[v], j = f.level[v] - f.global - 1;
      add(f.level[v], &f.q[3 * v], double(p.level(c, j)) / double(splits[size_t(c) * J + j]));
    }
  const std::vector<const uint32_t *> root = cluster_roots(f);
  for (uint32_t c = 0; c < C; ++c)
    for (uint32_t j = 0; j < J; ++j)
      if (splits[size_t(c) * J + j] == 0 && p.level(c, j) > 0 && root[c])
        add(f.global + 1 + j, root[c], double(p.level(c, j)));
  for (size_t t = 0; t < tiers.size(); ++t) {
    out.bytes[t].assign(cells[t].begin(), cells[t].end());
    std::sort(out.bytes[t].begin(), out.bytes[t].end());
  }
  return out;
}

TierRead read_tiered(const TierFile &f, const TierCells &cells, const Box &region) {
  const auto &tiers = f.report.tiers;
  TierRead r;
  std::vector<Box> selected; // the cells of the tier before
  double read = 0;
  for (size_t t = 0; t < tiers.size(); ++t) {
    std::vector<Box> now;
    double bytes = 0;
    for (const auto &[key, b] : cells.bytes[t]) {
      const Box box = cell_box(tiers[t], key);
      bool take = false;
      if (t == 0)
        take = box.meets(region);
      else
        for (const Box &s : selected)
          if ((take = box.meets(s, tiers[t].longest_edge)))
            break;
      if (take) {
        now.push_back(box);
        bytes += b;
      }
    }
    r.per_tier_cells.push_back(uint32_t(now.size()));
    r.per_tier_bytes.push_back(uint64_t(bytes + 0.5));
    r.cells += uint32_t(now.size());
    read += bytes;
    selected.swap(now);
  }
  r.read = uint64_t(read + 0.5) + cells.uncovered; // (levels outside the tiers: all read)
  return r;
}

/// The exact dependencies between tiers: deps[t] maps a cell of tier t to the cells of
/// tier t + 1 that hold one of its vertices or one of their neighbours in the mesh the
/// tier starts from (decoded to the level before the tier's first).
using TierDeps = std::vector<std::unordered_map<uint64_t, std::vector<uint64_t>>>;

TierDeps tier_dependencies(const TierFile &f) {
  const auto &tiers = f.report.tiers;
  TierDeps deps(tiers.size());
  for (size_t t = 0; t + 1 < tiers.size(); ++t) {
    if (tiers[t].first_level <= int(f.global) + 1)
      break; // the tiers from here on start from the global part, which is always read
    const pomar::Mesh m = pomar::decode(f.data.data(), f.data.size(), tiers[t].first_level - 1);
    std::vector<uint32_t> q(m.positions.size());
    for (size_t i = 0; i < q.size(); ++i)
      q[i] = f.report.info.grid.quantize(int(i % 3), m.positions[i]);
    std::unordered_map<uint64_t, std::vector<uint64_t>> &d = deps[t];
    for (size_t c = 0; c < m.triangles.size(); ++c) {
      const uint32_t a = m.triangles[c], b = m.triangles[c - c % 3 + (c + 1) % 3];
      const uint64_t fine[2] = {cell_of(tiers[t], &q[3 * size_t(a)]),
                                cell_of(tiers[t], &q[3 * size_t(b)])};
      const uint64_t coarse[2] = {cell_of(tiers[t + 1], &q[3 * size_t(a)]),
                                  cell_of(tiers[t + 1], &q[3 * size_t(b)])};
      for (uint64_t e : fine)
        for (uint64_t g : coarse)
          d[e].push_back(g);
    }
    for (auto &[e, list] : d) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
    }
  }
  return deps;
}

/// read_tiered with the exact dependencies instead of the longest-edge margin.
uint64_t read_tiered_exact(const TierFile &f, const TierCells &cells, const TierDeps &deps,
                           const Box &region, std::vector<uint64_t> *per_tier = nullptr) {
  const auto &tiers = f.report.tiers;
  std::vector<uint64_t> selected;
  double read = 0;
  for (size_t t = 0; t < tiers.size(); ++t) {
    std::vector<uint64_t> now;
    if (t == 0) {
      for (const auto &kb : cells.bytes[0])
        if (cell_box(tiers[0], kb.first).meets(region))
          now.push_back(kb.first);
    } else if (!deps[t - 1].empty()) {
      for (uint64_t e : selected) {
        const auto it = deps[t - 1].find(e);
        if (it != deps[t - 1].end())
          now.insert(now.end(), it->second.begin(), it->second.end());
      }
      std::sort(now.begin(), now.end());
      now.erase(std::unique(now.begin(), now.end()), now.end());
    } else { // a tier started from the global part: read whole
      for (const auto &kb : cells.bytes[t])
        now.push_back(kb.first);
    }
    double bytes = 0;
    for (uint64_t e : now) {
      const auto it = std::lower_bound(cells.bytes[t].begin(), cells.bytes[t].end(),
                                       std::pair<uint64_t, double>(e, -1.0));
      if (it != cells.bytes[t].end() && it->first == e)
        bytes += it->second;
    }
    read += bytes;
    if (per_tier)
      per_tier->push_back(uint64_t(bytes + 0.5));
    selected.swap(now);
  }
  return uint64_t(read + 0.5) + cells.uncovered;
}

std::vector<uint32_t> parse_list(const std::string &text) {
  std::vector<uint32_t> out;
  size_t at = 0;
  while (at <= text.size()) {
    const size_t end = std::min(text.find(',', at), text.size());
    out.push_back(uint32_t(std::stoul(text.substr(at, end - at))));
    at = end + 1;
  }
  return out;
}

/// `tiers MESH [--rounds 3,4,5] [--cells 256,1024,4096] [--centres K] [--bits N]`: the
/// cost (file size, levels) of decimating the clustered levels in tiers, and what a
/// tiered decoder would read for a close-up (a box of side 0.1 x the bounding box diagonal
/// around K surface points: vertices evenly spaced in the decoded numbering) against the
/// level map on the default file. Prints a markdown table.
int run_tiers(int argc, char **argv) {
  if (argc < 3)
    usage("tiers needs MESH");
  std::vector<uint32_t> rounds = {3, 4, 5}, cells = {256, 1024, 4096};
  uint32_t centres = 8;
  int bits = 12;
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string opt = argv[i];
    if (opt == "--rounds")
      rounds = parse_list(argv[i + 1]);
    else if (opt == "--cells")
      cells = parse_list(argv[i + 1]);
    else if (opt == "--centres")
      centres = uint32_t(std::stoul(argv[i + 1]));
    else if (opt == "--bits")
      bits = std::stoi(argv[i + 1]);
    else
      usage(("unknown option '" + opt + "' for tiers").c_str());
  }
  const pomar::Mesh mesh = pomar::load_mesh(argv[2]);
  std::fprintf(stderr, "pomar_ra_bench: %s default ...\n", base_name(argv[2]).c_str());
  const TierFile base = encode_tiered(mesh, bits, 0, 0);
  // The region: a cube of side 0.1 x the diagonal of the grid positions' box, around K
  // decoded vertices of the default file.
  double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
  for (size_t i = 0; i < base.q.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], double(base.q[i]));
    hi[i % 3] = std::max(hi[i % 3], double(base.q[i]));
  }
  const double diag =
      std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
  std::vector<Box> regions;
  const size_t nv = base.q.size() / 3;
  for (uint32_t i = 0; i < centres; ++i) {
    const size_t v = (size_t(2 * i + 1) * nv) / (2 * size_t(centres));
    Box b;
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = double(base.q[3 * v + a]) - 0.05 * diag;
      b.hi[a] = double(base.q[3 * v + a]) + 0.05 * diag;
    }
    regions.push_back(b);
  }
  const double file = double(base.data.size());
  const auto pct = [&](double bytes) { return 100.0 * bytes / file; };
  std::printf("#### tiers of clustered levels: %s (%s vertices, %d-bit, close-up: %u boxes of "
              "side 0.1 x diagonal)\n\n",
              base_name(argv[2]).c_str(), with_commas(nv).c_str(), bits, centres);
  TodayRead mean;
  for (const Box &r : regions) {
    const TodayRead t = read_today(base, r);
    mean.open += t.open, mean.read += t.read, mean.whole += t.whole, mean.prefix += t.prefix;
    mean.region += t.region, mean.region_clusters += t.region_clusters, mean.raised += t.raised;
  }
  std::printf("- default: %s bytes, %zu levels (%u clustered), %u clusters; open reads %.1f%%; "
              "the close-up (mean of %u): %u region clusters, %u raised; read %.1f%% (model: "
              "whole blocks %.1f%%, level prefixes %.1f%%, the region's blocks alone %.1f%%)\n\n",
              with_commas(base.data.size()).c_str(), base.report.info.levels.size(),
              base.clustered_levels, base.report.info.clusters, pct(double(mean.open) / centres),
              centres, mean.region_clusters / centres, mean.raised / centres,
              pct(double(mean.read) / centres), pct(double(mean.whole) / centres),
              pct(double(mean.prefix) / centres), pct(double(mean.region) / centres));
  std::printf("| T | cell vertices | file bytes | vs default | connectivity, geometry vs "
              "default | levels (clustered) | tiers: cell bits | border vertices | open | "
              "close-up: tiered, margin | tiered, exact | of it, finest tier |\n");
  std::printf("|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n");
  for (uint32_t T : rounds)
    for (uint32_t cv : cells) {
      std::fprintf(stderr, "pomar_ra_bench: %s T %u cells %u ...\n", base_name(argv[2]).c_str(), T,
                   cv);
      const TierFile f = encode_tiered(mesh, bits, T, cv);
      const TierCells tc = tier_cells(f);
      const TierDeps deps = tier_dependencies(f);
      double read = 0, finest = 0, exact = 0;
      for (const auto &t : f.report.tiers)
        std::fprintf(stderr,
                     "  tier levels %d..%d: k %d%s, %u vertices, %u cells, %u border, "
                     "longest edge %.0f\n",
                     t.first_level, t.first_level + t.levels - 1, t.cell_bits,
                     t.shifted ? " shifted" : "", t.vertices, t.cells, t.border, t.longest_edge);
      for (const Box &r : regions) {
        const TierRead t = read_tiered(f, tc, r);
        std::fprintf(stderr, "  close-up: %.1f%% (per tier, finest first:", pct(double(t.read)));
        for (size_t k = 0; k < t.per_tier_cells.size(); ++k)
          std::fprintf(stderr, " %u cells %.2f%%", t.per_tier_cells[k],
                       pct(double(t.per_tier_bytes[k])));
        std::fprintf(stderr, ")\n");
        read += double(t.read);
        std::vector<uint64_t> per_tier;
        exact += double(read_tiered_exact(f, tc, deps, r, &per_tier));
        std::fprintf(stderr, "  exact dependencies, per tier:");
        for (uint64_t b : per_tier)
          std::fprintf(stderr, " %.2f%%", pct(double(b)));
        std::fprintf(stderr, "\n");
        finest += t.per_tier_bytes.empty() ? 0 : double(t.per_tier_bytes[0]);
      }
      std::string ks;
      uint64_t border = 0, vertices = 0;
      for (const auto &t : f.report.tiers) {
        if (t.first_level + t.levels - 1 <= int(f.global))
          continue; // a tier of global levels only
        ks += (ks.empty() ? "" : ",") + std::to_string(t.cell_bits);
        border += t.border;
        vertices += t.vertices;
      }
      pomar::SelectiveDecoder d(
          std::make_unique<pomar::MemorySource>(f.data.data(), f.data.size()));
      const pomar::FileInfo &fi = f.report.info, &bi = base.report.info;
      std::printf(
          "| %u | %u | %s | %+.2f%% | %+.1f%%, %+.1f%% | %zu (%u) | %s | %.1f%% | %.1f%% | "
          "%.1f%% | %.1f%% | %.1f%% |\n",
          T, cv, with_commas(f.data.size()).c_str(), 100.0 * (double(f.data.size()) / file - 1.0),
          100.0 * (double(fi.connectivity_bytes) / double(bi.connectivity_bytes) - 1.0),
          100.0 * (double(fi.geometry_bytes) / double(bi.geometry_bytes) - 1.0), fi.levels.size(),
          f.clustered_levels, ks.c_str(),
          vertices ? 100.0 * double(border) / double(vertices) : 0.0, pct(double(d.bytes_read())),
          pct(read / centres), pct(exact / centres), pct(finest / centres));
      if (tc.uncovered)
        std::printf("|  | (%s clustered bytes in levels outside every tier, counted as read) "
                    "||||||||||\n",
                    with_commas(tc.uncovered).c_str());
    }
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  if (argc > 1 && std::string(argv[1]) == "tiers") {
    try {
      return run_tiers(argc, argv);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "pomar_ra_bench: %s\n", e.what());
      return 1;
    }
  }
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
