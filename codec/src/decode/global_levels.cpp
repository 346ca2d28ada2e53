// Decoding the global part of a file: base mesh, then global levels (paper section 5.1),
// each through the shared per-level step.
#include "decode/global_levels.h"

#include <string>

#include "decode/damage.h"
#include "decode/decoder_codec.h"
#include "format/geometry_prediction.h"
#include "geometry/quantize.h"
#include "refine/level_step.h"

namespace pomar {

Mesh to_mesh(const LevelMesh &lm, const Quantizer &grid) {
  Mesh out;
  out.positions = dequantize(grid, lm.q);
  out.triangles = lm.ct.V;
  return out;
}

namespace {
template <class T> void release(std::vector<T> &v) { std::vector<T>().swap(v); }
} // namespace

Mesh to_mesh(LevelMesh &&lm, const Quantizer &grid) {
  // What only refinement needs is freed before the positions are made, so that they do
  // not add to the peak: opposite corners, corners of vertices, lineage, face claims.
  release(lm.ct.O);
  release(lm.ct.VC);
  release(lm.lineage);
  release(lm.face_claim);
  Mesh out;
  out.positions = dequantize(grid, lm.q);
  release(lm.q);
  out.triangles = std::move(lm.ct.V);
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
    throw Error(Error::Kind::DamagedFile,
                std::string("damaged .pomar file: invalid base mesh: ") + e.what());
  }
  lm.init_lineage();
  return lm;
}

size_t decode_global_levels(const uint8_t *data, const FileLayout &layout, size_t from, size_t to,
                            LevelMesh &lm, Models &models, const Progress &progress,
                            std::vector<DamagedBlock> *damaged) {
  const FileHeader &h = layout.header;
  models.conn.patch_rank = h.ranks_patches(); // (the models' set of a file's version)
  const std::vector<NormalPredictor> normal = load_geometry_prediction(data, layout);
  DecoderCodec codec(h.grid.bits);
  LevelStep step;
  RangeDecoder conn, geom;
  for (size_t i = from; i < to; ++i) {
    const LevelEntry &e = h.levels[i];
    try {
      check_level(data, layout, i);
      const uint8_t *p = data + layout.level_offset[i];
      conn.reset(p, e.connectivity_bytes);
      geom.reset(p + e.connectivity_bytes, e.geometry_bytes);
      models.normal = normal[i];
      codec.set(&models, &conn, &geom, static_cast<uint32_t>(i + 1));
      step.global_level(lm, codec, static_cast<uint32_t>(i + 1), [&](const StepCounts &n) {
        if (conn.overrun() || geom.overrun())
          codec.corrupt("the level's data ends too early");
        if (n.vertices != e.vertices)
          codec.corrupt("the number of vertex splits differs from the level table");
        if (n.faces != e.faces)
          codec.corrupt("the face count differs from the level table");
      });
    } catch (const Error &err) {
      if (!damaged)
        throw;
      // The step checks before it applies: the mesh is still level i.
      damaged->push_back(damaged_level(i + 1, err.what()));
      return i;
    }
    if (progress)
      progress(double(i + 1) / double(to), "decode");
  }
  return to;
}

} // namespace pomar
