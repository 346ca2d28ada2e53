// The deterministic breadth-first traversal of one level (paper section 5.1, Figure 3),
// shared by the encoder and the decoder so that both walk the mesh identically.
//
// Starting from the first halfedge of the first base face, a vertex is processed when the
// first halfedge pointing to it leaves the FIFO; then its outgoing halfedges are queued in
// clockwise order, starting from the one back to where it came from. For each vertex the
// codec codes s_v; for a split vertex (v_to) also s_e, s_l, s_r (version 5: s_l + s_r and
// the rank of the patch's placement, refine/patch_rank.h) and the position of
// v_from as a residual to the patch barycentre in the local Frenet frame. The splits are
// only collected here; refine/level_step.h runs a traversal, its checks and then applies
// them (Figure 3, step 4): that step is the only caller.
//
// The Codec policy provides (encoder: writes what it knows; decoder: reads):
//   int  split_flag(uint32_t v, int context);
//   bool ranks_patches();              // version 5: patch_faces + patch_placement
//   void split_symbols(uint32_t v, const Ring& ring, const uint32_t* ranked,
//                      SplitSymbols& s);      // versions 1-4: s_e, s_l, s_r; ranked = ring
//                                     indices, longest edge first
//                                     (nullptr if Codec::kSelectsSplitEdge: see code_vertex)
//   uint32_t patch_faces(uint32_t v, const Ring& ring);  // version 5: s_l + s_r
//   uint32_t patch_placement(const Ring& ring, uint32_t faces,
//                            const PatchPlacements& p);  // the patch's placement (index in p)
//   const NormalPredictor& normal_predictor();  // the level's (geometry/predict.h)
//   void geometry(uint32_t v_to, const Prediction& prediction, int32_t position[3]);
//                                     // prediction: geometry/predict.h
//   void attributes(const LevelMesh& mesh, const int64_t* prediction, int64_t* codes); // if any
//   void skip_attributes(uint32_t n);  // optional (decoder): read past n codes (attr_skipped)
//   [[noreturn]] void corrupt(const char* what);
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "attributes/attribute_quantize.h"
#include "attributes/wedge_prediction.h"
#include "entropy/models.h"
#include "geometry/predict.h"
#include "mesh/corner_table.h"
#include "refine/level_mesh.h"
#include "refine/patch.h"
#include "refine/traversal_marks.h"
#include "refine/vertex_split.h"

namespace pomar {

/// What is coded per split vertex besides the split itself: the data of the new vertex
/// v_from. code_vertex codes it (Codec::geometry, Codec::attributes), apply_splits
/// (level_step.h) stores it with the new vertex: the position in PendingSplit, the
/// attribute codes (LevelMesh::attr_codes per split, often none) beside, in
/// SplitList::attr, so that a split takes 28 bytes whatever the attributes.
constexpr uint32_t kMaxAttributeCodes = 16; // integer codes of all attributes of a vertex
struct PendingSplit {
  SplitOp op;
  int32_t position[3]; // v_from's, quantized
};

/// The splits of one step, in the order they were coded.
struct SplitList {
  std::vector<PendingSplit> split;
  std::vector<int64_t> attr; // split i's attribute codes: [i * attr_codes, (i + 1) * attr_codes)
  size_t size() const { return split.size(); }
  void clear() {
    split.clear();
    attr.clear();
  }
  void swap(SplitList &other) {
    split.swap(other.split);
    attr.swap(other.attr);
  }
};

/// s_v context from what the decoder already knows at v: how many of v's faces earlier
/// patches of this level hold (0..3+), how many neighbours were split (0..2+), and v's
/// valence (<=5, 6, 7, 8+: a v_to gained the valence of the vertex it absorbed).
/// Returns -1 when every face is held: v cannot be split, s_v is not coded at all.
/// `split_neighbours` counts the ring's entries split earlier in this traversal
/// (queue_neighbours counts them).
template <class Marks>
int sv_context(const Marks &marks, const Ring &ring, uint32_t split_neighbours) {
  // Every patch face contains its v_to: without a split neighbour no face is held.
  uint32_t claimed = 0;
  if (split_neighbours) {
    for (uint32_t c : ring.corner)
      claimed += marks.claimed(c / 3);
    if (claimed == ring.faces())
      return -1;
  }
  const uint32_t valence = ring.size() <= 5 ? 0 : std::min(ring.size() - 5, 3u);
  return static_cast<int>((std::min(claimed, 3u) * 3 + std::min(split_neighbours, 2u)) * 4 +
                          valence);
}

/// The level a clustered traversal decodes, and what it can skip: vertices below
/// `older_than` are known to be older than `level` (0: not known; set when the level
/// starts on a mesh that holds nothing finer, it spares the view its lineage lookups).
struct LevelView {
  uint32_t level;
  uint32_t older_than = 0;
};

/// The level-(l-1) view of v's one-ring while level l is being decoded: neighbours created
/// at level l or later (by splits of neighbouring clusters already applied) stand for
/// their parents, and the faces those splits added (degenerate in the view) are skipped.
/// The view is the same whatever clusters were decoded before, which is what makes
/// selective and incremental decoding equal to a full decode.
inline uint32_t view_of(const LevelMesh::Lineage *lineage, uint32_t v, const LevelView &view) {
  if (v < view.older_than)
    return v;
  while (lineage[v].level >= view.level && lineage[v].parent != v)
    v = lineage[v].parent;
  return v;
}

/// Like get_ring, naming the neighbours through view_of: the faces that collapse in the
/// view (two neighbours with one name) are left out.
inline void get_view_ring(const LevelMesh &mesh, uint32_t v, const LevelView &level, Ring &view) {
  // (What view_of reads, copied: kept in registers through the walk. The neighbour's
  // lineage and position are fetched as soon as it is named: the cluster's marks read
  // the first next, code_vertex the second if the vertex is split.)
  const auto name = [lineage = mesh.lineage.data(), q = mesh.q.data(), level](uint32_t n) {
    const uint32_t v = view_of(lineage, n, level);
    __builtin_prefetch(&lineage[v]);
    __builtin_prefetch(&q[3 * size_t(v)]);
    return v;
  };
  get_named_ring(mesh.ct, v, name, view);
}

/// Prediction of v_from's attribute codes: v_to's codes, except a quantized normal, which is
/// predicted by the octahedral code of 3 x the unit area-weighted normal of v_from's patch
/// faces (v_from at its decoded position with the patch ring; integer cross products) plus
/// v_to's decoded normal, when neither sum is zero (horse, 9 bits: 11.8 bits per vertex
/// with v_to's normal alone, 9.8 with the faces' alone, 9.0 with 3:1); by the faces' alone
/// if v_to's normal is zero-length. The seam cut's wedge texture coordinate (files with a
/// MATL section) is predicted by the mean of the codes of v_from's neighbours to be (v_to
/// and the patch ring, all in v_from's chart: the cut separates the charts), rounded half
/// away from zero, or, at the levels where the file says so, from the positions
/// (predict_wedge_from_positions; the mean where the patch faces have no area). `both`
/// (the encoder's, to choose the next level's predictor): the wedge's prediction by the mean
/// (both[0..1]) and from the positions (both[2..3]).
inline void predict_attributes(const LevelMesh &mesh, uint32_t level, uint32_t v_to,
                               const Ring &ring, const PatchRange &p, const int32_t position[3],
                               int64_t *pred, int64_t *both = nullptr) {
  const uint32_t n = mesh.attr_codes;
  std::copy(&mesh.attr[size_t(v_to) * n], &mesh.attr[size_t(v_to) * n] + n, pred);
  if (mesh.wedge_uv_code >= 0 && ring.size() > 0) {
    const uint32_t k = uint32_t(mesh.wedge_uv_code), m = ring.size();
    const bool positions = both || mesh.wedge_from_positions(level);
    int64_t by_positions[2];
    const bool got =
        positions && predict_wedge_from_positions(mesh, v_to, ring, p, position, by_positions);
    int64_t by_mean[2] = {pred[k], pred[k + 1]};
    if (!got || both) {
      int64_t su = pred[k], sv = pred[k + 1], count = 1;
      for (uint32_t t = 0, i = p.first_face; t <= p.faces; ++t, i = (i + 1) % m, ++count) {
        const int64_t *c = &mesh.attr[size_t(ring.neighbour[i]) * n + k];
        su += c[0];
        sv += c[1];
      }
      const auto mean = [count](int64_t x) {
        return (x >= 0 ? x + count / 2 : x - count / 2) / count;
      };
      by_mean[0] = mean(su);
      by_mean[1] = mean(sv);
    }
    const bool use_positions = got && mesh.wedge_from_positions(level);
    pred[k] = use_positions ? by_positions[0] : by_mean[0];
    pred[k + 1] = use_positions ? by_positions[1] : by_mean[1];
    if (both) {
      both[0] = by_mean[0];
      both[1] = by_mean[1];
      both[2] = got ? by_positions[0] : by_mean[0];
      both[3] = got ? by_positions[1] : by_mean[1];
    }
  }
  if (mesh.normal_code < 0)
    return;
  const auto &q = mesh.q;
  const uint32_t m = ring.size();
  int64_t sum[3] = {0, 0, 0};
  for (uint32_t t = 0, i = p.first_face; t < p.faces; ++t, i = (i + 1) % m) {
    const uint32_t a = ring.neighbour[i], b = ring.neighbour[(i + 1) % m];
    int64_t u[3], w[3];
    for (int k = 0; k < 3; ++k) {
      u[k] = int64_t(q[3 * a + k]) - position[k];
      w[k] = int64_t(q[3 * b + k]) - position[k];
    }
    sum[0] += u[1] * w[2] - u[2] * w[1];
    sum[1] += u[2] * w[0] - u[0] * w[2];
    sum[2] += u[0] * w[1] - u[1] * w[0];
  }
  if (sum[0] == 0 && sum[1] == 0 && sum[2] == 0)
    return;
  const double len = std::sqrt(double(sum[0]) * double(sum[0]) + double(sum[1]) * double(sum[1]) +
                               double(sum[2]) * double(sum[2]));
  float parent[3] = {0, 0, 0}; // a zero-length normal adds nothing to the faces' direction
  if (!mesh.normal_zero ||
      !is_zero_normal(pred[mesh.normal_code], pred[mesh.normal_code + 1], mesh.normal_bits))
    octahedral_decode(uint32_t(pred[mesh.normal_code]), uint32_t(pred[mesh.normal_code + 1]),
                      mesh.normal_bits, parent);
  float normal[3];
  for (int k = 0; k < 3; ++k)
    normal[k] = float(3.0 * double(sum[k]) / len + double(parent[k]));
  if (normal[0] == 0 && normal[1] == 0 && normal[2] == 0)
    return;
  uint32_t u, w;
  octahedral_encode(normal, mesh.normal_bits, u, w);
  pred[mesh.normal_code] = u;
  pred[mesh.normal_code + 1] = w;
}

/// What a stream whose patches overlap is told.
constexpr const char *kSharedFace = "two vertex splits of one level share a face";

/// Whether a Codec can read past attribute codes (the decoder's skip_attributes).
/// Whether a Codec weighs the two wedge predictors at every split (the encoder's
/// weigh_wedge: it chooses each level's from the one before).
template <class Codec, class = void> struct WeighsWedges : std::false_type {};
template <class Codec>
struct WeighsWedges<Codec, std::void_t<decltype(std::declval<Codec &>().weigh_wedge(
                               std::declval<const LevelMesh &>(), nullptr, nullptr))>>
    : std::true_type {};

template <class Codec, class = void> struct SkipsAttributes : std::false_type {};
template <class Codec>
struct SkipsAttributes<Codec, std::void_t<decltype(std::declval<Codec &>().skip_attributes(0u))>>
    : std::true_type {};

/// Whether a Codec's split_symbols ignores the ranked edges (the decoder: it reads s_e and
/// code_vertex then looks up that one edge, ranked_edge, instead of sorting them all).
template <class Codec, class = void> struct SelectsSplitEdge : std::false_type {};
template <class Codec>
struct SelectsSplitEdge<Codec, std::enable_if_t<Codec::kSelectsSplitEdge>> : std::true_type {};

/// Version 5's patch symbols (refine/patch_rank.h): s_l + s_r, then the rank of the patch's
/// placement among those of that size in `ring`; gives v_ref's ring index `j` and the
/// symbols resolve_patch turns into the patch.
template <class Codec, class Key>
void code_patch_rank(Codec &codec, TraversalScratch &s, uint32_t v, const Ring &ring,
                     const Key &key, uint32_t &j, SplitSymbols &sym) {
  const uint32_t m = ring.size();
  const uint32_t faces = codec.patch_faces(v, ring);
  if (faces == 0 || uint64_t(faces) + (ring.closed ? 1 : 0) > m)
    codec.corrupt("split symbols do not fit the vertex's neighbourhood");
  score_placements(ring, s.spokes.data(), faces, s.placements);
  const uint32_t k = codec.patch_placement(ring, faces, s.placements);
  patch_symbols(ring, s.spokes.data(), s.placements.il[k], faces, key, j, sym);
}

/// The split at split vertex v (code_vertex's, once s_v said so): symbols, patch, claim of
/// its faces, prediction and position. (A call: most vertices are not split, and their
/// visit, inlined in the traversal, does not pay for this one's frame.)
template <class Codec, class Key, class Marks>
[[gnu::noinline]] void code_split(LevelMesh &mesh, Codec &codec, TraversalScratch &s, uint32_t v,
                                  const Ring &ring, uint32_t level, const Key &key,
                                  const Marks &marks, SplitList &splits) {
  marks.vertex(v)->split = s.stamp;
  load_spokes(mesh.q, v, ring, s.spokes);
  SplitSymbols sym;
  uint32_t j = kNone;          // the ring index of edge v_to-v_ref (rank s_e)
  if (codec.ranks_patches()) { // version 5: s_l + s_r, then the placement's rank
    code_patch_rank(codec, s, v, ring, key, j, sym);
  } else if constexpr (SelectsSplitEdge<Codec>::value) {
    codec.split_symbols(v, ring, nullptr, sym);
    if (sym.s_e < ring.size() && ring.size() <= 16)
      j = ranked_edge(ring, s.spokes.data(), sym.s_e, key);
    else if (sym.s_e < ring.size()) {
      rank_edges(ring, s.spokes.data(), s.ranked, key);
      j = s.ranked[sym.s_e];
    }
  } else {
    rank_edges(ring, s.spokes.data(), s.ranked, key);
    codec.split_symbols(v, ring, s.ranked.data(), sym);
    if (sym.s_e < ring.size())
      j = s.ranked[sym.s_e];
  }
  PatchRange p;
  if (!resolve_patch(ring, j, sym, p))
    codec.corrupt("split symbols do not fit the vertex's neighbourhood");
  // Patches of one level must not share faces (that is what makes the splits
  // independent); a stream that says otherwise is damaged. (Deferred claims: the faces
  // other clusters hold are checked when the cluster is admitted, LevelStep::
  // admit_cluster_level, and LevelMesh::face_claim is not read here: it may be written
  // meanwhile.) The split walks the patch faces counter-clockwise in the actual mesh: they
  // must also be the ring's faces (true for valid data; a damaged stream could point
  // across a boundary or a face the view skipped), which the same pass follows, reported
  // once every face is claimed. (Locals: the claims' push_back could reallocate, and the
  // arrays would be read again at every face.)
  const uint32_t m = ring.size(), stamp = s.stamp;
  const uint32_t *corner = ring.corner.data(), *O = mesh.ct.O.data();
  uint32_t *claimed = s.claimed.data(); // (marks.claimed and marks.claim: by face id)
  uint16_t *face_claim = s.defer_claims ? nullptr : mesh.face_claim.data();
  bool matches = true;
  for (uint32_t t = 0, i = p.first_face, c = corner[i]; t < p.faces;
       ++t, i = i + 1 == m ? 0 : i + 1) {
    const uint32_t f = corner[i] / 3;
    if ((face_claim && face_claim[f] == level) || claimed[f] == stamp)
      codec.corrupt(kSharedFace);
    if (face_claim)
      face_claim[f] = static_cast<uint16_t>(level);
    claimed[f] = stamp;
    s.claims.push_back(f);
    if (matches) {
      if (c != corner[i]) {
        matches = false;
      } else { // swing_ccw
        const uint32_t o = O[CornerTable::next(c)];
        c = o == kNone ? kNone : CornerTable::next(o);
      }
    }
  }
  if (!matches)
    codec.corrupt("a vertex split does not match the mesh");
  PendingSplit ps;
  ps.op = {v, ring.corner[p.first_face], p.faces, p.il != kNone, p.ir != kNone};
  Prediction prediction;
  predict(&mesh.q[3 * size_t(v)], ring, s.spokes.data(), p, codec.normal_predictor(), prediction);
  codec.geometry(v, prediction, ps.position);
  if (mesh.attr_codes) {
    int64_t pred[kMaxAttributeCodes], codes[kMaxAttributeCodes];
    if constexpr (WeighsWedges<Codec>::value) {
      int64_t both[4];
      predict_attributes(mesh, level, v, ring, p, ps.position, pred,
                         mesh.wedge_uv_code >= 0 ? both : nullptr);
      codec.attributes(mesh, pred, codes);
      if (mesh.wedge_uv_code >= 0 && ring.size() > 0)
        codec.weigh_wedge(mesh, codes, both);
    } else {
      predict_attributes(mesh, level, v, ring, p, ps.position, pred);
      codec.attributes(mesh, pred, codes);
    }
    splits.attr.insert(splits.attr.end(), codes, codes + mesh.attr_codes);
  } else if constexpr (SkipsAttributes<Codec>::value) {
    if (mesh.attr_skipped)
      codec.skip_attributes(mesh.attr_skipped);
  }
  splits.split.push_back(ps);
}

/// Code (or decode) s_v at v and, for a split vertex, the split (code_split). `ring` is v's
/// ring as the level sees it.
template <class Codec, class Key, class Marks>
[[gnu::always_inline]] inline void code_vertex(LevelMesh &mesh, Codec &codec, TraversalScratch &s,
                                               uint32_t v, const Ring &ring, uint32_t level,
                                               const Key &key, const Marks &marks,
                                               uint32_t split_neighbours, SplitList &splits) {
  const int context = sv_context(marks, ring, split_neighbours);
  if (context >= 0 && codec.split_flag(v, context))
    code_split(mesh, codec, s, v, ring, level, key, marks, splits);
}

/// Queue v's neighbours clockwise, starting with the one back to `from`; returns how many
/// of them were split earlier in this traversal (for sv_context: one pass over the ring's
/// marks; v's own coding, which follows, changes neither the queue nor those marks).
/// `marks.with_vertex(n, f)` hands f n's marks, and does nothing for a vertex the traversal
/// does not visit (another cluster's: never queued nor split here).
template <class Marks>
uint32_t queue_neighbours(TraversalScratch &s, uint32_t v, uint32_t from, const Ring &ring,
                          const Marks &marks) {
  const uint32_t m = ring.size(), stamp = s.stamp; // (a local: the mark stores could alias it)
  if (m == 0)
    return 0;
  const uint32_t *neighbour = ring.neighbour.data();
  uint32_t start = 0;
  for (uint32_t i = 0; i < m; ++i)
    if (neighbour[i] == from) {
      start = i;
      break;
    }
  // (Room for every neighbour first: the loops write the queue through a local pointer.)
  uint32_t queued = s.queue.size();
  std::pair<uint32_t, uint32_t> *queue = s.queue.grow_to(size_t(queued) + m);
  uint32_t split = 0;
  const auto visit = [&](uint32_t n) {
    marks.with_vertex(n, [&](VertexMarks &mark) {
      split += mark.split == stamp;
      if (mark.queued != stamp) {
        mark.queued = stamp;
        queue[queued++] = {n, v};
      }
    });
  };
  // Clockwise: start, start - 1, ..., 0, then m - 1, ..., start + 1.
  for (uint32_t i = start + 1; i-- > 0;)
    visit(neighbour[i]);
  for (uint32_t i = m; i-- > start + 1;)
    visit(neighbour[i]);
  s.queue.resize(queued);
  return split;
}

/// The walks are memory bound: fetch the corner reference of the vertex 16 places ahead in
/// the queue, the corners of its first face 8 places ahead, and 4 places ahead the two
/// faces next to that one in its fan (their O entries have arrived by then). (A further
/// stage, the next face on either side 2 places ahead, gained nothing: walk_fan has
/// fetched most of those as the faces beyond an earlier fan.) Always inlined (see
/// CornerTable::prefetch).
[[gnu::always_inline]] inline void prefetch_ahead(const LevelMesh &mesh, const TraversalScratch &s,
                                                  size_t head) {
  const CornerTable &ct = mesh.ct;
  const size_t n = s.queue.size();
  if (head + 4 < n) {
    const uint32_t c = ct.VC[s.queue[head + 4].first];
    if (c != kNone) {
      ct.prefetch(ct.O[CornerTable::next(c)]);
      ct.prefetch(ct.O[CornerTable::prev(c)]);
    }
  }
  if (head + 8 < n)
    ct.prefetch(ct.VC[s.queue[head + 8].first]);
  if (head + 16 < n)
    __builtin_prefetch(&ct.VC[s.queue[head + 16].first]);
}

/// Traverse the whole mesh once for global level `level` (all components, seeded by the
/// base faces in order), appending the splits to `splits`. `s` is begun by the caller.
template <class Codec>
void traverse_level(LevelMesh &mesh, Codec &codec, TraversalScratch &s, uint32_t level,
                    SplitList &splits) {
  const auto id = [](uint32_t v) { return uint64_t(v); };
  const GlobalMarks marks{{s}};
  size_t head = 0;
  for (uint32_t f = 0; f < mesh.seed_faces; ++f) {
    const uint32_t a = mesh.ct.V[3 * f], b = mesh.ct.V[3 * f + 1];
    VertexMarks &mark = *marks.vertex(b);
    if (mark.queued == s.stamp)
      continue;
    mark.queued = s.stamp;
    s.queue.push_back({b, a});
    while (head < s.queue.size()) {
      prefetch_ahead(mesh, s, head);
      const auto [v, from] = s.queue[head++];
      get_ring(mesh.ct, v, s.ring);
      const uint32_t split = queue_neighbours(s, v, from, s.ring, marks);
      code_vertex(mesh, codec, s, v, s.ring, level, id, marks, split, splits);
    }
  }
}

/// Traverse one cluster for clustered level `level` (paper section 5.2): breadth-first
/// from the cluster's root (its base clustered mesh vertex), starting clockwise from the
/// root's neighbour of smallest key, visiting only the cluster's vertices, on the
/// level-(l-1) view of the mesh, appending the splits to `splits`. `s` is begun by the
/// caller.
template <class Codec>
void traverse_cluster(LevelMesh &mesh, Codec &codec, TraversalScratch &s, uint32_t root,
                      const LevelView &level, SplitList &splits) {
  const uint32_t cluster = mesh.cluster_of(root);
  const auto key = [&](uint32_t v) { return mesh.key(v); };
  const ClusterMarks marks{{s}, mesh.lineage.data(), cluster};
  get_view_ring(mesh, root, level, s.ring);
  if (s.ring.neighbour.empty())
    return;
  uint32_t from = s.ring.neighbour[0];
  for (uint32_t n : s.ring.neighbour)
    if (mesh.key(n) < mesh.key(from))
      from = n;
  marks.vertex(root)->queued = s.stamp;
  s.queue.push_back({root, from});
  const uint32_t *claimed = s.claimed.data();
  const uint16_t *face_claim = mesh.face_claim.data();
  for (size_t head = 0; head < s.queue.size();) {
    prefetch_ahead(mesh, s, head);
    const auto [v, came_from] = s.queue[head++];
    if (head > 1) // (the root's ring is s.ring already)
      get_view_ring(mesh, v, level, s.ring);
    const uint32_t *corner = s.ring.corner.data(), faces = s.ring.faces();
    if (s.defer_claims) { // (what sv_context and code_vertex read)
      for (uint32_t i = 0; i < faces; ++i)
        __builtin_prefetch(&claimed[corner[i] / 3]);
    } else {
      for (uint32_t i = 0; i < faces; ++i) {
        const uint32_t f = corner[i] / 3;
        __builtin_prefetch(&claimed[f]);
        __builtin_prefetch(&face_claim[f]);
      }
    }
    const uint32_t split = queue_neighbours(s, v, came_from, s.ring, marks);
    code_vertex(mesh, codec, s, v, s.ring, level.level, key, marks, split, splits);
  }
}

} // namespace pomar
