#include "decimate/decimate.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>

#include "parallel/thread_pool.h"

namespace pomar {
namespace {

using Corner = CornerTable;

/// Squared distance of two quantized positions held as doubles: exact, since grids have at
/// most 24 bits (differences < 2^24, squares < 2^48, their sum < 2^50 < 2^53).
double dist2(const double *a, const double *b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

/// The edge from a to b, b - a (exact: the coordinates are quantized integers).
inline void edge(const double a[3], const double b[3], double e[3]) {
  e[0] = b[0] - a[0];
  e[1] = b[1] - a[1];
  e[2] = b[2] - a[2];
}

/// u x v: the unnormalised normal of a triangle (a, b, c) with u = b - a, v = c - a, in
/// doubles (decimation decisions only; the decoder never repeats them, so they need not be
/// bit-exact across machines). The fans below pass each edge on to the next face.
inline void cross(const double u[3], const double v[3], double n[3]) {
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
}

double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// One halfedge of v_from's ring chosen for collapse: v_to = ring.neighbour[i].
struct Option {
  int64_t metric;
  uint32_t i;
  bool operator<(const Option &o) const { return metric != o.metric ? metric < o.metric : i < o.i; }
};

struct Candidate {
  int64_t metric;
  uint32_t v_from, v_to;
};

/// Sort a level's candidates by (metric, v_from). They arrive by increasing v_from (`alive`
/// stays sorted and the threads' slices are joined in order), so a stable sort on the metric
/// alone gives that order: a least-significant-digit radix sort (metrics are >= 0), 11 bits
/// a pass, as many passes as the largest metric needs.
void sort_candidates(std::vector<Candidate> &c, std::vector<Candidate> &scratch) {
  constexpr int kBits = 11;
  constexpr uint64_t kMask = (uint64_t(1) << kBits) - 1;
  uint64_t largest = 0;
  for (const Candidate &x : c)
    largest = std::max(largest, uint64_t(x.metric));
  scratch.resize(c.size());
  std::vector<size_t> start(kMask + 2);
  for (int shift = 0; shift < 64 && (largest >> shift) != 0; shift += kBits) {
    std::fill(start.begin(), start.end(), 0);
    for (const Candidate &x : c)
      ++start[((uint64_t(x.metric) >> shift) & kMask) + 1];
    for (size_t d = 1; d < start.size(); ++d)
      start[d] += start[d - 1];
    for (const Candidate &x : c)
      scratch[start[(uint64_t(x.metric) >> shift) & kMask]++] = x;
    c.swap(scratch);
  }
}

/// What evaluating a collapse reads and its scratch (ring of v_from, its positions and face
/// normals, options, link marks): one per thread while the candidates of a level are
/// evaluated, the first one also for the greedy pass. Evaluation only reads the mesh.
/// (Cache-line aligned: each thread writes its own all the time; neighbours sharing a line
/// cost a second thread more than half of its evaluation time.)
class alignas(64) Evaluator {
public:
  Evaluator(const CornerTable &ct, const std::vector<int32_t> &q, const DecimationOptions &opt)
      : ct_(ct), q_(q), opt_(opt), nb_stamp_(ct.vertex_count(), 0) {}

  /// The candidates of the vertices [first, last) of `alive`, in that order.
  void evaluate(const uint32_t *first, const uint32_t *last, std::vector<Candidate> &out) {
    for (const uint32_t *v = first; v != last; ++v) {
      if (last - v > 8)
        __builtin_prefetch(&ct_.VC[v[8]]);
      if (last - v > 4) { // alive vertices have a corner
        __builtin_prefetch(&ct_.V[ct_.VC[v[4]]]);
        __builtin_prefetch(&ct_.O[ct_.VC[v[4]]]);
      }
      load(*v);
      Candidate c;
      if (best_option(c))
        out.push_back(c);
    }
  }

  /// Make v_from the vertex under evaluation: fill from_ and forget what was derived from
  /// the previous one (positions, face normals and link marks are computed when needed).
  void load(uint32_t v_from) {
    get_ring(ct_, v_from, from_);
    v_from_ = v_from;
    have_normals_ = false;
    have_marks_ = false;
  }

  uint32_t v_l_index(uint32_t i) const { // index of v_l in ring_from_, or kNone
    const uint32_t m = from_.size();
    if (from_.closed)
      return (i + 1) % m;
    return i + 1 < m ? i + 1 : kNone;
  }
  uint32_t v_r_index(uint32_t i) const { // index of v_r in ring_from_, or kNone
    const uint32_t m = from_.size();
    if (from_.closed)
      return (i + m - 1) % m;
    return i > 0 ? i - 1 : kNone;
  }
  bool face_survives(uint32_t k, uint32_t i) const { // face k of from_ kept by collapse i?
    const uint32_t m = from_.size();
    return k != i && k != (from_.closed ? (i + m - 1) % m : i - 1);
  }
  bool link_ok(uint32_t i);
  /// Whether collapse i of the loaded vertex is allowed (boundary rule), keeps the patch
  /// normals and the link condition.
  bool admissible(uint32_t i) { return allowed_direction(i) && normals_ok(i) && link_ok(i); }
  void gather() { gather_positions(); }

  Ring from_;
  /// Per vertex, during a tier's rounds: 1 = a border vertex of the tier (never v_from,
  /// never v_to); null outside tiers.
  const uint8_t *tier_lock = nullptr;
  std::vector<Candidate> found; // scratch of the parallel evaluation (Decimator::candidates)

private:
  bool allowed_direction(uint32_t i) const;
  void collect_options();
  void gather_positions();
  void farthest_apart();
  bool normals_ok(uint32_t i);
  void normals_before();
  bool best_option(Candidate &out);
  const double *at_d(uint32_t k) const { return &pos_d_[3 * size_t(k)]; }

  const CornerTable &ct_;
  const std::vector<int32_t> &q_;
  const DecimationOptions &opt_;
  uint32_t v_from_ = kNone;
  std::vector<double> pos_d_;      // positions of from_.neighbour, then v_from's (grow only)
  std::vector<double> farthest_;   // per neighbour: its largest distance^2 to a non-adjacent one
  std::vector<double> before_;     // per face of from_: its normal and the normal's length^2
  bool have_normals_ = false;      // before_ is v_from_'s
  std::vector<uint32_t> nb_stamp_; // scratch marks for the link condition
  uint32_t nb_counter_ = 0;
  bool have_marks_ = false; // from_'s neighbours carry nb_counter_
  std::vector<Option> options_;
};

class Decimator {
public:
  Decimator(CornerTable &ct, const std::vector<int32_t> &q, const DecimationOptions &opt)
      : ct_(ct), opt_(opt), target_mark_(ct.vertex_count(), 0), dirty_(ct.vertex_count(), 0),
        twin_eval_(ct, q, opt) {
    if (opt.threads > 1 && ct.vertex_count() >= 2 * kSlice)
      pool_ = std::make_unique<ThreadPool>(opt.threads);
    for (unsigned t = 0; t < (pool_ ? pool_->size() : 1); ++t)
      eval_.emplace_back(ct, q, opt);
  }

  /// Run one level; returns its collapses.
  std::vector<Collapse> run_level(std::vector<uint32_t> &alive);
  /// The border vertices of the current tier (per vertex, 1 = locked), or null: no tier.
  void set_tier_lock(const uint8_t *lock) {
    for (Evaluator &e : eval_)
      e.tier_lock = lock;
    twin_eval_.tier_lock = lock;
  }

private:
  std::vector<Candidate> candidates(const std::vector<uint32_t> &alive);
  Collapse collapse(const Evaluator &e, uint32_t v_from, uint32_t i);
  int twin_option(uint32_t v_to);

  CornerTable &ct_;
  const DecimationOptions &opt_;
  std::vector<uint32_t> target_mark_; // level stamp of vertices already used as v_to
  std::vector<uint32_t> dirty_;       // level stamp of vertices whose ring changed
  uint32_t level_stamp_ = 0;
  // Candidate evaluation: slices of kSlice alive vertices (a few ms of work each, far more
  // than handing one to a thread costs).
  static constexpr size_t kSlice = 2048;
  std::unique_ptr<ThreadPool> pool_;          // none with one thread or a small mesh
  std::deque<Evaluator> eval_;                // per pool thread; eval_[0]: also the greedy pass's
  std::vector<std::vector<Candidate>> slice_; // per slice: its candidates
  std::vector<Candidate> sort_scratch_;
  Evaluator twin_eval_; // the twin of a candidate on a texture seam
};

// Boundary rule: a boundary vertex may only slide along its boundary (onto the first or
// last neighbour of its open fan); an interior vertex may collapse onto any neighbour.
bool Evaluator::allowed_direction(uint32_t i) const {
  const uint32_t m = from_.size();
  if (m < 3)
    return false; // v_from would leave no face behind
  if (tier_lock && tier_lock[from_.neighbour[i]])
    return false; // v_to on the border of its tier's cell
  return from_.closed || i == 0 || i == m - 1;
}

// The allowed options with their metric: length^2 of v_to-v_ref, v_ref being the farthest
// vertex that gets a new edge to v_to, i.e. any neighbour but v_to, v_l and v_r (its ring
// neighbours). With no new edge (v_from of valence 3), v_ref is v_l (or v_r on a boundary).
// Distances are symmetric, so each pair of non-adjacent neighbours is measured once, for
// both ends.
void Evaluator::collect_options() {
  options_.clear();
  const uint32_t m = from_.size();
  if (m < 3)
    return;
  gather_positions();
  farthest_apart();
  for (uint32_t i = 0; i < m; ++i) {
    if (!allowed_direction(i))
      continue;
    const uint32_t il = v_l_index(i);
    const int64_t metric = int64_t(
        farthest_[i] >= 0 ? farthest_[i] : dist2(at_d(i), at_d(il != kNone ? il : v_r_index(i))));
    options_.push_back({metric, i});
  }
}

// pos_d_ := the positions of from_'s neighbours, then v_from's; farthest_ := -1 (none yet)
// for every neighbour. The arrays only grow: their tails past the ring are stale.
void Evaluator::gather_positions() {
  const uint32_t m = from_.size();
  if (pos_d_.size() < 3 * size_t(m + 1)) {
    pos_d_.resize(3 * size_t(m + 1));
    farthest_.resize(m);
  }
  const int32_t *q = q_.data();
  const uint32_t *neighbour = from_.neighbour.data();
  double *d = pos_d_.data(), *far = farthest_.data();
  for (uint32_t k = 0; k < m; ++k, d += 3) {
    const int32_t *s = q + 3 * size_t(neighbour[k]);
    d[0] = s[0], d[1] = s[1], d[2] = s[2];
    far[k] = -1;
  }
  const int32_t *s = q + 3 * size_t(v_from_);
  d[0] = s[0], d[1] = s[1], d[2] = s[2];
}

// farthest_[k] := the largest distance^2 from neighbour k to a neighbour not adjacent to it
// in the ring (stays -1 if none). Distances are symmetric: each pair is measured once.
void Evaluator::farthest_apart() {
  const uint32_t m = from_.size();
  double *far = farthest_.data();
  // (in a closed ring neighbours 0 and m-1 are adjacent across its start)
  for (uint32_t i = 0, end = from_.closed ? m - 1 : m; i + 2 < end; ++i, end = m) {
    const double *a = at_d(i);
    double far_i = far[i];
    for (uint32_t k = i + 2; k < end; ++k) {
      const double d = dist2(a, at_d(k));
      far_i = std::max(far_i, d);
      far[k] = std::max(far[k], d);
    }
    far[i] = far_i;
  }
}

// Link condition: v_from and v_to may share no neighbour but v_l and v_r. Also refuse to
// collapse an edge of a tetrahedron (two closed valence-3 vertices). v_to's fan is walked
// as get_ring does, counting instead of storing.
bool Evaluator::link_ok(uint32_t i) {
  if (!have_marks_) {
    if (++nb_counter_ == 0) { // stamp wrap-around: reset
      std::fill(nb_stamp_.begin(), nb_stamp_.end(), 0);
      nb_counter_ = 1;
    }
    for (uint32_t n : from_.neighbour)
      nb_stamp_[n] = nb_counter_;
    have_marks_ = true;
  }
  uint32_t shared = 0, size = 0;
  const auto visit = [&](uint32_t n) {
    ++size;
    shared += n != v_from_ && nb_stamp_[n] == nb_counter_;
  };
  const uint32_t *V = ct_.V.data(), *O = ct_.O.data();
  const uint32_t start = ct_.VC[from_.neighbour[i]]; // v_to has faces: it is in a face of v_from
  // Counter-clockwise from start: face c = (v_to, a, b) gives a = V[next(c)]; the next face
  // is the one across (v_to, a), its corner next(o) for o = O[next(c)], and that corner's
  // next is prev(o) (one `% 3` a face, as in walk_fan).
  uint32_t c = start, c_next = Corner::next(start);
  bool to_closed = true;
  for (;;) {
    visit(V[c_next]);
    const uint32_t o = O[c_next];
    if (o == kNone) {
      to_closed = false;
      break;
    }
    const uint32_t k = o % 3;
    c = k == 2 ? o - 2 : o + 1;
    if (c == start)
      break;
    c_next = k == 0 ? o + 2 : o - 1;
  }
  if (!to_closed) { // the far end of the last face, then the faces clockwise of start
    visit(V[Corner::prev(c)]);
    for (uint32_t b = ct_.swing_cw(start); b != kNone; b = ct_.swing_cw(b))
      visit(ct_.V[Corner::next(b)]);
  }
  if (from_.closed && to_closed && from_.size() == 3 && size == 3)
    return false;
  const uint32_t expected = (v_l_index(i) != kNone) + (v_r_index(i) != kNone);
  return shared == expected;
}

// No surviving patch face may turn its normal by more than acos(normal_cosine). The normals
// before the collapse do not depend on v_to: computed once per v_from.
bool Evaluator::normals_ok(uint32_t i) {
  const uint32_t m = from_.size(), faces = from_.faces();
  if (!have_normals_)
    normals_before();
  const double c2 = opt_.normal_cosine * opt_.normal_cosine;
  const uint32_t gone_r = from_.closed && i == 0 ? m - 1 : i - 1; // face (v_from, v_r, v_to)
  const double *to = at_d(i);
  const double *before = before_.data();
  double u[3], v[3];   // the edges from v_to to the face's two neighbours
  bool have_u = false; // u is face k's (the previous face's v)
  for (uint32_t k = 0; k < faces; ++k, before += 4) {
    const double lb = before[3];
    if (k == i || k == gone_r || lb == 0.0) {
      have_u = false;
      continue; // a zero-area face has no orientation to preserve
    }
    if (!have_u)
      edge(to, at_d(k), u);
    edge(to, at_d(k + 1 == m ? 0 : k + 1), v);
    double after[3];
    cross(u, v, after);
    const double la = dot(after, after);
    if (la == 0.0)
      return false; // would create a zero-area face
    const double d = dot(before, after);
    if (d <= 0.0 || d * d < c2 * la * lb)
      return false;
    std::copy_n(v, 3, u);
    have_u = true;
  }
  return true;
}

// before_ := per face of from_, its normal and the normal's length^2 (grows only).
void Evaluator::normals_before() {
  const uint32_t m = from_.size(), faces = from_.faces();
  if (before_.size() < 4 * size_t(faces))
    before_.resize(4 * size_t(faces));
  const double *from = at_d(m);
  double *n = before_.data();
  double u[3], v[3]; // the edges from v_from to the face's two neighbours
  edge(from, at_d(0), u);
  for (uint32_t k = 0; k < faces; ++k, n += 4) {
    edge(from, at_d(k + 1 == m ? 0 : k + 1), v);
    cross(u, v, n);
    n[3] = dot(n, n);
    std::copy_n(v, 3, u);
  }
  have_normals_ = true;
}

// The admissible halfedge of v_from with the smallest (metric, index). The options are
// tried smallest first, picking the smallest left each time: usually the first or second
// one is admissible, so this is cheaper than sorting them.
bool Evaluator::best_option(Candidate &out) {
  if (tier_lock && tier_lock[v_from_])
    return false; // on the border of its tier's cell
  collect_options();
  while (!options_.empty()) {
    auto best = std::min_element(options_.begin(), options_.end());
    const Option o = *best;
    if (normals_ok(o.i) && link_ok(o.i)) {
      out = {o.metric, v_from_, from_.neighbour[o.i]};
      return true;
    }
    *best = options_.back();
    options_.pop_back();
  }
  return false;
}

// Halfedge collapse v_from -> v_to = from_.neighbour[i] on the corner table.
Collapse Decimator::collapse(const Evaluator &e, uint32_t v_from, uint32_t i) {
  const Ring &from_ = e.from_;
  const uint32_t m = from_.size();
  const uint32_t il = e.v_l_index(i), ir = e.v_r_index(i);
  const uint32_t v_to = from_.neighbour[i];
  Collapse op{v_from, v_to, il == kNone ? kNone : from_.neighbour[il],
              ir == kNone ? kNone : from_.neighbour[ir]};
  // Faces that disappear: (v_from, v_to, v_l) = face i, (v_from, v_r, v_to) = face i-1.
  const uint32_t dead_l = il != kNone ? from_.corner[i] : kNone;
  const uint32_t dead_r =
      ir != kNone ? from_.corner[from_.closed ? (i + m - 1) % m : i - 1] : kNone;
  // Relabel the surviving faces of v_from (the patch).
  for (uint32_t k = 0; k < from_.faces(); ++k) {
    if (!e.face_survives(k, i))
      continue;
    ct_.V[from_.corner[k]] = v_to;
    ct_.VC[v_to] = from_.corner[k];
  }
  if (dead_l != kNone) { // stitch the faces across (v_to,v_l) and (v_l,v_from)
    const uint32_t a = ct_.O[dead_l], b = ct_.O[Corner::next(dead_l)];
    ct_.link(a, b);
    ct_.VC[op.v_l] = b != kNone ? Corner::prev(b) : Corner::next(a);
  }
  if (dead_r != kNone) { // stitch the faces across (v_r,v_to) and (v_from,v_r)
    const uint32_t qc = ct_.O[dead_r], p = ct_.O[Corner::prev(dead_r)];
    ct_.link(p, qc);
    ct_.VC[op.v_r] = qc != kNone ? Corner::prev(qc) : Corner::next(p);
  }
  for (uint32_t d : {dead_l, dead_r}) {
    if (d == kNone)
      continue;
    const uint32_t f = d / 3;
    for (uint32_t c = 3 * f; c < 3 * f + 3; ++c) {
      ct_.O[c] = kNone;
      ct_.V[c] = kNone;
    }
  }
  ct_.VC[v_from] = kNone;
  target_mark_[v_to] = level_stamp_;
  dirty_[v_from] = level_stamp_;
  for (uint32_t n : from_.neighbour)
    dirty_[n] = level_stamp_;
  return op;
}

// The collapse of the twin loaded in twin_eval_ that goes with v_from -> v_to: onto the end
// of its open fan that is a copy of v_to (another vertex than v_to, not yet a v_to of this
// level, its ring unchanged or the link condition still true), if admissible; else -1.
int Decimator::twin_option(uint32_t v_to) {
  const Ring &r = twin_eval_.from_;
  const uint32_t m = r.size();
  if (r.closed || m < 3)
    return -1;
  const uint32_t origin = (*opt_.origin)[v_to];
  bool gathered = false;
  for (uint32_t i : {0u, m - 1}) {
    const uint32_t t = r.neighbour[i];
    if (t == v_to || (*opt_.origin)[t] != origin || target_mark_[t] == level_stamp_)
      continue;
    if (!gathered) // (the positions of the twin's ring, for the normal test)
      twin_eval_.gather();
    gathered = true;
    if (twin_eval_.admissible(i))
      return static_cast<int>(i);
  }
  return -1;
}

// Every alive vertex's best collapse. Evaluation only reads the mesh: `alive` is cut into
// slices of kSlice vertices, the pool's threads evaluate them (each with its own
// Evaluator, taking the next slice when done: a thread slowed down by a busy machine just
// takes fewer), and the slices are joined in order, so the list is the same whatever the
// thread count.
std::vector<Candidate> Decimator::candidates(const std::vector<uint32_t> &alive) {
  const size_t n = alive.size(), slices = (n + kSlice - 1) / kSlice;
  std::vector<Candidate> out;
  out.reserve(n);
  if (!pool_ || slices < 2) {
    eval_[0].evaluate(alive.data(), alive.data() + n, out);
    return out;
  }
  if (slice_.size() < slices)
    slice_.resize(slices);
  pool_->run(slices, [&](size_t i, unsigned t) {
    // (Filled in the thread's own Evaluator, then copied: the threads' push_backs would
    // otherwise write the adjacent headers of slice_[], one cache line, all the time.)
    Evaluator &e = eval_[t];
    e.found.clear();
    e.evaluate(alive.data() + i * kSlice, alive.data() + std::min(n, (i + 1) * kSlice), e.found);
    slice_[i].assign(e.found.begin(), e.found.end());
  });
  for (size_t i = 0; i < slices; ++i)
    out.insert(out.end(), slice_[i].begin(), slice_[i].end());
  return out;
}

std::vector<Collapse> Decimator::run_level(std::vector<uint32_t> &alive) {
  ++level_stamp_;
  std::vector<Candidate> candidates = this->candidates(alive);
  sort_candidates(candidates, sort_scratch_);
  Evaluator &e = eval_[0];
  Ring &from_ = e.from_;
  // Greedy pass, shortest first. A candidate whose v_from has an unchanged ring still has
  // untouched faces (a collapse touching one of them would have changed that ring) and an
  // unchanged metric and normal test; only the link condition depends on v_to's ring.
  // The candidates are in metric order, scattered over the mesh: fetch the marks and the
  // first corner of v_from 16 candidates ahead, that corner's face 8 ahead.
  std::vector<Collapse> done;
  for (size_t j = 0; j < candidates.size(); ++j) {
    if (j + 16 < candidates.size()) {
      const Candidate &f = candidates[j + 16];
      __builtin_prefetch(&dirty_[f.v_from]);
      __builtin_prefetch(&target_mark_[f.v_to]);
      __builtin_prefetch(&ct_.VC[f.v_from]);
    }
    if (j + 8 < candidates.size()) {
      const uint32_t corner = ct_.VC[candidates[j + 8].v_from];
      if (corner != kNone) {
        __builtin_prefetch(&ct_.V[corner]);
        __builtin_prefetch(&ct_.O[corner]);
      }
    }
    const Candidate &c = candidates[j];
    if (dirty_[c.v_from] == level_stamp_ || target_mark_[c.v_to] == level_stamp_)
      continue;
    const uint32_t twin = opt_.twin ? (*opt_.twin)[c.v_from] : kNone;
    if (twin != kNone && (dirty_[twin] == level_stamp_ || (e.tier_lock && e.tier_lock[twin])))
      continue;
    e.load(c.v_from);
    const int i = from_.index_of(c.v_to);
    if (i < 0 || (dirty_[c.v_to] == level_stamp_ && !e.link_ok(static_cast<uint32_t>(i))))
      continue;
    if (twin == kNone) {
      done.push_back(collapse(e, c.v_from, static_cast<uint32_t>(i)));
      continue;
    }
    // A seam vertex and its twin slide onto the copies of one vertex, both or neither (the
    // two sides' fans share no face: the first collapse leaves the second's checks true).
    twin_eval_.load(twin);
    const int k = twin_option(c.v_to);
    if (k < 0)
      continue;
    done.push_back(collapse(e, c.v_from, static_cast<uint32_t>(i)));
    done.push_back(collapse(twin_eval_, twin, static_cast<uint32_t>(k)));
  }
  alive.erase(
      std::remove_if(alive.begin(), alive.end(), [&](uint32_t v) { return ct_.VC[v] == kNone; }),
      alive.end());
  return done;
}

/// The packed cell coordinates of q for cells of side 2^k, shifted by `shift` units.
inline uint64_t cell_key(const int32_t *q, int k, int32_t shift) {
  const auto axis = [&](int a) { return uint64_t(uint32_t(q[a] + shift) >> k) & 0x1FFFFF; };
  return axis(0) << 42 | axis(1) << 21 | axis(2);
}

/// Starts tier number `index` at decimation round `round` on the current mesh: chooses the
/// cell side (the k whose occupied cells hold, on average, closest in ratio to the wanted
/// number of vertices), marks the border vertices in `lock` and measures the longest edge.
DecimationTier start_tier(const CornerTable &ct, const std::vector<int32_t> &q,
                          const DecimationTiers &opt, uint32_t index, uint32_t round,
                          std::vector<uint8_t> &lock) {
  DecimationTier t;
  t.first_round = round;
  t.shifted = index % 2 == 1;
  std::vector<uint32_t> live;
  for (uint32_t v = 0; v < ct.vertex_count(); ++v)
    if (ct.VC[v] != kNone)
      live.push_back(v);
  t.vertices = static_cast<uint32_t>(live.size());
  std::vector<uint64_t> keys(live.size());
  double best_err = 0;
  for (int k = 1; k <= opt.bits; ++k) {
    const int32_t shift = t.shifted ? int32_t(1) << (k - 1) : 0;
    for (size_t i = 0; i < live.size(); ++i)
      keys[i] = cell_key(&q[3 * size_t(live[i])], k, shift);
    std::sort(keys.begin(), keys.end());
    const size_t cells = size_t(std::unique(keys.begin(), keys.end()) - keys.begin());
    const double err =
        std::fabs(std::log(double(live.size()) / double(cells) / double(opt.cell_vertices)));
    if (k == 1 || err < best_err) {
      best_err = err;
      t.cell_bits = k;
      t.cells = static_cast<uint32_t>(cells);
    }
  }
  const int32_t shift = t.shifted ? int32_t(1) << (t.cell_bits - 1) : 0;
  std::vector<uint64_t> key(ct.vertex_count());
  for (uint32_t v : live)
    key[v] = cell_key(&q[3 * size_t(v)], t.cell_bits, shift);
  lock.assign(ct.vertex_count(), 0);
  double longest2 = 0;
  for (uint32_t f = 0; f < ct.face_count(); ++f) {
    if (ct.V[3 * f] == kNone)
      continue;
    for (uint32_t j = 0; j < 3; ++j) {
      const uint32_t a = ct.V[3 * f + j], b = ct.V[3 * f + (j + 1) % 3];
      if (key[a] != key[b])
        lock[a] = lock[b] = 1;
      double d2 = 0;
      for (int x = 0; x < 3; ++x) {
        const double d = double(q[3 * size_t(a) + x]) - double(q[3 * size_t(b) + x]);
        d2 += d * d;
      }
      longest2 = std::max(longest2, d2);
    }
  }
  t.longest_edge = std::sqrt(longest2);
  for (uint32_t v : live)
    t.border += lock[v];
  return t;
}

} // namespace

uint64_t tier_cell(const DecimationTier &t, const int32_t *q) {
  return cell_key(q, t.cell_bits, t.shifted ? int32_t(1) << (t.cell_bits - 1) : 0);
}

Decimation decimate(CornerTable ct, const std::vector<int32_t> &q, const DecimationOptions &options,
                    const Progress &progress) {
  Decimation result;
  std::vector<uint32_t> alive;
  for (uint32_t v = 0; v < ct.vertex_count(); ++v)
    if (ct.VC[v] != kNone && !(options.locked && (*options.locked)[v]))
      alive.push_back(v); // (the candidates v_from: a locked vertex is never one)
  const double initial = static_cast<double>(alive.size());
  Decimator d(ct, q, options);
  // Tiers: a new one every `rounds` rounds while the mesh has more than until_vertices
  // vertices. A round of a tier that removes nothing or too little ends the tier (its cells
  // are used up, not the mesh); one that does so as the first of its tier ends the
  // decimation, as without tiers.
  std::vector<uint8_t> tier_lock;
  size_t live = 0;
  for (uint32_t v = 0; v < ct.vertex_count(); ++v)
    live += ct.VC[v] != kNone;
  bool tiered = options.tiers && options.tiers->rounds > 0;
  bool tier_ended = true;
  while (result.levels.size() < options.max_levels) {
    const size_t before = alive.size();
    if (tiered && (tier_ended || result.tiers.back().rounds == options.tiers->rounds)) {
      tier_ended = false;
      if (live > options.tiers->until_vertices) {
        result.tiers.push_back(start_tier(ct, q, *options.tiers,
                                          static_cast<uint32_t>(result.tiers.size()),
                                          static_cast<uint32_t>(result.levels.size()), tier_lock));
        d.set_tier_lock(tier_lock.data());
      } else {
        tiered = false;
        d.set_tier_lock(nullptr);
      }
    }
    std::vector<Collapse> level = d.run_level(alive);
    const bool small =
        level.empty() || double(level.size()) < options.min_level_fraction * double(before);
    const bool end_tier = tiered && small && result.tiers.back().rounds > 0;
    if (end_tier) {
      tier_ended = true; // (an empty round is dropped; a small one is kept)
      if (level.empty())
        continue;
    }
    if (level.empty()) {
      if (tiered)
        result.tiers.pop_back();
      break;
    }
    if (tiered)
      ++result.tiers.back().rounds;
    live -= level.size();
    level.shrink_to_fit(); // kept to the end of the encode: without push_back's slack
    result.levels.push_back(std::move(level));
    if (progress)
      progress(std::min(1.0, std::log(initial / double(alive.size())) /
                                 std::max(1.0, std::log(initial / 16.0))),
               "decimate");
    if (small && !end_tier)
      break;
  }
  for (uint32_t f = 0; f < ct.face_count(); ++f)
    if (ct.V[3 * f] != kNone)
      result.base_triangles.insert(result.base_triangles.end(), &ct.V[3 * f], &ct.V[3 * f] + 3);
  return result;
}

} // namespace pomar
