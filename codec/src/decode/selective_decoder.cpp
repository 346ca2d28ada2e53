// Random access (paper section 6): the level map and selective, incremental decoding.
#include <algorithm>
#include <cerrno>
#include <cstring>

#include "decode/decoder_codec.h"
#include "entropy/static_tables.h"
#include "format/file_format.h"
#include "lossless/lossless_stage.h"
#include "pomar/limits.h"
#include "pomar/random_access.h"

namespace pomar {

// ---------------------------------------------------------------- byte sources

void MemorySource::read(uint64_t offset, size_t n, uint8_t *out) {
  if (offset > size_ || n > size_ - offset)
    throw Error("read past the end of the .pomar data (truncated file?)");
  if (n) // an empty source has no data pointer to copy from (found by fuzzing)
    std::memcpy(out, data_ + offset, n);
}

FileSource::FileSource(const std::string &path) : path_(path) {
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_)
    throw Error("cannot open " + path + ": " + std::strerror(errno));
  if (std::fseek(file_, 0, SEEK_END) != 0 || std::ftell(file_) < 0) {
    std::fclose(file_);
    throw Error("cannot read " + path + ": not a regular file");
  }
  size_ = static_cast<uint64_t>(std::ftell(file_));
}

FileSource::~FileSource() {
  if (file_)
    std::fclose(file_);
}

void FileSource::read(uint64_t offset, size_t n, uint8_t *out) {
  if (offset > size_ || n > size_ - offset)
    throw Error("truncated .pomar file: " + path_ + " ends before byte " +
                std::to_string(offset + n));
  if (n == 0)
    return;
  if (std::fseek(file_, static_cast<long>(offset), SEEK_SET) != 0 ||
      std::fread(out, 1, n, file_) != n)
    throw Error("cannot read " + path_ + ": " + std::strerror(errno));
}

// ---------------------------------------------------------------- level map

std::vector<int> complete_level_map(const std::vector<int> &wanted,
                                    const std::vector<uint32_t> &start,
                                    const std::vector<uint32_t> &adj, int floor) {
  const size_t n = wanted.size();
  std::vector<int> m(n);
  int top = floor;
  for (size_t c = 0; c < n; ++c) {
    m[c] = std::max(wanted[c], floor);
    top = std::max(top, m[c]);
  }
  // Buckets by level, highest first: each cluster lowers its neighbours' floor to its
  // own level - 1 (the topological distance term of section 6).
  std::vector<std::vector<uint32_t>> bucket(size_t(top - floor + 1));
  for (size_t c = 0; c < n; ++c)
    if (m[c] > floor)
      bucket[size_t(m[c] - floor)].push_back(static_cast<uint32_t>(c));
  for (int lvl = top; lvl > floor; --lvl) {
    for (size_t i = 0; i < bucket[size_t(lvl - floor)].size(); ++i) {
      const uint32_t c = bucket[size_t(lvl - floor)][i];
      if (m[c] != lvl)
        continue;
      for (uint32_t k = start[c]; k < start[c + 1]; ++k) {
        const uint32_t nb = adj[k];
        if (m[nb] < lvl - 1) {
          m[nb] = lvl - 1;
          if (lvl - 1 > floor)
            bucket[size_t(lvl - 1 - floor)].push_back(nb);
        }
      }
    }
  }
  return m;
}

/// limit[x] = min over clusters c of cap[c] + d(c, x) (d = edge distance in the cluster
/// graph), at most `top`: the finest level map that respects every cap and the level map
/// rule. Buckets by value, lowest first (a multi-source breadth-first search).
static std::vector<int> cap_distance_map(const std::vector<int> &cap,
                                         const std::vector<uint32_t> &start,
                                         const std::vector<uint32_t> &adj, int top) {
  std::vector<int> limit(cap.size(), top);
  int low = top;
  for (size_t c = 0; c < cap.size(); ++c) {
    limit[c] = std::min(cap[c], top);
    low = std::min(low, limit[c]);
  }
  std::vector<std::vector<uint32_t>> bucket(size_t(top - low + 1));
  for (size_t c = 0; c < cap.size(); ++c)
    if (limit[c] < top)
      bucket[size_t(limit[c] - low)].push_back(static_cast<uint32_t>(c));
  for (int lvl = low; lvl < top; ++lvl) {
    for (size_t i = 0; i < bucket[size_t(lvl - low)].size(); ++i) {
      const uint32_t c = bucket[size_t(lvl - low)][i];
      if (limit[c] != lvl)
        continue;
      for (uint32_t k = start[c]; k < start[c + 1]; ++k)
        if (limit[adj[k]] > lvl + 1) {
          limit[adj[k]] = lvl + 1;
          bucket[size_t(lvl + 1 - low)].push_back(adj[k]);
        }
    }
  }
  return limit;
}

// ---------------------------------------------------------------- decoder state

struct SelectiveDecoder::State {
  std::unique_ptr<ByteSource> source;
  std::vector<uint8_t> global; // the file's prefix: header .. cluster index
  FileLayout layout;
  FileInfo info;
  int global_levels = 0, finest = 0;
  uint64_t bytes_read = 0;
  uint32_t blocks_read = 0;

  // Progressive part.
  Models global_models;
  LevelMesh mesh;        // current state
  LevelMesh snapshot;    // the base clustered mesh (clustered) or base mesh (progressive)
  int uniform_level = 0; // progressive files: the level of the whole mesh

  // Clustered part.
  std::vector<Models> level_models;
  ClusterIndex index;
  std::vector<uint32_t> adj_start, adj;
  /// A cluster's block, read from the source in chunks as its decoder consumes it.
  struct Cluster : StreamRefill {
    State *state = nullptr;
    uint32_t id = 0;
    std::vector<uint8_t> block; // sized to the whole block; [0, loaded) read so far
    size_t loaded = 0;
    bool checked = false;
    RangeDecoder rc;
    int level = 0;
    uint32_t next_local = 1;
    size_t more(size_t needed) override { return state->fetch(*this, needed); }
  };
  std::vector<Cluster> clusters;
  std::vector<int> wanted, levels;

  // Damaged blocks (skip_damaged): cap[c] = the finest level cluster c may reach.
  bool skip_damaged = false;
  std::vector<int> cap;
  std::vector<DamagedBlock> damaged;
  uint32_t decoding = kNone; // the cluster being decoded, for error reports
  bool traversing = false;   // its traversal has started (it may have claimed faces)
  bool data_checked = false; // the version 3 checksum of all cluster data was verified
  int uniform_cap = 1 << 30; // progressive files: the level before a damaged one

  TraversalScratch scratch;
  std::vector<PendingSplit> splits;

  bool clustered() const { return layout.header.clustered(); }
  static constexpr size_t kChunk = 4; // bytes per on-demand read of a cluster block
  size_t fetch(Cluster &k, size_t needed);
  void start(uint32_t c, bool whole);
  void reset_to_snapshot();
  void decode_cluster_level(uint32_t c, int level);
  void decode_target(const Progress &progress);
  void check_cluster_data();
  bool skip_cluster(uint32_t c, const Error &e);
  std::vector<int> target; // the level map being decoded
  int target_of(uint32_t c) const { return target.empty() ? finest : target[c]; }
};

size_t SelectiveDecoder::State::fetch(Cluster &k, size_t needed) {
  const size_t size = k.block.size();
  if (k.loaded >= size)
    return k.loaded; // past the end: the decoder reads zeros (and notices overruns)
  const size_t upto = std::min(size, std::max(needed, k.loaded + kChunk));
  source->read(index.offset[k.id] + k.loaded, upto - k.loaded, k.block.data() + k.loaded);
  bytes_read += upto - k.loaded;
  if (k.loaded == 0)
    ++blocks_read;
  k.loaded = upto;
  if (k.loaded == size && !k.checked) {
    if (!passes_block_check(k.block.data(), size, index.check[k.id]))
      throw Error("damaged .pomar file: checksum mismatch in the block of cluster " +
                  std::to_string(k.id));
    k.checked = true;
  }
  return k.loaded;
}

/// (Re)start cluster c's stream; `whole` reads its block at once (it will be decoded to
/// the end), otherwise bytes are read as the decoder needs them.
void SelectiveDecoder::State::start(uint32_t c, bool whole) {
  Cluster &k = clusters[c];
  // A truncated file (accepted with skip_damaged): nothing is allocated for a block that
  // is not there.
  if (index.offset[c] + index.size[c] > source->size())
    throw Error("truncated .pomar file: the block of cluster " + std::to_string(c) +
                " ends at byte " + std::to_string(index.offset[c] + index.size[c]) +
                ", the file has " + std::to_string(source->size()));
  if (k.block.empty() && index.size[c] > 0)
    k.block.resize(index.size[c]);
  if (whole)
    fetch(k, k.block.size());
  else if (k.loaded < std::min<size_t>(k.block.size(), 4))
    fetch(k, std::min<size_t>(k.block.size(), 4));
  k.rc.reset(k.block.data(), k.loaded, &k);
}

void SelectiveDecoder::State::reset_to_snapshot() {
  mesh = snapshot;
  for (Cluster &k : clusters) {
    k.level = global_levels;
    k.next_local = 1;
  }
}

void SelectiveDecoder::State::decode_cluster_level(uint32_t c, int level) {
  Cluster &k = clusters[c];
  decoding = c;
  if (k.level == global_levels) // first clustered level of this cluster: (re)start its stream
    start(c, skip_damaged || target_of(c) == finest);
  DecoderCodec codec(layout.header.grid.bits);
  codec.set(&level_models[size_t(level - global_levels - 1)], &k.rc, &k.rc,
            static_cast<uint32_t>(level), c);
  traversing = true;
  traverse_cluster(mesh, codec, scratch, c, static_cast<uint32_t>(level), splits);
  if (k.rc.overrun())
    codec.corrupt("the block ends too early");
  traversing = false;
  // Every check is done: a damaged block leaves the mesh as it was.
  apply_splits(mesh, splits, static_cast<uint32_t>(level), c, &k.next_local);
  k.level = level;
  decoding = kNone;
}

/// After `e` while decoding cluster `c` (kNone: not in a cluster): with skip_damaged,
/// record the damage, cap the cluster at the base clustered level and return true (the
/// caller decodes again); otherwise false (the caller rethrows).
bool SelectiveDecoder::State::skip_cluster(uint32_t c, const Error &e) {
  if (c == kNone)
    return false;
  // The failed traversal applied nothing; only its face claims need undoing.
  if (traversing)
    release_claims(mesh, scratch, static_cast<uint32_t>(clusters[c].level + 1));
  traversing = false;
  decoding = kNone;
  if (!skip_damaged)
    return false;
  damaged.push_back({"cluster " + std::to_string(c), e.what(), global_levels});
  // Levels of this cluster decoded earlier from the same block cannot be trusted either:
  // the cap coarsens it (decode_target re-decodes from the base clustered mesh then).
  cap[c] = global_levels;
  // A block that passed its 8-bit check and still fails may be intact and fail because a
  // neighbour's damaged block slipped through its own check (1 in 256) and decoded to a
  // wrong but valid state. The neighbours' blocks are suspects: keep them coarse too.
  if (clusters[c].checked) {
    // The damage may also lie further away, in a block whose wrong data happened to decode:
    // say so once (nothing can locate it).
    if (std::none_of(damaged.begin(), damaged.end(),
                     [](const DamagedBlock &b) { return b.level_kept < 0; }))
      damaged.push_back({"cluster data", kUnplacedDamage, -1});
    for (uint32_t k = adj_start[c]; k < adj_start[c + 1]; ++k) {
      const uint32_t nb = adj[k];
      if (cap[nb] == global_levels)
        continue;
      cap[nb] = global_levels;
      damaged.push_back({"cluster " + std::to_string(nb),
                         "suspect: its block passes its 8-bit check, but cluster " +
                             std::to_string(c) + " next to it failed to decode",
                         global_levels});
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
  const uint64_t file_size = s.source->size();
  // Header: the fixed part, then as much more as header_size() asks for (version 4 needs
  // one more step: its section count says how long the section table is).
  s.global.resize(std::min<uint64_t>(file_size, kFixedHeaderBytes));
  s.source->read(0, s.global.size(), s.global.data());
  size_t hsize = s.global.size();
  for (size_t want; (want = header_size(s.global.data(), hsize)) > hsize;) {
    if (want > file_size)
      throw Error("truncated .pomar file: the header alone needs " + std::to_string(want) +
                  " bytes");
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
                      options.memory_limit);
  // The global part (a truncated progressive file: what is there of it).
  s.global.resize(std::min<uint64_t>(s.layout.global_bytes, file_size));
  s.source->read(hsize, s.global.size() - hsize, s.global.data() + hsize);
  s.bytes_read = s.global.size();
  s.info = file_info(s.layout, file_size);
  const FileHeader &h = s.layout.header;
  s.finest = static_cast<int>(h.levels.size());
  s.mesh = base_level_mesh(s.global.data(), s.layout);
  if (!s.clustered()) {
    s.global_levels = 0;
    s.snapshot = s.mesh;
    s.uniform_level = 0;
    return;
  }
  s.global_levels = static_cast<int>(h.global_levels);
  check_block(s.global.data() + s.layout.tables_offset, h.tables_bytes, h.tables_checksum,
              "static model tables");
  s.level_models = read_tables(s.global.data() + s.layout.tables_offset, h.tables_bytes,
                               h.levels.size() - h.global_levels);
  s.index = read_cluster_index(s.global.data() + s.layout.index_offset, s.layout);
  s.info.cluster_block_bytes = s.index.size;
  decode_global_levels(s.global.data(), s.layout, 0, h.global_levels, s.mesh, s.global_models, {});
  // The base clustered mesh: each vertex roots its cluster.
  const uint32_t n = h.clusters;
  s.mesh.local.assign(n, 0);
  for (uint32_t c = 0; c < n; ++c)
    s.mesh.tag[c].cluster = c;
  s.snapshot = s.mesh;
  s.clusters.resize(n);
  for (uint32_t c = 0; c < n; ++c) {
    s.clusters[c].state = &s;
    s.clusters[c].id = c;
    s.clusters[c].level = s.global_levels;
  }
  s.wanted.assign(n, s.global_levels);
  s.levels.assign(n, s.global_levels);
  s.cap.assign(n, s.finest);
  // The cluster graph = the base clustered mesh's edges.
  Ring ring;
  s.adj_start.assign(n + 1, 0);
  for (uint32_t c = 0; c < n; ++c) {
    get_ring(s.mesh.ct, c, ring);
    s.adj.insert(s.adj.end(), ring.neighbour.begin(), ring.neighbour.end());
    s.adj_start[c + 1] = static_cast<uint32_t>(s.adj.size());
  }
}

SelectiveDecoder::~SelectiveDecoder() = default;

const FileInfo &SelectiveDecoder::info() const { return s_->info; }
uint32_t SelectiveDecoder::cluster_count() const {
  return static_cast<uint32_t>(s_->clusters.size());
}
int SelectiveDecoder::base_clustered_level() const { return s_->global_levels; }
int SelectiveDecoder::finest_level() const { return s_->finest; }
const std::vector<int> &SelectiveDecoder::wanted() const { return s_->wanted; }
const std::vector<int> &SelectiveDecoder::levels() const { return s_->levels; }
const std::vector<DamagedBlock> &SelectiveDecoder::damaged() const { return s_->damaged; }
uint64_t SelectiveDecoder::bytes_read() const { return s_->bytes_read; }
uint32_t SelectiveDecoder::blocks_read() const { return s_->blocks_read; }

uint32_t SelectiveDecoder::clusters_decoded() const {
  uint32_t n = 0;
  for (const auto &k : s_->clusters)
    n += k.level > s_->global_levels;
  return n;
}

// ---------------------------------------------------------------- requests

namespace {
int check_level(int level, int finest) {
  if (level < 0 || level > finest)
    throw Error("level " + std::to_string(level) + " does not exist: the file has levels 0.." +
                std::to_string(finest));
  return level;
}
} // namespace

void SelectiveDecoder::want_cluster(uint32_t cluster, int level) {
  check_level(level, s_->finest);
  if (cluster >= s_->clusters.size())
    throw Error("cluster " + std::to_string(cluster) + " does not exist: the file has " +
                std::to_string(s_->clusters.size()) + " clusters");
  s_->wanted[cluster] = std::max(s_->wanted[cluster], level);
}

void SelectiveDecoder::want_all(int level) {
  check_level(level, s_->finest);
  if (!s_->clustered()) {
    s_->uniform_level = std::max(s_->uniform_level, level);
    return;
  }
  for (int &w : s_->wanted)
    w = std::max(w, level);
}

void SelectiveDecoder::want_vertices(const std::vector<uint32_t> &vertices, int level) {
  check_level(level, s_->finest);
  if (!s_->clustered())
    return;
  for (uint32_t v : vertices) {
    if (v >= s_->mesh.vertex_count())
      throw Error("vertex " + std::to_string(v) + " is not in the decoded mesh");
    int &w = s_->wanted[s_->mesh.cluster_of(v)];
    w = std::max(w, level);
  }
}

void SelectiveDecoder::want_faces(const std::vector<uint32_t> &faces, int level) {
  std::vector<uint32_t> vertices;
  for (uint32_t f : faces) {
    if (f >= s_->mesh.ct.face_count())
      throw Error("face " + std::to_string(f) + " is not in the decoded mesh");
    vertices.insert(vertices.end(), &s_->mesh.ct.V[3 * f], &s_->mesh.ct.V[3 * f] + 3);
  }
  want_vertices(vertices, level);
}

namespace {
template <class Inside>
std::vector<uint32_t> vertices_where(const LevelMesh &m, const Quantizer &g, Inside inside) {
  std::vector<uint32_t> out;
  for (uint32_t v = 0; v < m.vertex_count(); ++v) {
    const float p[3] = {g.dequantize(0, uint32_t(m.q[3 * v])),
                        g.dequantize(1, uint32_t(m.q[3 * v + 1])),
                        g.dequantize(2, uint32_t(m.q[3 * v + 2]))};
    if (inside(p))
      out.push_back(v);
  }
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
    throw Error("set_wanted: " + std::to_string(levels.size()) + " levels for " +
                std::to_string(s_->clusters.size()) + " clusters");
  for (int l : levels)
    check_level(l, s_->finest);
  s_->wanted = levels;
}

// ---------------------------------------------------------------- decoding

void SelectiveDecoder::update(const Progress &progress) {
  State &s = *s_;
  if (!s.clustered()) {
    // The progressive mesh's level is the highest level of any vertex.
    int have = 0;
    for (const LevelMesh::Tag &t : s.mesh.tag)
      have = std::max(have, int(t.level));
    if (s.uniform_level < have) {
      s.mesh = s.snapshot;
      s.global_models = Models();
      have = 0;
    }
    const size_t want = size_t(std::min(s.uniform_level, s.uniform_cap));
    const size_t reached =
        decode_global_levels(s.global.data(), s.layout, size_t(have), want, s.mesh, s.global_models,
                             progress, s.skip_damaged ? &s.damaged : nullptr);
    if (reached < want)
      s.uniform_cap = int(reached);
    return;
  }
  // Decode the completed level map; a damaged block caps its cluster and the map is
  // completed and decoded again (each round skips one more block, so this ends).
  for (;;) {
    try {
      s.decode_target(progress);
      return;
    } catch (const Error &e) {
      if (!s.skip_cluster(s.decoding, e))
        throw;
    }
  }
}

/// Bring the mesh to the level map completed from `wanted` and limited by the caps.
void SelectiveDecoder::State::decode_target(const Progress &progress) {
  decoding = kNone;
  target = complete_level_map(wanted, adj_start, adj, global_levels);
  if (!damaged.empty()) {
    // Each damaged cluster limits the others to its cap + their distance to it, the
    // largest map below both the request and the caps that keeps the level map rule.
    const std::vector<int> limit = cap_distance_map(cap, adj_start, adj, finest);
    for (size_t c = 0; c < target.size(); ++c)
      target[c] = std::min(target[c], limit[c]);
  }
  bool coarser = false;
  for (size_t c = 0; c < target.size(); ++c)
    coarser = coarser || target[c] < clusters[c].level;
  if (coarser)
    reset_to_snapshot();
  size_t todo = 0, done = 0;
  for (size_t c = 0; c < target.size(); ++c)
    todo += size_t(target[c] - clusters[c].level);
  for (int level = global_levels + 1; level <= finest; ++level) {
    // Nothing finer than level-1 exists yet: every current vertex is older than `level`.
    int finest_now = global_levels;
    for (const auto &k : clusters)
      finest_now = std::max(finest_now, k.level);
    mesh.older_than_level = finest_now < level ? mesh.vertex_count() : 0;
    for (uint32_t c = 0; c < target.size(); ++c) {
      if (target[c] < level || clusters[c].level >= level)
        continue;
      decode_cluster_level(c, level);
      if (progress && (++done % 64 == 0 || done == todo))
        progress(double(done) / double(todo), "decode");
    }
  }
  mesh.older_than_level = 0;
  levels = target;
  check_cluster_data();
}

/// Once every block has been read whole (a full decode), check them together against the
/// version 3 checksum of the cluster data: a damaged block that passed its 8-bit check
/// (1 in 256) and decoded to a wrong but valid state is caught here.
void SelectiveDecoder::State::check_cluster_data() {
  const FileHeader &h = layout.header;
  if (data_checked || !h.has_cluster_checksum || !damaged.empty())
    return; // (damage found already: the cluster data cannot match)
  std::vector<const std::vector<uint8_t> *> blocks;
  for (const Cluster &k : clusters) {
    if (k.loaded != index.size[k.id])
      return; // not everything was read
    blocks.push_back(&k.block);
  }
  data_checked = true;
  if (checksum(blocks) == h.cluster_checksum)
    return;
  if (!skip_damaged)
    throw Error(kUnlocatedDamage);
  damaged.push_back({"cluster data", kUnlocatedDamage, -1});
}

Mesh SelectiveDecoder::mesh() const { return to_mesh(s_->mesh, s_->layout.header.grid); }

Mesh SelectiveDecoder::exact_mesh(std::vector<uint32_t> *source) const {
  Mesh m = mesh();
  const bool complete =
      s_->damaged.empty() &&
      (s_->clustered() ? std::all_of(s_->levels.begin(), s_->levels.end(),
                                     [&](int l) { return l == s_->finest; })
                       : s_->uniform_level == s_->finest);
  if (complete) {
    undo_cut(s_->global.data(), s_->layout, m, source); // the record lies in the global part
  } else if (source) {
    source->resize(m.vertex_count());
    for (uint32_t v = 0; v < source->size(); ++v)
      (*source)[v] = v;
  }
  return m;
}

std::vector<uint32_t> SelectiveDecoder::vertex_cluster() const {
  std::vector<uint32_t> out(s_->mesh.vertex_count(), 0);
  if (s_->clustered())
    for (uint32_t v = 0; v < out.size(); ++v)
      out[v] = s_->mesh.cluster_of(v);
  return out;
}

std::vector<uint32_t> SelectiveDecoder::vertex_level() const {
  std::vector<uint32_t> out(s_->mesh.vertex_count());
  for (uint32_t v = 0; v < out.size(); ++v)
    out[v] = s_->mesh.level_of(v);
  return out;
}

} // namespace pomar
