// The clusters (paper section 5.2); see clusters.h.
#include "encode/clusters.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <memory>

#include "encode/fit_prediction.h"
#include "entropy/static_tables.h"
#include "format/geometry_prediction.h"
#include "parallel/thread_pool.h"

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

namespace {

/// The clusters of a level recorded on several threads, in two phases per batch (the
/// decoder's, refine/level_step.h): every cluster of the batch traversed at once without
/// touching the mesh, each thread with its own step and a codec working for the level's
/// (which defers numbering the split vertices), then, in cluster order, the split vertices
/// numbered and the splits applied. The symbols, the mesh and the vertex numbering are
/// those of the clusters recorded one after the other, for any thread count.
class ParallelClusters {
public:
  ParallelClusters(Rebuild &rb, uint32_t clusters, unsigned threads) : rb_(rb) {
    if (threads < 2 || clusters < kMinClusters)
      return;
    pool_ = std::make_unique<ThreadPool>(threads);
    steps_.resize(pool_->size());
    for (unsigned t = 0; t < pool_->size(); ++t) {
      workers_.emplace_back(rb.q, rb.dec_to_input, rb.input_to_dec);
      workers_.back().set_attribute_codes(rb.attr_codes, rb.attr_codes_per_vertex);
    }
    traversed_.resize(kBatch);
    numbered_.resize(kBatch);
    counts_.resize(pool_->size());
  }
  bool on() const { return pool_ != nullptr; }
  ThreadPool *pool() const { return pool_.get(); }

  /// Record every cluster's splits of `where.level` (where.cluster is ignored), and count
  /// the symbols recorded (counts()).
  void level(EncoderCodec<RecorderStream> &codec, std::vector<SymbolRecorder> &recordings,
             ClusterLevel where, std::vector<uint32_t> &next_local) {
    for (auto &w : workers_)
      w.work_for(codec);
    const ModelSlots &slots = *recordings[0].slots; // (the level's, shared by every cluster)
    for (std::vector<uint32_t> &c : counts_)
      c.assign(slots.symbols(), 0);
    const uint32_t clusters = static_cast<uint32_t>(recordings.size());
    for (uint32_t first = 0; first < clusters; first += kBatch) {
      const uint32_t n = std::min(kBatch, clusters - first);
      pool_->run(n, [&](size_t i, unsigned t) {
        ClusterLevel at = where;
        at.cluster = first + static_cast<uint32_t>(i);
        RecorderStream conn{&recordings[at.cluster], 0}, geom{&recordings[at.cluster], 1};
        workers_[t].set_sinks(&conn, &geom);
        steps_[t].traverse_cluster_level(rb_.mesh, workers_[t], at, NoCheck{}, traversed_[i]);
        workers_[t].take_deferred(numbered_[i]);
        count_symbols(recordings[at.cluster], slots, counts_[t].data());
      });
      for (uint32_t i = 0; i < n; ++i) {
        ClusterLevel at = where;
        at.cluster = first + i;
        if (!traversed_[i].error)
          for (uint32_t v_from : numbered_[i])
            codec.number_split(v_from);
        rb_.step.apply_cluster_level(rb_.mesh, codec, at, next_local[at.cluster], traversed_[i]);
      }
    }
    for (auto &w : workers_)
      codec.add_emitted(w);
  }

  /// How often each symbol of the last level() was recorded: the threads' counts summed
  /// (integers: the same totals whichever thread counted which cluster).
  std::vector<uint32_t> counts() const {
    std::vector<uint32_t> total = counts_[0];
    for (size_t t = 1; t < counts_.size(); ++t)
      for (size_t s = 0; s < total.size(); ++s)
        total[s] += counts_[t][s];
    return total;
  }

  /// Range-code every cluster's recording of the level into its own coder, the clusters
  /// spread over the threads (the models are frozen: coding only reads them), while one
  /// thread runs `alongside` (the sequential sums of the ideal code lengths).
  void code(const std::vector<SymbolRecorder> &recordings, const ModelSlots &slots,
            std::vector<RangeEncoder> &coders, const std::function<void()> &alongside) {
    pool_->run(recordings.size() + 1, [&](size_t i, unsigned) {
      if (i == 0)
        alongside();
      else
        code_recording(recordings[i - 1], slots, coders[i - 1]);
    });
  }

private:
  static constexpr uint32_t kBatch = 1024;     // clusters whose traversals are held at once
  static constexpr uint32_t kMinClusters = 64; // fewer: the threads cost more than they save
  Rebuild &rb_;
  std::unique_ptr<ThreadPool> pool_;
  std::vector<LevelStep> steps_;
  std::deque<EncoderCodec<RecorderStream>> workers_; // (their addresses must not move)
  std::vector<TraversedCluster> traversed_;
  std::vector<std::vector<uint32_t>> numbered_; // per batch cluster: its v_from, in order
  std::vector<std::vector<uint32_t>> counts_;   // per thread: symbol counts of level()
};

} // namespace

ClusteredLevels encode_clustered_levels(Rebuild &rb, size_t global, FileHeader &header,
                                        unsigned threads, uint32_t min_parallel_vertices,
                                        const Progress &progress, ClusterErrorMeasure *errors) {
  const size_t L = rb.levels();
  LevelMesh &lm = rb.mesh;
  header.flags |= kFlagClustered;
  header.global_levels = static_cast<uint32_t>(global);
  const uint32_t clusters = lm.vertex_count();
  lm.root_clusters();
  std::vector<uint32_t> next_local(clusters, 1);
  std::vector<Models> level_models(L - global);
  for (Models &m : level_models) {
    m.conn.patch_rank = header.ranks_patches();
    m.attr = rb.attr_models;
  }
  // Level after level: record every cluster's symbols of the level, freeze the level's
  // models on them, code them into each cluster's own range coder (which lives across
  // levels: one stream per cluster block) and forget them. Only one level's symbols are
  // ever held (the finest level's are the most), not every clustered level's.
  ClusteredLevels out;
  out.blocks.resize(clusters);
  out.level_ends.resize(size_t(clusters) * (L - global));
  std::vector<RangeEncoder> block_coders;
  block_coders.reserve(clusters);
  for (uint32_t c = 0; c < clusters; ++c)
    block_coders.emplace_back(&out.blocks[c]);
  // Ideal code lengths: [0] connectivity, [1] geometry, [2 + k] attribute code k.
  double bits[2 + kMaxAttributeCodes] = {};
  std::vector<SymbolRecorder> recordings(clusters);
  LevelFreezer freezer(header.ranks_patches()); // (versions 1-4: their encoders' tables)
  EncoderCodec<RecorderStream> codec(rb.q, rb.dec_to_input, rb.input_to_dec);
  codec.set_attribute_codes(rb.attr_codes, rb.attr_codes_per_vertex);
  ParallelClusters parallel(rb, clusters, threads);
  for (size_t r = global; r < L; ++r) {
    const uint32_t level = static_cast<uint32_t>(r + 1);
    if (errors) // (the mesh holds level r)
      errors->measure(rb, parallel.pool());
    Models &models = level_models[r - global];
    choose_wedge_predictor(rb, level);
    if (rb.fit_normal)
      rb.normal[r] = fit_normal_predictor(rb, level, true, needs_geometry_prediction(rb.normal));
    models.normal = rb.normal[r];
    codec.begin_level(rb.collapses(level), &models);
    const uint32_t older_than = lm.vertex_count(); // levels are encoded in order
    const ModelSlots slots(models);
    for (SymbolRecorder &recording : recordings)
      recording.slots = &slots;
    // A level with little work (the coarse clustered levels: a few vertices per cluster)
    // is recorded and coded on this thread, like the decoder's small levels: the two
    // phases' hand-overs cost more than the threads save there. Same symbols either way.
    const bool threaded = parallel.on() && lm.vertex_count() >= min_parallel_vertices;
    if (threaded) {
      parallel.level(codec, recordings, {0, level, older_than}, next_local);
    } else {
      for (uint32_t c = 0; c < clusters; ++c) {
        RecorderStream conn{&recordings[c], 0}, geom{&recordings[c], 1};
        codec.set_sinks(&conn, &geom);
        rb.step.cluster_level(lm, codec, {c, level, older_than}, next_local[c]);
      }
    }
    codec.end_level();
    take_wedge_costs(rb, codec);
    add_level_entry(header, lm, 0, 0);
    if (threaded) {
      freezer.freeze(models, slots, parallel.counts());
    } else {
      std::vector<uint32_t> counts(slots.symbols(), 0);
      for (const SymbolRecorder &recording : recordings)
        count_symbols(recording, slots, counts.data());
      freezer.freeze(models, slots, std::move(counts));
    }
    // The ideal code lengths summed in cluster order (the same sums for any thread count),
    // and each cluster's symbols coded into its own coder.
    const std::vector<double> costs = symbol_costs(slots, freezer.counts());
    const auto sum_bits = [&] {
      for (const SymbolRecorder &recording : recordings)
        add_recording_bits(recording, slots, costs, bits);
    };
    if (threaded) {
      parallel.code(recordings, slots, block_coders, sum_bits);
    } else {
      sum_bits();
      for (uint32_t c = 0; c < clusters; ++c)
        code_recording(recordings[c], slots, block_coders[c]);
    }
    for (uint32_t c = 0; c < clusters; ++c)
      out.level_ends[size_t(c) * (L - global) + (r - global)] =
          static_cast<uint32_t>(out.blocks[c].size());
    for (SymbolRecorder &recording : recordings)
      recording.events.clear(); // keeps its capacity for the next, larger level
    if (progress)
      progress(double(r + 1) / double(L), "encode");
  }
  for (RangeEncoder &rc : block_coders)
    rc.finish();
  for (uint32_t c = 0; c < clusters; ++c)
    out.level_ends[size_t(c + 1) * (L - global) - 1] = static_cast<uint32_t>(out.blocks[c].size());
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
