// pomar: command-line front end of the codec.
//   pomar encode IN OUT.pomar [--bits N] [--progressive] [--strict | --repair] [--keep-order]
//                [--max-memory SIZE]
//   pomar decode IN.pomar OUT [--level L] [--cluster/--sphere/--box ...] [--skip-damaged]
//                [--max-memory SIZE]
//   pomar info IN.pomar [--json | --check]
//   pomar verify ORIGINAL IN.pomar [DECODED] [--repair]
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <sys/stat.h>
#include <unistd.h>

#include "pomar/limits.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "pomar/repair.h"

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Progress on a terminal: one self-overwriting stderr line; silent otherwise.
pomar::Progress terminal_progress(bool quiet) {
  if (quiet || !isatty(fileno(stderr)))
    return {};
  return [last = -1](double f, const char *stage) mutable {
    const int pct = static_cast<int>(f * 100.0);
    if (pct == last)
      return;
    last = pct;
    std::fprintf(stderr, "\r%-10s %3d%%", stage, pct);
    if (pct >= 100)
      std::fprintf(stderr, "\r%20s\r", "");
    std::fflush(stderr);
  };
}

constexpr const char *kRepairHint =
    " (without --strict pomar stores the cut and gives the mesh back exactly; --repair cuts it "
    "for good)";

/// Runs make_manifold() on `mesh` and prints what it changed on stderr, one line per kind
/// of change; "nothing to repair" only when not quiet. Returns the seconds it took.
double repair_and_report(pomar::Mesh &mesh, bool quiet) {
  const auto t0 = Clock::now();
  const pomar::RepairReport r = pomar::make_manifold(mesh);
  const double seconds = since(t0);
  if (!r.changed() && quiet)
    return seconds;
  const std::string summary = r.summary();
  size_t begin = 0;
  while (begin <= summary.size()) {
    const size_t end = std::min(summary.find('\n', begin), summary.size());
    std::fprintf(stderr, "pomar: repair: %s\n", summary.substr(begin, end - begin).c_str());
    begin = end + 1;
  }
  return seconds;
}

double bpv(uint64_t bytes, uint32_t vertices) {
  return vertices ? 8.0 * double(bytes) / double(vertices) : 0.0;
}

// ---------------------------------------------------------------- encode

struct EncodeArgs {
  std::string in, out;
  int bits = 12;
  uint32_t clusters = 0;
  double cluster_ratio = 0.01;
  bool progressive = false, quiet = false, repair = false, strict = false, keep_order = false;
  bool embed_textures = false, force = false;
  std::string max_memory = "auto";
  unsigned threads = 0;
  pomar::AttributeOptions attributes;
  std::string drop;
};

/// "--drop colour,normals,scalars,texcoords" (also "color", "normal", "scalar", "texcoord",
/// "uv", "all") as a mask of what is kept.
pomar::AttributeMask parse_drop(const std::string &list) {
  pomar::AttributeMask keep;
  size_t start = 0;
  while (start <= list.size() && !list.empty()) {
    const size_t comma = std::min(list.find(',', start), list.size());
    const std::string w = list.substr(start, comma - start);
    if (w == "colour" || w == "colours" || w == "color" || w == "colors")
      keep.colour = false;
    else if (w == "normal" || w == "normals")
      keep.normals = false;
    else if (w == "scalar" || w == "scalars" || w == "quality")
      keep.scalars = false;
    else if (w == "texcoord" || w == "texcoords" || w == "uv" || w == "uvs")
      keep.texcoords = false;
    else if (w == "all")
      keep = pomar::AttributeMask::none();
    else
      throw pomar::Error(pomar::Error::Kind::Usage,
                         "bad --drop '" + list + "': '" + w +
                             "' is not one of colour, normals, scalars, texcoords, all");
    start = comma + 1;
  }
  return keep;
}

/// "colour (3 x 8 bits, exact)", "normal (9-bit octahedral, <= 0.332 deg)", ...
std::string describe_precision(pomar::AttributeKind kind, uint32_t components, int bits,
                               double bound) {
  char text[160];
  if (kind == pomar::AttributeKind::Colour)
    std::snprintf(text, sizeof text, "%s, 8 bits exact", components == 4 ? "RGBA" : "RGB");
  else if (bits == 0)
    std::snprintf(text, sizeof text, "exact floats");
  else if (kind == pomar::AttributeKind::Normal)
    std::snprintf(text, sizeof text, "%d-bit octahedral, error <= %.3g deg", bits, bound);
  else
    std::snprintf(text, sizeof text, "%d bits over its range, error <= %.3g", bits, bound);
  return text;
}

void print_attributes(const pomar::FileInfo &i) {
  for (const pomar::AttributeInfo &a : i.attributes) {
    // (the seam cut's wedge values: per-corner texture coordinates and face materials)
    if (a.name == "pomar:corner texcoord")
      std::printf("  per-corner texture coordinates %.2f bits/vertex (%s)\n",
                  bpv(a.bytes, i.vertices),
                  describe_precision(a.kind, a.components, a.bits, a.bound).c_str());
    else if (a.name == "pomar:face material")
      std::printf("  face materials %.2f bits/vertex (exact)\n", bpv(a.bytes, i.vertices));
    else
      std::printf("  attribute %-10s %-8s %.2f bits/vertex (%s)\n",
                  pomar::printable(a.name).c_str(), pomar::kind_name(a.kind),
                  bpv(a.bytes, i.vertices),
                  describe_precision(a.kind, a.components, a.bits, a.bound).c_str());
  }
  for (size_t t = 0; t < i.texture_files.size(); ++t) {
    const uint64_t embedded = t < i.embedded_texture_bytes.size() ? i.embedded_texture_bytes[t] : 0;
    if (embedded)
      std::printf("  texture file %s (embedded, %llu bytes)\n",
                  pomar::printable(i.texture_files[t]).c_str(),
                  static_cast<unsigned long long>(embedded));
    else
      std::printf("  texture file %s\n", pomar::printable(i.texture_files[t]).c_str());
  }
}

/// The extension of `path` in lower case (".ply"), "" if it has none.
std::string lower_extension(const std::string &path) {
  const size_t dot = path.rfind('.'), slash = path.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

/// The folder of `path` ("" for the current one), with a trailing '/'.
std::string folder_of(const std::string &path) {
  const size_t slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

/// A texture file name as a path beside `mesh_path`: MeshLab's "<this>" stands for the mesh
/// file's name without its extension.
std::string texture_path(const std::string &mesh_path, const std::string &name) {
  std::string base = mesh_path.substr(folder_of(mesh_path).size());
  if (const size_t dot = base.rfind('.'); dot != std::string::npos && dot > 0)
    base.resize(dot);
  std::string out = name;
  for (size_t at = out.find("<this>"); at != std::string::npos; at = out.find("<this>", at))
    out.replace(at, 6, base);
  return out;
}

/// A texture file name a decode may write beside its output: relative, no "..", no control
/// characters (the names come from the file).
bool safe_texture_name(const std::string &name) {
  if (name.empty() || name[0] == '/' || name.find('\\') != std::string::npos)
    return false;
  for (unsigned char c : name)
    if (c < 0x20 || c == 0x7F)
      return false;
  for (size_t start = 0; start <= name.size();) {
    const size_t end = std::min(name.find('/', start), name.size());
    const std::string part = name.substr(start, end - start);
    if (part == ".." || part.empty())
      return false;
    start = end + 1;
  }
  return true;
}

/// Refuse an output that is the input (the same file, also through links: it would be
/// overwritten) and, unless `force`, a .pomar file written under a mesh file's extension.
void check_output(const std::string &in, const std::string &out, bool pomar_output, bool force) {
  struct stat a, b;
  if (::stat(in.c_str(), &a) == 0 && ::stat(out.c_str(), &b) == 0 && a.st_dev == b.st_dev &&
      a.st_ino == b.st_ino)
    throw pomar::Error(pomar::Error::Kind::Usage,
                       "the output " + out + " is the input " + in +
                           ": it would be overwritten; choose another output file");
  if (!pomar_output || force)
    return;
  const std::string ext = lower_extension(out);
  if (ext == ".ply" || ext == ".obj" || ext == ".off" || ext == ".stl")
    throw pomar::Error(pomar::Error::Kind::Usage,
                       "the output " + out +
                           " has a mesh file's extension, but pomar encode "
                           "writes a .pomar file, which mesh readers cannot open: name it " +
                           out.substr(0, out.size() - ext.size()) +
                           ".pomar (or add --force to write it under this name)");
}

/// `e` with the .pomar file's name in front of its message, if it does not name it yet.
pomar::Error naming(const pomar::Error &e, const std::string &path) {
  const std::string what = e.what();
  if (what.find(path) != std::string::npos)
    return e;
  pomar::Error named(e.kind(), path + ": " + what);
  named.with_path(e.path().empty() ? path : e.path()).in_block(e.level(), e.cluster());
  return named;
}

/// --embed-textures: each texture file's bytes, read beside the input mesh.
void embed_textures(const std::string &in, pomar::Mesh &mesh) {
  mesh.texture_images.assign(mesh.texture_files.size(), {});
  for (size_t t = 0; t < mesh.texture_files.size(); ++t) {
    const std::string &name = mesh.texture_files[t];
    const std::string file = texture_path(in, name);
    const std::string path = file.size() && file[0] == '/' ? file : folder_of(in) + file;
    try {
      mesh.texture_images[t] = pomar::read_file(path);
    } catch (const pomar::Error &e) {
      throw pomar::Error(pomar::Error::Kind::Io, "--embed-textures: texture file '" + name +
                                                     "' of " + in + " cannot be read: " + e.what());
    }
  }
}

/// The decoded mesh's embedded images, written beside `out` under their texture file
/// names; an existing file is never replaced (the same bytes: nothing to do; other bytes:
/// a warning). Returns how many images were written.
size_t write_embedded_textures(const std::string &out, const pomar::Mesh &mesh, bool quiet) {
  size_t written = 0;
  for (size_t t = 0; t < mesh.texture_images.size() && t < mesh.texture_files.size(); ++t) {
    const std::vector<uint8_t> &image = mesh.texture_images[t];
    const std::string name = texture_path(out, mesh.texture_files[t]);
    if (image.empty())
      continue;
    if (!safe_texture_name(name)) {
      std::fprintf(stderr,
                   "pomar: warning: embedded texture %zu not written: its name is not a "
                   "relative path inside the output's folder\n",
                   t);
      continue;
    }
    const std::string path = folder_of(out) + name;
    if (std::FILE *f = std::fopen(path.c_str(), "rb")) {
      std::fclose(f);
      if (pomar::read_file(path) != image && !quiet)
        std::fprintf(stderr,
                     "pomar: warning: %s exists and differs from the embedded texture '%s': "
                     "kept as it is\n",
                     path.c_str(), name.c_str());
      continue;
    }
    const size_t slash = name.rfind('/');
    if (slash != std::string::npos) // its folders inside the output's
      for (size_t at = name.find('/'); at != std::string::npos && at <= slash;
           at = name.find('/', at + 1))
        ::mkdir((folder_of(out) + name.substr(0, at)).c_str(), 0777);
    pomar::write_file_atomic(path, image.data(), image.size());
    ++written;
  }
  return written;
}

/// One stderr warning naming what is lost: `what` is the list, `why` ends the line.
void warn_dropped(const std::string &file, const std::vector<std::string> &what, const char *verb,
                  const char *why) {
  if (what.empty())
    return;
  std::string list;
  for (const auto &s : what)
    list += (list.empty() ? "" : ", ") + s;
  std::fprintf(stderr, "pomar: warning: %s %s %s%s\n", file.c_str(), verb,
               pomar::printable(list).c_str(), why);
}

/// What follows the list of what a mesh file cannot hold: where it would be kept.
const char *not_written_hint(const std::string &path) {
  return lower_extension(path) == ".ply" ? ": not written (.obj keeps them)"
                                         : ": not written (.ply keeps every attribute)";
}

int run_encode(const EncodeArgs &a) {
  check_output(a.in, a.out, true, a.force);
  const auto t0 = Clock::now();
  const uint64_t memory_limit = pomar::parse_memory_size(a.max_memory);
  pomar::LoadReport load;
  // Refused as soon as the file's header tells the mesh size, before it is read, with the
  // estimate for the file's format (its reader's own peak) and, with --keep-order, the
  // lossless stage's part (a mesh that turns out to need cutting is checked for it by the
  // encoder, before the encoding).
  pomar::Mesh mesh = pomar::load_mesh(a.in, &load, [&](uint64_t v, uint64_t f) {
    const uint64_t lossless = a.keep_order ? pomar::lossless_encode_memory(f, true) : 0;
    pomar::check_encode_memory(v, f, memory_limit, 0, 0, 1, pomar::encode_input(load),
                               pomar::encode_input_extra(load, v) + lossless);
  });
  if (!a.quiet)
    warn_dropped(a.in, load.ignored_attributes, "has",
                 ", not kept (.pomar keeps positions, triangles, per-vertex colour, normals, "
                 "scalars and texture coordinates, per-corner texture coordinates and "
                 "materials)");
  const double t_load = since(t0);
  const double t_repair = a.repair ? repair_and_report(mesh, a.quiet) : 0.0;
  if (a.embed_textures)
    embed_textures(a.in, mesh);
  pomar::EncodeOptions opt;
  opt.bits = a.bits;
  opt.clusters = a.clusters;
  opt.cluster_ratio = a.cluster_ratio;
  opt.progressive = a.progressive;
  opt.threads = a.threads;
  opt.progress = terminal_progress(a.quiet);
  opt.memory_limit = memory_limit;
  opt.attributes = a.attributes;
  opt.attributes.keep = parse_drop(a.drop);
  opt.strict = a.strict;
  opt.keep_order = a.keep_order;
  pomar::EncodeReport r;
  const auto t1 = Clock::now();
  std::vector<uint8_t> file;
  const size_t input_vertices = mesh.vertex_count(), input_faces = mesh.triangle_count();
  try {
    // The mesh is handed over (freed once quantized: a smaller peak), except with --strict,
    // whose refusal looks at it again to hint at --repair.
    file = a.strict ? pomar::encode(mesh, opt, &r) : pomar::encode(std::move(mesh), opt, &r);
  } catch (const pomar::Error &e) {
    if (a.strict && pomar::repair_would_change(mesh))
      throw pomar::Error(e.kind(), e.what() + std::string(kRepairHint));
    throw;
  }
  const double t_encode = since(t1);
  pomar::write_file_atomic(a.out, file.data(), file.size());
  if (a.quiet)
    return 0;
  const pomar::FileInfo &i = r.info;
  if (r.lossless.stored) // the one line saying what the file keeps beyond the coded mesh
    std::fprintf(stderr, "pomar: stored for an exact decode: %s\n", r.lossless.summary().c_str());
  std::printf("%s: %zu vertices, %zu faces", a.in.c_str(), input_vertices, input_faces);
  if (r.unreferenced_vertices)
    std::printf(" (%zu unreferenced vertices %s)", r.unreferenced_vertices,
                r.lossless.unreferenced_vertices ? "kept" : "dropped");
  if (load.welded_vertices)
    std::printf(" (%zu duplicate STL corners welded)", load.welded_vertices);
  std::printf("\n%s: %zu bytes, %.2f bits/vertex (connectivity %.2f, geometry %.2f), %d-bit "
              "grid, %zu levels over a %u-vertex base mesh\n",
              a.out.c_str(), file.size(), bpv(file.size(), i.vertices),
              bpv(i.connectivity_bytes, i.vertices), bpv(i.geometry_bytes, i.vertices), i.bits,
              i.levels.size(), i.base_vertices);
  if (r.lossless.stored)
    std::printf("lossless record: %lu bytes = %.3f bits/vertex (the coded mesh has %u vertices "
                "and %u faces)\n",
                static_cast<unsigned long>(i.lossless_bytes), bpv(i.lossless_bytes, i.vertices),
                i.vertices, i.faces);
  if (i.clustered())
    std::printf("random access: %u clusters from level %u (global part %lu bytes, cluster "
                "blocks %lu bytes)\n",
                i.clusters, i.global_levels, static_cast<unsigned long>(i.global_bytes),
                static_cast<unsigned long>(i.cluster_bytes));
  else
    std::printf("pure progressive (no random access)\n");
  print_attributes(i);
  std::printf("time: read %.3f s, ", t_load);
  if (a.repair)
    std::printf("repair %.3f s, ", t_repair);
  std::printf("encode %.3f s (decimate %.3f s, code %.3f s)\n", t_encode, r.decimate_seconds,
              r.encode_seconds);
  return 0;
}

// ---------------------------------------------------------------- decode

struct DecodeArgs {
  std::string in, out;
  int level = -1;
  std::vector<std::string> clusters, spheres, boxes;
  bool ascii = false, quiet = false, stats = false, skip_damaged = false;
  bool no_attributes = false;
  unsigned threads = 0;
  std::string max_memory = "auto";
  bool selective() const { return !clusters.empty() || !spheres.empty() || !boxes.empty(); }
};

/// "a,b,c[:LEVEL]" -> numbers and level (default `finest`). Throws pomar::Error.
std::vector<double> parse_spec(const std::string &spec, size_t count, int finest, int &level,
                               const char *what) {
  std::string body = spec;
  level = finest;
  const size_t colon = spec.find(':');
  if (colon != std::string::npos) {
    body = spec.substr(0, colon);
    try {
      size_t used = 0;
      level = std::stoi(spec.substr(colon + 1), &used);
      if (used != spec.size() - colon - 1)
        throw std::invalid_argument("level");
    } catch (const std::exception &) {
      throw pomar::Error(pomar::Error::Kind::Usage,
                         std::string("bad ") + what + " '" + spec +
                             "': the level after ':' must be an integer");
    }
  }
  std::vector<double> v;
  size_t pos = 0;
  while (pos <= body.size()) {
    const size_t comma = body.find(',', pos);
    const std::string item =
        body.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    try {
      size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size())
        throw std::invalid_argument("number");
    } catch (const std::exception &) {
      throw pomar::Error(pomar::Error::Kind::Usage, std::string("bad ") + what + " '" + spec +
                                                        "': '" + item + "' is not a number");
    }
    if (comma == std::string::npos)
      break;
    pos = comma + 1;
  }
  if (v.size() != count)
    throw pomar::Error(pomar::Error::Kind::Usage, std::string("bad ") + what + " '" + spec +
                                                      "': expected " + std::to_string(count) +
                                                      " numbers");
  return v;
}

// Exit statuses (README "Exit codes"): one per kind of failure, so that scripts can tell
// a bad mesh from a damaged file from a full disk without reading the message.
// exit_status() is the one place that maps pomar::Error kinds to statuses.
constexpr int kExitError = 1;       // any other error
constexpr int kExitUsage = 2;       // a value the command cannot use (level, cluster, size...)
constexpr int kExitMismatch = 3;    // verify: the mesh differs
constexpr int kExitDamaged = 4;     // a damaged or truncated .pomar file; info --check and
                                    // decode --skip-damaged: damaged blocks (output written)
constexpr int kExitInvalidMesh = 5; // a mesh the codec cannot take (or an unreadable mesh file)
constexpr int kExitIo = 6;          // a file that cannot be read or written
constexpr int kExitMemory = 7;      // the memory limit
constexpr int kExitUnsupported = 8; // a .pomar version or section this build does not read
constexpr int kExitInternal = 70;   // EX_SOFTWARE: a broken invariant of the codec (a bug)

int exit_status(const pomar::Error &e) {
  using Kind = pomar::Error::Kind;
  switch (e.kind()) {
  case Kind::Usage:
    return kExitUsage;
  case Kind::DamagedFile:
  case Kind::TruncatedFile:
    return kExitDamaged;
  case Kind::InvalidMesh:
    return kExitInvalidMesh;
  case Kind::Io:
    return kExitIo;
  case Kind::MemoryLimit:
    return kExitMemory;
  case Kind::Unsupported:
    return kExitUnsupported;
  case Kind::Internal:
    return kExitInternal;
  default:
    return kExitError;
  }
}

/// List skipped blocks on stderr; returns the exit status (0 or kExitDamaged).
int report_damage(const std::vector<pomar::DamagedBlock> &damaged, const std::string &out) {
  if (damaged.empty())
    return 0;
  std::vector<pomar::DamagedBlock> skipped;
  for (const pomar::DamagedBlock &b : damaged) {
    if (b.level_kept >= 0)
      skipped.push_back(b);
    else // damage no block check located: nothing could be skipped
      std::fprintf(stderr, "pomar: warning: %s: %s\n", out.c_str(), b.problem.c_str());
  }
  if (skipped.empty())
    return kExitDamaged;
  std::fprintf(stderr,
               "pomar: warning: %zu damaged block%s skipped; %s is a valid mesh, coarser where "
               "they were:\n%s\n",
               skipped.size(), skipped.size() == 1 ? "" : "s", out.c_str(),
               pomar::describe_damage(skipped, 0, 20).c_str());
  return kExitDamaged;
}

/// A damaged or missing level or cluster block (or a truncated file) can be skipped; say
/// so in the error.
[[noreturn]] void rethrow_with_hint(const pomar::Error &e) {
  using Kind = pomar::Error::Kind;
  const bool skippable =
      e.kind() == Kind::TruncatedFile || (e.kind() == Kind::DamagedFile && e.in_block());
  if (!skippable)
    throw e;
  pomar::Error hinted(e.kind(), e.what() + std::string(" (pomar info --check lists damaged "
                                                       "blocks; pomar decode --skip-damaged "
                                                       "decodes the rest)"));
  hinted.with_path(e.path()).in_block(e.level(), e.cluster());
  throw hinted;
}

int run_selective_decode(const DecodeArgs &a) {
  const auto t0 = Clock::now();
  pomar::SelectiveOptions options;
  options.skip_damaged = a.skip_damaged;
  options.memory_limit = pomar::parse_memory_size(a.max_memory);
  options.threads = a.threads;
  if (a.no_attributes)
    options.attributes = pomar::AttributeMask::none();
  pomar::SelectiveDecoder d(std::make_unique<pomar::FileSource>(a.in), options);
  if (!d.info().clustered())
    throw pomar::Error(pomar::Error::Kind::Usage,
                       a.in + " is a pure progressive file (encoded with --progressive): it has "
                              "no clusters to select; use --level");
  const int finest = d.finest_level();
  if (a.level >= 0)
    d.want_all(std::max(a.level, d.base_clustered_level()));
  for (const std::string &spec : a.clusters) {
    int level;
    const std::vector<double> id = parse_spec(spec, 1, finest, level, "--cluster");
    if (id[0] < 0 || id[0] != double(uint32_t(id[0])))
      throw pomar::Error(pomar::Error::Kind::Usage,
                         "bad --cluster '" + spec +
                             "': the cluster id must be a non-negative integer");
    d.want_cluster(static_cast<uint32_t>(id[0]), level);
  }
  for (const std::string &spec : a.spheres) {
    int level;
    const std::vector<double> v = parse_spec(spec, 4, finest, level, "--sphere");
    const float c[3] = {float(v[0]), float(v[1]), float(v[2])};
    d.want_sphere(c, float(v[3]), level);
  }
  for (const std::string &spec : a.boxes) {
    int level;
    const std::vector<double> v = parse_spec(spec, 6, finest, level, "--box");
    const float lo[3] = {float(v[0]), float(v[1]), float(v[2])};
    const float hi[3] = {float(v[3]), float(v[4]), float(v[5])};
    d.want_box(lo, hi, level);
  }
  try {
    d.update(terminal_progress(a.quiet));
  } catch (const pomar::Error &e) {
    rethrow_with_hint(e);
  }
  const pomar::Mesh mesh = d.exact_mesh(); // every region at its finest: the input exactly
  const double t_decode = since(t0);
  pomar::save_mesh(a.out, mesh, !a.ascii);
  write_embedded_textures(a.out, mesh, a.quiet);
  if (!a.quiet)
    warn_dropped(a.out, pomar::attributes_not_saved(a.out, mesh), "cannot hold",
                 not_written_hint(a.out));
  if (a.stats || !a.quiet) {
    const uint64_t file_size = d.info().total_bytes;
    std::printf("%s: %zu vertices, %zu faces; %u of %u clusters refined (levels %d..%d), %u "
                "blocks read, %lu of %lu bytes read (%.1f%%), %.3f s\n",
                a.out.c_str(), mesh.vertex_count(), mesh.triangle_count(), d.clusters_decoded(),
                d.cluster_count(), d.base_clustered_level(), finest, d.blocks_read(),
                static_cast<unsigned long>(d.bytes_read()), static_cast<unsigned long>(file_size),
                100.0 * double(d.bytes_read()) / double(file_size), t_decode);
  }
  return report_damage(d.damaged(), a.out);
}

int run_decode(const DecodeArgs &a) {
  check_output(a.in, a.out, false, false);
  if (a.selective())
    return run_selective_decode(a);
  const uint64_t memory_limit = pomar::parse_memory_size(a.max_memory);
  const auto t0 = Clock::now();
  const std::vector<uint8_t> data = pomar::read_file(a.in);
  pomar::DecodeOptions options;
  options.level = a.level;
  options.skip_damaged = a.skip_damaged;
  options.memory_limit = memory_limit;
  options.threads = a.threads;
  options.progress = terminal_progress(a.quiet);
  if (a.no_attributes)
    options.attributes = pomar::AttributeMask::none();
  pomar::DecodeReport report;
  pomar::Mesh mesh;
  try {
    mesh = pomar::decode(data.data(), data.size(), options, &report);
  } catch (const pomar::Error &e) {
    rethrow_with_hint(naming(e, a.in));
  }
  const double t_decode = since(t0);
  pomar::save_mesh(a.out, mesh, !a.ascii);
  write_embedded_textures(a.out, mesh, a.quiet);
  if (!a.quiet)
    warn_dropped(a.out, pomar::attributes_not_saved(a.out, mesh), "cannot hold",
                 not_written_hint(a.out));
  if (!a.quiet || a.stats)
    std::printf("%s: %zu vertices, %zu faces (decoded in %.3f s, %zu bytes read)\n", a.out.c_str(),
                mesh.vertex_count(), mesh.triangle_count(), t_decode, data.size());
  if (!report.damaged.empty() && report.clusters_below_request)
    std::fprintf(stderr, "pomar: warning: %u clusters below the requested level\n",
                 report.clusters_below_request);
  return report_damage(report.damaged, a.out);
}

// ---------------------------------------------------------------- info

nlohmann::json info_json(const pomar::FileInfo &i) {
  nlohmann::json j;
  j["version"] = i.version;
  j["vertices"] = i.vertices;
  j["faces"] = i.faces;
  j["bits"] = i.bits;
  j["bbox_min"] = {i.bbox_min[0], i.bbox_min[1], i.bbox_min[2]};
  j["grid_max"] = {i.bbox_max[0], i.bbox_max[1], i.bbox_max[2]};
  j["base_vertices"] = i.base_vertices;
  j["base_faces"] = i.base_faces;
  nlohmann::json levels = nlohmann::json::array();
  levels.push_back({{"level", 0},
                    {"vertices", i.base_vertices},
                    {"faces", i.base_faces},
                    {"bytes", i.base_bytes}});
  for (size_t l = 0; l < i.levels.size(); ++l)
    levels.push_back({{"level", l + 1},
                      {"vertices", i.levels[l].vertices},
                      {"faces", i.levels[l].faces},
                      {"connectivity_bytes", i.levels[l].connectivity_bytes},
                      {"geometry_bytes", i.levels[l].geometry_bytes}});
  j["levels"] = levels;
  j["level_count"] = i.levels.size();
  j["connectivity_bits"] = 8 * i.connectivity_bytes;
  j["geometry_bits"] = 8 * i.geometry_bytes;
  j["clusters"] = i.clusters;
  j["global_levels"] = i.global_levels;
  j["global_bytes"] = i.global_bytes;
  j["tables_bytes"] = i.tables_bytes;
  j["index_bytes"] = i.index_bytes;
  j["cluster_bytes"] = i.cluster_bytes;
  j["lossless_bytes"] = i.lossless_bytes;
  j["lossless_bits_per_vertex"] = bpv(i.lossless_bytes, i.vertices);
  j["input_vertices"] = i.input_vertices;
  j["input_faces"] = i.input_faces;
  j["cluster_block_bytes"] = i.cluster_block_bytes;
  nlohmann::json sections = nlohmann::json::array();
  for (const pomar::FileInfo::Section &sec : i.sections)
    sections.push_back({{"name", sec.name},
                        {"bytes", sec.bytes},
                        {"bpv", bpv(sec.bytes, i.vertices)},
                        {"required", sec.required}});
  j["sections"] = sections;
  j["header_bytes"] = i.header_bytes;
  j["base_bytes"] = i.base_bytes;
  j["total_bytes"] = i.total_bytes;
  j["bpv"] = bpv(i.total_bytes, i.vertices);
  j["connectivity_bpv"] = bpv(i.connectivity_bytes, i.vertices);
  j["geometry_bpv"] = bpv(i.geometry_bytes, i.vertices);
  nlohmann::json attributes = nlohmann::json::array();
  for (const pomar::AttributeInfo &a : i.attributes)
    attributes.push_back({{"kind", pomar::kind_name(a.kind)},
                          {"name", a.name},
                          {"components", a.components},
                          {"bits", a.bits},
                          {"exact", a.bits == 0},
                          {"bound", a.bound},
                          {"bytes", a.bytes},
                          {"bpv", bpv(a.bytes, i.vertices)}});
  j["attributes"] = attributes;
  j["attribute_bytes"] = i.attribute_bytes;
  j["texture_files"] = i.texture_files;
  j["embedded_texture_bytes"] = i.embedded_texture_bytes;
  return j;
}

/// info --check: every block's checksum; exit kExitDamaged if one fails.
int run_check(const std::string &in) {
  const std::vector<uint8_t> data = pomar::read_file(in);
  const std::vector<pomar::DamagedBlock> damaged = pomar::check_blocks(data.data(), data.size());
  if (damaged.empty()) {
    std::printf("%s: every block passes its check\n", in.c_str());
    return 0;
  }
  std::printf("%s: %zu damaged block%s (pomar decode --skip-damaged decodes the rest):\n",
              in.c_str(), damaged.size(), damaged.size() == 1 ? "" : "s");
  for (const pomar::DamagedBlock &b : damaged)
    std::printf("  %s: %s\n", b.block.c_str(), b.problem.c_str());
  return kExitDamaged;
}

int run_info(const std::string &in, bool json) {
  const std::vector<uint8_t> data = pomar::read_file(in);
  const pomar::FileInfo i = pomar::inspect(data.data(), data.size());
  if (json) {
    std::printf("%s\n", info_json(i).dump(2).c_str());
    return 0;
  }
  if (i.clustered())
    std::printf("%s: .pomar version %u, random access: %u clusters, levels 1..%u global\n",
                in.c_str(), i.version, i.clusters, i.global_levels);
  else
    std::printf("%s: .pomar version %u, pure progressive (global levels only)\n", in.c_str(),
                i.version);
  std::printf("  vertices %u, faces %u, %d-bit grid from (%g, %g, %g), cell %.6g\n", i.vertices,
              i.faces, i.bits, i.bbox_min[0], i.bbox_min[1], i.bbox_min[2],
              (double(i.bbox_max[0]) - i.bbox_min[0]) / double((1u << i.bits) - 1));
  std::printf("  size %lu bytes = %.2f bits/vertex: connectivity %.2f, geometry %.2f, base mesh "
              "%.2f, header %.2f\n",
              static_cast<unsigned long>(i.total_bytes), bpv(i.total_bytes, i.vertices),
              bpv(i.connectivity_bytes, i.vertices), bpv(i.geometry_bytes, i.vertices),
              bpv(i.base_bytes, i.vertices), bpv(i.header_bytes, i.vertices));
  if (!i.attributes.empty() || !i.texture_files.empty()) {
    uint64_t coded = 0;
    for (const pomar::AttributeInfo &a : i.attributes)
      coded += a.bytes;
    std::printf("  attributes about %.2f bits/vertex, coded with the positions in the levels and "
                "cluster blocks (encoder's estimate; ATTR section with the base mesh's: %lu "
                "bytes):\n",
                bpv(coded, i.vertices), static_cast<unsigned long>(i.attribute_bytes));
    print_attributes(i);
  }
  if (i.clustered()) {
    std::vector<uint32_t> sizes = i.cluster_block_bytes;
    std::sort(sizes.begin(), sizes.end());
    std::printf("  global part %lu bytes (header, base mesh, %u global levels, model tables %lu, "
                "cluster index %lu); cluster blocks %lu bytes\n",
                static_cast<unsigned long>(i.global_bytes), i.global_levels,
                static_cast<unsigned long>(i.tables_bytes),
                static_cast<unsigned long>(i.index_bytes),
                static_cast<unsigned long>(i.cluster_bytes));
    if (!sizes.empty())
      std::printf("  %u clusters, block bytes min %u, median %u, max %u (pomar info --json lists "
                  "them all)\n",
                  i.clusters, sizes.front(), sizes[sizes.size() / 2], sizes.back());
  }
  for (const pomar::FileInfo::Section &sec : i.sections)
    std::printf("  section %s: %lu bytes = %.2f bits/vertex%s\n",
                pomar::printable(sec.name).c_str(), static_cast<unsigned long>(sec.bytes),
                bpv(sec.bytes, i.vertices), sec.required ? " (required)" : "");
  if (i.lossless_bytes)
    std::printf("  lossless record (section LSLS): a full decode gives back the input's %lu "
                "vertices and %lu faces exactly (levels and regions show the coded, cut mesh)\n",
                static_cast<unsigned long>(i.input_vertices),
                static_cast<unsigned long>(i.input_faces));
  std::printf("  level  vertices     faces  conn.bytes  geom.bytes\n");
  std::printf("  %5d %9u %9u  %10lu  (base mesh)\n", 0, i.base_vertices, i.base_faces,
              static_cast<unsigned long>(i.base_bytes));
  for (size_t l = 0; l < i.levels.size(); ++l) {
    if (l < i.global_levels)
      std::printf("  %5zu %9u %9u  %10lu  %10lu\n", l + 1, i.levels[l].vertices, i.levels[l].faces,
                  static_cast<unsigned long>(i.levels[l].connectivity_bytes),
                  static_cast<unsigned long>(i.levels[l].geometry_bytes));
    else
      std::printf("  %5zu %9u %9u  (clustered)\n", l + 1, i.levels[l].vertices, i.levels[l].faces);
  }
  return 0;
}

// ---------------------------------------------------------------- verify

using Point = std::array<float, 3>;
using Triangle = std::array<Point, 3>;

/// The mesh as a sorted multiset of triangles of positions, each in its smallest rotation:
/// equal for two meshes with the same oriented triangles and positions,
/// whatever the vertex and face order.
std::vector<Triangle> triangle_multiset(const pomar::Mesh &m) {
  std::vector<Triangle> out(m.triangle_count());
  auto p = [&](uint32_t v) {
    return Point{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
  };
  for (size_t f = 0; f < out.size(); ++f) {
    const Triangle t = {p(m.triangles[3 * f]), p(m.triangles[3 * f + 1]),
                        p(m.triangles[3 * f + 2])};
    // The smallest of the three rotations (corners may share a position).
    const Triangle r1 = {t[1], t[2], t[0]}, r2 = {t[2], t[0], t[1]};
    out[f] = std::min({t, r1, r2});
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Largest difference between attribute values a (of vertex i) and b (of vertex j):
/// degrees for normals, absolute otherwise; exact attributes: 0 when bit-identical.
double attribute_error(const pomar::VertexAttribute &a, size_t i, const pomar::VertexAttribute &b,
                       size_t j, bool exact) {
  const uint32_t n = a.components;
  if (a.kind == pomar::AttributeKind::Colour) {
    double e = 0;
    for (uint32_t k = 0; k < n; ++k)
      e = std::max(e, std::fabs(double(a.colour[i * n + k]) - double(b.colour[j * n + k])));
    return e;
  }
  const float *x = &a.values[i * n], *y = &b.values[j * n];
  if (exact && std::memcmp(x, y, 4 * n) == 0)
    return 0;
  if (a.kind == pomar::AttributeKind::Normal && !exact) {
    const bool zero_x = x[0] == 0 && x[1] == 0 && x[2] == 0;
    const bool zero_y = y[0] == 0 && y[1] == 0 && y[2] == 0;
    if (zero_x || zero_y) // a zero-length normal comes back as exactly zero
      return zero_x && zero_y ? 0 : HUGE_VAL;
    const double cx = double(x[1]) * y[2] - double(x[2]) * y[1];
    const double cy = double(x[2]) * y[0] - double(x[0]) * y[2];
    const double cz = double(x[0]) * y[1] - double(x[1]) * y[0];
    const double dot = double(x[0]) * y[0] + double(x[1]) * y[1] + double(x[2]) * y[2];
    return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * 180.0 / M_PI;
  }
  double e = 0;
  for (uint32_t k = 0; k < n; ++k) {
    const double d = std::fabs(double(x[k]) - double(y[k]));
    e = std::max(e, std::isnan(d) ? HUGE_VAL : d);
  }
  return exact && e == 0 ? HUGE_VAL : e; // bit patterns differ (-0 and 0, NaN payloads)
}

/// verify: every attribute of `ref` the file should keep against `out`, vertices matched by
/// position (a vertex may share its position with others: the closest of them counts).
/// Prints one line per attribute; false if one is missing or outside its bound.
bool verify_attributes(const pomar::Mesh &ref, const pomar::Mesh &out, const pomar::FileInfo &info,
                       const pomar::AttributeMask &keep) {
  std::map<Point, std::vector<uint32_t>> at;
  for (uint32_t v = 0; v < ref.vertex_count(); ++v)
    at[Point{ref.positions[3 * v], ref.positions[3 * v + 1], ref.positions[3 * v + 2]}].push_back(
        v);
  bool ok = true;
  for (const pomar::VertexAttribute &a : ref.attributes) {
    if (!keep.keeps(a.kind))
      continue;
    const pomar::VertexAttribute *b = out.find(a.kind, a.name);
    const pomar::AttributeInfo *stored = nullptr;
    for (const pomar::AttributeInfo &s : info.attributes)
      if (s.kind == a.kind && s.name == a.name)
        stored = &s;
    if (!b || !stored || b->components != a.components) {
      std::fprintf(stderr, "pomar: MISMATCH: %s attribute '%s' of the original is %s\n",
                   pomar::kind_name(a.kind), a.name.c_str(),
                   !stored ? "not in the file (verify --drop if it was dropped on purpose)"
                           : "missing from the decoded mesh");
      ok = false;
      continue;
    }
    const bool exact = stored->bits == 0;
    double worst = 0;
    for (uint32_t v = 0; v < out.vertex_count(); ++v) {
      const auto it =
          at.find(Point{out.positions[3 * v], out.positions[3 * v + 1], out.positions[3 * v + 2]});
      if (it == at.end())
        continue; // the geometry check reports it
      double best = HUGE_VAL;
      for (uint32_t r : it->second)
        best = std::min(best, attribute_error(a, r, *b, v, exact));
      worst = std::max(worst, best);
    }
    const bool within = exact ? worst == 0 : worst <= stored->bound;
    ok &= within;
    std::fprintf(within ? stdout : stderr, "%s  %s '%s': %s, max error %.6g%s\n",
                 within ? "" : "pomar: MISMATCH:", pomar::kind_name(a.kind), a.name.c_str(),
                 describe_precision(a.kind, a.components, stored->bits, stored->bound).c_str(),
                 worst, a.kind == pomar::AttributeKind::Normal && !exact ? " deg" : "");
  }
  if (keep.texcoords && ref.texture_files != out.texture_files) {
    std::fprintf(stderr, "pomar: MISMATCH: texture file names differ\n");
    ok = false;
  }
  return ok;
}

/// The texture coordinates of every corner of `m`: corner_texcoords, or the per-vertex ones
/// at each corner (what the OBJ reader gives when no vertex has two); empty if none.
std::vector<float> corner_uvs(const pomar::Mesh &m) {
  if (!m.corner_texcoords.empty())
    return m.corner_texcoords;
  const pomar::VertexAttribute *uv = m.find(pomar::AttributeKind::TexCoord);
  std::vector<float> out;
  if (uv && uv->vertex_count() == m.vertex_count())
    for (const uint32_t v : m.triangles)
      out.insert(out.end(), {uv->values[2 * v], uv->values[2 * v + 1]});
  return out;
}

/// Triangle f's material as "name|texture file|properties" (`names`: else the texture
/// file only), "" without materials.
std::string face_material_text(const pomar::Mesh &m, size_t f, bool names) {
  if (m.face_materials.empty())
    return "";
  const pomar::Material &mat = m.materials[m.face_materials[f]];
  const std::string file = mat.texture >= 0 ? m.texture_files[size_t(mat.texture)] : "";
  return names ? mat.name + "|" + file + "|" + mat.properties : file;
}

/// verify: the per-corner texture coordinates and face materials of `ref` against `out`,
/// faces matched by their corner positions (in their smallest rotation, the corners taken
/// in that order; of several faces with the same corners, the closest). UVs within `bound`
/// (0 = exact: bit for bit); materials by name, texture file and properties (`names`), else
/// by texture file. Prints a line for each; false if one is missing or differs.
bool verify_corners(const pomar::Mesh &ref, const pomar::Mesh &out, int bits, double bound,
                    bool names) {
  const std::vector<float> ru = corner_uvs(ref), ou = corner_uvs(out);
  const bool uvs = !ref.corner_texcoords.empty(), materials = !ref.face_materials.empty();
  if (!uvs && !materials)
    return true;
  if (uvs && ou.empty()) {
    std::fprintf(stderr, "pomar: MISMATCH: the per-corner texture coordinates of the original "
                         "are missing from the decoded mesh\n");
    return false;
  }
  if (materials && out.face_materials.empty()) {
    std::fprintf(stderr, "pomar: MISMATCH: the face materials of the original are missing from "
                         "the decoded mesh\n");
    return false;
  }
  // The smallest rotation of each face's corners, and that rotation.
  auto key = [](const pomar::Mesh &m, size_t f, int &rotation) {
    Triangle t;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.triangles[3 * f + size_t(k)];
      t[size_t(k)] = Point{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
    }
    const Triangle r[3] = {t, {t[1], t[2], t[0]}, {t[2], t[0], t[1]}};
    rotation = int(std::min_element(r, r + 3) - r);
    return r[rotation];
  };
  std::map<Triangle, std::vector<std::pair<size_t, int>>> faces; // of ref: (face, rotation)
  for (size_t f = 0; f < ref.triangle_count(); ++f) {
    int rotation = 0;
    const Triangle t = key(ref, f, rotation);
    faces[t].push_back({f, rotation});
  }
  const bool exact = bound == 0;
  double worst = 0;
  size_t material_mismatches = 0;
  for (size_t g = 0; g < out.triangle_count(); ++g) {
    int rotation = 0;
    const auto it = faces.find(key(out, g, rotation));
    if (it == faces.end())
      continue; // the geometry check reports it
    double best = HUGE_VAL;
    bool material_ok = !materials;
    for (const auto &[f, r] : it->second) {
      double e = 0;
      for (int k = 0; uvs && k < 3; ++k) {
        const float *a = &ru[6 * f + 2 * size_t((k + r) % 3)];
        const float *b = &ou[6 * g + 2 * size_t((k + rotation) % 3)];
        for (int c = 0; c < 2; ++c) {
          const double d = std::fabs(double(a[c]) - double(b[c]));
          e = std::max(e, exact           ? (std::memcmp(a + c, b + c, 4) == 0 ? 0 : HUGE_VAL)
                          : std::isnan(d) ? HUGE_VAL
                                          : d);
        }
      }
      best = std::min(best, e);
      material_ok |= face_material_text(ref, f, names) == face_material_text(out, g, names);
    }
    worst = std::max(worst, best);
    material_mismatches += !material_ok;
  }
  bool ok = true;
  if (uvs) {
    const bool within = exact ? worst == 0 : worst <= bound;
    ok &= within;
    std::fprintf(within ? stdout : stderr,
                 "%s  per-corner texture coordinates: %s, max error %.6g\n",
                 within ? "" : "pomar: MISMATCH:",
                 exact ? std::string("exact").c_str()
                       : (std::to_string(bits) + " bits, within " + std::to_string(bound)).c_str(),
                 worst);
  }
  if (materials) {
    ok &= material_mismatches == 0;
    std::fprintf(material_mismatches ? stderr : stdout, "%s  face materials: %zu materials, %s\n",
                 material_mismatches ? "pomar: MISMATCH:" : "", ref.materials.size(),
                 material_mismatches
                     ? (std::to_string(material_mismatches) + " faces differ").c_str()
                 : names ? "the same per face (names, textures, properties)"
                         : "the same texture per face");
  }
  return ok;
}

/// The vertex positions of `m`, sorted: equal for meshes with the same vertices.
std::vector<Point> point_multiset(const pomar::Mesh &m) {
  std::vector<Point> out(m.vertex_count());
  for (size_t v = 0; v < out.size(); ++v)
    out[v] = {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
  std::sort(out.begin(), out.end());
  return out;
}

int run_verify(const std::string &original, const std::string &file, const std::string &decoded,
               bool repair, const std::string &drop) {
  pomar::Mesh ref = pomar::load_mesh(original);
  // With --repair the reference is the repaired original: what `encode --repair` encoded.
  if (repair)
    repair_and_report(ref, true);
  const std::vector<uint8_t> data = pomar::read_file(file);
  const pomar::FileInfo info = pomar::inspect(data.data(), data.size());
  // A file without a lossless record (encode --strict, or older) has no unreferenced vertex.
  const size_t dropped = info.lossless_bytes == 0 ? pomar::drop_unreferenced_vertices(ref) : 0;
  const bool could_repair = !repair && info.lossless_bytes == 0 && pomar::repair_would_change(ref);
  const pomar::Mesh out =
      decoded.empty() ? pomar::decode(data.data(), data.size()) : pomar::load_mesh(decoded);
  // Snap the original onto the file's grid, as the encoder did.
  for (size_t i = 0; i < ref.positions.size(); ++i) {
    const int axis = static_cast<int>(i % 3);
    ref.positions[i] = info.grid.dequantize(axis, info.grid.quantize(axis, ref.positions[i]));
  }
  // STL stores triangles only (no vertex shared or unused): the triangles are compared.
  std::string ext = decoded.size() >= 4 ? decoded.substr(decoded.size() - 4) : "";
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  const bool triangles_only = ext == ".stl";
  const bool same = triangle_multiset(ref) == triangle_multiset(out) &&
                    (triangles_only || (ref.vertex_count() == out.vertex_count() &&
                                        point_multiset(ref) == point_multiset(out)));
  const std::string what = decoded.empty() ? file : decoded;
  const pomar::AttributeMask keep = parse_drop(drop);
  bool attributes_ok = !same || verify_attributes(ref, out, info, keep);
  if (same && keep.texcoords && (!ref.corner_texcoords.empty() || !ref.face_materials.empty())) {
    // The precision of the stored corners: the decoded mesh's (a decoded mesh file has
    // none: the file is decoded for it).
    int corner_bits = out.corner_texcoord_bits;
    double corner_bound = out.corner_texcoord_bound;
    if (!decoded.empty()) {
      const pomar::Mesh full = pomar::decode(data.data(), data.size());
      corner_bits = full.corner_texcoord_bits;
      corner_bound = full.corner_texcoord_bound;
    }
    // PLY keeps each face's texture, not the material's name and properties.
    const bool names = ext != ".ply";
    attributes_ok &= verify_corners(ref, out, corner_bits, corner_bound, names);
  }
  if (!same) {
    std::fprintf(stderr,
                 "pomar: MISMATCH: %s differs from %s on the %d-bit grid (%zu vertices and %zu "
                 "faces against %zu and %zu)%s\n",
                 what.c_str(), original.c_str(), info.bits, out.vertex_count(),
                 out.triangle_count(), ref.vertex_count(), ref.triangle_count(),
                 could_repair
                     ? " (the original needs a repair to be encoded: if it was encoded with "
                       "--repair, verify with --repair)"
                     : "");
    return kExitMismatch;
  }
  if (!attributes_ok) {
    std::fprintf(stderr, "pomar: MISMATCH: %s has the geometry of %s but not its attributes\n",
                 what.c_str(), original.c_str());
    return 3;
  }
  std::printf("OK: %s matches %s%s: the same %zu vertices and %zu oriented triangles, every vertex "
              "on its %d-bit grid position",
              what.c_str(), original.c_str(), repair ? " after repair" : "", out.vertex_count(),
              out.triangle_count(), info.bits);
  if (dropped)
    std::printf(" (%zu unreferenced vertices of the original are not in the file: encoded with "
                "--strict)",
                dropped);
  if (triangles_only)
    std::printf(" (STL keeps triangles only: vertices not compared)");
  if (!info.attributes.empty())
    std::printf(", attributes within their bounds");
  std::printf("\n");
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  CLI::App app{
      "pomar: progressive, randomly accessible compression of manifold triangle meshes "
      "(POMAR, Maglo et al. 2013).\n\nExamples:\n"
      "  pomar encode bunny.ply bunny.pomar          # 12-bit grid, all levels\n"
      "  pomar info bunny.pomar                      # levels and bits per vertex\n"
      "  pomar decode bunny.pomar coarse.ply --level 10\n"
      "  pomar decode bunny.pomar ear.ply --sphere -0.06,0.16,0.0,0.02 --stats\n"
      "  pomar verify bunny.ply bunny.pomar          # lossless check\n"
      "  pomar encode messy.stl messy.pomar          # any mesh: the cut is stored, exact decode\n"
      "  pomar encode messy.stl fixed.pomar --repair # keep the cut (manifold) mesh instead\n"
      "  pomar verify messy.stl fixed.pomar --repair # lossless w.r.t. the repaired mesh\n"};
  app.require_subcommand(1);
  app.footer("Exit status: 0 success, 1 other error, 2 unusable value (level, cluster, size), "
             "3 verify mismatch, 4 damaged or truncated .pomar (or damaged blocks found or "
             "skipped), 5 mesh the codec cannot take, 6 I/O, 7 memory limit, 8 unsupported "
             ".pomar version or section, 70 internal error.");
  // Ctrl-C or kill during a write: no temporary file left, the old output untouched.
  pomar::remove_temporary_files_on_signals();
  app.set_version_flag("--version",
                       "pomar 0.1.0 (writes .pomar format versions 1, 3 and 4, reads 1 to 4)");

  EncodeArgs ea;
  auto *enc =
      app.add_subcommand("encode", "Compress a mesh (PLY, OBJ, OFF, STL) into a .pomar file");
  enc->add_option("input", ea.in,
                  "Input mesh, any triangles: a non-manifold or inconsistently oriented mesh, "
                  "duplicate faces, faces repeating a vertex and unreferenced vertices are coded "
                  "as a manifold cut plus a record that a full decode undoes (one line on stderr "
                  "says what was stored)")
      ->required();
  enc->add_option("output", ea.out, "Output .pomar file (written atomically)")->required();
  enc->add_option("-b,--bits", ea.bits,
                  "Quantization bits per coordinate on the bounding box (4..24); the geometry "
                  "error is at most half a cell")
      ->check(CLI::Range(4, 24))
      ->capture_default_str();
  enc->add_option("--clusters", ea.clusters,
                  "Random access: about N clusters (regions decodable on their own)")
      ->check(CLI::PositiveNumber);
  enc->add_option("--cluster-ratio", ea.cluster_ratio,
                  "Random access: clusters as a fraction of the vertices (paper: 1-5%)")
      ->check(CLI::Range(0.0001, 1.0))
      ->capture_default_str();
  enc->add_flag("--progressive", ea.progressive,
                "Pure progressive mode: global levels only, no random access (a little smaller)");
  enc->add_option("--threads", ea.threads,
                  "Threads for decimation (0 = every core this process may use); the output is the "
                  "same for any number")
      ->capture_default_str();
  enc->add_flag("--repair", ea.repair,
                "Opt-in: first cut a non-manifold, inconsistently oriented or degenerate mesh into "
                "a manifold one (remove faces repeating a vertex and exact duplicate faces, "
                "reorient faces, cut edges of more than two faces or that cannot be oriented, "
                "split vertices joining several fans into copies at the same position) and print "
                "every change on stderr. Positions are never moved; the file holds the repaired "
                "mesh (verify with --repair)");
  enc->add_flag("--strict", ea.strict,
                "Refuse a mesh that needs cutting (non-manifold, inconsistently oriented, "
                "duplicate or degenerate faces) and drop unreferenced vertices: for pipelines "
                "that want clean input (the file then carries no lossless record)");
  enc->add_flag("--keep-order", ea.keep_order,
                "Also store the input's vertex numbering (a full decode gives the vertices back "
                "in the input order, e.g. for per-vertex data kept elsewhere); costs a few bits "
                "per vertex (pomar info shows it as the lossless record)");
  enc->add_flag("--embed-textures", ea.embed_textures,
                "Store the texture image files (found beside the input, by the names its "
                "materials or header give) in the .pomar, so that one file is the whole asset; "
                "decode writes them beside its output (never over an existing file). Without "
                "it, the names are kept and resolved relative to the file");
  enc->add_flag("--force", ea.force,
                "Write the .pomar file even under a mesh file's extension (.ply .obj .off "
                ".stl), which is otherwise refused (an output that is the input is always "
                "refused)");
  enc->add_flag("-q,--quiet", ea.quiet,
                "Print nothing on success (what --repair changed is still printed)");
  enc->add_option("--drop", ea.drop,
                  "Per-vertex attributes to leave out, comma-separated: colour, normals, "
                  "scalars (quality and named PLY properties), texcoords (with the texture file "
                  "names), or all. Default: everything the input has is kept")
      ->type_name("LIST");
  enc->add_option("--normal-bits", ea.attributes.normal_bits,
                  "Bits per octahedral coordinate of normals (4..16); the angle error is at most "
                  "0.332 deg at 9, halved by each bit (0.67 at 8, 0.166 at 10, 0.0026 at 16)")
      ->check(CLI::Range(4, 16))
      ->capture_default_str();
  enc->add_option("--scalar-bits", ea.attributes.scalar_bits,
                  "Bits over each scalar's range (1..24): error at most half of range/(2^bits-1)")
      ->check(CLI::Range(1, 24))
      ->capture_default_str();
  enc->add_option("--texcoord-bits", ea.attributes.texcoord_bits,
                  "Bits over the range of u and of v (1..24): error at most half a step")
      ->check(CLI::Range(1, 24))
      ->capture_default_str();
  enc->add_flag("--exact-attributes", ea.attributes.exact,
                "Store normals, scalars and texture coordinates bit for bit (NaN, infinities, "
                "denormals, -0 included); colour is always exact. Without it a NaN or "
                "infinite value is an error (a zero-length normal comes back as (0, 0, 0))");
  enc->add_option("--max-memory", ea.max_memory,
                  "Refuse (exit 7, no output file) a mesh whose loading and encoding would need "
                  "more than SIZE of memory, checked from the file's header before reading it: "
                  "bytes or a number with K, M, G, T (powers of 1024), e.g. 512M, 2G, 1.5GiB; "
                  "'none' = no check. Default 'auto': the memory available (the smallest of "
                  "MemAvailable, the cgroup's limit and ulimit -v/-d; no check if unknown)")
      ->type_name("SIZE")
      ->capture_default_str();

  DecodeArgs da;
  auto *dec = app.add_subcommand("decode", "Decompress a .pomar file into a mesh file");
  dec->add_option("input", da.in, "Input .pomar file")->required();
  dec->add_option("output", da.out,
                  "Output mesh; the format follows the extension (.ply .obj .off .stl). PLY keeps "
                  "every attribute; OBJ colour, normals, UVs and texture names (OUT.mtl beside "
                  "it); OFF colour and normals; STL none (a warning names what is not written)")
      ->required();
  dec->add_option("-l,--level", da.level,
                  "Stop after L refinement levels (0 = base mesh; default: full resolution). With "
                  "--cluster/--sphere/--box: the level of every other cluster (default: the base "
                  "clustered mesh)")
      ->check(CLI::NonNegativeNumber);
  dec->add_option("--cluster", da.clusters,
                  "Refine cluster ID to LEVEL (default: finest); repeatable. Neighbouring "
                  "clusters are refined as needed (at most one level apart)")
      ->type_name("ID[:LEVEL]");
  dec->add_option("--sphere", da.spheres,
                  "Refine the clusters with a vertex within R of (X,Y,Z) (of the base clustered "
                  "mesh) to LEVEL; repeatable")
      ->type_name("X,Y,Z,R[:LEVEL]");
  dec->add_option("--box", da.boxes,
                  "Refine the clusters with a vertex in the box to LEVEL; repeatable")
      ->type_name("X0,Y0,Z0,X1,Y1,Z1[:LEVEL]");
  dec->add_flag("--stats", da.stats,
                "Print clusters decoded, bytes read of the file size, vertices and time");
  dec->add_flag("--ascii", da.ascii, "Write ASCII PLY instead of binary");
  dec->add_flag("--skip-damaged", da.skip_damaged,
                "Decode around damaged or missing blocks (bit rot, truncated download) instead "
                "of failing: a damaged cluster stays at the base clustered level and its "
                "neighbours at most one level finer per step, a damaged global level stops the "
                "decoding before it. Skipped blocks are listed on stderr and the exit status is "
                "4 (the output is written). The header, base mesh, tables and index must be "
                "intact");
  dec->add_flag("-q,--quiet", da.quiet, "Print nothing on success");
  dec->add_option("--threads", da.threads,
                  "Threads for the clusters of a random-access file (0 = every core this process "
                  "may use, at most 8; pure progressive files decode on one); the output is the "
                  "same for any number")
      ->capture_default_str();
  dec->add_flag("--no-attributes", da.no_attributes,
                "Write positions and triangles only: leave out colour, normals, scalars and "
                "texture coordinates (their codes, interleaved with the positions, are read "
                "past without being decoded into values: less memory, a little less time)");
  dec->add_option("--max-memory", da.max_memory,
                  "Refuse (exit 7, no output file) a file whose decoding would need more than "
                  "SIZE of memory, checked from its header (with --cluster/--sphere/--box: the "
                  "base clustered mesh, then the clusters asked for, estimated from the level "
                  "table): as for encode, e.g. 512M, 2G, 'none'; default 'auto' = the memory "
                  "available")
      ->type_name("SIZE")
      ->capture_default_str();

  std::string info_in;
  bool info_jsonf = false, info_check = false;
  auto *inf = app.add_subcommand("info", "Describe a .pomar file: counts, levels, bits per vertex");
  inf->add_option("input", info_in, "Input .pomar file")->required();
  inf->add_flag("--json", info_jsonf,
                "One JSON object (keys: vertices, faces, bits, levels, "
                "connectivity_bits, geometry_bits, total_bytes, ...)");
  inf->add_flag("--check", info_check,
                "Check every block's checksum instead (no decoding); exit status 4 lists the "
                "damaged or missing blocks");

  std::string v_orig, v_file, v_decoded, v_drop;
  bool v_repair = false;
  auto *ver = app.add_subcommand(
      "verify", "Check that a .pomar file (or a mesh decoded from it) is the original, losslessly");
  ver->add_option("original", v_orig, "The mesh that was encoded")->required();
  ver->add_option("pomar", v_file, "The .pomar file")->required();
  ver->add_option("decoded", v_decoded, "A mesh decoded from it (default: decode in memory)");
  ver->add_flag("--repair", v_repair,
                "The file was encoded with encode --repair: compare with the original as repaired "
                "(the same cut as encode --repair; lossless means equal to that mesh)");
  ver->add_option("--drop", v_drop,
                  "The file was encoded with encode --drop LIST: do not expect those attributes")
      ->type_name("LIST");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError &e) {
    return app.exit(e);
  }
  try {
    if (*enc)
      return run_encode(ea);
    if (*dec)
      return run_decode(da);
    if (*inf)
      return info_check ? run_check(info_in) : run_info(info_in, info_jsonf);
    if (*ver)
      return run_verify(v_orig, v_file, v_decoded, v_repair, v_drop);
  } catch (const pomar::Error &e) {
    std::fprintf(stderr, "pomar: error: %s\n", pomar::printable(e.what()).c_str());
    return exit_status(e);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "pomar: error: %s\n", pomar::printable(e.what()).c_str());
    return kExitError;
  }
  return 0;
}
