// The traversal policy of the encoder, and the mesh it rebuilds as the decoder will.
//
// After decimation the encoder rebuilds the mesh from the base mesh exactly as the
// decoder will (same traversal, same splits, same vertex numbering), and at each vertex
// writes what the decoder needs to repeat the step: the encoder is a decoder that knows
// the answers.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "attributes/attribute_quantize.h"
#include "decimate/decimate.h"
#include "entropy/models.h"
#include "entropy/static_tables.h"
#include "format/file_format.h"
#include "refine/level_step.h"

namespace pomar {

/// The residuals the two predictors of the wedge texture coordinate (0: the mean, 1: from
/// the positions) would leave on a level, tallied as put_signed codes them
/// (entropy/models.h): the bit length n of each code's residual, in the context the
/// attribute models give it (the u code: one; the v code: the u residual's bit length),
/// then n bits (sign, top and lower bits). bits() is the empirical code length of each:
/// integer counts, the same for any thread count.
struct WedgeTally {
  static constexpr int kContexts = 1 + kAttributeContexts, kClasses = 65;
  uint32_t classes[2][kContexts][kClasses] = {};
  uint64_t raw[2] = {0, 0};

  void add(int predictor, int64_t ru, int64_t rv) {
    const int nu = bit_length(uint64_t(ru < 0 ? -ru : ru));
    const int nv = bit_length(uint64_t(rv < 0 ? -rv : rv));
    ++classes[predictor][0][nu];
    ++classes[predictor][1 + std::min(nu, kAttributeContexts - 1)][nv];
    raw[predictor] += uint64_t(nu + nv);
  }
  void add(const WedgeTally &o) {
    for (int i = 0; i < 2; ++i) {
      raw[i] += o.raw[i];
      for (int c = 0; c < kContexts; ++c)
        for (int n = 0; n < kClasses; ++n)
          classes[i][c][n] += o.classes[i][c][n];
    }
  }
  void clear() { *this = WedgeTally(); }
  bool empty() const { return raw[0] == 0 && raw[1] == 0 && classes[0][0][0] == 0; }
  double bits(int predictor) const {
    // Each context's classes as an adaptive model would code them, learning as it goes
    // (Krichevsky-Trofimov: a class seen h times of t costs log2((t + K/2) / (h + 1/2)));
    // the total depends on the counts alone, not on their order. A class seen once costs far
    // more than its empirical share: what the level's frozen table pays to hold it.
    constexpr double a = 0.5, k = 32;
    double nats = 0;
    for (int c = 0; c < kContexts; ++c) {
      uint64_t total = 0;
      for (int n = 0; n < kClasses; ++n) {
        const uint32_t h = classes[predictor][c][n];
        total += h;
        if (h)
          nats -= std::lgamma(double(h) + a) - std::lgamma(a);
      }
      if (total)
        nats += std::lgamma(double(total) + k * a) - std::lgamma(k * a);
    }
    return double(raw[predictor]) + nats / std::log(2.0);
  }
};

/// The traversal policy of the encoder: it knows every collapse of the level. `Sink` is a
/// RangeEncoder (global levels) or a RecorderStream (clustered levels, coded later).
/// (Cache-line aligned: the parallel clustered levels give each thread its own codec, which
/// it writes at every vertex; codecs sharing a line slowed the threads down.)
template <class Sink> class alignas(64) EncoderCodec {
public:
  EncoderCodec(const std::vector<int32_t> &input_q, std::vector<uint32_t> &dec_to_input,
               std::vector<uint32_t> &input_to_dec)
      : input_q_(input_q), dec_to_input_(dec_to_input), input_to_dec_(input_to_dec) {}

  void begin_level(const std::vector<Collapse> &level, Models *models) {
    level_ = &level;
    m_ = models;
    if (collapse_at_.empty())
      collapse_at_.assign(input_to_dec_.size(), kNone);
    for (uint32_t i = 0; i < level.size(); ++i)
      collapse_at_[level[i].v_to] = i;
    emitted_ = 0;
  }
  void set_sinks(Sink *conn, Sink *geom) {
    conn_ = conn;
    geom_ = geom;
  }
  void end_level() {
    for (const Collapse &c : *level_)
      collapse_at_[c.v_to] = kNone;
    if (emitted_ != level_->size())
      corrupt("a collapse of the level was not reached by the traversal");
  }

  /// A codec for another thread of the same level (clustered levels in parallel): it reads
  /// `owner`'s level (collapses, index, models) and defers the numbering of the vertices it
  /// splits (take_deferred), which the owner's thread applies in cluster order.
  void work_for(EncoderCodec &owner) {
    index_ = &owner.collapse_at_;
    level_ = owner.level_;
    m_ = owner.m_;
    attr_codes_ = owner.attr_codes_;
    defer_ids_ = true;
    emitted_ = 0;
  }
  /// The input ids of the v_from this codec coded since the last call, in coding order
  /// (work_for codecs): number them with number_split in the same order as the splits.
  void take_deferred(std::vector<uint32_t> &out) {
    out.swap(deferred_);
    deferred_.clear();
  }
  /// Give input vertex v_from the next id of the decoder's numbering.
  void number_split(uint32_t v_from) {
    input_to_dec_[v_from] = static_cast<uint32_t>(dec_to_input_.size());
    dec_to_input_.push_back(v_from);
  }
  /// Splits coded by a work_for codec count for the owner's end_level check.
  void add_emitted(EncoderCodec &worker) {
    emitted_ += worker.emitted_;
    worker.emitted_ = 0;
    wedge_tally.add(worker.wedge_tally);
    worker.wedge_tally.clear();
  }

  int split_flag(uint32_t v, int context) {
    current_ = (index_ ? *index_ : collapse_at_)[dec_to_input_[v]];
    const int flag = current_ != kNone;
    bits.s_v += bits_for<Sink>(m_->conn.sv[context], flag);
    conn_->encode_bit(m_->conn.sv[context], flag);
    emitted_ += flag;
    return flag;
  }

  void split_symbols(uint32_t v, const Ring &ring, const uint32_t *ranked, SplitSymbols &s) {
    (void)v;
    const Collapse &c = (*level_)[current_];
    const uint32_t m = ring.size();
    const uint32_t il = ring_index(ring, c.v_l), ir = ring_index(ring, c.v_r);
    // Vertices strictly inside the patch (they get a new edge to v_to at the collapse).
    auto inside = [&](uint32_t i) {
      if (ring.closed)
        return (i + m - il) % m != 0 && (i + m - il) % m < (ir + m - il) % m;
      const uint32_t lo = il == kNone ? 0 : il + 1, hi = ir == kNone ? m - 1 : ir - 1;
      return i >= lo && i <= hi && hi != kNone;
    };
    uint32_t e = kNone;
    for (uint32_t r = 0; r < m && e == kNone; ++r)
      if (inside(ranked[r]))
        e = r;
    for (uint32_t r = 0; r < m && e == kNone; ++r)
      if (ranked[r] == il || ranked[r] == ir)
        e = r;
    const uint32_t j = ranked[e];
    s.s_e = e;
    s.s_l = ring.closed ? (j + m - il) % m : (il == kNone ? j + 1 : j - il);
    s.s_r = ring.closed ? (ir + m - j) % m : (ir == kNone ? m - j : ir - j);
    const uint32_t faces = s.s_l + s.s_r;
    bits.s_e += put_small(*conn_, m_->conn.se[valence_context(m)], s.s_e);
    bits.faces += put_small(*conn_, m_->conn.faces[faces_context(m, ring.closed)], faces);
    bits.s_l += put_small(*conn_, m_->conn.sl[sl_context(faces)], s.s_l);
  }

  /// Version 5: the patch as s_l + s_r and the rank of its placement (refine/patch_rank.h).
  bool ranks_patches() const { return m_->conn.patch_rank; }
  uint32_t patch_faces(uint32_t v, const Ring &ring) {
    (void)v;
    const Collapse &c = (*level_)[current_];
    const uint32_t m = ring.size();
    const uint32_t il = ring_index(ring, c.v_l), ir = ring_index(ring, c.v_r);
    // v_l and v_r in the extended index of PatchPlacements (open fans: -1 / m = none).
    const int32_t l = il == kNone ? -1 : int32_t(il), r = ir == kNone ? int32_t(m) : int32_t(ir);
    const uint32_t faces = ring.closed ? (ir + m - il) % m : uint32_t(r - l);
    true_il_ = l;
    bits.faces += put_small(*conn_, m_->conn.faces[faces_context(m, ring.closed)], faces);
    return faces;
  }
  uint32_t patch_placement(const Ring &ring, uint32_t faces, const PatchPlacements &p) {
    const uint32_t k = placement_index(p, true_il_);
    if (k == kNone)
      corrupt("the collapse's patch is not a placement of its size");
    bits.rank += put_small(*conn_, m_->conn.rank[rank_context(faces, ring.size(), ring.closed)],
                           placement_rank(p, k));
    return k;
  }

  const NormalPredictor &normal_predictor() const { return m_->normal; }
  void geometry(uint32_t v_to, const Prediction &p, int32_t position[3]) {
    (void)v_to;
    const uint32_t v_from = (*level_)[current_].v_from;
    int64_t r[3];
    for (int k = 0; k < 3; ++k) {
      position[k] = input_q_[3 * v_from + k];
      r[k] = int64_t(position[k]) - p.barycentre[k];
    }
    to_local(p.frame, r);
    bits.tangential += put_residual(*geom_, m_->geom, 0, p.context, r[0] - p.offset[0]);
    bits.tangential += put_residual(*geom_, m_->geom, 0, p.context, r[1] - p.offset[1]);
    bits.normal += put_residual(*geom_, m_->geom, 1, p.context, r[2] - p.offset[2]);
    // The step applies the splits in the order they are coded: v_from gets the next id
    // (a work_for codec's splits are applied later, in cluster order: numbered then).
    if (defer_ids_)
      deferred_.push_back(v_from);
    else
      number_split(v_from);
  }

  /// The split vertex's attribute codes (from the input), coded against the prediction.
  void attributes(const LevelMesh &mesh, const int64_t *pred, int64_t *codes) {
    const uint32_t n = mesh.attr_codes;
    const uint32_t v_from = (*level_)[current_].v_from;
    int64_t r[kMaxAttributeCodes];
    for (uint32_t k = 0; k < n; ++k) {
      codes[k] = (*attr_codes_)[size_t(v_from) * n + k];
      r[k] = codes[k] - pred[k];
      AttributeCodeModels &m = m_->attr[k];
      FrequencyModel &classes = m.classes[attribute_context(m, r, k)];
      if constexpr (std::is_same_v<Sink, RecorderStream>) {
        // Clustered levels: tagged per code for the statistics (code_recording).
        RecorderStream tagged{geom_->recorder, static_cast<uint8_t>(2 + k)};
        put_signed(tagged, classes, m.top, r[k]);
      } else {
        attr_bits[k] += put_signed(*geom_, classes, m.top, r[k]);
      }
    }
  }
  /// The residuals the split vertex's wedge texture coordinate (its `codes`) would leave
  /// predicted by the mean (both[0..1]) and from the positions (both[2..3]), whichever the
  /// level uses, tallied in wedge_tally.
  void weigh_wedge(const LevelMesh &mesh, const int64_t *codes, const int64_t *both) {
    const uint32_t k = uint32_t(mesh.wedge_uv_code);
    for (int i = 0; i < 2; ++i)
      wedge_tally.add(i, codes[k] - both[2 * i], codes[k + 1] - both[2 * i + 1]);
  }
  WedgeTally wedge_tally;

  /// Attribute codes of every input vertex (encoder numbering), `n` per vertex.
  void set_attribute_codes(const std::vector<int64_t> *codes, uint32_t n) {
    attr_codes_ = codes;
    attr_bits.assign(n, 0.0);
  }

  SymbolBits bits; // ideal code lengths per symbol kind (global levels: a recorder has none)
  std::vector<double> attr_bits; // ideal code lengths per attribute code (global levels)

  [[noreturn]] void corrupt(const char *what) {
    throw Error(Error::Kind::Internal, std::string("internal encoder error: ") + what);
  }

private:
  uint32_t ring_index(const Ring &ring, uint32_t input_vertex) {
    if (input_vertex == kNone)
      return kNone;
    const int i = ring.index_of(input_to_dec_[input_vertex]);
    if (i < 0)
      corrupt("v_l/v_r is not a neighbour of v_to");
    return static_cast<uint32_t>(i);
  }

  Models *m_ = nullptr;
  const std::vector<int32_t> &input_q_;
  std::vector<uint32_t> &dec_to_input_, &input_to_dec_;
  std::vector<uint32_t> collapse_at_;            // input vertex -> index of its collapse as v_to
  const std::vector<uint32_t> *index_ = nullptr; // the owner's collapse_at_ (work_for codecs)
  bool defer_ids_ = false;
  std::vector<uint32_t> deferred_; // v_from coded, numbered later (work_for codecs)
  const std::vector<Collapse> *level_ = nullptr;
  Sink *conn_ = nullptr, *geom_ = nullptr;
  const std::vector<int64_t> *attr_codes_ = nullptr;
  uint32_t current_ = kNone;
  int32_t true_il_ = 0; // the patch_faces split's v_l (extended index, see PatchPlacements)
  size_t emitted_ = 0;
};

/// The mesh the encoder rebuilds level by level from the base mesh, in the decoder's
/// vertex numbering, with the maps between that numbering and the input's.
struct Rebuild {
  Rebuild(const std::vector<int32_t> &input_q, const Decimation &decimation)
      : q(input_q), dec(decimation), input_to_dec(input_q.size() / 3, kNone) {}
  const std::vector<int32_t> &q; // quantized input positions (input numbering)
  const Decimation &dec;
  LevelMesh mesh;
  std::vector<uint32_t> dec_to_input, input_to_dec;
  LevelStep step;
  // Attributes (attributes/): the input vertices' codes, `attr_codes_per_vertex` each, and
  // the ideal code length of each code over all levels (for `pomar info`).
  const std::vector<int64_t> *attr_codes = nullptr;
  uint32_t attr_codes_per_vertex = 0;
  std::vector<AttributeCodeModels> attr_models; // fresh models for one level set
  std::vector<double> attr_bits;
  // The quantized wedge texture coordinate's predictor, chosen level by level
  // (choose_wedge_predictor): the first level takes the base mesh's (`wedge_first`), every
  // other the one whose residuals on the level before (wedge_tally) cost less.
  bool wedge_choice = false, wedge_first = false;
  WedgeTally wedge_tally;
  // Format version 5: fit each level's normal predictor (encode/fit_prediction.h) before it
  // is coded; normal[l - 1] is level l's (the GEOP section).
  bool fit_normal = false;
  std::vector<NormalPredictor> normal;

  size_t levels() const { return dec.levels.size(); }
  /// The collapses that refinement level `level` (1 = first above the base) undoes.
  const std::vector<Collapse> &collapses(size_t level) const {
    return dec.levels[dec.levels.size() - level];
  }
};

/// After a level: the estimates `codec` gathered on it (EncoderCodec::weigh_wedge), handed
/// over to `rb` for the next level's choice.
template <class Codec> void take_wedge_costs(Rebuild &rb, Codec &codec) {
  rb.wedge_tally.add(codec.wedge_tally);
  codec.wedge_tally.clear();
}

/// Before refinement level `level`: the wedge texture coordinate's predictor for it in
/// `rb.mesh.wedge_uv_positions`: the first level takes the base mesh's, every other the
/// predictor of the level before, or the other one if its residuals on the level before
/// (take_wedge_costs) cost more than kSwitchBits less.
inline void choose_wedge_predictor(Rebuild &rb, uint32_t level) {
  if (!rb.wedge_choice)
    return;
  std::vector<uint8_t> &p = rb.mesh.wedge_uv_positions;
  p.resize(size_t(level) + 1, 0);
  // A level keeps the predictor of the level before unless the other saves more than a
  // switch costs in the level's frozen tables (kSwitchBits, a rough figure: the tables are
  // coded against the level before's, and the bits of their classes are what change).
  constexpr double kSwitchBits = 128;
  const bool before = level == 1 ? rb.wedge_first : p[level - 1] != 0;
  const double mean = rb.wedge_tally.bits(0), positions = rb.wedge_tally.bits(1);
  p[level] = before;
  if (level > 1 && !rb.wedge_tally.empty() &&
      (before ? mean + kSwitchBits < positions : positions + kSwitchBits < mean))
    p[level] = !before;
  rb.wedge_tally.clear();
}

/// Append the level table entry of the level just encoded (the mesh's counts after it).
inline void add_level_entry(FileHeader &header, const LevelMesh &mesh, uint32_t conn_bytes,
                            uint32_t geom_bytes) {
  LevelEntry e;
  e.vertices = mesh.vertex_count();
  e.faces = mesh.ct.face_count();
  e.connectivity_bytes = conn_bytes;
  e.geometry_bytes = geom_bytes;
  header.levels.push_back(e);
}

} // namespace pomar
