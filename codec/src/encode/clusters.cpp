// The clusters (paper section 5.2); see clusters.h.
#include "encode/clusters.h"

#include <cmath>

#include "entropy/static_tables.h"

namespace pomar {

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

ClusteredLevels encode_clustered_levels(Rebuild &rb, size_t global, FileHeader &header,
                                        const Progress &progress) {
  const size_t L = rb.levels();
  LevelMesh &lm = rb.mesh;
  header.flags |= kFlagClustered;
  header.global_levels = static_cast<uint32_t>(global);
  const uint32_t clusters = lm.vertex_count();
  lm.root_clusters();
  std::vector<uint32_t> next_local(clusters, 1);
  std::vector<Models> level_models(L - global);
  for (Models &m : level_models)
    m.attr = rb.attr_models;
  // Level after level: record every cluster's symbols of the level, freeze the level's
  // models on them, code them into each cluster's own range coder (which lives across
  // levels: one stream per cluster block) and forget them. Only one level's symbols are
  // ever held (the finest level's are the most), not every clustered level's.
  ClusteredLevels out;
  out.blocks.resize(clusters);
  std::vector<RangeEncoder> block_coders;
  block_coders.reserve(clusters);
  for (uint32_t c = 0; c < clusters; ++c)
    block_coders.emplace_back(&out.blocks[c]);
  // Ideal code lengths: [0] connectivity, [1] geometry, [2 + k] attribute code k.
  double bits[2 + kMaxAttributeCodes] = {};
  std::vector<SymbolRecorder> recordings(clusters);
  LevelFreezer freezer;
  EncoderCodec<RecorderStream> codec(rb.q, rb.dec_to_input, rb.input_to_dec);
  codec.set_attribute_codes(rb.attr_codes, rb.attr_codes_per_vertex);
  for (size_t r = global; r < L; ++r) {
    const uint32_t level = static_cast<uint32_t>(r + 1);
    Models &models = level_models[r - global];
    codec.begin_level(rb.collapses(level), &models);
    const uint32_t older_than = lm.vertex_count(); // levels are encoded in order
    const ModelAddresses addresses(models);
    for (uint32_t c = 0; c < clusters; ++c) {
      recordings[c].addresses = &addresses;
      RecorderStream conn{&recordings[c], 0}, geom{&recordings[c], 1};
      codec.set_sinks(&conn, &geom);
      rb.step.cluster_level(lm, codec, {c, level, older_than}, next_local[c]);
    }
    codec.end_level();
    add_level_entry(header, lm, 0, 0);
    freezer.freeze(models, recordings);
    for (uint32_t c = 0; c < clusters; ++c) {
      code_recording(recordings[c], block_coders[c], bits);
      recordings[c].events.clear(); // keeps its capacity for the next, larger level
    }
    if (progress)
      progress(double(r + 1) / double(L), "encode");
  }
  for (RangeEncoder &rc : block_coders)
    rc.finish();
  out.tables = write_tables(level_models);
  uint64_t cluster_bytes = 0;
  for (const auto &b : out.blocks)
    cluster_bytes += b.size();
  double all_bits = 0;
  for (double b : bits)
    all_bits += b;
  header.cluster_connectivity_bytes =
      all_bits > 0 ? static_cast<uint64_t>(double(cluster_bytes) * bits[0] / all_bits) : 0;
  for (uint32_t k = 0; k < rb.attr_codes_per_vertex; ++k)
    rb.attr_bits[k] += all_bits > 0 ? 8.0 * double(cluster_bytes) * bits[2 + k] / all_bits : 0;
  return out;
}

} // namespace pomar
