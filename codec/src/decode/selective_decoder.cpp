// Random access (paper section 6), the orchestration: requests -> the level map completed
// and limited around damage (decode/level_map.cpp) -> the missing cluster levels, level by
// level, each through the per-level step (refine/level_step.h) on the cluster's stream
// (decode/cluster_stream.cpp); coarsening re-decodes from the base clustered mesh.
// With several threads, the clusters of a level are traversed on every thread, admitted
// in cluster order one thread at a time and applied on every thread, a window at a time
// (decode/level_schedule.h; LevelStep::traverse_cluster_level, admit_cluster_level,
// apply_admitted): the mesh is the same for any thread count.
#include <algorithm>

#include "attributes/attribute_section.h"
#include "attributes/material_section.h"
#include "attributes/texture_images.h"
#include "decode/cluster_stream.h"
#include "decode/damage.h"
#include "decode/decoder_codec.h"
#include "decode/global_levels.h"
#include "decode/level_map.h"
#include "decode/level_schedule.h"
#include "entropy/static_tables.h"
#include "format/block_checks.h"
#include "format/block_order.h"
#include "format/cluster_errors.h"
#include "format/file_format.h"
#include "format/geometry_prediction.h"
#include "geometry/quantize.h"
#include "lossless/lossless_stage.h"
#include "parallel/thread_pool.h"
#include "pomar/limits.h"
#include "pomar/random_access.h"
#include "refine/level_step.h"

namespace pomar {

// ---------------------------------------------------------------- decoder state

struct SelectiveDecoder::State {
  std::unique_ptr<ByteSource> source;
  std::vector<uint8_t> global; // the file's prefix: header .. cluster index (see lazy)
  FileLayout layout;
  FileInfo info;
  int global_levels = 0, finest = 0;
  ReadStats reads; // bytes_read counts the global part too

  // Progressive part.
  Models global_models;
  LevelMesh mesh;        // current state
  LevelMesh snapshot;    // the base clustered mesh (clustered) or base mesh (progressive)
  int uniform_level = 0; // progressive files: the level of the whole mesh

  // Clustered part.
  std::vector<Models> level_models;
  ClusterIndex index;
  ClusterErrors errors; // the CERR section (empty without one or until read)
  // The per-cluster sections, read from the source when first needed rather than at open
  // (their bytes in `global` stay zero until then): CERR when a view-dependent selection
  // first asks for a stored error, BCHK before the first cluster block is read.
  struct LazySection {
    int index = -1;      // in the section table; -1: the file has none
    bool read = false;   // its bytes are in `global`
    bool loaded = false; // and were taken in (BCHK: the checks completed)
  };
  LazySection errors_section, checks_section;
  const uint8_t *read_lazy(LazySection &section);
  void load_errors();
  void load_block_checks_once();
  std::vector<uint32_t> block_order; // the blocks' order in the file (BLKO; empty: id order)
  ClusterGraph graph;
  // (Cache-line aligned: the clusters of a batch are decoded on several threads, each
  // writing its cluster's stream state at every symbol.)
  struct alignas(64) Cluster {
    ClusterStream stream;
    int level = 0;           // the level it is decoded to
    uint32_t next_local = 1; // its counter of created vertices (LevelMesh::local)
  };
  std::vector<Cluster> clusters;
  std::vector<int> wanted, levels;
  bool record_numbering = false;
  std::vector<SelectiveDecoder::NumberedLevel> numbered; // (SelectiveDecoder::numbered_levels)

  // Damaged blocks (skip_damaged): cap[c] = the finest level cluster c may reach.
  bool skip_damaged = false;
  std::vector<int> cap;
  std::vector<DamagedBlock> damaged;
  bool data_checked = false; // the version 3 checksum of all cluster data was verified
  int uniform_cap = 1 << 30; // progressive files: the level before a damaged one

  // steps[0]: the sequential step; with threads > 1, one step per thread of `pool` and
  // the traversals of the batch being decoded.
  unsigned threads = 1;
  uint32_t min_parallel_vertices = 0; // SelectiveOptions::min_parallel_vertices
  uint64_t memory_limit = 0;          // SelectiveOptions::memory_limit
  std::unique_ptr<ThreadPool> pool;
  std::vector<LevelStep> steps{1};
  std::vector<TraversedCluster> traversed;
  std::vector<RangeDecoder> stream_before; // each batch cluster's stream before its traversal
  std::vector<StepCounts> first_new;       // each batch cluster's first new vertex and face
  std::vector<uint32_t> ranks;             // breadth_first_ranks(graph), for the schedule

  // Attributes: descriptors and base codes (the other codes come with the positions).
  AttributeMask attribute_mask;
  std::unique_ptr<AttributeTable> attributes;
  std::unique_ptr<MaterialTable> materials; // per-corner values (MATL section)

  bool clustered() const { return layout.header.clustered(); }
  void reset_to_snapshot();
  void back_to_base(); // after take_mesh(): the base (clustered) mesh, requests kept
  void decode_cluster_level(uint32_t c, int level, uint32_t older_than);
  void decode_level_parallel(const std::vector<uint32_t> &refine, int level, uint32_t older_than,
                             const std::function<void()> &applied, uint32_t &decoding);
  LevelSchedule schedule;
  DecoderCodec cluster_codec(uint32_t c, int level);
  void decode_target(const Progress &progress);
  void limit_target(const std::vector<int> &request);
  bool decode_levels(const std::vector<int> &request, const std::function<void()> &applied);
  void decode_level(int level, uint32_t older_than, const std::function<void()> &applied,
                    uint32_t &decoding);
  void check_target_memory() const;
  void check_cluster_data();
  bool skip_cluster(uint32_t c, const Error &e);
  void cap_failing_blocks();
  uint32_t rounds = 0;     // passes over a level map (SelectiveDecoder::decode_rounds)
  std::vector<int> target; // the level map being decoded
  int target_of(uint32_t c) const { return target.empty() ? finest : target[c]; }
};

void SelectiveDecoder::State::reset_to_snapshot() {
  mesh = snapshot;
  numbered.clear();
  for (Cluster &k : clusters) {
    k.level = global_levels;
    k.next_local = 1;
  }
}

void SelectiveDecoder::State::back_to_base() {
  reset_to_snapshot();
  levels.assign(clusters.size(), global_levels);
  global_models = Models(); // (progressive files: the models adapt from the base mesh on)
  if (attributes)
    global_models.attr = attribute_models(*attributes);
}

/// The codec reading cluster c's data of `level` (the cluster is at level - 1) from its
/// stream, (re)started at the cluster's first clustered level.
DecoderCodec SelectiveDecoder::State::cluster_codec(uint32_t c, int level) {
  Cluster &k = clusters[c];
  if (k.level == global_levels)
    k.stream.start(skip_damaged || target_of(c) == finest);
  RangeDecoder &rc = k.stream.decoder();
  DecoderCodec codec(layout.header.grid.bits);
  codec.set(&level_models[size_t(level - global_levels - 1)], &rc, &rc,
            static_cast<uint32_t>(level), c);
  return codec;
}

/// The check after a cluster's traversal: its stream must not have run out.
struct StreamCheck {
  const RangeDecoder &rc;
  DecoderCodec &codec;
  void operator()(const StepCounts &) const {
    if (rc.overrun())
      codec.corrupt("the block ends too early");
  }
};

/// Cluster c's data of `level` (the cluster is at level - 1); a damaged block throws and
/// leaves the mesh as it was.
void SelectiveDecoder::State::decode_cluster_level(uint32_t c, int level, uint32_t older_than) {
  Cluster &k = clusters[c];
  DecoderCodec codec = cluster_codec(c, level);
  const uint32_t v0 = mesh.vertex_count(), f0 = mesh.ct.face_count();
  steps[0].cluster_level(mesh, codec, {c, static_cast<uint32_t>(level), older_than}, k.next_local,
                         StreamCheck{k.stream.decoder(), codec});
  k.level = level;
  if (record_numbering)
    numbered.push_back({c, static_cast<uint32_t>(level), v0, mesh.vertex_count() - v0, f0,
                        mesh.ct.face_count() - f0});
}

/// The data of `level` of the clusters `refine` (increasing), on the pool's threads, a
/// window at a time: traversed on every thread, checked and numbered in cluster order
/// one thread at a time, applied on every thread (decode/level_schedule.h). Throws what
/// decode_cluster_level would throw for the first cluster that fails (`decoding` names it),
/// with the clusters before it applied and the others as they were (their streams put
/// back).
void SelectiveDecoder::State::decode_level_parallel(const std::vector<uint32_t> &refine, int level,
                                                    uint32_t older_than,
                                                    const std::function<void()> &applied,
                                                    uint32_t &decoding) {
  // The clusters traversed before the window's applies, at most kWindow (2048 clusters of
  // a 1M-vertex file's finest level hold about 2 MB of splits; 4096 gained nothing
  // measurable); the window does not depend on the thread count (neither does anything
  // else the decoder does).
  constexpr size_t kWindow = 2048;
  const size_t window = std::min(kWindow, refine.size());
  if (traversed.size() < window) {
    traversed.resize(window);
    stream_before.resize(window);
    first_new.resize(window);
  }
  if (ranks.empty())
    ranks = breadth_first_ranks(graph);
  const uint32_t l = static_cast<uint32_t>(level);
  std::exception_ptr failure; // why the index that failed to be admitted failed
  uint64_t vertices = mesh.vertex_count(), faces = mesh.ct.face_count(); // once admitted
  LevelSchedule::Steps work;
  work.traverse = [&](size_t i, unsigned thread) {
    const uint32_t c = refine[i];
    TraversedCluster &out = traversed[i % window];
    stream_before[i % window] = clusters[c].stream.decoder();
    try {
      DecoderCodec codec = cluster_codec(c, level);
      steps[thread].traverse_cluster_level(mesh, codec, {c, l, older_than},
                                           StreamCheck{clusters[c].stream.decoder(), codec}, out);
    } catch (...) { // (the stream did not start)
      out.splits.clear();
      out.claims.clear();
      out.adds = {};
      out.error = std::current_exception();
    }
  };
  work.admit = [&](size_t i) {
    const uint32_t c = refine[i];
    TraversedCluster &in = traversed[i % window];
    DecoderCodec codec(layout.header.grid.bits); // (names the cluster in errors)
    codec.set(nullptr, nullptr, nullptr, l, c);
    try {
      LevelStep::admit_cluster_level(mesh, codec, {c, l, older_than}, in);
    } catch (...) {
      failure = std::current_exception();
      return false;
    }
    first_new[i % window] = {vertices, faces};
    if (record_numbering)
      numbered.push_back({c, l, static_cast<uint32_t>(vertices),
                          static_cast<uint32_t>(in.adds.vertices), static_cast<uint32_t>(faces),
                          static_cast<uint32_t>(in.adds.faces)});
    vertices += in.adds.vertices;
    faces += in.adds.faces;
    return true;
  };
  // A level that refines every cluster reaches the level table's counts (unless a block is
  // damaged): the arrays grow to them at the start, on one thread while the others
  // traverse (the first writes to the new pages cost as much as the traversals save), when
  // that moves no array (a traversal may be reading them). The windows then grow them only
  // past what they hold; the arrays take their exact counts at the end of the level.
  const LevelEntry &counts = layout.header.levels[size_t(level - 1)];
  if (refine.size() == clusters.size() && mesh.has_room(counts.vertices, counts.faces))
    work.early = [&] {
      mesh.grow(std::max<uint64_t>(counts.vertices, vertices),
                std::max<uint64_t>(counts.faces, faces));
    };
  work.grow = [&] {
    mesh.grow(std::max<uint64_t>(mesh.vertex_count(), vertices),
              std::max<uint64_t>(mesh.ct.face_count(), faces));
  };
  work.apply = [&](size_t i, unsigned) {
    const uint32_t c = refine[i];
    const StepCounts &at = first_new[i % window];
    LevelStep::apply_admitted(mesh, {c, l, older_than}, clusters[c].next_local,
                              traversed[i % window], static_cast<uint32_t>(at.vertices),
                              static_cast<uint32_t>(at.faces));
  };
  work.applied = [&](size_t i) {
    clusters[refine[i]].level = level;
    applied();
  };
  work.rewind = [&](size_t j) { clusters[refine[j]].stream.decoder() = stream_before[j % window]; };
  const size_t failed =
      schedule.run(*pool, graph, ranks, refine.data(), refine.size(), window, work);
  mesh.grow(vertices, faces); // (the exact counts: a damaged block adds fewer)
  if (failed < refine.size()) {
    decoding = refine[failed];
    std::rethrow_exception(failure);
  }
}

/// With skip_damaged, before a level map is decoded: the blocks it needs that are missing
/// (truncated file) or fail their 8-bit check, all found at once without a throw (each is
/// read whole, as its decode would read it) and capped as skip_cluster caps them. A level
/// map limited by the caps needs no other block, so the decode that follows meets only
/// damage no check can see (a block that passes its checks and still fails).
void SelectiveDecoder::State::cap_failing_blocks() {
  for (uint32_t c = 0; c < target.size(); ++c) {
    if (target[c] <= clusters[c].level || cap[c] == global_levels)
      continue;
    const std::string problem = clusters[c].stream.problem();
    if (problem.empty())
      continue;
    damaged.push_back(damaged_cluster(c, problem, global_levels));
    cap[c] = global_levels;
  }
}

/// After `e` while decoding cluster `c` (kNone: not in a cluster): with skip_damaged,
/// record the damage, cap the cluster at the base clustered level and return true (the
/// caller decodes again); otherwise false (the caller rethrows).
bool SelectiveDecoder::State::skip_cluster(uint32_t c, const Error &e) {
  // (The failed step applied nothing and released its face claims.)
  if (c == kNone || !skip_damaged)
    return false;
  damaged.push_back(damaged_cluster(c, e.what(), global_levels));
  // Levels of this cluster decoded earlier from the same block cannot be trusted either:
  // the cap coarsens it (decode_target re-decodes from the base clustered mesh then).
  cap[c] = global_levels;
  // A block that passed its 8-bit check and still fails may be intact and fail because a
  // neighbour's damaged block slipped through its own check (1 in 256) and decoded to a
  // wrong but valid state. The neighbours' blocks are suspects: keep them coarse too.
  if (clusters[c].stream.checked()) {
    // The damage may also lie further away, in a block whose wrong data happened to decode:
    // say so once (nothing can locate it).
    if (std::none_of(damaged.begin(), damaged.end(),
                     [](const DamagedBlock &b) { return b.level_kept < 0; }))
      damaged.push_back(unlocated_damage(kUnplacedDamage));
    for (uint32_t k = graph.start[c]; k < graph.start[c + 1]; ++k) {
      const uint32_t nb = graph.adj[k];
      if (cap[nb] == global_levels)
        continue;
      cap[nb] = global_levels;
      damaged.push_back(damaged_cluster(nb,
                                        "suspect: its block passes its 8-bit check, but "
                                        "cluster " +
                                            std::to_string(c) + " next to it failed to decode",
                                        global_levels));
    }
  }
  return true;
}

// ---------------------------------------------------------------- construction

SelectiveDecoder::SelectiveDecoder(std::unique_ptr<ByteSource> source,
                                   const SelectiveOptions &options)
    : s_(std::make_unique<State>()) {
  State &s = *s_;
  s.source = std::move(source);
  s.skip_damaged = options.skip_damaged;
  s.threads = decode_threads(options.threads);
  s.min_parallel_vertices = options.min_parallel_vertices;
  s.memory_limit = options.memory_limit;
  s.record_numbering = options.record_numbering;
  s.attribute_mask = options.attributes;
  const uint64_t file_size = s.source->size();
  // Header: the fixed part, then as much more as header_size() asks for (version 4 needs
  // one more step: its section count says how long the section table is).
  s.global.resize(std::min<uint64_t>(file_size, kFixedHeaderBytes));
  s.source->read(0, s.global.size(), s.global.data());
  size_t hsize = s.global.size();
  for (size_t want; (want = header_size(s.global.data(), hsize)) > hsize;) {
    if (want > file_size)
      throw Error(Error::Kind::TruncatedFile, "truncated .pomar file: the header alone needs " +
                                                  std::to_string(want) + " bytes");
    s.global.resize(want);
    s.source->read(hsize, want - hsize, s.global.data() + hsize);
    hsize = want;
  }
  s.layout = read_layout(s.global.data(), hsize, file_size, options.skip_damaged);
  require_known_sections(s.layout);
  // What the constructor decodes: the base clustered mesh (progressive files: the base
  // mesh). Further refinement is what the caller asks for, region by region.
  check_decode_memory(file_info(s.layout, file_size),
                      s.layout.header.clustered() ? int(s.layout.header.global_levels) : 0,
                      options.memory_limit, AttributeMask(), s.threads);
  // The global part (a truncated progressive file: what is there of it), but for the
  // per-cluster sections (read_lazy).
  s.global.resize(std::min<uint64_t>(s.layout.global_bytes, file_size));
  if (s.layout.header.clustered()) {
    s.errors_section.index = find_section(s.layout, kClusterErrorsTag);
    s.checks_section.index = find_section(s.layout, kBlockChecksTag);
  }
  {
    std::vector<std::pair<uint64_t, uint64_t>> skip; // [begin, end) of the lazy bodies
    for (const State::LazySection *l : {&s.errors_section, &s.checks_section})
      if (l->index >= 0) {
        const uint64_t at = s.layout.section_offset[size_t(l->index)];
        skip.emplace_back(at, at + s.layout.header.sections[size_t(l->index)].bytes);
      }
    std::sort(skip.begin(), skip.end());
    uint64_t at = hsize;
    const uint64_t end = s.global.size();
    for (const auto &[b, e] : skip) {
      if (b > at && at < end)
        s.source->read(at, std::min(b, end) - at, s.global.data() + at);
      at = std::max(at, e);
    }
    if (at < end)
      s.source->read(at, end - at, s.global.data() + at);
    s.reads.bytes = s.global.size();
    for (const auto &[b, e] : skip)
      s.reads.bytes -= std::min(e, end) - std::min(b, end);
  }
  s.info = file_info(s.layout, file_size);
  const FileHeader &h = s.layout.header;
  s.finest = static_cast<int>(h.levels.size());
  s.mesh = base_level_mesh(s.global.data(), s.layout);
  s.attributes = load_attribute_table(s.global.data(), s.layout, false); // (no codes kept)
  s.materials = load_material_table(s.global.data(), s.layout,
                                    s.attributes ? s.attributes->texture_files.size() : 0);
  if (s.attributes) { // attribute codes come with the positions, whatever the mask says
    describe_attributes(*s.attributes, s.info);
    // Checked again with the attributes, which only the global part describes, before the
    // base mesh's codes are stored.
    check_decode_memory(s.info, s.clustered() ? int(h.global_levels) : 0, options.memory_limit,
                        options.attributes, s.threads);
    s.attributes = load_attribute_table(s.global.data(), s.layout);
    init_attributes(*s.attributes, s.mesh, options.attributes);
    s.global_models.attr = attribute_models(*s.attributes);
  }
  if (!s.clustered()) {
    s.global_levels = 0;
    s.snapshot = s.mesh;
    s.uniform_level = 0;
    return;
  }
  s.global_levels = static_cast<int>(h.global_levels);
  check_block(s.global.data() + s.layout.tables_offset, h.tables_bytes, h.tables_checksum,
              "static model tables");
  s.level_models =
      read_tables(s.global.data() + s.layout.tables_offset, h.tables_bytes,
                  h.levels.size() - h.global_levels, h.ranks_patches(), s.global_models.attr);
  const std::vector<NormalPredictor> normal = load_geometry_prediction(s.global.data(), s.layout);
  for (size_t k = 0; k < s.level_models.size(); ++k) // (each clustered level's predictor)
    s.level_models[k].normal = normal[h.global_levels + k];
  s.index = read_cluster_index(s.global.data() + s.layout.index_offset, s.layout);
  s.info.cluster_block_bytes = s.index.size;
  decode_global_levels(s.global.data(), s.layout, 0, h.global_levels, s.mesh, s.global_models, {});
  const uint32_t n = h.clusters;
  s.mesh.root_clusters();
  // Blocks stored in the Morton order of their roots (BLKO): the offsets follow that order.
  if (has_block_order(s.global.data(), s.layout)) {
    s.block_order = morton_block_order(s.mesh.q, n, h.grid.bits);
    place_blocks(s.index, s.block_order, s.layout);
  }
  s.snapshot = s.mesh;
  s.clusters.resize(n);
  for (uint32_t c = 0; c < n; ++c) {
    s.clusters[c].stream.init(s.source.get(), c, s.index.offset[c], s.index.size[c],
                              s.index.check[c], s.index.check_mask, &s.reads);
    s.clusters[c].level = s.global_levels;
  }
  s.wanted.assign(n, s.global_levels);
  s.levels.assign(n, s.global_levels);
  s.cap.assign(n, s.finest);
  s.graph = cluster_graph(s.mesh.ct, n);
  if (s.materials) // texture seams: the clusters of a seam vertex's copies refine together
    link_coincident_clusters(s.mesh.q, n, s.graph);
}

SelectiveDecoder::~SelectiveDecoder() = default;

const FileInfo &SelectiveDecoder::info() const { return s_->info; }
uint32_t SelectiveDecoder::cluster_count() const {
  return static_cast<uint32_t>(s_->clusters.size());
}
int SelectiveDecoder::base_clustered_level() const { return s_->global_levels; }
void SelectiveDecoder::cluster_links(std::vector<uint32_t> &start,
                                     std::vector<uint32_t> &link) const {
  start = s_->graph.link_start;
  link = s_->graph.link;
  if (start.empty())
    start.assign(s_->clusters.size() + 1, 0);
}
int SelectiveDecoder::finest_level() const { return s_->finest; }
const std::vector<int> &SelectiveDecoder::wanted() const { return s_->wanted; }
const std::vector<int> &SelectiveDecoder::levels() const { return s_->levels; }
const std::vector<DamagedBlock> &SelectiveDecoder::damaged() const { return s_->damaged; }
uint64_t SelectiveDecoder::bytes_read() const { return s_->reads.bytes; }
uint32_t SelectiveDecoder::blocks_read() const { return s_->reads.blocks; }
uint32_t SelectiveDecoder::decode_rounds() const { return s_->rounds; }

uint32_t SelectiveDecoder::clusters_decoded() const {
  uint32_t n = 0;
  for (const auto &k : s_->clusters)
    n += k.level > s_->global_levels;
  return n;
}

// ---------------------------------------------------------------- requests

void check_level_exists(int level, int finest) {
  if (level < 0 || level > finest)
    throw Error(Error::Kind::Usage, "level " + std::to_string(level) +
                                        " does not exist: the file has levels 0.." +
                                        std::to_string(finest));
}

void SelectiveDecoder::want_cluster(uint32_t cluster, int level) {
  check_level_exists(level, s_->finest);
  if (cluster >= s_->clusters.size())
    throw Error(Error::Kind::Usage, "cluster " + std::to_string(cluster) +
                                        " does not exist: the file has " +
                                        std::to_string(s_->clusters.size()) + " clusters");
  s_->wanted[cluster] = std::max(s_->wanted[cluster], level);
}

void SelectiveDecoder::want_all(int level) {
  check_level_exists(level, s_->finest);
  if (!s_->clustered()) {
    s_->uniform_level = std::max(s_->uniform_level, level);
    return;
  }
  for (int &w : s_->wanted)
    w = std::max(w, level);
}

void SelectiveDecoder::want_vertices(const std::vector<uint32_t> &vertices, int level) {
  check_level_exists(level, s_->finest);
  if (!s_->clustered())
    return;
  for (uint32_t v : vertices) {
    if (v >= s_->mesh.vertex_count())
      throw Error(Error::Kind::Usage,
                  "vertex " + std::to_string(v) + " is not in the decoded mesh");
    int &w = s_->wanted[s_->mesh.cluster_of(v)];
    w = std::max(w, level);
  }
}

void SelectiveDecoder::want_faces(const std::vector<uint32_t> &faces, int level) {
  std::vector<uint32_t> vertices;
  for (uint32_t f : faces) {
    if (f >= s_->mesh.ct.face_count())
      throw Error(Error::Kind::Usage, "face " + std::to_string(f) + " is not in the decoded mesh");
    vertices.insert(vertices.end(), &s_->mesh.ct.V[3 * f], &s_->mesh.ct.V[3 * f] + 3);
  }
  want_vertices(vertices, level);
}

namespace {
template <class Inside>
std::vector<uint32_t> vertices_where(const LevelMesh &m, const Quantizer &g, Inside inside) {
  std::vector<uint32_t> out;
  const std::vector<float> p = dequantize(g, m.q);
  for (uint32_t v = 0; v < m.vertex_count(); ++v)
    if (inside(&p[3 * v]))
      out.push_back(v);
  return out;
}
} // namespace

void SelectiveDecoder::want_sphere(const float c[3], float radius, int level) {
  const double r2 = double(radius) * radius;
  want_vertices(vertices_where(s_->mesh, s_->layout.header.grid,
                               [&](const float *p) {
                                 double d2 = 0;
                                 for (int k = 0; k < 3; ++k)
                                   d2 += (double(p[k]) - c[k]) * (double(p[k]) - c[k]);
                                 return d2 <= r2;
                               }),
                level);
}

void SelectiveDecoder::want_box(const float lo[3], const float hi[3], int level) {
  want_vertices(vertices_where(s_->mesh, s_->layout.header.grid,
                               [&](const float *p) {
                                 for (int k = 0; k < 3; ++k)
                                   if (p[k] < lo[k] || p[k] > hi[k])
                                     return false;
                                 return true;
                               }),
                level);
}

void SelectiveDecoder::clear_wanted() {
  if (!s_->clustered()) {
    s_->uniform_level = 0;
    return;
  }
  std::fill(s_->wanted.begin(), s_->wanted.end(), s_->global_levels);
}

void SelectiveDecoder::set_wanted(const std::vector<int> &levels) {
  if (levels.size() != s_->clusters.size())
    throw Error(Error::Kind::Usage, "set_wanted: " + std::to_string(levels.size()) +
                                        " levels for " + std::to_string(s_->clusters.size()) +
                                        " clusters");
  for (int l : levels)
    check_level_exists(l, s_->finest);
  s_->wanted = levels;
}

// ---------------------------------------------------------------- decoding

void SelectiveDecoder::update(const Progress &progress) {
  State &s = *s_;
  if (!s.clustered()) {
    // The progressive mesh's level is the highest level of any vertex.
    int have = 0;
    for (const LevelMesh::Lineage &t : s.mesh.lineage)
      have = std::max(have, int(t.level));
    const int want_now = std::min(s.uniform_level, s.uniform_cap);
    if (want_now > have) // (before anything changes; exact counts: the level table's)
      check_decode_memory(s.info, want_now, s.memory_limit, s.attribute_mask, 1);
    if (s.uniform_level < have) {
      s.mesh = s.snapshot;
      s.global_models = Models();
      if (s.attributes)
        s.global_models.attr = attribute_models(*s.attributes);
      have = 0;
    }
    const size_t want = size_t(want_now);
    const size_t reached =
        decode_global_levels(s.global.data(), s.layout, size_t(have), want, s.mesh, s.global_models,
                             progress, s.skip_damaged ? &s.damaged : nullptr);
    if (reached < want)
      s.uniform_cap = int(reached);
    return;
  }
  s.decode_target(progress);
}

/// Bring the mesh to the level map completed from `wanted` and limited by the caps. With
/// skip_damaged, the blocks it needs that are missing or fail their check are capped
/// before anything is decoded (cap_failing_blocks); a block that fails while it is decoded
/// is capped where it fails (skip_cluster) and the pass goes on without it, so that one
/// pass meets every such block the map needs. Only when a cap falls below a level already
/// decoded (the failed cluster's own earlier levels, its suspect neighbours, clusters near
/// it) is the map decoded again from the base clustered mesh, once, after the pass: a
/// round (a block that passed in one round and fails in the next costs one more; each
/// round skips at least one more block, so this ends).
void SelectiveDecoder::State::decode_target(const Progress &progress) {
  const std::vector<int> request = complete_level_map(wanted, graph.start, graph.adj, global_levels,
                                                      graph.link_start, graph.link);
  target = request;
  for (size_t c = 0; c < target.size(); ++c)
    if (target[c] > clusters[c].level) { // a block will be read: its check first
      load_block_checks_once();
      break;
    }
  if (skip_damaged)
    cap_failing_blocks();
  limit_target(request);
  check_target_memory();
  size_t todo = 0, done = 0;
  const std::function<void()> applied = [&] {
    if (progress && (++done % 64 == 0 || done == todo))
      progress(std::min(1.0, double(done) / double(todo)), "decode");
  };
  for (;;) {
    ++rounds;
    bool coarser = false;
    for (size_t c = 0; c < target.size(); ++c)
      coarser = coarser || target[c] < clusters[c].level;
    if (coarser)
      reset_to_snapshot();
    for (size_t c = 0; c < target.size(); ++c)
      todo += size_t(target[c] - clusters[c].level);
    if (decode_levels(request, applied))
      break;
    limit_target(request); // (the map the caps allow, from the base clustered mesh)
  }
  levels = target;
  check_cluster_data();
}

/// target = the largest map below `request` and the caps that keeps the level map rule:
/// each damaged cluster limits the others to its cap + their distance to it.
void SelectiveDecoder::State::limit_target(const std::vector<int> &request) {
  target = request;
  if (damaged.empty())
    return;
  const std::vector<int> limit =
      cap_distance_map(cap, graph.start, graph.adj, finest, graph.link_start, graph.link);
  for (size_t c = 0; c < target.size(); ++c)
    target[c] = std::min(target[c], limit[c]);
}

/// One pass over the clustered levels towards `target`. A block that fails while it is
/// decoded (skip_damaged) caps its cluster and the pass goes on with the map the caps
/// allow, never below a level already decoded (the largest of two maps that keep the
/// level map rule keeps it too); returns false if some cluster is then finer than the caps
/// allow (the caller decodes again from the base clustered mesh, knowing every failure of
/// the pass).
bool SelectiveDecoder::State::decode_levels(const std::vector<int> &request,
                                            const std::function<void()> &applied) {
  // The whole mesh to one level (a full decode): the level table gives the final counts.
  const auto [lo, hi] = std::minmax_element(target.begin(), target.end());
  if (!target.empty() && *lo == *hi && *hi > global_levels) {
    const LevelEntry &e = layout.header.levels[size_t(*hi - 1)];
    mesh.reserve(e.vertices, e.faces, source->size());
  }
  bool too_fine = false; // a cluster is finer than the caps allow
  for (int level = global_levels + 1; level <= finest; ++level) {
    // Nothing finer than level-1 exists yet: every current vertex is older than `level`.
    int finest_now = global_levels;
    for (const auto &k : clusters)
      finest_now = std::max(finest_now, k.level);
    const uint32_t older_than = finest_now < level ? mesh.vertex_count() : 0;
    for (;;) {
      uint32_t decoding = kNone; // the cluster being decoded when an error is thrown
      try {
        decode_level(level, older_than, applied, decoding);
        break;
      } catch (const Error &e) {
        if (!skip_cluster(decoding, e))
          throw;
      }
      // The failed step applied nothing (the clusters before it in the level are applied,
      // the others as they were): go on with the map the new caps allow, where it is below
      // what is decoded already.
      limit_target(request);
      for (size_t c = 0; c < target.size(); ++c)
        if (target[c] < clusters[c].level) {
          target[c] = clusters[c].level;
          too_fine = true;
        }
    }
  }
  return !too_fine;
}

/// The clusters `target` refines to `level` (at level - 1 now), on the pool's threads or
/// this one; `decoding` names the cluster being decoded when an error is thrown.
void SelectiveDecoder::State::decode_level(int level, uint32_t older_than,
                                           const std::function<void()> &applied,
                                           uint32_t &decoding) {
  std::vector<uint32_t> refine; // the clusters to refine to `level`
  for (uint32_t c = 0; c < target.size(); ++c)
    if (target[c] >= level && clusters[c].level < level)
      refine.push_back(c);
  // A level with little to refine (a region's outer rings: many clusters of a few
  // vertices each) stays on this thread: the two phases' copies and hand-overs cost more
  // than the traversals save (one dragon cluster at the finest level: 19 ms on one
  // thread, 24-32 ms with every level on the pool). The work is estimated from the
  // level table: the level's vertices per cluster times the clusters to refine.
  const uint64_t work = uint64_t(refine.size()) * layout.header.levels[size_t(level - 1)].vertices /
                        std::max<size_t>(clusters.size(), 1);
  const bool parallel = threads > 1 && work >= min_parallel_vertices;
  if (parallel && !pool) {
    pool = std::make_unique<ThreadPool>(threads);
    steps.resize(pool->size());
  }
  if (parallel && pool->size() > 1) {
    decode_level_parallel(refine, level, older_than, applied, decoding);
    return;
  }
  for (uint32_t c : refine) {
    decoding = c;
    decode_cluster_level(c, level, older_than);
    decoding = kNone;
    applied();
  }
}

/// Refuse (pomar::Error, Kind::MemoryLimit) a level map `target` that would need more
/// memory than the limit (pomar/limits.h: check_level_map_memory), before anything is
/// decoded (the mesh stays as it is).
void SelectiveDecoder::State::check_target_memory() const {
  bool finer = false; // (nothing to decode: nothing to check)
  for (size_t c = 0; c < target.size(); ++c)
    finer = finer || target[c] > clusters[c].level;
  if (memory_limit == kNoMemoryLimit || !finer)
    return;
  const uint64_t held = decode_memory_estimate(mesh.vertex_count(), mesh.ct.face_count(), true);
  check_level_map_memory(info, target, global_levels, held, memory_limit, attribute_mask, threads);
}

/// Once every block has been read whole (a full decode), check them together against the
/// version 3 checksum of the cluster data: a damaged block that passed its 8-bit check
/// (1 in 256) and decoded to a wrong but valid state is caught here.
void SelectiveDecoder::State::check_cluster_data() {
  const FileHeader &h = layout.header;
  if (data_checked || !h.has_cluster_checksum || !damaged.empty())
    return; // (damage found already: the cluster data cannot match)
  std::vector<const std::vector<uint8_t> *> blocks;
  for (size_t i = 0; i < clusters.size(); ++i) { // in file order (BLKO: block_order)
    const Cluster &k = clusters[block_order.empty() ? i : block_order[i]];
    const std::vector<uint8_t> *block = k.stream.whole_block();
    if (!block)
      return; // not everything was read
    blocks.push_back(block);
  }
  data_checked = true;
  if (checksum(blocks) == h.cluster_checksum)
    return;
  if (!skip_damaged)
    throw Error(Error::Kind::DamagedFile, kUnlocatedDamage);
  damaged.push_back(unlocated_damage(kUnlocatedDamage));
}

Mesh SelectiveDecoder::mesh() const {
  const State &s = *s_;
  Mesh out = to_mesh(s.mesh, s.layout.header.grid);
  if (s.attributes)
    attach_attributes(*s.attributes, s.mesh, s.attribute_mask, out);
  if (s.materials)
    attach_materials(*s.materials, s.attribute_mask, out);
  return out;
}

bool SelectiveDecoder::complete() const {
  return s_->damaged.empty() &&
         (s_->clustered() ? std::all_of(s_->levels.begin(), s_->levels.end(),
                                        [&](int l) { return l == s_->finest; })
                          : s_->uniform_level == s_->finest);
}

Mesh SelectiveDecoder::exact_mesh(std::vector<uint32_t> *source) const {
  Mesh m = mesh();
  attach_texture_images(s_->global.data(), s_->layout, s_->attributes.get(), s_->attribute_mask,
                        m); // (the embedded images, TEXI)
  if (complete()) {
    undo_cut(s_->global.data(), s_->layout, m, source); // the record lies in the global part
  } else if (source) {
    source->resize(m.vertex_count());
    for (uint32_t v = 0; v < source->size(); ++v)
      (*source)[v] = v;
  }
  return m;
}

Mesh SelectiveDecoder::take_mesh() {
  State &s = *s_;
  // The working memory of the traversals goes first, so that the returned arrays do not
  // add to it: a one-shot decode's peak is then the decode's, not the decode's plus a copy.
  s.steps.assign(s.steps.size(), LevelStep());
  s.traversed = {};
  s.stream_before = {};
  Mesh out = to_mesh(std::move(s.mesh), s.layout.header.grid);
  if (s.attributes)
    attach_attributes(*s.attributes, s.mesh, s.attribute_mask, out);
  if (s.materials)
    attach_materials(*s.materials, s.attribute_mask, out);
  s.back_to_base();
  return out;
}

std::vector<uint32_t> SelectiveDecoder::vertex_cluster() const {
  std::vector<uint32_t> out(s_->mesh.vertex_count(), 0);
  if (s_->clustered())
    for (uint32_t v = 0; v < out.size(); ++v)
      out[v] = s_->mesh.cluster_of(v);
  return out;
}

const std::vector<SelectiveDecoder::NumberedLevel> &SelectiveDecoder::numbered_levels() const {
  return s_->numbered;
}

std::vector<uint32_t> SelectiveDecoder::vertex_level() const {
  std::vector<uint32_t> out(s_->mesh.vertex_count());
  for (uint32_t v = 0; v < out.size(); ++v)
    out[v] = s_->mesh.level_of(v);
  return out;
}

// ---------------------------------------------------------------- stored errors, blocks

/// The body of a per-cluster section, read from the source (and checked) the first time.
const uint8_t *SelectiveDecoder::State::read_lazy(LazySection &section) {
  const size_t i = size_t(section.index);
  const uint64_t at = layout.section_offset[i], bytes = layout.header.sections[i].bytes;
  if (!section.read) {
    if (at + bytes > global.size())
      throw Error(Error::Kind::TruncatedFile,
                  "truncated .pomar file: section " + section_name(layout.header.sections[i].tag) +
                      " ends at byte " + std::to_string(at + bytes) + ", the file has " +
                      std::to_string(global.size()));
    source->read(at, bytes, global.data() + at);
    reads.bytes += bytes;
    section.read = true;
  }
  return section_body(global.data(), layout, i); // (checks the section's checksum)
}

void SelectiveDecoder::State::load_errors() {
  if (errors_section.index < 0 || !errors.empty())
    return;
  const uint8_t *body = read_lazy(errors_section);
  errors =
      read_cluster_errors(body, layout.header.sections[size_t(errors_section.index)].bytes, layout);
}

void SelectiveDecoder::State::load_block_checks_once() {
  if (checks_section.index < 0 || checks_section.loaded)
    return;
  const uint8_t *body = read_lazy(checks_section);
  apply_block_checks(body, layout.header.sections[size_t(checks_section.index)].bytes, layout,
                     index);
  for (uint32_t c = 0; c < clusters.size(); ++c)
    clusters[c].stream.set_check(index.check[c], index.check_mask);
  checks_section.loaded = true;
}

bool SelectiveDecoder::has_cluster_errors() const { return s_->errors_section.index >= 0; }
double SelectiveDecoder::cluster_error(uint32_t cluster, int level) const {
  if (s_->errors_section.index < 0)
    return -1;
  s_->load_errors();
  if (cluster >= s_->clusters.size())
    throw Error(Error::Kind::Usage, "cluster " + std::to_string(cluster) +
                                        " does not exist: the file has " +
                                        std::to_string(s_->clusters.size()));
  check_level_exists(level, s_->finest);
  return s_->errors.bound(cluster, level);
}
uint64_t SelectiveDecoder::block_offset(uint32_t cluster) const {
  return s_->index.offset.at(cluster);
}
uint32_t SelectiveDecoder::block_size(uint32_t cluster) const { return s_->index.size.at(cluster); }

} // namespace pomar
