// The C ABI of the WebAssembly decoder (web/pomar_core.js wraps it): a SelectiveDecoder
// whose bytes arrive over the network. The JavaScript side (web/pomar_stream.js) fetches
// the global part, completes the wanted level map (pw_complete), fetches what the blocks
// of the raised clusters need with range requests, hands it over (pw_put_block) and
// decodes (pw_update). Every pomar::Error (and any
// other exception, e.g. out of memory) becomes a return code and a message
// (pw_last_error); nothing traps.
#include <emscripten/emscripten.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "attributes/attribute_section.h"
#include "decode/global_levels.h"
#include "format/file_format.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"

namespace {

std::string g_error;

/// WebAssembly has at most 4 GiB of memory: a file whose base clustered mesh needs more than
/// this is refused with a message before anything large is allocated.
constexpr uint64_t kMemoryLimit = uint64_t(1) << 31;

/// The bytes of the file the page has fetched: the global part, and a prefix of each cluster
/// block (the whole block, or as much as the levels wanted of it need; see pomar_stream.js).
/// A read of bytes not handed over throws and records where (pw_missing_cluster): the page
/// fetches them and decodes again.
class StagedSource : public pomar::ByteSource {
public:
  StagedSource(std::vector<uint8_t> prefix, uint64_t size)
      : prefix_(std::move(prefix)), size_(size) {}
  uint64_t size() const override { return size_; }
  void read(uint64_t offset, size_t n, uint8_t *out) override {
    if (offset > size_ || n > size_ - offset)
      throw pomar::Error("truncated .pomar file: it ends at byte " + std::to_string(size_) +
                         ", byte " + std::to_string(offset + n) + " is needed");
    if (offset + n <= prefix_.size()) {
      if (n)
        std::memcpy(out, prefix_.data() + offset, n);
      return;
    }
    auto it = staged_.upper_bound(offset);
    if (it != staged_.begin()) {
      --it;
      if (offset + n <= it->first + it->second.size()) {
        std::memcpy(out, it->second.data() + (offset - it->first), n);
        return;
      }
    }
    missing_ = offset;
    throw pomar::Error("bytes " + std::to_string(offset) + ".." + std::to_string(offset + n) +
                       " were not fetched");
  }
  /// The first `bytes` of the block at `offset` (replacing a shorter prefix).
  void stage(uint64_t offset, std::vector<uint8_t> bytes) { staged_[offset] = std::move(bytes); }
  uint64_t missing() const { return missing_; }
  void clear_missing() { missing_ = UINT64_MAX; }

private:
  std::vector<uint8_t> prefix_;
  uint64_t size_;
  std::map<uint64_t, std::vector<uint8_t>> staged_;
  uint64_t missing_ = UINT64_MAX;
};

struct Handle {
  StagedSource *source = nullptr; // owned by the decoder
  std::unique_ptr<pomar::SelectiveDecoder> decoder;
  pomar::ClusterIndex index;
  std::vector<uint32_t> adj_start, adj;   // the cluster graph (edges of the base clustered mesh)
  std::vector<uint32_t> link_start, link; // clusters decoded to one level (texture seams)
  // Results kept alive for JavaScript to copy out of the heap.
  pomar::Mesh mesh;
  std::vector<uint32_t> vertex_cluster, vertex_level;
  std::vector<float> errors;    // pw_cluster_errors
  bool textured = false;        // the file has per-corner texture coordinates
  bool keep_seams = false;      // pw_keep_seams: a full-resolution extract stays cut
  std::vector<float> texcoords; // per vertex of `mesh`: u, v (empty: none, or conflicts)
  size_t texcoord_conflicts = 0;
  std::vector<float> bounds;
  std::vector<int32_t> levels;
  std::vector<double> info;
  std::string text;
};

template <class F> int guarded(F &&f) {
  try {
    return f();
  } catch (const std::bad_alloc &) {
    g_error = "out of memory (WebAssembly has at most 2 GiB here)";
  } catch (const std::exception &e) {
    g_error = e.what();
  }
  return -1;
}

void cluster_graph(const pomar::Mesh &base, uint32_t n, std::vector<uint32_t> &start,
                   std::vector<uint32_t> &adj) {
  std::vector<std::vector<uint32_t>> nb(n);
  for (size_t f = 0; f < base.triangle_count(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = base.triangles[3 * f + k], b = base.triangles[3 * f + (k + 1) % 3];
      nb[a].push_back(b);
      nb[b].push_back(a);
    }
  start.assign(n + 1, 0);
  adj.clear();
  for (uint32_t c = 0; c < n; ++c) {
    std::sort(nb[c].begin(), nb[c].end());
    nb[c].erase(std::unique(nb[c].begin(), nb[c].end()), nb[c].end());
    adj.insert(adj.end(), nb[c].begin(), nb[c].end());
    start[c + 1] = static_cast<uint32_t>(adj.size());
  }
}

std::vector<int> to_levels(const Handle &h, const int32_t *wanted) {
  return std::vector<int>(wanted, wanted + h.decoder->cluster_count());
}

/// The extracted mesh's per-corner texture coordinates as one (u, v) per vertex, the value
/// of its corners, when all the corners of every vertex agree (the cut mesh: each vertex is
/// one wedge). Otherwise (a welded mesh: a vertex on a seam has corners in two charts) no
/// per-vertex value is right: none is given and the vertices in conflict are counted.
void per_vertex_texcoords(Handle &h) {
  const pomar::Mesh &m = h.mesh;
  h.texcoords.clear();
  h.texcoord_conflicts = 0;
  if (m.corner_texcoords.size() != 2 * m.triangles.size())
    return;
  std::vector<float> uv(2 * m.vertex_count(), 0.f);
  std::vector<uint8_t> seen(m.vertex_count(), 0);
  for (size_t c = 0; c < m.triangles.size(); ++c) {
    const uint32_t v = m.triangles[c];
    const float u = m.corner_texcoords[2 * c], w = m.corner_texcoords[2 * c + 1];
    if (!seen[v]) {
      seen[v] = 1;
      uv[2 * v] = u;
      uv[2 * v + 1] = w;
    } else if (seen[v] == 1 && (uv[2 * v] != u || uv[2 * v + 1] != w)) {
      seen[v] = 2;
      ++h.texcoord_conflicts;
    }
  }
  if (h.texcoord_conflicts == 0)
    h.texcoords = std::move(uv);
}

/// The mesh of pw_preview, kept for JavaScript to copy out of the heap.
pomar::Mesh g_preview;

/// The layout of a file of `file_size` bytes from its first `n` bytes, which must hold its
/// header (pw_global_bytes says how many).
pomar::FileLayout header_layout(const uint8_t *data, size_t n, double file_size) {
  const size_t hsize = pomar::header_size(data, n);
  if (n < hsize)
    throw pomar::Error("the header needs " + std::to_string(hsize) + " bytes");
  return pomar::read_layout(data, hsize, static_cast<uint64_t>(file_size), true);
}

} // namespace

extern "C" {

EMSCRIPTEN_KEEPALIVE const char *pw_last_error() { return g_error.c_str(); }

/// How many leading bytes of the file open needs: the header's size while `n` is too short
/// to tell more, then the whole global part (header, base mesh, global levels, model
/// tables, cluster index). -1 on a damaged header (pw_last_error).
EMSCRIPTEN_KEEPALIVE double pw_global_bytes(const uint8_t *data, size_t n, double file_size) {
  double out = -1;
  guarded([&] {
    const uint64_t size = static_cast<uint64_t>(file_size);
    if (n < pomar::kFixedHeaderBytes && n < size) {
      out = double(std::min<uint64_t>(size, pomar::kFixedHeaderBytes));
      return 0;
    }
    const size_t hsize = pomar::header_size(data, n);
    if (hsize > size)
      throw pomar::Error("truncated .pomar file: the header alone needs " + std::to_string(hsize) +
                         " bytes, the file has " + std::to_string(size));
    if (n < hsize) {
      out = double(hsize);
      return 0;
    }
    const pomar::FileLayout layout = pomar::read_layout(data, hsize, size, true);
    out = double(std::min<uint64_t>(layout.global_bytes, size));
    return 0;
  });
  return out;
}

/// Where the pieces of the global part lie, from the header alone (`n` >= the header size
/// pw_global_bytes asks for first): [header bytes, end of the base mesh, start and end of
/// the span of the sections the global levels need, ATTR and GEOP (0 0: none), global
/// levels G, then G values: the end of each global level's bytes, then the start of level 1, the
/// start of the model tables (clustered; else the end of the last level) and the global part's
/// size]. Null on a damaged header.
EMSCRIPTEN_KEEPALIVE const double *pw_layout(const uint8_t *data, size_t n, double file_size) {
  static std::vector<double> out;
  const int status = guarded([&] {
    const pomar::FileLayout layout = header_layout(data, n, file_size);
    const pomar::FileHeader &h = layout.header;
    const size_t global = h.clustered() ? h.global_levels : h.levels.size();
    out = {double(layout.header_bytes), double(layout.base_offset + h.base_bytes), 0, 0,
           double(global)};
    // The sections the global levels need (ATTR, GEOP): one span from the first's start to
    // the last's end.
    for (const uint32_t tag : {pomar::section_tag("ATTR"), pomar::section_tag("GEOP")}) {
      const int i = pomar::find_section(layout, tag);
      if (i < 0)
        continue;
      const double start = double(layout.section_offset[i]),
                   end = double(layout.section_offset[i] + h.sections[i].bytes);
      out[2] = out[3] == 0 ? start : std::min(out[2], start);
      out[3] = std::max(out[3], end);
    }
    for (size_t i = 0; i < global; ++i)
      out.push_back(double(layout.level_offset[i] + h.levels[i].connectivity_bytes +
                           h.levels[i].geometry_bytes));
    out.push_back(double(global ? layout.level_offset[0] : layout.global_bytes));
    out.push_back(double(h.clustered() ? layout.tables_offset : layout.global_bytes));
    out.push_back(
        double(std::min<uint64_t>(layout.global_bytes, static_cast<uint64_t>(file_size))));
    return 0;
  });
  return status < 0 ? nullptr : out.data();
}

/// The mesh a first frame can show before the global part is complete: the base mesh and
/// global levels 1..`levels` (a progressive file's levels). `data` holds the file's first
/// `n` bytes, of which only the header, the base mesh, the ATTR and GEOP sections (when the
/// file has them and `levels` > 0) and those levels need to be there (pw_layout says where; other
/// bytes may be zeros). Positions and triangles only (pw_preview_*). Returns the levels
/// decoded, -1 on error (pw_last_error).
EMSCRIPTEN_KEEPALIVE int pw_preview(const uint8_t *data, size_t n, double file_size, int levels) {
  int decoded = -1;
  guarded([&] {
    const pomar::FileLayout layout = header_layout(data, n, file_size);
    const pomar::FileHeader &h = layout.header;
    const size_t global = h.clustered() ? h.global_levels : h.levels.size();
    const size_t upto = std::min<size_t>(global, size_t(std::max(0, levels)));
    if (layout.base_offset + h.base_bytes > n ||
        (upto && layout.level_offset[upto - 1] + h.levels[upto - 1].connectivity_bytes +
                         h.levels[upto - 1].geometry_bytes >
                     n))
      throw pomar::Error("the first frame needs the base mesh and its levels");
    pomar::LevelMesh lm = pomar::base_level_mesh(data, layout);
    pomar::Models models;
    if (upto) {
      if (const auto attributes = pomar::load_attribute_table(data, layout)) {
        pomar::init_attributes(*attributes, lm, pomar::AttributeMask::none()); // read past
        models.attr = pomar::attribute_models(*attributes);
      }
    }
    // (No level: the sections the levels need may not be in yet.)
    decoded = upto ? int(pomar::decode_global_levels(data, layout, 0, upto, lm, models, {})) : 0;
    g_preview = pomar::to_mesh(std::move(lm), h.grid);
    return 0;
  });
  return decoded;
}
EMSCRIPTEN_KEEPALIVE int pw_preview_vertex_count() { return int(g_preview.vertex_count()); }
EMSCRIPTEN_KEEPALIVE int pw_preview_triangle_count() { return int(g_preview.triangle_count()); }
EMSCRIPTEN_KEEPALIVE const float *pw_preview_positions() { return g_preview.positions.data(); }
EMSCRIPTEN_KEEPALIVE const uint32_t *pw_preview_triangles() { return g_preview.triangles.data(); }
EMSCRIPTEN_KEEPALIVE void pw_preview_release() { g_preview = pomar::Mesh(); }

/// Decode the base clustered mesh from the file's first `n` bytes (at least
/// pw_global_bytes) of `file_size`. `tolerant`: damaged or missing cluster blocks are
/// skipped (SelectiveOptions::skip_damaged; every block is then read whole, to verify its
/// check before decoding it); otherwise blocks are read only as far as the wanted levels
/// need and any damage fails pw_update. Returns a handle, 0 on error (pw_last_error).
EMSCRIPTEN_KEEPALIVE Handle *pw_open(const uint8_t *data, size_t n, double file_size,
                                     int tolerant) {
  Handle *out = nullptr;
  guarded([&] {
    auto h = std::make_unique<Handle>();
    const uint64_t size = static_cast<uint64_t>(file_size);
    auto source = std::make_unique<StagedSource>(std::vector<uint8_t>(data, data + n), size);
    h->source = source.get();
    pomar::SelectiveOptions options;
    options.skip_damaged = tolerant != 0; // damaged blocks are skipped and listed (pw_damaged)
    options.memory_limit = kMemoryLimit;
    h->decoder = std::make_unique<pomar::SelectiveDecoder>(std::move(source), options);
    const uint32_t clusters = h->decoder->cluster_count();
    if (clusters) {
      const size_t hsize = pomar::header_size(data, n);
      const pomar::FileLayout layout = pomar::read_layout(data, hsize, size, true);
      h->index = pomar::read_cluster_index(data + layout.index_offset, layout);
      for (uint32_t c = 0; c < clusters; ++c) // (the decoder's: a BLKO file's block order)
        h->index.offset[c] = h->decoder->block_offset(c);
      h->decoder->cluster_links(h->link_start, h->link);
    }
    const pomar::Mesh base = h->decoder->mesh();
    h->textured = !base.corner_texcoords.empty();
    if (clusters)
      cluster_graph(base, clusters, h->adj_start, h->adj);
    out = h.release();
    return 0;
  });
  return out;
}

EMSCRIPTEN_KEEPALIVE void pw_close(Handle *h) { delete h; }

/// Facts as doubles: [clusters, base clustered level, finest level, vertices, faces,
/// file bytes, global bytes, bbox min xyz, bbox max xyz, version, bytes read by the decoder,
/// blocks read, base mesh vertices, faces, then per level 1..finest: vertices, faces].
EMSCRIPTEN_KEEPALIVE const double *pw_info(Handle *h) {
  const pomar::FileInfo &i = h->decoder->info();
  h->info = {double(h->decoder->cluster_count()),
             double(h->decoder->base_clustered_level()),
             double(h->decoder->finest_level()),
             double(i.vertices),
             double(i.faces),
             double(i.total_bytes),
             double(i.global_bytes),
             i.bbox_min[0],
             i.bbox_min[1],
             i.bbox_min[2],
             i.bbox_max[0],
             i.bbox_max[1],
             i.bbox_max[2],
             double(i.version),
             double(h->decoder->bytes_read()),
             double(h->decoder->blocks_read()),
             double(i.base_vertices),
             double(i.base_faces)};
  for (const pomar::LevelInfo &l : i.levels) {
    h->info.push_back(l.vertices);
    h->info.push_back(l.faces);
  }
  return h->info.data();
}
EMSCRIPTEN_KEEPALIVE int pw_info_size(Handle *h) { return int(pw_info(h) ? h->info.size() : 0); }

/// Where cluster c's block is in the file (offset; its size: pw_block_size).
EMSCRIPTEN_KEEPALIVE double pw_block_offset(Handle *h, uint32_t c) {
  return c < h->index.offset.size() ? double(h->index.offset[c]) : -1;
}
EMSCRIPTEN_KEEPALIVE double pw_block_size(Handle *h, uint32_t c) {
  return c < h->index.size.size() ? double(h->index.size[c]) : -1;
}

/// The completed level map for `wanted` (pw_levels_out), without decoding.
EMSCRIPTEN_KEEPALIVE int pw_complete(Handle *h, const int32_t *wanted) {
  return guarded([&] {
    const std::vector<int> target =
        pomar::complete_level_map(to_levels(*h, wanted), h->adj_start, h->adj,
                                  h->decoder->base_clustered_level(), h->link_start, h->link);
    h->levels.assign(target.begin(), target.end());
    return 0;
  });
}

/// Hand over the first `n` bytes of cluster c's block (all of it, or the prefix its wanted
/// levels need; replaces a shorter prefix handed over before).
EMSCRIPTEN_KEEPALIVE int pw_put_block(Handle *h, uint32_t c, const uint8_t *data, size_t n) {
  return guarded([&] {
    if (c >= h->index.offset.size())
      throw pomar::Error("cluster " + std::to_string(c) + " does not exist");
    h->source->stage(h->index.offset[c], std::vector<uint8_t>(data, data + n));
    return 0;
  });
}

/// After pw_update failed: the cluster whose block lacked bytes (-1: the failure was not a
/// missing byte). The mesh is intact but that cluster's stream is not: coarsen everything
/// to the base clustered level (pw_update) before decoding again.
EMSCRIPTEN_KEEPALIVE int pw_missing_cluster(Handle *h) {
  const uint64_t at = h->source->missing();
  if (at == UINT64_MAX)
    return -1;
  for (uint32_t c = 0; c < h->index.offset.size(); ++c)
    if (at >= h->index.offset[c] && at < h->index.offset[c] + h->index.size[c])
      return int(c);
  return -1;
}

/// Bring the mesh to the level map completed from `wanted` (clustered files) or to level
/// wanted[0] everywhere (progressive files). Tolerant decoders skip damaged or missing
/// blocks (pw_damaged). Returns 0, or -1 on error (pw_last_error, pw_missing_cluster).
EMSCRIPTEN_KEEPALIVE int pw_update(Handle *h, const int32_t *wanted) {
  h->source->clear_missing();
  return guarded([&] {
    if (h->decoder->cluster_count() == 0) {
      h->decoder->clear_wanted();
      h->decoder->want_all(wanted[0]);
    } else {
      h->decoder->set_wanted(to_levels(*h, wanted));
    }
    h->decoder->update();
    h->levels.assign(h->decoder->levels().begin(), h->decoder->levels().end());
    return 0;
  });
}

/// Read the stored error bounds (section CERR, read here for the first time): 1 when the
/// file stores them (then pw_cluster_errors_data), 0 when it stores none, -1 when the
/// section is damaged (pw_last_error names it).
EMSCRIPTEN_KEEPALIVE int pw_cluster_errors(Handle *h) {
  return guarded([&] {
    const uint32_t n = h->decoder->cluster_count();
    if (!n || !h->decoder->has_cluster_errors())
      return 0;
    const int base = h->decoder->base_clustered_level(), finest = h->decoder->finest_level();
    h->errors.resize(size_t(finest - base) * n);
    for (int l = base; l < finest; ++l)
      for (uint32_t c = 0; c < n; ++c)
        h->errors[size_t(l - base) * n + c] = float(h->decoder->cluster_error(c, l));
    return 1;
  });
}
/// After pw_cluster_errors returned 1: the bound of every cluster at every level from the
/// base clustered level to the one below the finest (level-major: [(l - base) * clusters
/// + c]).
EMSCRIPTEN_KEEPALIVE const float *pw_cluster_errors_data(Handle *h) { return h->errors.data(); }

/// SelectiveDecoder::view_levels for the camera `cam` (eye xyz, view-projection 16
/// column-major, vertical fov in radians, width, height, near: 23 floats) into pw_levels,
/// without decoding. Returns 0, or -1 on error.
EMSCRIPTEN_KEEPALIVE int pw_view_levels(Handle *h, const float *cam, float pixel_error) {
  return guarded([&] {
    pomar::ViewCamera camera;
    std::copy(cam, cam + 3, camera.eye);
    std::copy(cam + 3, cam + 19, camera.view_proj);
    camera.fov_y = cam[19];
    camera.width = cam[20];
    camera.height = cam[21];
    camera.near_distance = cam[22];
    const std::vector<int> levels = h->decoder->view_levels(camera, pixel_error);
    h->levels.assign(levels.begin(), levels.end());
    return 0;
  });
}

/// The level of every cluster after pw_update (or the map of pw_complete).
EMSCRIPTEN_KEEPALIVE const int32_t *pw_levels(Handle *h) { return h->levels.data(); }

/// Damaged blocks skipped so far, one line each ("" when none).
EMSCRIPTEN_KEEPALIVE const char *pw_damaged(Handle *h) {
  h->text = h->decoder->damaged().empty() ? "" : pomar::describe_damage(h->decoder->damaged());
  return h->text.c_str();
}
EMSCRIPTEN_KEEPALIVE int pw_damaged_count(Handle *h) { return int(h->decoder->damaged().size()); }

/// Extract the current mesh; then pw_positions (3 floats per vertex), pw_triangles (3
/// indices per face), pw_vertex_cluster, pw_vertex_level, pw_attribute_values,
/// pw_texcoords and pw_face_materials point at it until the next call.
EMSCRIPTEN_KEEPALIVE int pw_extract(Handle *h) {
  return guarded([&] {
    // Every cluster at the finest level: exactly the encoded input (a lossless record
    // undone, as `pomar decode` gives it; a textured file with pw_keep_seams: the coded,
    // cut mesh still); otherwise the coded mesh. Cluster and level follow each vertex from
    // the coded mesh (a vertex no coded face uses takes those of vertex 0: it draws
    // nothing).
    std::vector<uint32_t> from;
    if (h->textured && h->keep_seams) {
      h->mesh = h->decoder->mesh();
      from.resize(h->mesh.vertex_count());
      for (size_t v = 0; v < from.size(); ++v)
        from[v] = uint32_t(v);
    } else {
      h->mesh = h->decoder->exact_mesh(&from);
    }
    const std::vector<uint32_t> cluster = h->decoder->vertex_cluster();
    const std::vector<uint32_t> level = h->decoder->vertex_level();
    h->vertex_cluster.resize(from.size());
    h->vertex_level.resize(from.size());
    for (size_t v = 0; v < from.size(); ++v) {
      const uint32_t f = from[v] < cluster.size() ? from[v] : 0;
      h->vertex_cluster[v] = cluster.empty() ? 0 : cluster[f];
      h->vertex_level[v] = level.empty() ? 0 : level[f];
    }
    per_vertex_texcoords(*h);
    return 0;
  });
}
EMSCRIPTEN_KEEPALIVE int pw_vertex_count(Handle *h) { return int(h->mesh.vertex_count()); }
EMSCRIPTEN_KEEPALIVE int pw_triangle_count(Handle *h) { return int(h->mesh.triangle_count()); }
EMSCRIPTEN_KEEPALIVE const float *pw_positions(Handle *h) { return h->mesh.positions.data(); }
EMSCRIPTEN_KEEPALIVE const uint32_t *pw_triangles(Handle *h) { return h->mesh.triangles.data(); }
EMSCRIPTEN_KEEPALIVE const uint32_t *pw_vertex_cluster(Handle *h) {
  return h->vertex_cluster.data();
}
EMSCRIPTEN_KEEPALIVE const uint32_t *pw_vertex_level(Handle *h) { return h->vertex_level.data(); }

/// The extracted mesh's first attribute of `kind` (pomar::AttributeKind: 1 colour, 2
/// normal, 3 scalar, 4 texcoord): its components per vertex (colour 3 = RGB or 4 = RGBA;
/// 0: the mesh has no such attribute) and its values, pw_vertex_count() x components of
/// them (colour: bytes, 0..255 a channel; the other kinds: floats), valid until the next
/// pw_extract. The web viewer draws the colour (web/viewer.js).
EMSCRIPTEN_KEEPALIVE int pw_attribute_components(Handle *h, int kind) {
  const pomar::VertexAttribute *a = h->mesh.find(static_cast<pomar::AttributeKind>(kind));
  return a && a->vertex_count() == h->mesh.vertex_count() ? int(a->components) : 0;
}
EMSCRIPTEN_KEEPALIVE const void *pw_attribute_values(Handle *h, int kind) {
  const pomar::VertexAttribute *a = h->mesh.find(static_cast<pomar::AttributeKind>(kind));
  if (!a)
    return nullptr;
  return a->kind == pomar::AttributeKind::Colour ? static_cast<const void *>(a->colour.data())
                                                 : static_cast<const void *>(a->values.data());
}

/// Texture coordinates and materials. pw_keep_seams(h, 1): once every cluster is at the
/// finest level, pw_extract of a textured file still gives the coded mesh, cut at its
/// texture seams (both sides of a seam separate vertices), instead of the welded input, so
/// that every vertex keeps one texture coordinate (the viewer draws it so).
EMSCRIPTEN_KEEPALIVE void pw_keep_seams(Handle *h, int keep) { h->keep_seams = keep != 0; }
/// The extracted mesh's texture coordinates per vertex (2 floats, u and v, v = 0 at the
/// bottom of the image as in OBJ), or null: no texture coordinates, or some vertex's corners
/// disagree (pw_texcoord_conflicts counts those vertices; a welded full-resolution mesh).
EMSCRIPTEN_KEEPALIVE const float *pw_texcoords(Handle *h) {
  return h->texcoords.empty() ? nullptr : h->texcoords.data();
}
EMSCRIPTEN_KEEPALIVE int pw_texcoord_conflicts(Handle *h) { return int(h->texcoord_conflicts); }
/// The extracted mesh's texture coordinates per corner (6 floats per triangle: u, v of its
/// corners in order), as `pomar decode` writes them (PLY face `texcoord`), or null when the
/// mesh has none; valid until the next pw_extract.
EMSCRIPTEN_KEEPALIVE const float *pw_corner_texcoords(Handle *h) {
  return h->mesh.corner_texcoords.size() == 2 * h->mesh.triangles.size() &&
                 !h->mesh.corner_texcoords.empty()
             ? h->mesh.corner_texcoords.data()
             : nullptr;
}
/// The extracted mesh's material per triangle (index into the materials), or null.
EMSCRIPTEN_KEEPALIVE const uint32_t *pw_face_materials(Handle *h) {
  return h->mesh.face_materials.size() == h->mesh.triangle_count() &&
                 !h->mesh.face_materials.empty()
             ? h->mesh.face_materials.data()
             : nullptr;
}
/// The materials (name; texture: an index into the texture files, -1 for none) and the
/// texture file names, as the file stores them (e.g. relative paths from an OBJ's MTL).
EMSCRIPTEN_KEEPALIVE int pw_material_count(Handle *h) { return int(h->mesh.materials.size()); }
EMSCRIPTEN_KEEPALIVE const char *pw_material_name(Handle *h, int i) {
  return i >= 0 && size_t(i) < h->mesh.materials.size() ? h->mesh.materials[i].name.c_str() : "";
}
/// Its other MTL lines as the file keeps them (`Kd 0.8 0.2 0.2`, `Ns 10`, ...).
EMSCRIPTEN_KEEPALIVE const char *pw_material_properties(Handle *h, int i) {
  return i >= 0 && size_t(i) < h->mesh.materials.size() ? h->mesh.materials[i].properties.c_str()
                                                        : "";
}
EMSCRIPTEN_KEEPALIVE int pw_material_texture(Handle *h, int i) {
  return i >= 0 && size_t(i) < h->mesh.materials.size() ? h->mesh.materials[i].texture : -1;
}
EMSCRIPTEN_KEEPALIVE int pw_texture_count(Handle *h) { return int(h->mesh.texture_files.size()); }
EMSCRIPTEN_KEEPALIVE const char *pw_texture_file(Handle *h, int i) {
  return i >= 0 && size_t(i) < h->mesh.texture_files.size() ? h->mesh.texture_files[i].c_str() : "";
}

/// Per cluster of the extracted mesh, kBoundsStride floats (web/view_refine.js reads them):
///  0-5  bounding box min xyz, max xyz;
///  6    the longest edge between two of its vertices (or, if it has none, touching it: the
///       screen-space error proxy, see web/view_refine.js);
///  7    its face count (faces are counted in the cluster of their first vertex);
///  8-11 its normal cone: the unit axis (the area-weighted mean normal of the faces touching
///       the cluster) and the cosine of the widest angle between it and one of those faces'
///       normals (-1, a cone of every direction, when the axis is undefined);
///  12   the detail of its newest vertices: over the cluster's vertices created at the
///       highest level any of them has, the largest distance from a vertex to the plane of
///       its neighbours (through their centroid, normal to the area-weighted normal of the
///       faces around the vertex; see the function);
///  13   how many vertices that is (0: none measured, e.g. no vertex with a defined plane).
///       At the base clustered level a cluster is one vertex (from a global level): its
///       detail is that vertex's offset from its neighbours in the base clustered mesh.
constexpr size_t kBoundsStride = 14;

/// A face's corner positions, read once as doubles, and its normal times twice its area.
struct FaceGeometry {
  double q[3][3];
  double normal[3];
};
inline FaceGeometry face_geometry(const float *p, const uint32_t *v) {
  FaceGeometry g;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      g.q[k][j] = p[3 * v[k] + j];
  double e[2][3];
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      e[k][j] = g.q[k + 1][j] - g.q[0][j];
  g.normal[0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
  g.normal[1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
  g.normal[2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
  return g;
}

EMSCRIPTEN_KEEPALIVE const float *pw_cluster_bounds(Handle *h) {
  const pomar::Mesh &mesh = h->mesh;
  const uint32_t n = std::max<uint32_t>(1, h->decoder->cluster_count());
  const size_t nv = mesh.vertex_count(), nf = mesh.triangle_count();
  h->bounds.assign(size_t(n) * kBoundsStride, 0.f);
  float *const bounds = h->bounds.data();
  auto at = [bounds](uint32_t c) { return bounds + kBoundsStride * size_t(c); };
  const float *const p = mesh.positions.data();
  const uint32_t *const t = mesh.triangles.data();
  // Each vertex's cluster (pw_extract sets one per vertex; none before the first extract).
  std::vector<uint32_t> no_clusters;
  if (h->vertex_cluster.size() != nv)
    no_clusters.assign(nv, 0);
  const uint32_t *const cluster =
      h->vertex_cluster.size() == nv ? h->vertex_cluster.data() : no_clusters.data();

  for (uint32_t c = 0; c < n; ++c)
    for (int k = 0; k < 3; ++k) {
      at(c)[k] = 3.4e38f;
      at(c)[3 + k] = -3.4e38f;
    }
  for (size_t v = 0; v < nv; ++v) {
    float *b = at(cluster[v]);
    for (int k = 0; k < 3; ++k) {
      b[k] = std::min(b[k], p[3 * v + k]);
      b[3 + k] = std::max(b[3 + k], p[3 * v + k]);
    }
  }

  // One pass over the faces gathers what the entries need of each face:
  //  - the squared length of its edges: inside a cluster they measure it; a cluster with
  //    none (a single vertex, as at the base clustered level) takes the edges around it.
  //    Edges across a border do not count where a cluster has inner edges: they belong to
  //    the coarser neighbour as much as to it. (The root is taken once, of the longest.)
  //  - its normal times twice its area, summed per distinct cluster of its corners (the
  //    cone's axis; a second pass, once the axes are known, measures the cone's width;
  //  - per vertex, for its detail (entry 12): the sum of its neighbours' positions and of
  //    the normals of the faces around it. Each corner sees the other two: an inner
  //    neighbour is counted twice (once per face of the edge), a border one once, so the
  //    centroid leans a little inwards.
  const bool with_detail = !h->vertex_level.empty();
  std::vector<double> inner2(n, 0.0), around2(n, 0.0);
  std::vector<double> centroid, vertex_normal;
  std::vector<uint32_t> count;
  if (with_detail) {
    centroid.assign(3 * nv, 0.0);
    vertex_normal.assign(3 * nv, 0.0);
    count.assign(nv, 0);
  }
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t *v = &t[3 * f];
    const uint32_t c[3] = {cluster[v[0]], cluster[v[1]], cluster[v[2]]};
    const FaceGeometry g = face_geometry(p, v);
    const auto &q = g.q;
    const double *normal = g.normal;
    at(c[0])[7] += 1;
    for (int k = 0; k < 3; ++k) {
      const int l = k == 2 ? 0 : k + 1;
      double d2 = 0;
      for (int j = 0; j < 3; ++j)
        d2 += (q[k][j] - q[l][j]) * (q[k][j] - q[l][j]);
      if (c[k] == c[l]) {
        inner2[c[k]] = std::max(inner2[c[k]], d2);
      } else {
        around2[c[k]] = std::max(around2[c[k]], d2);
        around2[c[l]] = std::max(around2[c[l]], d2);
      }
    }
    const bool second = c[1] != c[0], third = c[2] != c[0] && c[2] != c[1];
    for (int j = 0; j < 3; ++j) {
      at(c[0])[8 + j] += float(normal[j]);
      if (second)
        at(c[1])[8 + j] += float(normal[j]);
      if (third)
        at(c[2])[8 + j] += float(normal[j]);
    }
    if (with_detail)
      for (int k = 0; k < 3; ++k) {
        const int l = k == 2 ? 0 : k + 1, m = l == 2 ? 0 : l + 1;
        double *sum = &centroid[3 * v[k]], *around = &vertex_normal[3 * v[k]];
        for (int j = 0; j < 3; ++j) {
          sum[j] += q[l][j] + q[m][j];
          around[j] += normal[j];
        }
        count[v[k]] += 2;
      }
  }
  for (uint32_t c = 0; c < n; ++c) {
    float *b = at(c);
    b[6] = float(std::sqrt(inner2[c]));
    if (b[6] == 0)
      b[6] = float(std::sqrt(around2[c]));
    const double length =
        std::sqrt(double(b[8]) * b[8] + double(b[9]) * b[9] + double(b[10]) * b[10]);
    for (int k = 0; k < 3; ++k)
      b[8 + k] = length > 0 ? float(b[8 + k] / length) : 0.f;
    b[11] = length > 0 ? 1.f : -1.f;
  }

  // The detail of each cluster's newest vertices (entries 12, 13). A vertex's detail is how
  // far it stands off the surface its neighbours span: the distance from its position to
  // the plane through the centroid of its neighbours whose normal is the area-weighted
  // normal of the faces around it (none where that normal is zero). A vertex created by a
  // vertex split at level l lands next to v_to, inside the fan that v_to had at level l-1;
  // its neighbours are (mostly) vertices of that fan, so this is the offset the split added
  // to the coarser surface there: on a smooth patch about e^2/2R (edge e, radius of
  // curvature R), plus the scan's noise. Unlike the distance to v_to, it does not grow with
  // the edge length on a flat patch; unlike the distance to the coarser faces themselves,
  // it needs only the current mesh.
  if (with_detail) {
    std::vector<float> detail(nv, -1.f);
    std::vector<uint32_t> newest(n, 0);
    for (size_t v = 0; v < nv; ++v) {
      const double *nrm = &vertex_normal[3 * v];
      const double length = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
      if (!(length > 0) || count[v] == 0)
        continue;
      double d = 0;
      for (int j = 0; j < 3; ++j)
        d += (double(p[3 * v + j]) - centroid[3 * v + j] / count[v]) * nrm[j];
      detail[v] = float(std::abs(d) / length);
      if (detail[v] >= 0)
        newest[cluster[v]] = std::max(newest[cluster[v]], h->vertex_level[v]);
    }
    for (size_t v = 0; v < nv; ++v) {
      float *b = at(cluster[v]);
      if (detail[v] >= 0 && h->vertex_level[v] == newest[cluster[v]]) {
        b[12] = std::max(b[12], detail[v]);
        b[13] += 1;
      }
    }
  }

  // The cone's width: the face normal furthest from the axis (zero-area faces have none).
  for (size_t f = 0; f < nf; ++f) {
    const FaceGeometry g = face_geometry(p, &t[3 * f]);
    const double *normal = g.normal;
    const double length =
        std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    if (!(length > 0))
      continue;
    const uint32_t c[3] = {cluster[t[3 * f]], cluster[t[3 * f + 1]], cluster[t[3 * f + 2]]};
    const bool distinct[3] = {true, c[1] != c[0], c[2] != c[0] && c[2] != c[1]};
    for (int i = 0; i < 3; ++i)
      if (distinct[i]) {
        float *b = at(c[i]);
        const double cosine = (normal[0] * b[8] + normal[1] * b[9] + normal[2] * b[10]) / length;
        b[11] = std::min(b[11], float(cosine));
      }
  }
  return h->bounds.data();
}

} // extern "C"
