// Decoder: file -> base mesh -> global levels -> mesh.
#include <memory>
#include <string>

#include "decode/decoder_codec.h"
#include "entropy/models.h"
#include "format/file_format.h"
#include "pomar/limits.h"
#include "pomar/random_access.h"
#include "refine/level_traversal.h"

namespace pomar {

Mesh to_mesh(const LevelMesh &lm, const Quantizer &grid) {
  Mesh out;
  out.positions.resize(lm.q.size());
  for (size_t i = 0; i < lm.q.size(); ++i)
    out.positions[i] = grid.dequantize(static_cast<int>(i % 3), static_cast<uint32_t>(lm.q[i]));
  out.triangles = lm.ct.V;
  return out;
}

LevelMesh base_level_mesh(const uint8_t *data, const FileLayout &layout) {
  const FileHeader &h = layout.header;
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
  return lm;
}

void decode_global_levels(const uint8_t *data, const FileLayout &layout, size_t from, size_t to,
                          LevelMesh &lm, Models &models, const Progress &progress) {
  const FileHeader &h = layout.header;
  DecoderCodec codec(h.grid.bits);
  TraversalScratch scratch;
  std::vector<PendingSplit> splits;
  RangeDecoder conn, geom;
  for (size_t i = from; i < to; ++i) {
    check_level(data, layout, i);
    const LevelEntry &e = h.levels[i];
    const uint8_t *p = data + layout.level_offset[i];
    conn.reset(p, e.connectivity_bytes);
    geom.reset(p + e.connectivity_bytes, e.geometry_bytes);
    codec.set(&models, &conn, &geom, static_cast<uint32_t>(i + 1));
    traverse_level(lm, codec, scratch, static_cast<uint32_t>(i + 1), splits);
    if (conn.overrun() || geom.overrun())
      codec.corrupt("the level's data ends too early");
    if (lm.vertex_count() + splits.size() != e.vertices)
      codec.corrupt("the number of vertex splits differs from the level table");
    apply_splits(lm, splits, static_cast<uint32_t>(i + 1));
    if (lm.ct.face_count() != e.faces)
      codec.corrupt("the face count differs from the level table");
    if (progress)
      progress(double(i + 1) / double(to), "decode");
  }
}

FileInfo inspect(const uint8_t *data, size_t size) {
  const FileLayout layout = read_layout(data, size);
  read_base_mesh(data, layout); // checks the base block too
  FileInfo info = file_info(layout, size);
  if (layout.header.clustered()) {
    check_block(data + layout.tables_offset, layout.header.tables_bytes,
                layout.header.tables_checksum, "static model tables");
    const ClusterIndex index = read_cluster_index(data + layout.index_offset, layout);
    info.cluster_block_bytes = index.size;
  }
  return info;
}

Mesh decode(const uint8_t *data, size_t size, int level, const Progress &progress,
            uint64_t memory_limit) {
  const FileLayout layout = read_layout(data, size);
  const FileHeader &h = layout.header;
  const size_t levels = h.levels.size();
  if (level < -1 || level > static_cast<int>(levels))
    throw Error("level " + std::to_string(level) + " does not exist: the file has levels 0.." +
                std::to_string(levels));
  check_decode_memory(file_info(layout, size), level, memory_limit);
  const size_t target = level < 0 ? levels : static_cast<size_t>(level);
  const size_t global = h.clustered() ? h.global_levels : levels;
  if (target > global) { // clustered levels: every cluster at `target`
    // Checked above for the whole target level; the constructor's check is smaller.
    SelectiveDecoder d(std::make_unique<MemorySource>(data, size), kNoMemoryLimit);
    d.want_all(static_cast<int>(target));
    d.update(progress);
    return d.mesh();
  }
  LevelMesh lm = base_level_mesh(data, layout);
  Models models;
  decode_global_levels(data, layout, 0, target, lm, models, progress);
  return to_mesh(lm, h.grid);
}

} // namespace pomar
