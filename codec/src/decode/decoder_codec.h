// The traversal policy of the decoder: every answer comes from range-coded streams.
// Global levels read two streams (connectivity, geometry) with the file's adaptive models;
// a cluster block is one stream read with its level's static models.
#pragma once

#include <string>

#include "entropy/models.h"
#include "format/file_format.h"
#include "refine/level_traversal.h"

namespace pomar {

class DecoderCodec {
public:
  explicit DecoderCodec(int bits) : top_((int64_t(1) << bits) - 1) {}

  /// Streams and models of what is decoded next: global level `level` (cluster kNone) or
  /// cluster `cluster`'s data of level `level` (named in error messages).
  void set(Models *models, RangeDecoder *conn, RangeDecoder *geom, uint32_t level,
           uint32_t cluster = kNone) {
    m_ = models;
    conn_ = conn;
    geom_ = geom;
    level_ = level;
    cluster_ = cluster;
  }

  /// split_symbols does not read the ranked edges (code_vertex looks up the one s_e names).
  static constexpr bool kSelectsSplitEdge = true;

  int split_flag(uint32_t, int context) { return conn_->decode_bit(m_->conn.sv[context]); }

  void split_symbols(uint32_t, const Ring &ring, const uint32_t *, SplitSymbols &s) {
    s.s_e = get_small(*conn_, m_->conn.se[valence_context(ring.size())]);
    const uint32_t faces =
        get_small(*conn_, m_->conn.faces[faces_context(ring.size(), ring.closed)]);
    if (faces > ring.size())
      corrupt("split symbols do not fit the vertex's neighbourhood");
    s.s_l = get_small(*conn_, m_->conn.sl[sl_context(faces)]);
    if (s.s_l > faces)
      corrupt("split symbols do not fit the vertex's neighbourhood");
    s.s_r = faces - s.s_l;
  }

  /// Version 5 (the models say): the patch as s_l + s_r and a placement rank.
  bool ranks_patches() const { return m_->conn.patch_rank; }
  uint32_t patch_faces(uint32_t, const Ring &ring) {
    return get_small(*conn_, m_->conn.faces[faces_context(ring.size(), ring.closed)]);
  }
  uint32_t patch_placement(const Ring &ring, uint32_t faces, const PatchPlacements &p) {
    const uint32_t r =
        get_small(*conn_, m_->conn.rank[rank_context(faces, ring.size(), ring.closed)]);
    if (r >= p.count)
      corrupt("split symbols do not fit the vertex's neighbourhood");
    return placement_of_rank(p, r);
  }

  const NormalPredictor &normal_predictor() const { return m_->normal; }
  void geometry(uint32_t, const Prediction &p, int32_t position[3]) {
    int64_t r[3];
    for (int k = 0; k < 3; ++k) // t1 and t2 share a model, n has its own
      r[k] = get_residual(*geom_, m_->geom, k == 2, p.context) + p.offset[k];
    to_global(p.frame, r);
    for (int k = 0; k < 3; ++k) {
      const int64_t v = p.barycentre[k] + r[k];
      if (v < 0 || v > top_)
        corrupt("a decoded position lies outside the quantization grid");
      position[k] = static_cast<int32_t>(v);
    }
  }

  /// A split vertex's attribute codes: v_to's codes plus the decoded residuals.
  void attributes(const LevelMesh &mesh, const int64_t *pred, int64_t *codes) {
    const uint32_t n = mesh.attr_codes;
    int64_t r[kMaxAttributeCodes];
    residuals(n, r);
    for (uint32_t k = 0; k < n; ++k) {
      codes[k] = pred[k] + r[k];
      if (codes[k] < mesh.attr_lo[k] || codes[k] > mesh.attr_hi[k])
        corrupt("a decoded attribute lies outside its range");
    }
  }

  /// Reads past a split vertex's n attribute codes (a decode that returns none of them):
  /// their models' contexts come from the residuals alone, so no prediction is needed.
  void skip_attributes(uint32_t n) {
    int64_t r[kMaxAttributeCodes];
    residuals(n, r);
  }

  [[noreturn]] void corrupt(const char *what) {
    std::string where = "level " + std::to_string(level_);
    if (cluster_ != kNone)
      where = "cluster " + std::to_string(cluster_) + " " + where;
    throw Error(Error::Kind::DamagedFile, "damaged .pomar file: " + where + ": " + what)
        .in_block(cluster_ == kNone ? int(level_) : Error::kNoBlock,
                  cluster_ == kNone ? Error::kNoBlock : int64_t(cluster_));
  }

private:
  void residuals(uint32_t n, int64_t *r) {
    for (uint32_t k = 0; k < n; ++k) {
      AttributeCodeModels &m = m_->attr[k];
      r[k] = get_signed(*geom_, m.classes[attribute_context(m, r, k)], m.top);
    }
  }

  Models *m_ = nullptr;
  RangeDecoder *conn_ = nullptr, *geom_ = nullptr;
  int64_t top_;
  uint32_t level_ = 0, cluster_ = kNone;
};

} // namespace pomar
