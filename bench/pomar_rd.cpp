// pomar_rd: rate-distortion of every level of detail of a .pomar file (docs/rate_distortion.md).
//
//   pomar_rd IN.mesh [IN.pomar] [--csv OUT.csv] [--svg OUT.svg] [--bits N] [--samples N]
//            [--seed N] [--no-draco] [--save-pomar OUT.pomar]
//
// IN.mesh is the original (PLY/OBJ/OFF/STL). Without IN.pomar the mesh is encoded in
// memory with the default options (--bits, default 12). For every level the tool decodes
// the mesh and measures, against the original:
//   - bytes read: global level l = header + base mesh + levels 1..l; clustered levels and
//     states = SelectiveDecoder::bytes_read() of a fresh decoder;
//   - bpv = 8 * bytes / vertices of the full mesh;
//   - the symmetric Hausdorff distance and RMS distance, relative to the bounding-box
//     diagonal of the original, and PSNR = 20 log10(diag / RMS).
// Distances are measured as Metro does, in both directions (original -> decoded and
// decoded -> original), with vcglib's SurfaceSampling + HausdorffSampler: every vertex
// plus N Monte-Carlo (area-weighted) samples on the faces of the sampled mesh, closest
// point on the other mesh through a static uniform grid. Symmetric Hausdorff = max of the
// two maxima (vertex and face samples), symmetric RMS = max of the two RMS values (face
// samples only, i.e. area-weighted).
//
// Random-access (clustered) files get rows for the global levels 0..G, for "every cluster
// at level l" (l = G+1..L), and for three clustered states: the base clustered mesh,
// cluster 0 at the finest level (with the clusters the level map pulls in), and
// everything refined. Draco's single-rate point (draco_encoder -qp BITS -cl 7, if the
// tools are installed) is measured the same way.
//
// Exit status: 0 on success, 1 on errors (including a .pomar that does not encode IN.mesh),
// 2 on bad arguments.
#include <pomar/mesh_io.h>
#include <pomar/pomar.h>
#include <pomar/random_access.h>
#include <pomar/vcg_adapter.h>

#include <vcg/complex/algorithms/point_sampling.h>
#include <vcg/complex/algorithms/update/normal.h>
#include <vcg/complex/complex.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace {

// ----- a vcglib mesh with what SurfaceSampling/HausdorffSampler need (double precision) -----
class RVertex;
class RFace;
struct RUsedTypes : public vcg::UsedTypes<vcg::Use<RVertex>::AsVertexType, vcg::Use<RFace>::AsFaceType> {};
class RVertex : public vcg::Vertex<RUsedTypes, vcg::vertex::Coord3d, vcg::vertex::Normal3d,
                                   vcg::vertex::Qualityd, vcg::vertex::BitFlags, vcg::vertex::Mark> {};
class RFace : public vcg::Face<RUsedTypes, vcg::face::VertexRef, vcg::face::Normal3d,
                               vcg::face::BitFlags, vcg::face::Mark> {};
class RMesh : public vcg::tri::TriMesh<std::vector<RVertex>, std::vector<RFace>> {};

using Sampler = vcg::tri::HausdorffSampler<RMesh>;
using Sampling = vcg::tri::SurfaceSampling<RMesh, Sampler>;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void prepare(RMesh &m) {
  vcg::tri::UpdateBounding<RMesh>::Box(m);
  vcg::tri::UpdateNormal<RMesh>::PerFaceNormalized(m);
  vcg::tri::UpdateNormal<RMesh>::PerVertexNormalized(m);
}

struct OneWay {
  double max = 0, rms = 0;
  long samples = 0;
};

/// Sample `from` (all vertices + n Monte-Carlo face samples), find the closest point on the
/// mesh indexed by `target` (its grid is built once in the sampler's constructor).
OneWay one_way(RMesh &from, Sampler &target, long n, double bound, unsigned seed) {
  target.min_dist = std::numeric_limits<double>::max();
  target.max_dist = 0;
  target.mean_dist = 0;
  target.RMS_dist = 0;
  target.n_total_samples = 0;
  target.dist_upper_bound = bound;
  // Vertices count for the maximum only: they are not area-weighted samples, and a
  // vertex carries the full quantization displacement while face interiors average it,
  // so mixing them in would bias the RMS by the vertex/face sample ratio.
  Sampling::AllVertex(from, target);
  const double vertex_max = target.max_dist;
  const long vertex_samples = target.n_total_samples;
  target.max_dist = 0;
  target.RMS_dist = 0;
  target.n_total_samples = 0;
  Sampling::SamplingRandomGenerator().initialize(seed);
  Sampling::Montecarlo(from, target, static_cast<int>(n));
  OneWay r;
  r.samples = vertex_samples + target.n_total_samples;
  r.max = std::max(vertex_max, double(target.max_dist));
  r.rms = target.n_total_samples ? std::sqrt(target.RMS_dist / target.n_total_samples) : 0.0;
  if (r.samples < from.vn + n) // a sample beyond the bound: cannot happen with bound > both diagonals
    throw pomar::Error("distance: " + std::to_string(from.vn + n - r.samples) +
                       " samples found no closest point within the search bound");
  return r;
}

struct Measure {
  std::string kind;  // global | clustered | state | draco
  std::string state; // label
  int level = -1;
  uint64_t bytes = 0;
  double bpv = 0;
  size_t vertices = 0, faces = 0;
  double hausdorff = 0, rms = 0, psnr = 0; // relative to the original's bbox diagonal
  double h_fwd = 0, h_bwd = 0;             // original->decoded, decoded->original
  long samples_fwd = 0, samples_bwd = 0;    // samples per direction (vertices included)
  double seconds = 0;
};

constexpr long kMinSamples = 20000;

struct Reference {
  RMesh mesh;
  std::unique_ptr<Sampler> sampler; // grid on the original
  double diag = 0;
  long samples = 0;
  unsigned seed = 1;
};

void measure(Reference &ref, const pomar::Mesh &decoded, Measure &out) {
  const auto t0 = Clock::now();
  RMesh m;
  pomar::to_vcg(decoded, m);
  prepare(m);
  out.vertices = decoded.vertex_count();
  out.faces = decoded.triangle_count();
  vcg::Box3d both = ref.mesh.bbox;
  both.Add(m.bbox);
  const double bound = 2.0 * both.Diag() + 1e-30;
  Sampler on_decoded(&m);
  // The original gets ref.samples face samples; the decoded mesh 10 per face, at least
  // kMinSamples and at most ref.samples: a coarse level has few large faces, and its samples
  // lie far from the original, where every closest-point query costs many grid cells.
  const long n_dec = std::min(ref.samples, std::max(kMinSamples, 10L * long(out.faces)));
  const OneWay fwd = one_way(ref.mesh, on_decoded, ref.samples, bound, ref.seed);
  const OneWay bwd = one_way(m, *ref.sampler, n_dec, bound, ref.seed + 7919);
  out.samples_fwd = fwd.samples;
  out.samples_bwd = bwd.samples;
  out.h_fwd = fwd.max / ref.diag;
  out.h_bwd = bwd.max / ref.diag;
  out.hausdorff = std::max(out.h_fwd, out.h_bwd);
  out.rms = std::max(fwd.rms, bwd.rms) / ref.diag;
  out.psnr = out.rms > 0 ? -20.0 * std::log10(out.rms) : std::numeric_limits<double>::infinity();
  out.seconds = seconds_since(t0);
}

// ----- argument parsing -----
struct Args {
  std::string mesh, pomar, csv, svg, save_pomar;
  int bits = 12;
  bool bits_given = false;
  long samples = 0; // 0 = default
  unsigned seed = 1;
  bool draco = true;
};

[[noreturn]] void usage(const char *msg) {
  if (msg)
    std::fprintf(stderr, "pomar_rd: %s\n", msg);
  std::fprintf(stderr,
               "usage: pomar_rd IN.mesh [IN.pomar] [--csv OUT.csv] [--svg OUT.svg] [--bits N]\n"
               "                [--samples N] [--seed N] [--no-draco] [--save-pomar OUT.pomar]\n");
  std::exit(2);
}

long parse_long(const char *s, const char *what) {
  char *end = nullptr;
  errno = 0;
  const long v = std::strtol(s, &end, 10);
  if (errno || end == s || *end)
    usage((std::string("bad value for ") + what + ": " + s).c_str());
  return v;
}

Args parse(int argc, char **argv) {
  Args a;
  std::vector<std::string> pos;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    auto value = [&](const char *name) -> const char * {
      if (i + 1 >= argc)
        usage((std::string(name) + " needs a value").c_str());
      return argv[++i];
    };
    if (s == "--csv")
      a.csv = value("--csv");
    else if (s == "--svg")
      a.svg = value("--svg");
    else if (s == "--save-pomar")
      a.save_pomar = value("--save-pomar");
    else if (s == "--bits") {
      a.bits = static_cast<int>(parse_long(value("--bits"), "--bits"));
      a.bits_given = true;
      if (a.bits < 4 || a.bits > 24)
        usage("--bits must be in 4..24");
    } else if (s == "--samples") {
      a.samples = parse_long(value("--samples"), "--samples");
      if (a.samples < 1000 || a.samples > 100000000)
        usage("--samples must be in 1000..100000000");
    } else if (s == "--seed")
      a.seed = static_cast<unsigned>(parse_long(value("--seed"), "--seed"));
    else if (s == "--no-draco")
      a.draco = false;
    else if (s == "-h" || s == "--help")
      usage(nullptr);
    else if (!s.empty() && s[0] == '-')
      usage(("unknown option " + s).c_str());
    else
      pos.push_back(s);
  }
  if (pos.empty() || pos.size() > 2)
    usage("expected IN.mesh [IN.pomar]");
  a.mesh = pos[0];
  if (pos.size() == 2)
    a.pomar = pos[1];
  return a;
}

/// Throws unless `file` (full decode `full`) encodes `input`.
void check_match(const pomar::Mesh &input, const pomar::FileInfo &info, const pomar::Mesh &full,
                 const std::string &mesh_path, const std::string &pomar_path) {
  const std::string pre = pomar_path + " does not encode " + mesh_path + ": ";
  if (full.vertex_count() != input.vertex_count() || full.triangle_count() != input.triangle_count())
    throw pomar::Error(pre + "it decodes to " + std::to_string(full.vertex_count()) + " vertices, " +
                       std::to_string(full.triangle_count()) + " faces, the mesh has " +
                       std::to_string(input.vertex_count()) + " vertices, " +
                       std::to_string(input.triangle_count()) +
                       " faces (after dropping unreferenced vertices)");
  // The encoder's grid: origin = bbox min, extent = largest bbox side.
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k)
    lo[k] = hi[k] = input.positions[k];
  for (size_t i = 0; i < input.vertex_count(); ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], input.positions[3 * i + k]);
      hi[k] = std::max(hi[k], input.positions[3 * i + k]);
    }
  double extent = 0;
  for (int k = 0; k < 3; ++k)
    extent = std::max(extent, double(hi[k]) - double(lo[k]));
  const double tol = 1e-5 * std::max(extent, 1e-30);
  bool ok = std::fabs(double(info.grid.extent) - extent) <= tol;
  for (int k = 0; k < 3; ++k)
    ok = ok && std::fabs(double(info.grid.origin[k]) - double(lo[k])) <= tol;
  if (!ok) {
    char buf[400];
    std::snprintf(buf, sizeof buf,
                  "its grid (origin %g,%g,%g, extent %g) is not the mesh's bounding box "
                  "(min %g,%g,%g, largest side %g)",
                  info.grid.origin[0], info.grid.origin[1], info.grid.origin[2], info.grid.extent,
                  lo[0], lo[1], lo[2], extent);
    throw pomar::Error(pre + buf);
  }
}

// ----- Draco -----
bool have_program(const char *name) {
  const char *path = std::getenv("PATH");
  if (!path)
    return false;
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':'))
    if (!dir.empty() && access((dir + "/" + name).c_str(), X_OK) == 0)
      return true;
  return false;
}

int run(const std::vector<std::string> &cmd) {
  std::string line;
  for (const auto &c : cmd) {
    line += "'";
    for (char ch : c)
      line += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    line += "' ";
  }
  line += ">/dev/null 2>&1";
  const int st = std::system(line.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

// ----- output -----
std::string fmt(const char *f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

void print_table(const std::vector<Measure> &rows) {
  std::printf("| %-22s | %9s | %7s | %8s | %8s | %11s | %11s | %7s |\n", "level / state", "bytes",
              "bpv", "vertices", "faces", "Hausdorff", "RMS", "PSNR dB");
  std::printf("|%s|%s|%s|%s|%s|%s|%s|%s|\n", std::string(24, '-').c_str(), std::string(11, '-').c_str(),
              std::string(9, '-').c_str(), std::string(10, '-').c_str(), std::string(10, '-').c_str(),
              std::string(13, '-').c_str(), std::string(13, '-').c_str(), std::string(9, '-').c_str());
  for (const auto &r : rows)
    std::printf("| %-22s | %9llu | %7.3f | %8zu | %8zu | %11.4e | %11.4e | %7.2f |\n", r.state.c_str(),
                static_cast<unsigned long long>(r.bytes), r.bpv, r.vertices, r.faces, r.hausdorff,
                r.rms, r.psnr);
}

void write_csv(const std::string &path, const std::vector<Measure> &rows) {
  std::ostringstream o;
  o << "kind,state,level,bytes,bpv,vertices,faces,hausdorff_rel,rms_rel,psnr_db,"
       "hausdorff_orig_to_dec_rel,hausdorff_dec_to_orig_rel,samples_orig,samples_dec\n";
  for (const auto &r : rows)
    o << r.kind << ',' << r.state << ',' << r.level << ',' << r.bytes << ',' << fmt("%.4f", r.bpv)
      << ',' << r.vertices << ',' << r.faces << ',' << fmt("%.6e", r.hausdorff) << ','
      << fmt("%.6e", r.rms) << ',' << fmt("%.3f", r.psnr) << ',' << fmt("%.6e", r.h_fwd) << ','
      << fmt("%.6e", r.h_bwd) << ',' << r.samples_fwd << ',' << r.samples_bwd << '\n';
  const std::string s = o.str();
  pomar::write_file_atomic(path, s.data(), s.size());
}

std::string xml_escape(const std::string &s) {
  std::string o;
  for (char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else
      o += c;
  }
  return o;
}

/// "Nice" tick step for a range (1, 2 or 5 x 10^k), about `n` ticks.
double nice_step(double range, int n) {
  const double raw = range / n;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw)
      return m * p;
  return 10 * p;
}

/// x = bits per vertex (linear), y = PSNR in dB (i.e. RMS on a log scale).
void write_svg(const std::string &path, const std::string &title, const std::vector<Measure> &rows,
               double quant_psnr) {
  const double W = 820, H = 540, L = 80, R = 200, T = 50, B = 60;
  double xmax = 0, ymin = 1e9, ymax = -1e9;
  for (const auto &r : rows) {
    if (!std::isfinite(r.psnr))
      continue;
    xmax = std::max(xmax, r.bpv);
    ymin = std::min(ymin, r.psnr);
    ymax = std::max(ymax, r.psnr);
  }
  if (std::isfinite(quant_psnr))
    ymax = std::max(ymax, quant_psnr);
  if (xmax <= 0)
    xmax = 1;
  const double xs = nice_step(xmax, 8);
  xmax = std::ceil(xmax * 1.02 / xs) * xs;
  const double ys = nice_step(std::max(ymax - ymin, 1.0), 8);
  ymin = std::floor(ymin / ys) * ys;
  ymax = std::ceil((ymax + 0.01) / ys) * ys;
  auto X = [&](double v) { return L + (W - L - R) * v / xmax; };
  auto Y = [&](double v) { return H - B - (H - T - B) * (v - ymin) / (ymax - ymin); };

  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
    << "\" viewBox=\"0 0 " << W << ' ' << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text x=\"" << (L + (W - L - R) / 2) << "\" y=\"25\" text-anchor=\"middle\" font-size=\"15\">"
    << xml_escape(title) << "</text>\n";
  // grid + ticks
  for (double v = 0; v <= xmax + 1e-9; v += xs) {
    o << "<line x1=\"" << X(v) << "\" y1=\"" << T << "\" x2=\"" << X(v) << "\" y2=\"" << H - B
      << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << X(v) << "\" y=\"" << H - B + 16 << "\" text-anchor=\"middle\">" << fmt("%g", v)
      << "</text>\n";
  }
  for (double v = ymin; v <= ymax + 1e-9; v += ys) {
    o << "<line x1=\"" << L << "\" y1=\"" << Y(v) << "\" x2=\"" << W - R << "\" y2=\"" << Y(v)
      << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << L - 6 << "\" y=\"" << Y(v) + 4 << "\" text-anchor=\"end\">" << fmt("%g", v)
      << "</text>\n";
  }
  o << "<rect x=\"" << L << "\" y=\"" << T << "\" width=\"" << W - L - R << "\" height=\"" << H - T - B
    << "\" fill=\"none\" stroke=\"black\"/>\n";
  o << "<text x=\"" << (L + (W - L - R) / 2) << "\" y=\"" << H - 15
    << "\" text-anchor=\"middle\">bits per vertex (of the full mesh)</text>\n";
  o << "<text transform=\"translate(20," << (T + (H - T - B) / 2)
    << ") rotate(-90)\" text-anchor=\"middle\">PSNR = 20 log10(bbox diag / RMS) [dB]</text>\n";
  if (std::isfinite(quant_psnr) && quant_psnr <= ymax) {
    o << "<line x1=\"" << L << "\" y1=\"" << Y(quant_psnr) << "\" x2=\"" << W - R << "\" y2=\""
      << Y(quant_psnr) << "\" stroke=\"#999\" stroke-dasharray=\"4,4\"/>\n";
  }
  // curves
  auto polyline = [&](const char *kind, const char *color) {
    std::string pts;
    for (const auto &r : rows)
      if (r.kind == kind && std::isfinite(r.psnr))
        pts += fmt("%.2f", X(r.bpv)) + "," + fmt("%.2f", Y(r.psnr)) + " ";
    if (pts.empty())
      return;
    o << "<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"1.5\" points=\"" << pts
      << "\"/>\n";
    for (const auto &r : rows)
      if (r.kind == kind && std::isfinite(r.psnr))
        o << "<circle cx=\"" << X(r.bpv) << "\" cy=\"" << Y(r.psnr) << "\" r=\"2.5\" fill=\"" << color
          << "\"><title>" << xml_escape(r.state) << fmt(": %.3f bpv, ", r.bpv)
          << fmt("%.2f dB", r.psnr) << "</title></circle>\n";
  };
  polyline("global", "#1f77b4");
  polyline("clustered", "#2ca02c");
  for (const auto &r : rows) {
    if (!std::isfinite(r.psnr) || (r.kind != "state" && r.kind != "draco"))
      continue;
    const char *color = r.kind == "draco" ? "#d62728" : "#ff7f0e";
    if (r.kind == "draco")
      o << "<rect x=\"" << X(r.bpv) - 5 << "\" y=\"" << Y(r.psnr) - 5
        << "\" width=\"10\" height=\"10\" fill=\"" << color << "\"/>\n";
    else
      o << "<path d=\"M" << X(r.bpv) << ',' << Y(r.psnr) - 6 << " l6,6 l-6,6 l-6,-6 z\" fill=\"" << color
        << "\"/>\n";
    o << "<text x=\"" << X(r.bpv) + 8 << "\" y=\"" << Y(r.psnr) - 6 << "\" font-size=\"10\" fill=\""
      << color << "\">" << xml_escape(r.state) << "</text>\n";
  }
  // legend
  const double lx = W - R + 15;
  double ly = T + 10;
  auto legend = [&](const char *color, const char *shape, const std::string &text) {
    if (std::string(shape) == "line")
      o << "<line x1=\"" << lx << "\" y1=\"" << ly << "\" x2=\"" << lx + 20 << "\" y2=\"" << ly
        << "\" stroke=\"" << color << "\" stroke-width=\"2\"/>\n";
    else if (std::string(shape) == "square")
      o << "<rect x=\"" << lx + 5 << "\" y=\"" << ly - 5 << "\" width=\"10\" height=\"10\" fill=\"" << color
        << "\"/>\n";
    else if (std::string(shape) == "dash")
      o << "<line x1=\"" << lx << "\" y1=\"" << ly << "\" x2=\"" << lx + 20 << "\" y2=\"" << ly
        << "\" stroke=\"" << color << "\" stroke-dasharray=\"4,4\"/>\n";
    else
      o << "<path d=\"M" << lx + 10 << ',' << ly - 6 << " l6,6 l-6,6 l-6,-6 z\" fill=\"" << color << "\"/>\n";
    o << "<text x=\"" << lx + 26 << "\" y=\"" << ly + 4 << "\">" << xml_escape(text) << "</text>\n";
    ly += 20;
  };
  bool has_cl = false, has_state = false, has_draco = false;
  for (const auto &r : rows) {
    has_cl |= r.kind == "clustered";
    has_state |= r.kind == "state";
    has_draco |= r.kind == "draco";
  }
  legend("#1f77b4", "line", "pomar global levels");
  if (has_cl)
    legend("#2ca02c", "line", "pomar, all clusters at l");
  if (has_state)
    legend("#ff7f0e", "diamond", "pomar clustered states");
  if (has_draco)
    legend("#d62728", "square", "Draco (single rate)");
  if (std::isfinite(quant_psnr))
    legend("#999", "dash", "quantization bound");
  o << "</svg>\n";
  const std::string s = o.str();
  pomar::write_file_atomic(path, s.data(), s.size());
}

int real_main(int argc, char **argv) {
  const Args args = parse(argc, argv);
  const auto t_start = Clock::now();

  pomar::Mesh input = pomar::load_mesh(args.mesh);

  std::vector<uint8_t> data;
  std::string pomar_name = args.pomar;
  if (!args.pomar.empty()) {
    data = pomar::read_file(args.pomar);
  } else {
    pomar::EncodeOptions opt;
    opt.bits = args.bits;
    data = pomar::encode(input, opt);
    pomar_name = "(in-memory encode of " + args.mesh + ")";
    if (!args.save_pomar.empty())
      pomar::write_file_atomic(args.save_pomar, data.data(), data.size());
  }
  const pomar::FileInfo info = pomar::inspect(data.data(), data.size());
  pomar::Mesh full = pomar::decode(data.data(), data.size(), -1);
  // Distances are between surfaces: vertices no face uses (a lossless file keeps them) are
  // not samples of either.
  pomar::drop_unreferenced_vertices(input);
  pomar::drop_unreferenced_vertices(full);
  check_match(input, info, full, args.mesh, pomar_name);
  if (!args.pomar.empty() && args.bits_given && args.bits != info.bits)
    std::fprintf(stderr, "pomar_rd: note: %s uses a %d-bit grid; --bits %d only applies to Draco\n",
                 args.pomar.c_str(), info.bits, args.bits);
  const int bits = args.pomar.empty() || !args.bits_given ? info.bits : args.bits;

  Reference ref;
  pomar::to_vcg(input, ref.mesh);
  prepare(ref.mesh);
  ref.diag = ref.mesh.bbox.Diag();
  ref.seed = args.seed;
  ref.samples = args.samples ? args.samples
                             : std::clamp<long>(10L * long(input.triangle_count()), 200000L, 2000000L);
  ref.sampler = std::make_unique<Sampler>(&ref.mesh);
  const double quant_rel = std::sqrt(3.0) / 2.0 * info.grid.step() / ref.diag;
  const double full_v = double(input.vertex_count());

  std::printf("%s: %zu vertices, %zu faces, bbox diagonal %.6g\n", args.mesh.c_str(),
              input.vertex_count(), input.triangle_count(), ref.diag);
  std::printf("%s: %zu bytes, %d-bit grid (cell %.6g), %zu levels%s\n", pomar_name.c_str(), data.size(),
              info.bits, info.grid.step(), info.levels.size(),
              info.clustered() ? (", random access: " + std::to_string(info.clusters) + " clusters, " +
                                  std::to_string(info.global_levels) + " global levels")
                                     .c_str()
                               : ", pure progressive");
  std::printf("sampling: every vertex + Monte-Carlo face samples: %ld on the original, "
              "min(%ld, max(%ld, 10 x faces)) on a decoded mesh; seed %u\n",
              ref.samples, ref.samples, kMinSamples, ref.seed);
  std::printf("quantization bound (sqrt(3)/2 * cell / diag): %.4e (PSNR %.2f dB)\n\n", quant_rel,
              -20 * std::log10(quant_rel));

  std::vector<Measure> rows;
  const int L = static_cast<int>(info.levels.size());
  const int G = info.clustered() ? static_cast<int>(info.global_levels) : L;

  // Global levels: header + base + levels 1..l.
  uint64_t bytes = info.header_bytes + info.base_bytes;
  for (int l = 0; l <= G; ++l) {
    if (l > 0)
      bytes += info.levels[l - 1].connectivity_bytes + info.levels[l - 1].geometry_bytes;
    Measure m;
    m.kind = "global";
    m.state = "level " + std::to_string(l);
    m.level = l;
    m.bytes = bytes;
    m.bpv = 8.0 * double(bytes) / full_v;
    if (l == L)
      measure(ref, full, m);
    else
      measure(ref, pomar::decode(data.data(), data.size(), l), m);
    rows.push_back(m);
    std::fprintf(stderr, "  %s: %.2f s\n", m.state.c_str(), m.seconds);
  }

  if (info.clustered()) {
    auto selective = [&](const char *kind, const std::string &label, int level,
                         const std::function<void(pomar::SelectiveDecoder &)> &want) {
      pomar::SelectiveDecoder d(std::make_unique<pomar::MemorySource>(data.data(), data.size()));
      want(d);
      d.update();
      Measure m;
      m.kind = kind;
      m.state = label;
      m.level = level;
      m.bytes = d.bytes_read();
      m.bpv = 8.0 * double(m.bytes) / full_v;
      measure(ref, d.mesh(), m);
      std::fprintf(stderr, "  %s: %.2f s\n", m.state.c_str(), m.seconds);
      return m;
    };
    for (int l = G + 1; l <= L; ++l)
      rows.push_back(selective("clustered", "all clusters " + std::to_string(l), l,
                               [&](pomar::SelectiveDecoder &d) { d.want_all(l); }));
    rows.push_back(selective("state", "base clustered", G, [](pomar::SelectiveDecoder &) {}));
    rows.push_back(selective("state", "cluster 0 finest", -1,
                             [&](pomar::SelectiveDecoder &d) { d.want_cluster(0, L); }));
    // Everything refined = the "all clusters L" row (same decode, same bytes).
    Measure all = rows[rows.size() - 3];
    all.kind = "state";
    all.state = "all refined";
    rows.push_back(all);
  }

  if (args.draco) {
    if (!have_program("draco_encoder") || !have_program("draco_decoder")) {
      std::fprintf(stderr, "pomar_rd: draco_encoder/draco_decoder not found: no Draco point\n");
    } else {
      char tmpl[] = "/tmp/pomar_rd.XXXXXX";
      if (!mkdtemp(tmpl))
        throw pomar::Error("cannot create a temporary directory");
      const std::string dir = tmpl, drc = dir + "/mesh.drc", dec = dir + "/mesh.ply";
      const auto t0 = Clock::now();
      // Positions and triangles only, like pomar (the horse's PLY carries normals).
      const int rc1 = run({"draco_encoder", "-i", args.mesh, "-o", drc, "-qp", std::to_string(bits),
                           "-cl", "7", "--skip", "NORMAL", "--skip", "TEX_COORD", "--skip",
                           "GENERIC"});
      const int rc2 = rc1 == 0 ? run({"draco_decoder", "-i", drc, "-o", dec}) : -1;
      if (rc1 != 0 || rc2 != 0) {
        std::fprintf(stderr, "pomar_rd: draco failed (encoder %d, decoder %d): no Draco point\n", rc1, rc2);
      } else {
        const double draco_s = seconds_since(t0);
        Measure m;
        m.kind = "draco";
        m.state = "draco qp" + std::to_string(bits) + " cl7";
        m.level = -1;
        m.bytes = std::filesystem::file_size(drc);
        m.bpv = 8.0 * double(m.bytes) / full_v;
        measure(ref, pomar::load_mesh(dec), m);
        rows.push_back(m);
        std::fprintf(stderr, "  draco: encode+decode %.2f s, measure %.2f s\n", draco_s, m.seconds);
      }
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  }

  print_table(rows);
  if (!args.csv.empty())
    write_csv(args.csv, rows);
  if (!args.svg.empty()) {
    std::string title = std::filesystem::path(args.mesh).filename().string() + ": " +
                        std::to_string(input.vertex_count()) + " vertices, " +
                        std::to_string(info.bits) + "-bit grid";
    write_svg(args.svg, title, rows, -20 * std::log10(quant_rel));
  }
  std::printf("\ntotal time %.1f s\n", seconds_since(t_start));
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  try {
    return real_main(argc, argv);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "pomar_rd: error: %s\n", e.what());
    return 1;
  }
}
