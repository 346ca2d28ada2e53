// pomar: command-line front end of the codec.
//   pomar encode IN OUT.pomar [--bits N] [--progressive]
//   pomar decode IN.pomar OUT [--level L]
//   pomar info IN.pomar [--json]
//   pomar verify ORIGINAL IN.pomar [DECODED]
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <unistd.h>

#include "pomar/mesh_io.h"
#include "pomar/pomar.h"

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

double bpv(uint64_t bytes, uint32_t vertices) {
  return vertices ? 8.0 * double(bytes) / double(vertices) : 0.0;
}

// ---------------------------------------------------------------- encode

struct EncodeArgs {
  std::string in, out;
  int bits = 12;
  bool progressive = true, quiet = false;
};

int run_encode(const EncodeArgs &a) {
  const auto t0 = Clock::now();
  pomar::LoadReport load;
  const pomar::Mesh mesh = pomar::load_mesh(a.in, &load);
  if (!load.ignored_attributes.empty() && !a.quiet) {
    std::string list;
    for (const auto &s : load.ignored_attributes)
      list += (list.empty() ? "" : ", ") + s;
    std::fprintf(stderr, "pomar: warning: %s has %s; .pomar keeps positions and triangles only\n",
                 a.in.c_str(), list.c_str());
  }
  const double t_load = since(t0);
  pomar::EncodeOptions opt;
  opt.bits = a.bits;
  opt.progress = terminal_progress(a.quiet);
  pomar::EncodeReport r;
  const auto t1 = Clock::now();
  const std::vector<uint8_t> file = pomar::encode(mesh, opt, &r);
  const double t_encode = since(t1);
  pomar::write_file_atomic(a.out, file.data(), file.size());
  if (a.quiet)
    return 0;
  const pomar::FileInfo &i = r.info;
  std::printf("%s: %u vertices, %u faces", a.in.c_str(), i.vertices, i.faces);
  if (r.unreferenced_vertices)
    std::printf(" (%zu unreferenced vertices dropped)", r.unreferenced_vertices);
  if (load.welded_vertices)
    std::printf(" (%zu duplicate STL corners welded)", load.welded_vertices);
  std::printf("\n%s: %zu bytes, %.2f bits/vertex (connectivity %.2f, geometry %.2f), %d-bit "
              "grid, %zu levels over a %u-vertex base mesh\n",
              a.out.c_str(), file.size(), bpv(file.size(), i.vertices),
              bpv(i.connectivity_bytes, i.vertices), bpv(i.geometry_bytes, i.vertices), i.bits,
              i.levels.size(), i.base_vertices);
  std::printf("time: read %.3f s, encode %.3f s (decimate %.3f s, code %.3f s)\n", t_load,
              t_encode, r.decimate_seconds, r.encode_seconds);
  return 0;
}

// ---------------------------------------------------------------- decode

struct DecodeArgs {
  std::string in, out;
  int level = -1;
  bool ascii = false, quiet = false;
};

int run_decode(const DecodeArgs &a) {
  const auto t0 = Clock::now();
  const std::vector<uint8_t> data = pomar::read_file(a.in);
  const pomar::Mesh mesh =
      pomar::decode(data.data(), data.size(), a.level, terminal_progress(a.quiet));
  const double t_decode = since(t0);
  pomar::save_mesh(a.out, mesh, !a.ascii);
  if (!a.quiet)
    std::printf("%s: %zu vertices, %zu faces (decoded in %.3f s)\n", a.out.c_str(),
                mesh.vertex_count(), mesh.triangle_count(), t_decode);
  return 0;
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
  levels.push_back({{"level", 0}, {"vertices", i.base_vertices}, {"faces", i.base_faces},
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
  j["header_bytes"] = i.header_bytes;
  j["base_bytes"] = i.base_bytes;
  j["total_bytes"] = i.total_bytes;
  j["bpv"] = bpv(i.total_bytes, i.vertices);
  j["connectivity_bpv"] = bpv(i.connectivity_bytes, i.vertices);
  j["geometry_bpv"] = bpv(i.geometry_bytes, i.vertices);
  return j;
}

int run_info(const std::string &in, bool json) {
  const std::vector<uint8_t> data = pomar::read_file(in);
  const pomar::FileInfo i = pomar::inspect(data.data(), data.size());
  if (json) {
    std::printf("%s\n", info_json(i).dump(2).c_str());
    return 0;
  }
  std::printf("%s: .pomar version %u, progressive (global levels only)\n", in.c_str(), i.version);
  std::printf("  vertices %u, faces %u, %d-bit grid from (%g, %g, %g), cell %.6g\n", i.vertices,
              i.faces, i.bits, i.bbox_min[0], i.bbox_min[1], i.bbox_min[2],
              (double(i.bbox_max[0]) - i.bbox_min[0]) / double((1u << i.bits) - 1));
  std::printf("  size %lu bytes = %.2f bits/vertex: connectivity %.2f, geometry %.2f, base mesh "
              "%.2f, header %.2f\n",
              static_cast<unsigned long>(i.total_bytes), bpv(i.total_bytes, i.vertices),
              bpv(i.connectivity_bytes, i.vertices), bpv(i.geometry_bytes, i.vertices),
              bpv(i.base_bytes, i.vertices), bpv(i.header_bytes, i.vertices));
  std::printf("  level  vertices     faces  conn.bytes  geom.bytes\n");
  std::printf("  %5d %9u %9u  %10lu  (base mesh)\n", 0, i.base_vertices, i.base_faces,
              static_cast<unsigned long>(i.base_bytes));
  for (size_t l = 0; l < i.levels.size(); ++l)
    std::printf("  %5zu %9u %9u  %10lu  %10lu\n", l + 1, i.levels[l].vertices, i.levels[l].faces,
                static_cast<unsigned long>(i.levels[l].connectivity_bytes),
                static_cast<unsigned long>(i.levels[l].geometry_bytes));
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

int run_verify(const std::string &original, const std::string &file, const std::string &decoded) {
  pomar::Mesh ref = pomar::load_mesh(original);
  const std::vector<uint8_t> data = pomar::read_file(file);
  const pomar::FileInfo info = pomar::inspect(data.data(), data.size());
  const pomar::Mesh out =
      decoded.empty() ? pomar::decode(data.data(), data.size()) : pomar::load_mesh(decoded);
  // Snap the original onto the file's grid, as the encoder did.
  for (size_t i = 0; i < ref.positions.size(); ++i) {
    const int axis = static_cast<int>(i % 3);
    ref.positions[i] = info.grid.dequantize(axis, info.grid.quantize(axis, ref.positions[i]));
  }
  const bool same = triangle_multiset(ref) == triangle_multiset(out);
  const std::string what = decoded.empty() ? file : decoded;
  if (!same) {
    std::fprintf(stderr, "pomar: MISMATCH: %s differs from %s on the %d-bit grid\n", what.c_str(),
                 original.c_str(), info.bits);
    return 3;
  }
  std::printf("OK: %s matches %s: the same %zu oriented triangles, every vertex on its %d-bit "
              "grid position\n",
              what.c_str(), original.c_str(), out.triangle_count(), info.bits);
  return 0;
}

} // namespace

int main(int argc, char **argv) {
  CLI::App app{"pomar: progressive, randomly accessible compression of manifold triangle meshes "
               "(POMAR, Maglo et al. 2013).\n\nExamples:\n"
               "  pomar encode bunny.ply bunny.pomar          # 12-bit grid, all levels\n"
               "  pomar info bunny.pomar                      # levels and bits per vertex\n"
               "  pomar decode bunny.pomar coarse.ply --level 10\n"
               "  pomar verify bunny.ply bunny.pomar          # lossless check\n"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pomar 0.1.0 (file format version 1)");

  EncodeArgs ea;
  auto *enc = app.add_subcommand("encode", "Compress a mesh (PLY, OBJ, OFF, STL) into a .pomar file");
  enc->add_option("input", ea.in, "Input mesh: manifold, consistently oriented triangles")
      ->required();
  enc->add_option("output", ea.out, "Output .pomar file (written atomically)")->required();
  enc->add_option("-b,--bits", ea.bits,
                  "Quantization bits per coordinate on the bounding box (4..24); the geometry "
                  "error is at most half a cell")
      ->check(CLI::Range(4, 24))
      ->capture_default_str();
  enc->add_flag("--progressive", ea.progressive,
                "Pure progressive mode: global levels only (the only mode of format version 1)");
  enc->add_flag("-q,--quiet", ea.quiet, "Print nothing on success");

  DecodeArgs da;
  auto *dec = app.add_subcommand("decode", "Decompress a .pomar file into a mesh file");
  dec->add_option("input", da.in, "Input .pomar file")->required();
  dec->add_option("output", da.out, "Output mesh; the format follows the extension (.ply .obj .off .stl)")
      ->required();
  dec->add_option("-l,--level", da.level,
                  "Stop after L refinement levels (0 = base mesh; default: full resolution)")
      ->check(CLI::NonNegativeNumber);
  dec->add_flag("--ascii", da.ascii, "Write ASCII PLY instead of binary");
  dec->add_flag("-q,--quiet", da.quiet, "Print nothing on success");

  std::string info_in;
  bool info_jsonf = false;
  auto *inf = app.add_subcommand("info", "Describe a .pomar file: counts, levels, bits per vertex");
  inf->add_option("input", info_in, "Input .pomar file")->required();
  inf->add_flag("--json", info_jsonf, "One JSON object (keys: vertices, faces, bits, levels, "
                                      "connectivity_bits, geometry_bits, total_bytes, ...)");

  std::string v_orig, v_file, v_decoded;
  auto *ver = app.add_subcommand(
      "verify", "Check that a .pomar file (or a mesh decoded from it) is the original, losslessly");
  ver->add_option("original", v_orig, "The mesh that was encoded")->required();
  ver->add_option("pomar", v_file, "The .pomar file")->required();
  ver->add_option("decoded", v_decoded, "A mesh decoded from it (default: decode in memory)");

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
      return run_info(info_in, info_jsonf);
    if (*ver)
      return run_verify(v_orig, v_file, v_decoded);
  } catch (const pomar::Error &e) {
    std::fprintf(stderr, "pomar: error: %s\n", e.what());
    return 1;
  } catch (const std::exception &e) {
    std::fprintf(stderr, "pomar: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
