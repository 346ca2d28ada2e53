// The manifold encoder (encode_manifold, called by pomar::encode in encode/encode.cpp), as a
// list of steps: prepare the input (validate, quantize, renumber) -> decimate (section 4) ->
// base mesh -> global levels (section 5.1) -> clustered levels (section 5.2,
// encode/clusters.cpp) -> sections -> file (format/file_format.cpp) -> report.
// The levels are coded by the traversal the decoder runs (encode/encoder_codec.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include "attributes/attribute_section.h"
#include "attributes/material_section.h"
#include "attributes/texture_images.h"
#include "decimate/decimate.h"
#include "encode/cluster_error_measure.h"
#include "encode/clusters.h"
#include "encode/encoder_codec.h"
#include "encode/fit_prediction.h"
#include "entropy/models.h"
#include "format/block_checks.h"
#include "format/block_order.h"
#include "format/cluster_errors.h"
#include "format/file_format.h"
#include "format/geometry_prediction.h"
#include "geometry/quantize.h"
#include "lossless/lossless_stage.h"
#include "memory/prefault.h"
#include "mesh/reorder.h"
#include "parallel/thread_pool.h"
#include "pomar/limits.h"

namespace pomar {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The triangles in the numbering of the referenced vertices (unreferenced ones dropped,
/// the others kept in input order); fills compact_to_input. Checks every index.
std::vector<uint32_t> compact_triangles(const Mesh &mesh, std::vector<uint32_t> &compact_to_input) {
  const size_t nv = mesh.vertex_count();
  std::vector<uint32_t> remap = filled_vector<uint32_t>(nv, kNone); // (memory/prefault.h)
  std::vector<uint32_t> triangles = mesh.triangles;
  for (uint32_t i : triangles) {
    if (i >= nv)
      throw Error(Error::Kind::InvalidMesh, "a triangle refers to vertex " + std::to_string(i) +
                                                " but the mesh has only " + std::to_string(nv) +
                                                " vertices");
    remap[i] = 0; // mark used; numbered below in input order
  }
  compact_to_input.clear();
  compact_to_input.reserve(nv);
  for (uint32_t v = 0; v < nv; ++v)
    if (remap[v] != kNone) {
      remap[v] = static_cast<uint32_t>(compact_to_input.size());
      compact_to_input.push_back(v);
    }
  if (compact_to_input.size() < nv) // else the numbering is the input's
    for (uint32_t &i : triangles)
      i = remap[i];
  return triangles;
}

/// The positions of the vertices compact_to_input names, in that order (xyz floats).
std::vector<float> gather_positions(const Mesh &mesh,
                                    const std::vector<uint32_t> &compact_to_input) {
  std::vector<float> positions = filled_vector<float>(3 * compact_to_input.size());
  for (size_t i = 0; i < compact_to_input.size(); ++i)
    std::copy_n(&mesh.positions[3 * size_t(compact_to_input[i])], 3, &positions[3 * i]);
  return positions;
}

void check_input(const Mesh &mesh, const EncodeOptions &options) {
  if (options.bits < 4 || options.bits > 24)
    throw Error(Error::Kind::Usage, "quantization bits must be between 4 and 24 (got " +
                                        std::to_string(options.bits) + ")");
  if (options.format_version != 4 && options.format_version != 5)
    throw Error(Error::Kind::Usage, "the encoder writes format version 4 or 5 (got " +
                                        std::to_string(options.format_version) + ")");
  if (mesh.positions.size() % 3 || mesh.triangles.size() % 3)
    throw Error(Error::Kind::InvalidMesh,
                "position and triangle arrays must hold multiples of 3 values");
  if (mesh.triangle_count() == 0)
    throw Error(Error::Kind::InvalidMesh, "the mesh contains no triangles");
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (!std::isfinite(mesh.positions[i]))
      throw Error(Error::Kind::InvalidMesh,
                  "vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
}

/// The input ready for decimation: referenced vertices only, quantized, renumbered for
/// memory locality, connectivity built and validated.
struct PreparedInput {
  Quantizer grid;
  std::vector<int32_t> q; // quantized xyz, prepared numbering
  CornerTable ct;
  std::vector<uint32_t> to_input; // prepared vertex -> the caller's vertex
  uint32_t vertices = 0, faces = 0;
};

PreparedInput prepare_input(const Mesh &mesh, const EncodeOptions &options,
                            const LosslessHook *hook, bool name_refusal) {
  check_input(mesh, options);
  validate_attributes(mesh, !options.attributes.exact, options.attributes.keep);
  // The caller already holds the input mesh: an automatic check counts only the rest.
  uint64_t held = mesh.positions.size() * sizeof(float) + mesh.triangles.size() * sizeof(uint32_t);
  for (const VertexAttribute &a : mesh.attributes)
    held += a.colour.size() + a.values.size() * sizeof(float);
  // (With a lossless record: the input, which the caller holds too, and the record's work.)
  check_encode_memory(mesh.vertex_count(), mesh.triangle_count(), options.memory_limit, held,
                      encode_attribute_bytes_per_vertex(mesh, options.attributes),
                      decode_threads(options.threads), EncodeInput::Mesh,
                      hook ? lossless_encode_memory(mesh.triangle_count(), options.keep_order) : 0);
  PreparedInput in;
  std::vector<uint32_t> compact_to_input;
  std::vector<uint32_t> triangles = compact_triangles(mesh, compact_to_input);
  const uint32_t nv = static_cast<uint32_t>(compact_to_input.size());
  const uint32_t nf = static_cast<uint32_t>(triangles.size() / 3);
  in.vertices = nv;
  in.faces = nf;
  { // quantize the referenced vertices (the input's own array when it has no other)
    std::vector<float> gathered;
    if (nv < mesh.vertex_count())
      gathered = gather_positions(mesh, compact_to_input);
    const float *positions = gathered.empty() ? mesh.positions.data() : gathered.data();
    in.grid = hook ? hook->grid : make_quantizer(positions, nv, options.bits);
    in.q = quantize(in.grid, positions, nv);
  }
  // Renumber for memory locality, then build (and validate) the connectivity: the table
  // is built on the renamed faces while another thread sorts them, then takes their order.
  const std::vector<uint32_t> old_to_new = reorder_vertices(in.q, triangles);
  resize_prefaulted(in.to_input, nv); // (memory/prefault.h)
  for (uint32_t v = 0; v < nv; ++v)
    in.to_input[old_to_new[v]] = compact_to_input[v];
  try {
    std::vector<uint32_t> order;
    constexpr uint32_t kMinParallelFaces = 16384; // fewer: a thread costs more than it saves
    ThreadPool pool(nf >= kMinParallelFaces ? std::min(2u, resolve_threads(options.threads)) : 1);
    pool.run(2, [&](size_t task, unsigned) {
      if (task == 0)
        order = face_order(triangles);
      else
        build_corner_table(triangles.data(), nf, nv, in.ct);
    });
    reorder_faces(in.ct, order);
  } catch (const Error &) {
    // An invalid mesh is validated again in the caller's numbering (its face order too) so
    // that the message names its indices (unless the caller cuts it anyway).
    if (!name_refusal)
      throw;
    const std::vector<uint32_t> input_triangles = compact_triangles(mesh, compact_to_input);
    build_corner_table(input_triangles.data(), nf, nv, in.ct); // throws with input indices
    throw;
  }
  return in;
}

/// The base mesh (what decimation left), its vertices numbered in input order; starts
/// the rebuild from it.
BaseMesh start_from_base_mesh(Rebuild &rb, uint32_t nv) {
  BaseMesh base;
  for (uint32_t i : rb.dec.base_triangles)
    rb.input_to_dec[i] = 0;
  for (uint32_t v = 0; v < nv; ++v)
    if (rb.input_to_dec[v] != kNone) {
      rb.input_to_dec[v] = static_cast<uint32_t>(rb.dec_to_input.size());
      rb.dec_to_input.push_back(v);
      base.q.insert(base.q.end(), &rb.q[3 * v], &rb.q[3 * v] + 3);
    }
  for (uint32_t i : rb.dec.base_triangles)
    base.triangles.push_back(rb.input_to_dec[i]);
  canonical_faces(base.triangles); // the order the file stores them in

  LevelMesh &lm = rb.mesh;
  lm.q = base.q;
  lm.seed_faces = static_cast<uint32_t>(base.triangles.size() / 3);
  build_corner_table(base.triangles.data(), lm.seed_faces, rb.dec_to_input.size(), lm.ct);
  lm.init_lineage();
  return base;
}

/// Refinement levels 1..global: one adaptive model set for the whole file, two streams
/// (connectivity, geometry) per level, one block per level. Adds their level entries.
std::vector<std::vector<uint8_t>> encode_global_levels(Rebuild &rb, size_t global,
                                                       FileHeader &header, SymbolBits &bits,
                                                       const Progress &progress) {
  Models models;
  models.conn.patch_rank = header.ranks_patches();
  models.attr = rb.attr_models;
  EncoderCodec<RangeEncoder> codec(rb.q, rb.dec_to_input, rb.input_to_dec);
  codec.set_attribute_codes(rb.attr_codes, rb.attr_codes_per_vertex);
  std::vector<std::vector<uint8_t>> blocks;
  for (size_t r = 0; r < global; ++r) {
    const uint32_t level = static_cast<uint32_t>(r + 1);
    std::vector<uint8_t> conn, geom;
    RangeEncoder conn_rc(&conn), geom_rc(&geom);
    choose_wedge_predictor(rb, level);
    if (rb.fit_normal)
      rb.normal[r] = fit_normal_predictor(rb, level, false, needs_geometry_prediction(rb.normal));
    models.normal = rb.normal[r];
    codec.begin_level(rb.collapses(level), &models);
    codec.set_sinks(&conn_rc, &geom_rc);
    rb.step.global_level(rb.mesh, codec, level);
    codec.end_level();
    take_wedge_costs(rb, codec);
    conn_rc.finish();
    geom_rc.finish();
    add_level_entry(header, rb.mesh, static_cast<uint32_t>(conn.size()),
                    static_cast<uint32_t>(geom.size()));
    conn.insert(conn.end(), geom.begin(), geom.end());
    blocks.push_back(std::move(conn));
    if (progress)
      progress(double(r + 1) / double(rb.levels()), "encode");
  }
  bits = codec.bits;
  for (size_t k = 0; k < codec.attr_bits.size(); ++k)
    rb.attr_bits[k] += codec.attr_bits[k];
  return blocks;
}

/// The texture seams of the lossless stage (hook->locked, twin, origin) in the prepared
/// numbering, for decimation; empty without a seam.
struct SeamLocks {
  std::vector<uint8_t> locked;
  std::vector<uint32_t> twin, origin;
};

SeamLocks seam_locks(const LosslessHook *hook, const PreparedInput &in) {
  SeamLocks s;
  if (!hook || hook->locked.empty())
    return s;
  const uint32_t nv = in.vertices;
  s.locked.resize(nv);
  s.twin.assign(nv, kNone);
  s.origin.resize(nv);
  std::vector<uint32_t> prepared(hook->locked.size(), kNone);
  for (uint32_t v = 0; v < nv; ++v)
    prepared[in.to_input[v]] = v;
  for (uint32_t v = 0; v < nv; ++v) {
    const uint32_t c = in.to_input[v];
    s.locked[v] = hook->locked[c];
    s.origin[v] = hook->origin[c];
    if (hook->twin[c] != kNone)
      s.twin[v] = prepared[hook->twin[c]];
  }
  return s;
}

/// The attribute codes of the base mesh's vertices, and the rebuild's attribute state.
void start_attributes(Rebuild &rb, AttributeTable &attributes, const std::vector<int64_t> &codes) {
  for (uint32_t v : rb.dec_to_input)
    attributes.base.insert(attributes.base.end(), codes.begin() + size_t(v) * attributes.codes,
                           codes.begin() + size_t(v + 1) * attributes.codes);
  init_attributes(attributes, rb.mesh);
  plan_wedge_residuals(attributes, rb.mesh); // (the base mesh's connectivity predicts them)
  rb.attr_codes = &codes;
  rb.attr_codes_per_vertex = attributes.codes;
  rb.attr_models = attribute_models(attributes);
  rb.attr_bits.assign(attributes.codes, 0.0);
  rb.wedge_choice = has_wedge_grid(attributes);
  rb.wedge_first = base_wedge_from_positions(attributes);
}

FileHeader make_header(const EncodeOptions &options, const PreparedInput &in, const Rebuild &rb) {
  FileHeader header;
  // Version 5: patches as placement ranks; else version 1, 3 or 4 (write_file decides).
  header.version = options.format_version == 5 ? kPatchRankFormatVersion : kFormatVersion;
  header.grid = in.grid;
  header.vertices = in.vertices;
  header.faces = in.faces;
  header.base_vertices = static_cast<uint32_t>(rb.dec_to_input.size());
  header.base_faces = rb.mesh.seed_faces;
  return header;
}

/// The sections after the levels: attributes (format version 4, "ATTR": descriptors, base
/// mesh codes, sizes), texture images, the lossless stage's materials and record.
std::vector<Section> extra_sections(AttributeTable &attributes, const Rebuild &rb,
                                    const FileHeader &header, std::vector<uint8_t> images,
                                    const LosslessHook *hook, const PreparedInput &in) {
  std::vector<Section> sections;
  set_wedge_levels(attributes, rb.mesh.wedge_uv_positions);
  if (!attributes.stored.empty() || !attributes.texture_files.empty()) {
    for (size_t i = 0, k = 0; i < attributes.stored.size(); ++i) {
      double attr_bits = 0;
      for (uint32_t c = 0; c < attributes.stored[i].codes(); ++c, ++k)
        attr_bits += rb.attr_bits[k];
      attributes.estimated_bytes[i] = static_cast<uint64_t>(attr_bits / 8.0 + 0.5);
    }
    sections.push_back(
        {kAttributeSectionTag, 0, write_attributes(attributes, header.base_vertices)}); // optional
  }
  if (!images.empty())
    sections.push_back({kTextureImagesTag, 0, std::move(images)});
  if (hook && !hook->materials.empty()) // per-corner values: a reader must turn them back
    sections.push_back({kMaterialSectionTag, kSectionRequired, hook->materials});
  if (hook) { // the lossless stage's record, in the decoder's numbering
    const uint32_t nv = in.vertices;
    std::vector<uint32_t> decoded_to_cut(nv);
    for (uint32_t i = 0; i < nv; ++i)
      decoded_to_cut[i] = in.to_input[rb.dec_to_input[i]];
    // Required: a reader that ignored it would give the cut mesh for the input.
    sections.push_back({kLosslessTag, kSectionRequired, hook->record(decoded_to_cut)});
  }
  return sections;
}

/// The report, read from the file just written: a failure here is the encoder's own
/// inconsistency, never a damaged file.
void fill_report(const std::vector<uint8_t> &file, const PreparedInput &in, const Rebuild &rb,
                 size_t input_vertices, EncodeReport &report) {
  try {
    const FileLayout layout = read_layout(file.data(), file.size());
    report.info = file_info(layout, file.size());
    if (const auto table = load_attribute_table(file.data(), layout))
      describe_attributes(*table, report.info);
  } catch (const Error &e) {
    throw Error(Error::Kind::Internal,
                std::string("internal encoder error: the file it wrote does not read back (") +
                    e.what() + ")");
  }
  const uint32_t nv = in.vertices;
  report.input_vertices = input_vertices;
  report.unreferenced_vertices = input_vertices - nv;
  report.decoded_to_input.resize(nv);
  for (uint32_t i = 0; i < nv; ++i)
    report.decoded_to_input[i] = in.to_input[rb.dec_to_input[i]];
}

} // namespace

void check_encode_input(const Mesh &mesh, const EncodeOptions &options) {
  check_input(mesh, options);
}

std::vector<uint8_t> encode_manifold(const Mesh &mesh, const EncodeOptions &options,
                                     EncodeReport *report, const LosslessHook *hook,
                                     const std::function<void()> &release_input,
                                     bool name_refusal) {
  auto t0 = std::chrono::steady_clock::now();
  PreparedInput in = prepare_input(mesh, options, hook, name_refusal);
  const uint32_t nv = in.vertices, nf = in.faces;
  const double t_quantize = seconds_since(t0);
  // Attributes: codes of every vertex (prepared numbering); the base mesh's go to the ATTR
  // section, the others are coded with their positions by the level steps.
  AttributeTable attributes = plan_attributes(mesh, options.attributes);
  const std::vector<int64_t> codes =
      attributes.codes ? attribute_codes(mesh, attributes, options.attributes, in.to_input)
                       : std::vector<int64_t>();
  const size_t input_vertices = mesh.vertex_count();
  std::vector<uint8_t> images; // (optional section: embedded texture images)
  if (options.attributes.keep.texcoords && has_texture_images(mesh))
    images = write_texture_images(mesh);
  if (release_input)
    release_input(); // `mesh` is not read past this point

  auto t1 = std::chrono::steady_clock::now();
  DecimationOptions decimation;
  decimation.threads = resolve_threads(options.threads);
  const SeamLocks seams = seam_locks(hook, in); // texture seams (prepared numbering)
  if (hook && !hook->locked.empty()) {
    decimation.locked = &seams.locked;
    decimation.twin = &seams.twin;
    decimation.origin = &seams.origin;
  }
  DecimationTiers tiers; // (measurement only: EncodeOptions::tier_rounds)
  if (options.tier_rounds > 0 && !options.progressive) {
    tiers.rounds = options.tier_rounds;
    tiers.cell_vertices = std::max(1u, options.tier_cell_vertices);
    tiers.until_vertices = static_cast<uint32_t>(
        options.clusters ? options.clusters : options.cluster_ratio * double(nv));
    tiers.bits = in.grid.bits;
    decimation.tiers = &tiers;
  }
  const Decimation dec = decimate(std::move(in.ct), in.q, decimation, options.progress);
  const double t_decimate = seconds_since(t1);

  auto t2 = std::chrono::steady_clock::now();
  Rebuild rb(in.q, dec);
  const BaseMesh base = start_from_base_mesh(rb, nv);
  rb.mesh.reserve_counts(nv, nf); // the splits append without reallocating
  start_attributes(rb, attributes, codes);
  FileHeader header = make_header(options, in, rb);
  rb.fit_normal = header.ranks_patches(); // (version 5)
  rb.normal.assign(rb.levels(), NormalPredictor{});
  const size_t global = choose_global_levels(dec, header.base_vertices, nv, options);
  SymbolBits bits;
  const std::vector<std::vector<uint8_t>> blocks =
      encode_global_levels(rb, global, header, bits, options.progress);
  ClusteredLevels clustered;
  std::optional<ClusterErrorMeasure> errors; // (section CERR, bounded level by level)
  if (global < rb.levels()) {
    if (options.cluster_errors && options.format_version >= 5)
      errors.emplace(rb, global, in.grid);
    clustered = encode_clustered_levels(rb, global, header, decode_threads(options.threads),
                                        options.min_parallel_vertices, options.progress,
                                        errors ? &*errors : nullptr);
  }
  if (rb.mesh.vertex_count() != nv || rb.mesh.ct.face_count() != nf)
    throw Error(Error::Kind::Internal,
                "internal encoder error: the refined mesh does not match the input");

  std::vector<Section> sections =
      extra_sections(attributes, rb, header, std::move(images), hook, in);
  // Levels with a linear normal predictor (section GEOP, required: a reader that ignored it
  // would predict those levels' positions with the curvature term).
  if (needs_geometry_prediction(rb.normal))
    sections.push_back(
        {kGeometryPredictionTag, kSectionRequired, write_geometry_prediction(rb.normal)});
  // Random access, version 5: each block's whole XXH32 (section BCHK, optional).
  if (header.clustered() && header.ranks_patches() && options.block_checks)
    sections.push_back({kBlockChecksTag, 0, write_block_checks(clustered.blocks)});
  // Random access: the blocks in the Morton order of their roots (section BLKO, required:
  // a reader that does not know it would look for the blocks in id order). Both it and
  // CERR are version 5's: format_version 4 writes the files of the readers before it.
  std::vector<uint32_t> block_order;
  if (header.clustered() && options.spatial_layout && options.format_version >= 5) {
    block_order =
        morton_block_order(rb.mesh.q, static_cast<uint32_t>(clustered.blocks.size()), in.grid.bits);
    sections.push_back({kBlockOrderTag, kSectionRequired, write_block_order()});
  }
  if (errors) // the error per cluster and level (section CERR, optional)
    sections.push_back({kClusterErrorsTag, 0, errors->section()});
  std::vector<uint8_t> file =
      write_file(header, pack_base_mesh(base, in.grid.bits), blocks, clustered.tables,
                 clustered.blocks, sections, block_order.empty() ? nullptr : &block_order);
  if (report) {
    fill_report(file, in, rb, input_vertices, *report);
    report->quantize_seconds = t_quantize;
    report->decimate_seconds = t_decimate;
    report->encode_seconds = seconds_since(t2);
    report->symbol_bits = bits;
    report->cluster_level_ends = std::move(clustered.level_ends);
    const int L = static_cast<int>(dec.levels.size());
    for (const DecimationTier &t : dec.tiers) {
      EncodeReport::Tier r;
      r.levels = static_cast<int>(t.rounds);
      r.first_level = L - static_cast<int>(t.first_round + t.rounds) + 1;
      r.cell_bits = t.cell_bits;
      r.shifted = t.shifted;
      r.vertices = t.vertices;
      r.cells = t.cells;
      r.border = t.border;
      r.longest_edge = t.longest_edge;
      report->tiers.push_back(r);
    }
  }
  return file;
}

} // namespace pomar
