// pomar encode: load (memory checked from the header), optional repair, encode, write
// atomically, report sizes and times.
#include <cstdio>
#include <utility>

#include "commands.h"
#include "console.h"
#include "output_paths.h"
#include "pomar/limits.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"
#include "pomar/repair.h"
#include "specs.h"
#include "textures.h"

namespace pomar::tool {

namespace {

constexpr const char *kRepairHint =
    " (without --strict pomar stores the cut and gives the mesh back exactly; --repair cuts it "
    "for good)";

} // namespace

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
  opt.cluster_errors = !a.no_stored_errors;
  opt.spatial_layout = a.block_order == "spatial";
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

} // namespace pomar::tool
