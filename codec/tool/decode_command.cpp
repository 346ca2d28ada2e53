// pomar decode: a whole file or a level (pomar::decode), or regions (a SelectiveDecoder on
// the file); damaged blocks skipped on request and reported (exit 4).
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "console.h"
#include "exit_codes.h"
#include "output_paths.h"
#include "pomar/limits.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "specs.h"
#include "textures.h"

namespace pomar::tool {

namespace {

/// Writes the decoded mesh and the texture images it embeds beside it, and says what the
/// output format cannot hold.
void save_decoded(const DecodeArgs &a, const pomar::Mesh &mesh) {
  pomar::save_mesh(a.out, mesh, !a.ascii);
  write_embedded_textures(a.out, mesh, a.quiet);
  if (!a.quiet)
    warn_dropped(a.out, pomar::attributes_not_saved(a.out, mesh), "cannot hold",
                 not_written_hint(a.out));
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
  save_decoded(a, mesh);
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

/// A full decode to binary PLY can be written region by region when it does not fit.
bool can_decode_bounded(const DecodeArgs &a) {
  if (a.selective() || a.level >= 0 || a.skip_damaged || a.ascii)
    return false;
  std::string ext = a.out.size() >= 4 ? a.out.substr(a.out.size() - 4) : "";
  for (char &c : ext)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".ply";
}

/// The decode that did not fit (`refused`), region by region within the limit.
int run_bounded_decode(const DecodeArgs &a, uint64_t memory_limit, const pomar::Error &refused) {
  const auto t0 = Clock::now();
  pomar::BoundedDecodeOptions options;
  options.memory_limit = memory_limit;
  options.threads = a.threads;
  options.progress = terminal_progress(a.quiet);
  pomar::BoundedDecodeReport report;
  try {
    report = pomar::decode_to_ply_bounded(a.in, a.out, options);
  } catch (const pomar::Error &e) {
    if (e.kind() == pomar::Error::Kind::Unsupported) // say what did not fit first
      throw pomar::Error(pomar::Error::Kind::MemoryLimit,
                         refused.what() + std::string("; ") + e.what());
    rethrow_with_hint(naming(e, a.in));
  }
  if (!a.quiet || a.stats)
    std::printf("%s: %lu vertices, %lu faces (decoded in %u regions within %s, the largest "
                "estimated at %s, in %.3f s)\n",
                a.out.c_str(), static_cast<unsigned long>(report.vertices),
                static_cast<unsigned long>(report.faces), report.regions,
                pomar::format_memory_size(memory_limit).c_str(),
                pomar::format_memory_size(report.largest_region).c_str(), since(t0));
  return 0;
}

} // namespace

int run_decode(const DecodeArgs &a) {
  check_output(a.in, a.out, false, false);
  if (a.selective())
    return run_selective_decode(a);
  const uint64_t memory_limit = pomar::parse_memory_size(a.max_memory);
  const auto t0 = Clock::now();
  std::vector<uint8_t> data = pomar::read_file(a.in);
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
    if (e.kind() == pomar::Error::Kind::MemoryLimit && !can_decode_bounded(a) && !a.selective() &&
        a.level < 0 && !a.skip_damaged) {
      pomar::Error hinted(e.kind(), naming(e, a.in).what() +
                                        std::string(" (to a binary .ply, a full decode is "
                                                    "written region by region within the limit)"));
      throw hinted;
    }
    if (e.kind() != pomar::Error::Kind::MemoryLimit || !can_decode_bounded(a))
      rethrow_with_hint(naming(e, a.in));
    data = {}; // (the bounded decode reads the file region by region)
    return run_bounded_decode(a, memory_limit, naming(e, a.in));
  }
  const double t_decode = since(t0);
  save_decoded(a, mesh);
  if (!a.quiet || a.stats)
    std::printf("%s: %zu vertices, %zu faces (decoded in %.3f s, %zu bytes read)\n", a.out.c_str(),
                mesh.vertex_count(), mesh.triangle_count(), t_decode, data.size());
  if (!report.damaged.empty() && report.clusters_below_request)
    std::fprintf(stderr, "pomar: warning: %u clusters below the requested level\n",
                 report.clusters_below_request);
  return report_damage(report.damaged, a.out);
}

} // namespace pomar::tool
