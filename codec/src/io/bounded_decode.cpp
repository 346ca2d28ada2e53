// A full decode written to a binary PLY region by region, in bounded memory
// (pomar/mesh_io.h: decode_to_ply_bounded).
//
// A full decode numbers the vertices and faces of a clustered level cluster by cluster in
// id order: cluster c's k-th new vertex of level l is V(l - 1) + (the vertices the clusters
// before c add in level l) + k, and its faces likewise. A selective decode of any region
// creates the same vertices and faces of each cluster level, in the same order
// (SelectiveDecoder::numbered_levels says where). So:
//   plan    the cluster graph and a Morton order of the cluster roots, from the base
//           clustered mesh; regions = runs of that order whose level map (the region and its
//           neighbours at full resolution) fits the budget;
//   count   each region decoded at full resolution: what each of its clusters adds in each
//           level; prefix sums over the clusters give every cluster level's first number;
//   write   each region and its neighbours decoded at full resolution: the region's
//           vertices and the faces its clusters created (base clustered faces: the cluster
//           of their first corner), whose corners lie in the region or a neighbour (a face
//           created by cluster c joins c's vertices and vertices of clusters next to c, and
//           a vertex keeps its cluster), written at their full-decode numbers into the
//           PLY's fixed-size records.
// The file is that of save_mesh(out, decode(in)) byte for byte.
#include "io/io_common.h"
#include "mesh/morton.h"
#include "parallel/thread_pool.h"

#include "pomar/limits.h"
#include "pomar/mesh_io.h"
#include "pomar/random_access.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

namespace pomar {
namespace {

using Numbered = SelectiveDecoder::NumberedLevel;

struct Plan {
  FileInfo info;
  int base_level = 0, finest = 0;
  uint32_t clusters = 0, base_faces = 0; // of the base clustered mesh
  std::vector<uint32_t> start, adj;      // the cluster graph (CSR)
  std::vector<uint32_t> order;           // clusters in the Morton order of their roots
  uint64_t fixed = 0;                    // bytes held through both passes
};

/// Vertices (faces) of the whole mesh after `level` levels.
uint64_t vertices_after(const FileInfo &info, int level) {
  return level == 0 ? info.base_vertices : info.levels[size_t(level) - 1].vertices;
}
uint64_t faces_after(const FileInfo &info, int level) {
  return level == 0 ? info.base_faces : info.levels[size_t(level) - 1].faces;
}

/// What the file needs that a bounded decode cannot give: an empty string if none.
std::string unsupported(const FileInfo &info) {
  if (!info.clustered())
    return "it is a pure progressive file (encoded with --progressive): its levels refine the "
           "whole mesh at once";
  if (info.lossless_bytes > 0)
    return "it carries a lossless record (LSLS: the input was cut into a manifold, or had "
           "unreferenced vertices), which is undone on the whole mesh";
  if (!info.attributes.empty())
    return "it has per-vertex attributes";
  for (const FileInfo::Section &s : info.sections)
    if (s.name == "MATL" || s.name == "TEXI" || s.name == "ATTR")
      return "it has a " + s.name + " section";
  return "";
}

Plan make_plan(const std::string &in, unsigned threads) {
  Plan p;
  SelectiveOptions so;
  so.memory_limit = kNoMemoryLimit; // (checked by the caller against the plan's needs)
  so.threads = threads;
  so.attributes = AttributeMask::none();
  SelectiveDecoder d(std::make_unique<FileSource>(in), so);
  p.info = d.info();
  const std::string why = unsupported(p.info);
  if (!why.empty())
    throw Error(Error::Kind::Unsupported,
                in + " cannot be decoded in bounded memory: " + why +
                    "; decode it whole (more memory: --max-memory) or with --level");
  p.base_level = d.base_clustered_level();
  p.finest = d.finest_level();
  p.clusters = d.cluster_count();
  const Mesh base = d.mesh(); // vertex c roots cluster c
  p.base_faces = static_cast<uint32_t>(base.triangle_count());
  std::vector<uint64_t> edges; // (a << 32 | b), both directions
  edges.reserve(6 * base.triangle_count());
  for (size_t f = 0; f < base.triangle_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = base.triangles[3 * f + k], b = base.triangles[3 * f + (k + 1) % 3];
      edges.push_back(a << 32 | b);
      edges.push_back(b << 32 | a);
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  p.start.assign(p.clusters + 1, 0);
  p.adj.resize(edges.size());
  for (size_t i = 0; i < edges.size(); ++i) {
    ++p.start[(edges[i] >> 32) + 1];
    p.adj[i] = static_cast<uint32_t>(edges[i]);
  }
  for (uint32_t c = 0; c < p.clusters; ++c)
    p.start[c + 1] += p.start[c];
  edges = {};
  // Morton order of the roots (21 bits per axis over the bounding box).
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k)
    lo[k] = hi[k] = base.positions[k];
  for (size_t v = 0; v < base.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], base.positions[3 * v + k]);
      hi[k] = std::max(hi[k], base.positions[3 * v + k]);
    }
  std::vector<std::pair<uint64_t, uint32_t>> keyed(p.clusters);
  for (uint32_t c = 0; c < p.clusters; ++c) {
    uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double side = std::max(1e-30, double(hi[k]) - double(lo[k]));
      const double t = (double(base.positions[3 * c + k]) - lo[k]) / side;
      code |= spread3(static_cast<uint64_t>(std::clamp(t, 0.0, 1.0) * 2097151.0)) << k;
    }
    keyed[c] = {code, c};
  }
  std::sort(keyed.begin(), keyed.end());
  p.order.resize(p.clusters);
  for (uint32_t i = 0; i < p.clusters; ++i)
    p.order[i] = keyed[i].second;
  // Held through both passes: the per-cluster-level counts (8 bytes each), the graph, the
  // order and the region's per-cluster arrays.
  const uint64_t cluster_levels = uint64_t(p.clusters) * uint64_t(p.finest - p.base_level);
  p.fixed = 8 * cluster_levels + 4 * (p.start.size() + p.adj.size()) + 16 * uint64_t(p.clusters);
  return p;
}

/// The level map of a region at full resolution with (`halo`) its neighbours.
std::vector<int> region_map(const Plan &p, const uint32_t *members, size_t count, bool halo) {
  std::vector<int> wanted(p.clusters, p.base_level);
  for (size_t i = 0; i < count; ++i) {
    const uint32_t c = members[i];
    wanted[c] = p.finest;
    if (halo)
      for (uint32_t k = p.start[c]; k < p.start[c + 1]; ++k)
        wanted[p.adj[k]] = p.finest;
  }
  return complete_level_map(wanted, p.start, p.adj, p.base_level);
}

/// The bytes the write pass needs for a region: the decoder's (the level map's estimate,
/// pomar/limits.h) and the arrays written out (numbers, records, the numbered levels).
uint64_t region_needs(const Plan &p, const std::vector<int> &map, unsigned threads) {
  uint64_t v = 0, f = 0;
  const uint64_t decoder =
      level_map_memory_estimate(p.info, map, p.base_level, AttributeMask::none(), threads, &v, &f);
  uint64_t cluster_levels = 0;
  for (int l : map)
    cluster_levels += uint64_t(l - p.base_level);
  return decoder + 12 * v + 8 * f + 24 * cluster_levels;
}

/// Regions: runs of the Morton order, each as long as its write pass fits `budget` (found
/// by doubling, then bisection). Throws MemoryLimit when one cluster does not fit.
std::vector<size_t> make_regions(const Plan &p, uint64_t limit, unsigned threads, uint64_t &largest,
                                 const std::string &in) {
  std::vector<size_t> ends;
  const uint64_t budget = limit > p.fixed ? limit - p.fixed : 0;
  size_t first = 0;
  largest = 0;
  while (first < p.clusters) {
    auto fits = [&](size_t count, uint64_t *needs) {
      const uint64_t n = region_needs(p, region_map(p, &p.order[first], count, true), threads);
      if (needs)
        *needs = n;
      return n <= budget;
    };
    uint64_t needs = 0;
    if (!fits(1, &needs)) {
      Error e(Error::Kind::MemoryLimit,
              "not enough memory to decode " + in +
                  " in bounded memory: its smallest region (one cluster and its neighbours at full "
                  "resolution, the other clusters at the levels the level map asks) needs about " +
                  format_memory_size(needs) + " and the per-cluster tables " +
                  format_memory_size(p.fixed) + ", " + format_memory_size(needs + p.fixed) +
                  " in all; the limit is " + format_memory_size(limit) +
                  "; use --max-memory to raise it");
      throw e;
    }
    size_t good = 1, bad = 0; // fits(good), !fits(bad) (0: not found yet)
    const size_t left = p.clusters - first;
    while (bad == 0 && good < left) {
      const size_t next = std::min(left, 2 * good);
      if (fits(next, nullptr))
        good = next;
      else
        bad = next;
    }
    while (bad > good + 1) {
      const size_t mid = good + (bad - good) / 2;
      (fits(mid, nullptr) ? good : bad) = mid;
    }
    fits(good, &needs);
    largest = std::max(largest, needs + p.fixed);
    first += good;
    ends.push_back(first);
  }
  return ends;
}

/// Cluster c's counts of clustered level l: table[(l - base_level - 1) * clusters + c].
struct LevelTable {
  const Plan &p;
  std::vector<uint32_t> vertices, faces;
  explicit LevelTable(const Plan &plan) : p(plan) {
    const size_t n = size_t(p.clusters) * size_t(p.finest - p.base_level);
    vertices.assign(n, 0);
    faces.assign(n, 0);
  }
  size_t at(uint32_t c, uint32_t level) const {
    return size_t(level - uint32_t(p.base_level) - 1) * p.clusters + c;
  }
  /// Counts -> each cluster level's first vertex and face in the full decode, checked
  /// against the level table.
  void number(const std::string &in) {
    for (int l = p.base_level + 1; l <= p.finest; ++l) {
      uint64_t v = vertices_after(p.info, l - 1), f = faces_after(p.info, l - 1);
      for (uint32_t c = 0; c < p.clusters; ++c) {
        const size_t i = at(c, uint32_t(l));
        const uint64_t nv = vertices[i], nf = faces[i];
        vertices[i] = static_cast<uint32_t>(v);
        faces[i] = static_cast<uint32_t>(f);
        v += nv;
        f += nf;
      }
      if (v != vertices_after(p.info, l) || f != faces_after(p.info, l))
        throw Error(Error::Kind::DamagedFile,
                    "damaged .pomar file: " + in + ": level " + std::to_string(l) +
                        "'s clusters add up to " + std::to_string(v) + " vertices and " +
                        std::to_string(f) + " faces, the level table says " +
                        std::to_string(vertices_after(p.info, l)) + " and " +
                        std::to_string(faces_after(p.info, l)));
    }
  }
};

/// The output file: fixed-size records written at their offsets.
class RecordFile {
public:
  RecordFile(const std::string &out, uint64_t vertices, uint64_t faces) : out_(out), tmp_(out) {
    header_ = io::binary_ply_header(vertices, faces);
    faces_at_ = header_.size() + 12 * vertices;
    size_ = faces_at_ + 13 * faces;
    const size_t slash = out.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : out.substr(0, slash + 1);
    struct statvfs fs;
    if (::statvfs(dir.c_str(), &fs) == 0 && uint64_t(fs.f_bavail) * uint64_t(fs.f_frsize) < size_)
      io::fail_io(out, "not enough disk space: the decoded mesh takes " +
                           format_memory_size(size_) + ", the disk has " +
                           format_memory_size(uint64_t(fs.f_bavail) * uint64_t(fs.f_frsize)) +
                           " free");
    fd_ = ::open(tmp_.path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0)
      io::fail_io(out, "cannot create: " + io::errno_text(errno));
    if (::ftruncate(fd_, static_cast<off_t>(size_)) != 0)
      io::fail_io(out, "cannot size the file: " + io::errno_text(errno));
    write(0, header_.data(), header_.size());
  }
  ~RecordFile() {
    if (fd_ >= 0)
      ::close(fd_);
  }
  uint64_t vertex_offset(uint64_t v) const { return header_.size() + 12 * v; }
  uint64_t face_offset(uint64_t f) const { return faces_at_ + 13 * f; }
  void write(uint64_t offset, const char *data, size_t n) {
    while (n > 0) {
      const ssize_t w = ::pwrite(fd_, data, n, static_cast<off_t>(offset));
      if (w < 0 && errno == EINTR)
        continue;
      if (w <= 0)
        io::fail_io(out_, "cannot write: " + io::errno_text(errno));
      data += w, n -= size_t(w), offset += uint64_t(w);
    }
  }
  void commit() {
    if (::fsync(fd_) != 0 || ::close(fd_) != 0) {
      fd_ = -1;
      io::fail_io(out_, "cannot write: " + io::errno_text(errno));
    }
    fd_ = -1;
    tmp_.commit(false);
  }

private:
  std::string out_;
  io::TempFile tmp_;
  std::string header_;
  uint64_t faces_at_ = 0, size_ = 0;
  int fd_ = -1;
};

/// Records sorted by number, written in runs of consecutive numbers.
template <size_t Size> class RunWriter {
public:
  RunWriter(RecordFile &file, bool faces) : file_(file), faces_(faces) {}
  /// Writes items (number, payload index) sorted, `fill(payload, out)` making each record.
  template <class Fill> void write(std::vector<std::pair<uint32_t, uint32_t>> &items, Fill fill) {
    std::sort(items.begin(), items.end());
    std::vector<char> run;
    run.reserve(kRun * Size);
    uint64_t first = 0;
    auto flush = [&] {
      if (!run.empty())
        file_.write(faces_ ? file_.face_offset(first) : file_.vertex_offset(first), run.data(),
                    run.size());
      run.clear();
    };
    for (size_t i = 0; i < items.size(); ++i) {
      if (i > 0 && items[i].first == items[i - 1].first)
        throw Error(Error::Kind::Internal,
                    "bounded decode: record " + std::to_string(items[i].first) + " written twice");
      if (run.empty() || items[i].first != first + run.size() / Size || run.size() >= kRun * Size) {
        flush();
        first = items[i].first;
      }
      const size_t at = run.size();
      run.resize(at + Size);
      fill(items[i].second, run.data() + at);
    }
    flush();
  }

private:
  static constexpr size_t kRun = 1 << 16;
  RecordFile &file_;
  bool faces_;
};

} // namespace

BoundedDecodeReport decode_to_ply_bounded(const std::string &in, const std::string &out,
                                          const BoundedDecodeOptions &options) {
  const size_t dot = out.find_last_of("./");
  std::string ext = dot == std::string::npos || out[dot] != '.' ? "" : out.substr(dot);
  for (char &ch : ext)
    ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext != ".ply")
    throw Error(Error::Kind::Usage, "a decode in bounded memory writes binary PLY only: " + out +
                                        " is not a .ply file");
  const unsigned threads = decode_threads(options.threads);
  uint64_t limit = options.memory_limit;
  if (limit == 0) {
    const AvailableMemory a = available_memory();
    limit = a.known ? a.bytes : kNoMemoryLimit;
  }
  const Plan p = make_plan(in, threads);
  BoundedDecodeReport report;
  report.vertices = p.info.vertices;
  report.faces = p.info.faces;
  const std::vector<size_t> ends = make_regions(p, limit, threads, report.largest_region, in);
  report.regions = static_cast<uint32_t>(ends.size());
  const size_t steps = 2 * ends.size();
  size_t done = 0;
  auto progress = [&](const char *stage) {
    ++done;
    if (options.progress)
      options.progress(double(done) / double(steps), stage);
  };

  SelectiveOptions so;
  so.memory_limit = kNoMemoryLimit; // (each region's map is within the budget: make_regions)
  so.threads = threads;
  so.attributes = AttributeMask::none();
  so.record_numbering = true;
  so.min_parallel_vertices = options.min_parallel_vertices;
  const uint32_t n = p.clusters;

  // Count: what each cluster adds in each level.
  LevelTable table(p);
  size_t first = 0;
  for (size_t end : ends) {
    SelectiveDecoder d(std::make_unique<FileSource>(in), so);
    d.set_wanted(region_map(p, &p.order[first], end - first, false));
    d.update();
    std::vector<char> member(n, 0);
    for (size_t i = first; i < end; ++i)
      member[p.order[i]] = 1;
    for (const Numbered &s : d.numbered_levels())
      if (member[s.cluster]) {
        table.vertices[table.at(s.cluster, s.level)] = s.vertices;
        table.faces[table.at(s.cluster, s.level)] = s.faces;
      }
    first = end;
    progress("count");
  }
  table.number(in);

  // Write: each region's vertices and faces at their full-decode numbers.
  RecordFile file(out, p.info.vertices, p.info.faces);
  RunWriter<12> vertex_writer(file, false);
  RunWriter<13> face_writer(file, true);
  uint64_t vertices_written = 0, faces_written = 0;
  first = 0;
  std::vector<char> member(n), final_cluster(n);
  for (size_t end : ends) {
    std::fill(member.begin(), member.end(), 0);
    std::fill(final_cluster.begin(), final_cluster.end(), 0);
    for (size_t i = first; i < end; ++i) {
      const uint32_t c = p.order[i];
      member[c] = final_cluster[c] = 1;
      for (uint32_t k = p.start[c]; k < p.start[c + 1]; ++k)
        final_cluster[p.adj[k]] = 1;
    }
    std::vector<Numbered> spans;
    Mesh m;
    {
      SelectiveDecoder d(std::make_unique<FileSource>(in), so);
      d.set_wanted(region_map(p, &p.order[first], end - first, true));
      d.update();
      spans = d.numbered_levels();
      m = d.take_mesh();
    }
    // Full-decode numbers of the final vertices (UINT32_MAX: a cluster not final here).
    std::vector<uint32_t> number(m.vertex_count(), UINT32_MAX);
    std::vector<std::pair<uint32_t, uint32_t>> items; // (number, vertex or face of m)
    for (uint32_t c = 0; c < n; ++c)
      if (final_cluster[c]) {
        number[c] = c; // the base clustered mesh: vertex c roots cluster c
        if (member[c])
          items.push_back({c, c});
      }
    std::sort(spans.begin(), spans.end(),
              [](const Numbered &a, const Numbered &b) { // (an empty level before its successor)
                return a.first_vertex < b.first_vertex ||
                       (a.first_vertex == b.first_vertex && a.vertices < b.vertices);
              });
    for (const Numbered &s : spans)
      if (final_cluster[s.cluster]) {
        const uint32_t at = table.vertices[table.at(s.cluster, s.level)];
        for (uint32_t r = 0; r < s.vertices; ++r) {
          number[s.first_vertex + r] = at + r;
          if (member[s.cluster])
            items.push_back({at + r, s.first_vertex + r});
        }
      }
    vertices_written += items.size();
    vertex_writer.write(
        items, [&](uint32_t v, char *rec) { std::memcpy(rec, &m.positions[3 * size_t(v)], 12); });
    // The cluster of a vertex of m (the span that created it: the last one starting at or
    // before it, which is not empty).
    auto cluster_of = [&](uint32_t v) -> uint32_t {
      if (v < n)
        return v;
      auto it = std::upper_bound(spans.begin(), spans.end(), v,
                                 [](uint32_t x, const Numbered &s) { return x < s.first_vertex; });
      return std::prev(it)->cluster;
    };
    items.clear();
    for (uint32_t f = 0; f < p.base_faces; ++f)
      if (member[cluster_of(m.triangles[3 * size_t(f)])])
        items.push_back({f, f});
    for (const Numbered &s : spans)
      if (member[s.cluster]) {
        const uint32_t at = table.faces[table.at(s.cluster, s.level)];
        for (uint32_t r = 0; r < s.faces; ++r)
          items.push_back({at + r, s.first_face + r});
      }
    faces_written += items.size();
    face_writer.write(items, [&](uint32_t f, char *rec) {
      rec[0] = 3;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = number[m.triangles[3 * size_t(f) + k]];
        if (v == UINT32_MAX)
          throw Error(Error::Kind::Internal,
                      "bounded decode: face " + std::to_string(f) +
                          " of a region has a corner in a cluster that is not at full resolution");
        std::memcpy(rec + 1 + 4 * k, &v, 4);
      }
    });
    first = end;
    progress("write");
  }
  if (vertices_written != p.info.vertices || faces_written != p.info.faces)
    throw Error(Error::Kind::Internal, "bounded decode: wrote " + std::to_string(vertices_written) +
                                           " vertices and " + std::to_string(faces_written) +
                                           " faces of " + std::to_string(p.info.vertices) +
                                           " and " + std::to_string(p.info.faces));
  file.commit();
  return report;
}

} // namespace pomar
