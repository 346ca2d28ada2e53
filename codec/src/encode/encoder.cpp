// Encoder: mesh -> quantize -> decimate (levels) -> encode global levels -> file.
//
// After decimation the encoder rebuilds the mesh from the base mesh exactly as the
// decoder will (same traversal, same splits, same vertex numbering), and at each vertex
// writes what the decoder needs to repeat the step: the encoder is a decoder that knows
// the answers.
#include <chrono>
#include <cmath>
#include <string>

#include "decimate/decimate.h"
#include "entropy/models.h"
#include "entropy/static_tables.h"
#include "format/file_format.h"
#include "geometry/quantize.h"
#include "lossless/lossless_stage.h"
#include "mesh/reorder.h"
#include "pomar/limits.h"
#include "refine/level_traversal.h"

namespace pomar {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The traversal policy of the encoder: it knows every collapse of the level. `Sink` is a
/// RangeEncoder (global levels) or a RecorderStream (clustered levels, coded later).
template <class Sink> class EncoderCodec {
public:
  EncoderCodec(const std::vector<int32_t> &input_q, std::vector<uint32_t> &dec_to_input,
               std::vector<uint32_t> &input_to_dec)
      : input_q_(input_q), dec_to_input_(dec_to_input), input_to_dec_(input_to_dec),
        collapse_at_(input_to_dec.size(), kNone) {}

  void begin_level(const std::vector<Collapse> &level, Models *models) {
    level_ = &level;
    m_ = models;
    for (uint32_t i = 0; i < level.size(); ++i)
      collapse_at_[level[i].v_to] = i;
    emitted_ = 0;
  }
  void set_sinks(Sink *conn, Sink *geom) {
    conn_ = conn;
    geom_ = geom;
  }
  void end_level() {
    for (const Collapse &c : *level_)
      collapse_at_[c.v_to] = kNone;
    if (emitted_ != level_->size())
      corrupt("a collapse of the level was not reached by the traversal");
  }

  int split_flag(uint32_t v, int context) {
    current_ = collapse_at_[dec_to_input_[v]];
    const int flag = current_ != kNone;
    bits[0] += cost_bits(m_->conn.sv[context], flag);
    conn_->encode_bit(m_->conn.sv[context], flag);
    emitted_ += flag;
    return flag;
  }

  void split_symbols(uint32_t v, const Ring &ring, const uint32_t *ranked, SplitSymbols &s) {
    (void)v;
    const Collapse &c = (*level_)[current_];
    const uint32_t m = ring.size();
    const uint32_t il = ring_index(ring, c.v_l), ir = ring_index(ring, c.v_r);
    // Vertices strictly inside the patch (they get a new edge to v_to at the collapse).
    auto inside = [&](uint32_t i) {
      if (ring.closed)
        return (i + m - il) % m != 0 && (i + m - il) % m < (ir + m - il) % m;
      const uint32_t lo = il == kNone ? 0 : il + 1, hi = ir == kNone ? m - 1 : ir - 1;
      return i >= lo && i <= hi && hi != kNone;
    };
    uint32_t e = kNone;
    for (uint32_t r = 0; r < m && e == kNone; ++r)
      if (inside(ranked[r]))
        e = r;
    for (uint32_t r = 0; r < m && e == kNone; ++r)
      if (ranked[r] == il || ranked[r] == ir)
        e = r;
    const uint32_t j = ranked[e];
    s.s_e = e;
    s.s_l = ring.closed ? (j + m - il) % m : (il == kNone ? j + 1 : j - il);
    s.s_r = ring.closed ? (ir + m - j) % m : (ir == kNone ? m - j : ir - j);
    const uint32_t faces = s.s_l + s.s_r;
    bits[1] += put_small(*conn_, m_->conn.se[valence_context(m)], s.s_e);
    bits[2] += put_small(*conn_, m_->conn.faces[faces_context(m, ring.closed)], faces);
    bits[3] += put_small(*conn_, m_->conn.sl[sl_context(faces)], s.s_l);
  }

  void geometry(uint32_t v_to, const Prediction &p, int32_t position[3]) {
    (void)v_to;
    const uint32_t v_from = (*level_)[current_].v_from;
    int64_t r[3];
    for (int k = 0; k < 3; ++k) {
      position[k] = input_q_[3 * v_from + k];
      r[k] = int64_t(position[k]) - p.barycentre[k];
    }
    to_local(p.frame, r);
    bits[4] += put_residual(*geom_, m_->geom, 0, p.context, r[0] - p.offset[0]);
    bits[4] += put_residual(*geom_, m_->geom, 0, p.context, r[1] - p.offset[1]);
    bits[5] += put_residual(*geom_, m_->geom, 1, p.context, r[2] - p.offset[2]);
    new_vertices_.push_back(v_from);
  }

  double bits[6] = {0, 0, 0, 0, 0, 0}; // ideal code lengths per symbol kind

  [[noreturn]] void corrupt(const char *what) {
    throw Error(std::string("internal encoder error: ") + what);
  }

  /// Number the vertices created by the splits applied since the last call.
  void number_new_vertices() {
    for (uint32_t v : new_vertices_) {
      input_to_dec_[v] = static_cast<uint32_t>(dec_to_input_.size());
      dec_to_input_.push_back(v);
    }
    new_vertices_.clear();
  }

private:
  uint32_t ring_index(const Ring &ring, uint32_t input_vertex) {
    if (input_vertex == kNone)
      return kNone;
    const int i = ring.index_of(input_to_dec_[input_vertex]);
    if (i < 0)
      corrupt("v_l/v_r is not a neighbour of v_to");
    return static_cast<uint32_t>(i);
  }

  Models *m_ = nullptr;
  const std::vector<int32_t> &input_q_;
  std::vector<uint32_t> &dec_to_input_, &input_to_dec_;
  std::vector<uint32_t> collapse_at_; // input vertex -> index of its collapse as v_to
  const std::vector<Collapse> *level_ = nullptr;
  Sink *conn_ = nullptr, *geom_ = nullptr;
  uint32_t current_ = kNone;
  size_t emitted_ = 0;
  std::vector<uint32_t> new_vertices_;
};

/// How many levels stay global: the level whose vertex count is closest (in ratio) to the
/// wanted number of clusters. Returns `levels` when no level would be clustered.
size_t choose_global_levels(const Decimation &dec, uint32_t base_vertices, uint32_t vertices,
                            const EncodeOptions &o) {
  const size_t L = dec.levels.size();
  if (o.progressive || L == 0)
    return L;
  double wanted = o.clusters ? double(o.clusters) : o.cluster_ratio * double(vertices);
  wanted = std::max(wanted, 1.0);
  size_t best = 0;
  double count = base_vertices, best_err = std::fabs(std::log(count / wanted));
  for (size_t g = 1; g <= L; ++g) {
    count += double(dec.levels[L - g].size()); // refinement level g re-inserts these
    const double err = std::fabs(std::log(count / wanted));
    if (err < best_err) {
      best_err = err;
      best = g;
    }
  }
  return best;
}

/// Drop unreferenced vertices; returns the compact positions and fills the index maps.
std::vector<float> compact_vertices(const Mesh &mesh, std::vector<uint32_t> &triangles,
                                    std::vector<uint32_t> &compact_to_input) {
  const size_t nv = mesh.vertex_count();
  std::vector<uint32_t> remap(nv, kNone);
  triangles = mesh.triangles;
  for (uint32_t &i : triangles) {
    if (i >= nv)
      throw Error("a triangle refers to vertex " + std::to_string(i) + " but the mesh has only " +
                  std::to_string(nv) + " vertices");
    if (remap[i] == kNone) {
      remap[i] = 0; // mark used; numbered below in input order
    }
  }
  std::vector<float> positions;
  for (uint32_t v = 0; v < nv; ++v) {
    if (remap[v] == kNone)
      continue;
    remap[v] = static_cast<uint32_t>(compact_to_input.size());
    compact_to_input.push_back(v);
    positions.insert(positions.end(), &mesh.positions[3 * v], &mesh.positions[3 * v] + 3);
  }
  for (uint32_t &i : triangles)
    i = remap[i];
  return positions;
}

void check_input(const Mesh &mesh, const EncodeOptions &options) {
  if (options.bits < 4 || options.bits > 24)
    throw Error("quantization bits must be between 4 and 24 (got " + std::to_string(options.bits) +
                ")");
  if (mesh.positions.size() % 3 || mesh.triangles.size() % 3)
    throw Error("position and triangle arrays must hold multiples of 3 values");
  if (mesh.triangle_count() == 0)
    throw Error("the mesh contains no triangles");
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    if (!std::isfinite(mesh.positions[i]))
      throw Error("vertex " + std::to_string(i / 3) + " has a non-finite coordinate");
}

} // namespace

std::vector<uint8_t> encode_manifold(const Mesh &mesh, const EncodeOptions &options,
                                     EncodeReport *report, const LosslessHook *hook) {
  auto t0 = std::chrono::steady_clock::now();
  check_input(mesh, options);
  // The caller already holds the input mesh: an automatic check counts only the rest.
  const uint64_t held =
      mesh.positions.size() * sizeof(float) + mesh.triangles.size() * sizeof(uint32_t);
  check_encode_memory(mesh.vertex_count(), mesh.triangle_count(), options.memory_limit, held);
  std::vector<uint32_t> triangles, compact_to_input;
  const std::vector<float> positions = compact_vertices(mesh, triangles, compact_to_input);
  const uint32_t nv = static_cast<uint32_t>(compact_to_input.size());
  const uint32_t nf = static_cast<uint32_t>(triangles.size() / 3);
  const Quantizer grid = hook ? hook->grid : make_quantizer(positions.data(), nv, options.bits);
  std::vector<int32_t> q = quantize(grid, positions.data(), nv);
  // Renumber for memory locality, then build (and validate) the connectivity. An invalid
  // mesh is validated again in the caller's numbering so that the message names its indices.
  const std::vector<uint32_t> input_triangles = triangles;
  const std::vector<uint32_t> old_to_new = reorder_for_locality(q, triangles);
  {
    std::vector<uint32_t> c2i(nv);
    for (uint32_t v = 0; v < nv; ++v)
      c2i[old_to_new[v]] = compact_to_input[v];
    compact_to_input.swap(c2i);
  }
  CornerTable ct;
  try {
    build_corner_table(triangles.data(), nf, nv, ct);
  } catch (const Error &) {
    build_corner_table(input_triangles.data(), nf, nv, ct); // throws with input indices
    throw;
  }
  const double t_quantize = seconds_since(t0);

  auto t1 = std::chrono::steady_clock::now();
  const Decimation dec = decimate(std::move(ct), q, DecimationOptions{}, options.progress);
  const double t_decimate = seconds_since(t1);

  // Base mesh, vertices numbered in input order.
  auto t2 = std::chrono::steady_clock::now();
  std::vector<uint32_t> dec_to_input, input_to_dec(nv, kNone);
  BaseMesh base;
  for (uint32_t i : dec.base_triangles)
    input_to_dec[i] = 0;
  for (uint32_t v = 0; v < nv; ++v)
    if (input_to_dec[v] != kNone) {
      input_to_dec[v] = static_cast<uint32_t>(dec_to_input.size());
      dec_to_input.push_back(v);
      base.q.insert(base.q.end(), &q[3 * v], &q[3 * v] + 3);
    }
  for (uint32_t i : dec.base_triangles)
    base.triangles.push_back(input_to_dec[i]);
  canonical_faces(base.triangles); // the order the file stores them in

  LevelMesh lm;
  lm.q = base.q;
  lm.seed_faces = static_cast<uint32_t>(base.triangles.size() / 3);
  build_corner_table(base.triangles.data(), lm.seed_faces, dec_to_input.size(), lm.ct);
  lm.init_lineage();

  FileHeader header;
  header.grid = grid;
  header.vertices = nv;
  header.faces = nf;
  header.base_vertices = static_cast<uint32_t>(dec_to_input.size());
  header.base_faces = lm.seed_faces;
  const size_t L = dec.levels.size();
  const size_t G = choose_global_levels(dec, header.base_vertices, nv, options);

  // Global levels: one adaptive model set for the whole file, two streams per level.
  Models models;
  EncoderCodec<RangeEncoder> codec(q, dec_to_input, input_to_dec);
  TraversalScratch scratch;
  std::vector<PendingSplit> splits;
  std::vector<std::vector<uint8_t>> blocks;
  auto add_level_entry = [&](uint32_t conn_bytes, uint32_t geom_bytes) {
    LevelEntry e;
    e.vertices = lm.vertex_count();
    e.faces = lm.ct.face_count();
    e.connectivity_bytes = conn_bytes;
    e.geometry_bytes = geom_bytes;
    header.levels.push_back(e);
  };
  for (size_t r = 0; r < G; ++r) {
    std::vector<uint8_t> conn, geom;
    RangeEncoder conn_rc(&conn), geom_rc(&geom);
    codec.begin_level(dec.levels[L - 1 - r], &models);
    codec.set_sinks(&conn_rc, &geom_rc);
    traverse_level(lm, codec, scratch, static_cast<uint32_t>(r + 1), splits);
    codec.end_level();
    conn_rc.finish();
    geom_rc.finish();
    apply_splits(lm, splits, static_cast<uint32_t>(r + 1));
    codec.number_new_vertices();
    add_level_entry(static_cast<uint32_t>(conn.size()), static_cast<uint32_t>(geom.size()));
    conn.insert(conn.end(), geom.begin(), geom.end());
    blocks.push_back(std::move(conn));
    if (options.progress)
      options.progress(double(r + 1) / double(L), "encode");
  }
  double symbol_bits[6];
  std::copy(codec.bits, codec.bits + 6, symbol_bits);

  // Clustered levels: every vertex of the base clustered mesh roots a cluster; each
  // cluster's splits of every clustered level are recorded, the level models frozen on
  // all clusters' symbols, then every cluster is coded into its own block.
  std::vector<uint8_t> tables;
  std::vector<std::vector<uint8_t>> cluster_blocks;
  if (G < L) {
    header.flags |= kFlagClustered;
    header.global_levels = static_cast<uint32_t>(G);
    const uint32_t clusters = lm.vertex_count();
    lm.local.assign(clusters, 0);
    for (uint32_t c = 0; c < clusters; ++c)
      lm.tag[c].cluster = c;
    std::vector<uint32_t> next_local(clusters, 1);
    std::vector<Models> level_models(L - G);
    std::vector<SymbolRecorder> recordings(clusters);
    EncoderCodec<RecorderStream> ccodec(q, dec_to_input, input_to_dec);
    for (size_t r = G; r < L; ++r) {
      const uint32_t level = static_cast<uint32_t>(r + 1);
      ccodec.begin_level(dec.levels[L - 1 - r], &level_models[r - G]);
      lm.older_than_level = lm.vertex_count(); // levels are encoded in order
      for (uint32_t c = 0; c < clusters; ++c) {
        RecorderStream conn{&recordings[c], 0}, geom{&recordings[c], 1};
        ccodec.set_sinks(&conn, &geom);
        traverse_cluster(lm, ccodec, scratch, c, level, splits);
        apply_splits(lm, splits, level, c, &next_local[c]);
        ccodec.number_new_vertices();
      }
      ccodec.end_level();
      lm.older_than_level = 0;
      add_level_entry(0, 0);
      if (options.progress)
        options.progress(double(r + 1) / double(L), "encode");
    }
    freeze_on_recordings(level_models, recordings);
    tables = write_tables(level_models);
    double bits[2] = {0, 0};
    cluster_blocks.reserve(clusters);
    for (const SymbolRecorder &rec : recordings)
      cluster_blocks.push_back(code_recording(rec, bits));
    uint64_t cluster_bytes = 0;
    for (const auto &b : cluster_blocks)
      cluster_bytes += b.size();
    header.cluster_connectivity_bytes =
        bits[0] + bits[1] > 0
            ? static_cast<uint64_t>(double(cluster_bytes) * bits[0] / (bits[0] + bits[1]))
            : 0;
  }
  if (lm.vertex_count() != nv || lm.ct.face_count() != nf)
    throw Error("internal encoder error: the refined mesh does not match the input");

  std::vector<Section> sections;
  if (hook) { // the lossless stage's record, in the decoder's numbering
    std::vector<uint32_t> decoded_to_cut(nv);
    for (uint32_t i = 0; i < nv; ++i)
      decoded_to_cut[i] = compact_to_input[dec_to_input[i]];
    // Required: a reader that ignored it would give the cut mesh for the input.
    sections.push_back({kLosslessTag, kSectionRequired, hook->record(decoded_to_cut)});
  }
  std::vector<uint8_t> file = write_file(header, pack_base_mesh(base, grid.bits), blocks, tables,
                                         cluster_blocks, sections);
  if (report) {
    const FileLayout layout = read_layout(file.data(), file.size());
    report->info = file_info(layout, file.size());
    report->input_vertices = mesh.vertex_count();
    report->unreferenced_vertices = mesh.vertex_count() - nv;
    report->quantize_seconds = t_quantize;
    report->decimate_seconds = t_decimate;
    report->encode_seconds = seconds_since(t2);
    for (int k = 0; k < 6; ++k)
      report->symbol_bits[k] = symbol_bits[k];
    report->decoded_to_input.resize(nv);
    for (uint32_t i = 0; i < nv; ++i)
      report->decoded_to_input[i] = compact_to_input[dec_to_input[i]];
  }
  return file;
}

} // namespace pomar
