// Decoder: file -> base mesh -> global levels -> mesh.
#include <string>

#include "entropy/models.h"
#include "format/file_format.h"
#include "refine/level_traversal.h"

namespace pomar {
namespace {

/// The traversal policy of the decoder: every answer comes from the level's streams.
class DecoderCodec {
public:
  DecoderCodec(Models &models, int bits) : m_(models), top_((int64_t(1) << bits) - 1) {}

  void begin_level(size_t level, const uint8_t *conn, size_t conn_size, const uint8_t *geom,
                   size_t geom_size) {
    level_ = level;
    conn_.reset(conn, conn_size);
    geom_.reset(geom, geom_size);
  }
  void end_level() {
    if (conn_.overrun() || geom_.overrun())
      corrupt("the level's data ends too early");
  }

  int split_flag(uint32_t, int context) { return conn_.decode_bit(m_.conn.sv[context]); }

  void split_symbols(uint32_t, const Ring &ring, const uint32_t *, SplitSymbols &s) {
    s.s_e = get_small(conn_, m_.conn.se[valence_context(ring.size())]);
    const uint32_t faces = get_small(conn_, m_.conn.faces[faces_context(ring.size(), ring.closed)]);
    if (faces > ring.size())
      corrupt("split symbols do not fit the vertex's neighbourhood");
    s.s_l = get_small(conn_, m_.conn.sl[sl_context(faces)]);
    if (s.s_l > faces)
      corrupt("split symbols do not fit the vertex's neighbourhood");
    s.s_r = faces - s.s_l;
  }

  void geometry(uint32_t, const Prediction &p, int32_t position[3]) {
    int64_t r[3];
    r[0] = get_residual(geom_, m_.geom, 0, p.context) + p.offset[0];
    r[1] = get_residual(geom_, m_.geom, 0, p.context) + p.offset[1];
    r[2] = get_residual(geom_, m_.geom, 1, p.context) + p.offset[2];
    to_global(p.frame, r);
    for (int k = 0; k < 3; ++k) {
      const int64_t v = p.barycentre[k] + r[k];
      if (v < 0 || v > top_)
        corrupt("a decoded position lies outside the quantization grid");
      position[k] = static_cast<int32_t>(v);
    }
  }

  [[noreturn]] void corrupt(const char *what) {
    throw Error("damaged .pomar file: level " + std::to_string(level_ + 1) + ": " + what);
  }

private:
  Models &m_;
  int64_t top_;
  size_t level_ = 0;
  RangeDecoder conn_, geom_;
};

Mesh to_mesh(const LevelMesh &lm, const Quantizer &grid) {
  Mesh out;
  out.positions.resize(lm.q.size());
  for (size_t i = 0; i < lm.q.size(); ++i)
    out.positions[i] = grid.dequantize(static_cast<int>(i % 3), static_cast<uint32_t>(lm.q[i]));
  out.triangles = lm.ct.V;
  return out;
}

} // namespace

FileInfo inspect(const uint8_t *data, size_t size) {
  const FileLayout layout = read_layout(data, size);
  read_base_mesh(data, layout); // checks the base block too
  return file_info(layout, size);
}

Mesh decode(const uint8_t *data, size_t size, int level, const Progress &progress) {
  const FileLayout layout = read_layout(data, size);
  const FileHeader &h = layout.header;
  const size_t levels = h.levels.size();
  if (level < -1 || level > static_cast<int>(levels))
    throw Error("level " + std::to_string(level) + " does not exist: the file has levels 0.." +
                std::to_string(levels));
  const size_t target = level < 0 ? levels : static_cast<size_t>(level);
  const BaseMesh base = read_base_mesh(data, layout);
  LevelMesh lm;
  lm.q = base.q;
  lm.seed_faces = h.base_faces;
  try {
    build_corner_table(base.triangles.data(), h.base_faces, h.base_vertices, lm.ct);
  } catch (const Error &e) {
    throw Error(std::string("damaged .pomar file: invalid base mesh: ") + e.what());
  }
  lm.init_lineage();
  Models models;
  DecoderCodec codec(models, h.grid.bits);
  TraversalScratch scratch;
  std::vector<PendingSplit> splits;
  for (size_t i = 0; i < target; ++i) {
    check_level(data, layout, i);
    const LevelEntry &e = h.levels[i];
    const uint8_t *conn = data + layout.level_offset[i];
    codec.begin_level(i, conn, e.connectivity_bytes, conn + e.connectivity_bytes,
                      e.geometry_bytes);
    traverse_level(lm, codec, scratch, static_cast<uint32_t>(i + 1), splits);
    codec.end_level();
    if (lm.vertex_count() + splits.size() != e.vertices)
      codec.corrupt("the number of vertex splits differs from the level table");
    apply_splits(lm, splits, static_cast<uint32_t>(i + 1));
    if (lm.ct.face_count() != e.faces)
      codec.corrupt("the face count differs from the level table");
    if (progress)
      progress(double(i + 1) / double(target), "decode");
  }
  return to_mesh(lm, h.grid);
}

} // namespace pomar
