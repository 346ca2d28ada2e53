// Random access (paper section 6): the level map and selective, incremental decoding.
#include <algorithm>
#include <cerrno>
#include <cstring>

#include "decode/decoder_codec.h"
#include "entropy/static_tables.h"
#include "format/file_format.h"
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
  LevelMesh mesh;     // current state
  LevelMesh snapshot; // the base clustered mesh (clustered) or base mesh (progressive)
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

  TraversalScratch scratch;
  std::vector<PendingSplit> splits;

  bool clustered() const { return layout.header.clustered(); }
  static constexpr size_t kChunk = 4; // bytes per on-demand read of a cluster block
  size_t fetch(Cluster &k, size_t needed);
  void start(uint32_t c, bool whole);
  void reset_to_snapshot();
  void decode_cluster_level(uint32_t c, int level);
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
    if ((checksum(k.block.data(), size) & 0xFF) != index.check[k.id])
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
  if (k.level == global_levels) // first clustered level of this cluster: (re)start its stream
    start(c, target_of(c) == finest);
  DecoderCodec codec(layout.header.grid.bits);
  codec.set(&level_models[size_t(level - global_levels - 1)], &k.rc, &k.rc,
            static_cast<uint32_t>(level), c);
  traverse_cluster(mesh, codec, scratch, c, static_cast<uint32_t>(level), splits);
  apply_splits(mesh, splits, static_cast<uint32_t>(level), c, &k.next_local);
  if (k.rc.overrun())
    codec.corrupt("the block ends too early");
  k.level = level;
}

// ---------------------------------------------------------------- construction

SelectiveDecoder::SelectiveDecoder(std::unique_ptr<ByteSource> source, uint64_t memory_limit)
    : s_(std::make_unique<State>()) {
  State &s = *s_;
  s.source = std::move(source);
  const uint64_t file_size = s.source->size();
  // Header: fixed part, then its full size.
  s.global.resize(std::min<uint64_t>(file_size, kFixedHeaderBytes));
  s.source->read(0, s.global.size(), s.global.data());
  const size_t hsize = header_size(s.global.data(), s.global.size());
  if (hsize > file_size)
    throw Error("truncated .pomar file: the header alone needs " + std::to_string(hsize) +
                " bytes");
  s.global.resize(hsize);
  s.source->read(0, hsize, s.global.data());
  s.layout = read_layout(s.global.data(), hsize, file_size);
  // What the constructor decodes: the base clustered mesh (progressive files: the base
  // mesh). Further refinement is what the caller asks for, region by region.
  check_decode_memory(file_info(s.layout, file_size),
                      s.layout.header.clustered() ? int(s.layout.header.global_levels) : 0,
                      memory_limit);
  // The global part.
  s.global.resize(s.layout.global_bytes);
  s.source->read(hsize, s.layout.global_bytes - hsize, s.global.data() + hsize);
  s.bytes_read = s.layout.global_bytes;
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
  decode_global_levels(s.global.data(), s.layout, 0, h.global_levels, s.mesh, s.global_models,
                       {});
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
    decode_global_levels(s.global.data(), s.layout, size_t(have), size_t(s.uniform_level), s.mesh,
                         s.global_models, progress);
    return;
  }
  s.target = complete_level_map(s.wanted, s.adj_start, s.adj, s.global_levels);
  const std::vector<int> &target = s.target;
  bool coarser = false;
  for (size_t c = 0; c < target.size(); ++c)
    coarser = coarser || target[c] < s.clusters[c].level;
  if (coarser)
    s.reset_to_snapshot();
  size_t todo = 0, done = 0;
  for (size_t c = 0; c < target.size(); ++c)
    todo += size_t(target[c] - s.clusters[c].level);
  for (int level = s.global_levels + 1; level <= s.finest; ++level) {
    // Nothing finer than level-1 exists yet: every current vertex is older than `level`.
    int finest_now = s.global_levels;
    for (const auto &k : s.clusters)
      finest_now = std::max(finest_now, k.level);
    s.mesh.older_than_level = finest_now < level ? s.mesh.vertex_count() : 0;
    for (uint32_t c = 0; c < target.size(); ++c) {
      if (target[c] < level || s.clusters[c].level >= level)
        continue;
      s.decode_cluster_level(c, level);
      if (progress && (++done % 64 == 0 || done == todo))
        progress(double(done) / double(todo), "decode");
    }
  }
  s.mesh.older_than_level = 0;
  s.levels = target;
}

Mesh SelectiveDecoder::mesh() const { return to_mesh(s_->mesh, s_->layout.header.grid); }

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
