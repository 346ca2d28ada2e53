#include "decimate/decimate.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

namespace pomar {
namespace {

using Corner = CornerTable;

int64_t dist2(const std::vector<int32_t> &q, uint32_t a, uint32_t b) {
  const int64_t dx = q[3 * a] - q[3 * b], dy = q[3 * a + 1] - q[3 * b + 1],
                dz = q[3 * a + 2] - q[3 * b + 2];
  return dx * dx + dy * dy + dz * dz;
}

/// Unnormalised normal of triangle (a,b,c) in doubles (decimation decisions only; the
/// decoder never repeats them, so they need not be bit-exact across machines).
void normal(const std::vector<int32_t> &q, uint32_t a, uint32_t b, uint32_t c, double n[3]) {
  double u[3], v[3];
  for (int k = 0; k < 3; ++k) {
    u[k] = double(q[3 * b + k]) - double(q[3 * a + k]);
    v[k] = double(q[3 * c + k]) - double(q[3 * a + k]);
  }
  n[0] = u[1] * v[2] - u[2] * v[1];
  n[1] = u[2] * v[0] - u[0] * v[2];
  n[2] = u[0] * v[1] - u[1] * v[0];
}

/// One halfedge of v_from's ring chosen for collapse: v_to = ring.neighbour[i].
struct Option {
  int64_t metric;
  uint32_t i;
};

struct Candidate {
  int64_t metric;
  uint32_t v_from, v_to;
  bool operator<(const Candidate &o) const {
    return metric != o.metric ? metric < o.metric : v_from < o.v_from;
  }
};

/// What evaluating a collapse reads and its scratch (rings, options, link marks): one per
/// thread while the candidates of a level are evaluated, the first one also for the
/// greedy pass. Evaluation only reads the mesh.
class Evaluator {
public:
  Evaluator(const CornerTable &ct, const std::vector<int32_t> &q, const DecimationOptions &opt)
      : ct_(ct), q_(q), opt_(opt), nb_stamp_(ct.vertex_count(), 0) {}

  /// The candidates of the vertices [first, last) of `alive`, in that order.
  void evaluate(const uint32_t *first, const uint32_t *last, std::vector<Candidate> &out) {
    for (const uint32_t *v = first; v != last; ++v) {
      get_ring(ct_, *v, from_);
      Candidate c;
      if (best_option(*v, c))
        out.push_back(c);
    }
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
  bool link_ok(uint32_t v_from, uint32_t i);

  Ring from_, to_;

private:
  bool allowed_direction(uint32_t i) const;
  int64_t metric(uint32_t i) const;
  bool normals_ok(uint32_t v_from, uint32_t i) const;
  bool best_option(uint32_t v_from, Candidate &out);

  const CornerTable &ct_;
  const std::vector<int32_t> &q_;
  const DecimationOptions &opt_;
  std::vector<uint32_t> nb_stamp_; // scratch marks for the link condition
  uint32_t nb_counter_ = 0;
  std::vector<Option> options_;
};

class Decimator {
public:
  Decimator(CornerTable &ct, const std::vector<int32_t> &q, const DecimationOptions &opt)
      : ct_(ct), target_mark_(ct.vertex_count(), 0), dirty_(ct.vertex_count(), 0) {
    const unsigned threads = std::max(1u, opt.threads);
    for (unsigned t = 0; t < threads; ++t)
      eval_.emplace_back(ct, q, opt);
  }

  /// Run one level; returns its collapses.
  std::vector<Collapse> run_level(std::vector<uint32_t> &alive);

private:
  std::vector<Candidate> candidates(const std::vector<uint32_t> &alive);
  Collapse collapse(uint32_t v_from, uint32_t i);

  CornerTable &ct_;
  std::vector<uint32_t> target_mark_; // level stamp of vertices already used as v_to
  std::vector<uint32_t> dirty_;       // level stamp of vertices whose ring changed
  uint32_t level_stamp_ = 0;
  std::deque<Evaluator> eval_;        // eval_[0]: also the greedy pass's
};

// Boundary rule: a boundary vertex may only slide along its boundary (onto the first or
// last neighbour of its open fan); an interior vertex may collapse onto any neighbour.
bool Evaluator::allowed_direction(uint32_t i) const {
  const uint32_t m = from_.size();
  if (m < 3)
    return false; // v_from would leave no face behind
  return from_.closed || i == 0 || i == m - 1;
}

// Length^2 of v_to-v_ref, v_ref being the farthest vertex that gets a new edge to v_to.
// With no new edge (v_from of valence 3), v_ref is v_l (or v_r on a boundary).
int64_t Evaluator::metric(uint32_t i) const {
  const uint32_t v_to = from_.neighbour[i];
  const uint32_t il = v_l_index(i), ir = v_r_index(i);
  int64_t best = -1;
  for (uint32_t k = 0; k < from_.size(); ++k)
    if (k != i && k != il && k != ir)
      best = std::max(best, dist2(q_, v_to, from_.neighbour[k]));
  if (best < 0)
    best = dist2(q_, v_to, from_.neighbour[il != kNone ? il : ir]);
  return best;
}

// Link condition: v_from and v_to may share no neighbour but v_l and v_r. Also refuse to
// collapse an edge of a tetrahedron (two closed valence-3 vertices).
bool Evaluator::link_ok(uint32_t v_from, uint32_t i) {
  const uint32_t v_to = from_.neighbour[i];
  get_ring(ct_, v_to, to_);
  if (from_.closed && to_.closed && from_.size() == 3 && to_.size() == 3)
    return false;
  if (++nb_counter_ == 0) { // stamp wrap-around: reset
    std::fill(nb_stamp_.begin(), nb_stamp_.end(), 0);
    nb_counter_ = 1;
  }
  for (uint32_t n : from_.neighbour)
    nb_stamp_[n] = nb_counter_;
  uint32_t shared = 0;
  for (uint32_t n : to_.neighbour)
    if (n != v_from && nb_stamp_[n] == nb_counter_)
      ++shared;
  const uint32_t expected = (v_l_index(i) != kNone) + (v_r_index(i) != kNone);
  return shared == expected;
}

// No surviving patch face may turn its normal by more than acos(normal_cosine).
bool Evaluator::normals_ok(uint32_t v_from, uint32_t i) const {
  (void)v_from;
  const uint32_t v_to = from_.neighbour[i];
  const double c2 = opt_.normal_cosine * opt_.normal_cosine;
  for (uint32_t k = 0; k < from_.faces(); ++k) {
    if (!face_survives(k, i))
      continue;
    const uint32_t a = from_.neighbour[k], b = from_.neighbour[(k + 1) % from_.size()];
    double before[3], after[3];
    normal(q_, v_from, a, b, before);
    normal(q_, v_to, a, b, after);
    const double lb = before[0] * before[0] + before[1] * before[1] + before[2] * before[2];
    const double la = after[0] * after[0] + after[1] * after[1] + after[2] * after[2];
    if (lb == 0.0)
      continue; // a zero-area face has no orientation to preserve
    if (la == 0.0)
      return false; // would create a zero-area face
    const double dot = before[0] * after[0] + before[1] * after[1] + before[2] * after[2];
    if (dot <= 0.0 || dot * dot < c2 * la * lb)
      return false;
  }
  return true;
}

// The admissible halfedge of v_from with the smallest metric (ring from_ is filled).
bool Evaluator::best_option(uint32_t v_from, Candidate &out) {
  options_.clear();
  for (uint32_t i = 0; i < from_.size(); ++i)
    if (allowed_direction(i))
      options_.push_back({metric(i), i});
  std::sort(options_.begin(), options_.end(), [](const Option &a, const Option &b) {
    return a.metric != b.metric ? a.metric < b.metric : a.i < b.i;
  });
  for (const Option &o : options_) {
    if (normals_ok(v_from, o.i) && link_ok(v_from, o.i)) {
      out = {o.metric, v_from, from_.neighbour[o.i]};
      return true;
    }
  }
  return false;
}

// Halfedge collapse v_from -> v_to = from_.neighbour[i] on the corner table.
Collapse Decimator::collapse(uint32_t v_from, uint32_t i) {
  const Evaluator &e = eval_[0];
  const Ring &from_ = e.from_;
  const uint32_t m = from_.size();
  const uint32_t il = e.v_l_index(i), ir = e.v_r_index(i);
  const uint32_t v_to = from_.neighbour[i];
  Collapse op{v_from, v_to, il == kNone ? kNone : from_.neighbour[il],
              ir == kNone ? kNone : from_.neighbour[ir]};
  // Faces that disappear: (v_from, v_to, v_l) = face i, (v_from, v_r, v_to) = face i-1.
  const uint32_t dead_l = il != kNone ? from_.corner[i] : kNone;
  const uint32_t dead_r = ir != kNone ? from_.corner[from_.closed ? (i + m - 1) % m : i - 1]
                                      : kNone;
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

// Every alive vertex's best collapse. Evaluation only reads the mesh: with several threads
// each evaluates one contiguous slice of `alive`, and the slices are joined in order, so
// the list is the same whatever the thread count.
std::vector<Candidate> Decimator::candidates(const std::vector<uint32_t> &alive) {
  constexpr size_t kMinSlice = 16384; // below this a thread costs more than it saves
  const size_t n = alive.size();
  const size_t threads = std::min<size_t>(eval_.size(), std::max<size_t>(1, n / kMinSlice));
  std::vector<std::vector<Candidate>> part(threads);
  const auto slice = [&](size_t t) {
    part[t].reserve(n / threads + 1);
    eval_[t].evaluate(alive.data() + n * t / threads, alive.data() + n * (t + 1) / threads,
                      part[t]);
  };
  std::vector<std::thread> pool;
  std::exception_ptr error;
  std::mutex error_mutex;
  const auto guarded_slice = [&](size_t t) {
    try {
      slice(t);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(error_mutex);
      error = std::current_exception();
    }
  };
  for (size_t t = 1; t < threads; ++t)
    pool.emplace_back(guarded_slice, t);
  guarded_slice(0);
  for (std::thread &th : pool)
    th.join();
  if (error)
    std::rethrow_exception(error);
  for (size_t t = 1; t < threads; ++t)
    part[0].insert(part[0].end(), part[t].begin(), part[t].end());
  return std::move(part[0]);
}

std::vector<Collapse> Decimator::run_level(std::vector<uint32_t> &alive) {
  ++level_stamp_;
  std::vector<Candidate> candidates = this->candidates(alive);
  std::sort(candidates.begin(), candidates.end());
  Evaluator &e = eval_[0];
  Ring &from_ = e.from_;
  // Greedy pass, shortest first. A candidate whose v_from has an unchanged ring still has
  // untouched faces (a collapse touching one of them would have changed that ring) and an
  // unchanged metric and normal test; only the link condition depends on v_to's ring.
  std::vector<Collapse> done;
  for (const Candidate &c : candidates) {
    if (dirty_[c.v_from] == level_stamp_ || target_mark_[c.v_to] == level_stamp_)
      continue;
    get_ring(ct_, c.v_from, from_);
    const int i = from_.index_of(c.v_to);
    if (i < 0 || (dirty_[c.v_to] == level_stamp_ && !e.link_ok(c.v_from, static_cast<uint32_t>(i))))
      continue;
    done.push_back(collapse(c.v_from, static_cast<uint32_t>(i)));
  }
  alive.erase(std::remove_if(alive.begin(), alive.end(),
                             [&](uint32_t v) { return ct_.VC[v] == kNone; }),
              alive.end());
  return done;
}

} // namespace

Decimation decimate(CornerTable ct, const std::vector<int32_t> &q,
                    const DecimationOptions &options, const Progress &progress) {
  Decimation result;
  std::vector<uint32_t> alive;
  for (uint32_t v = 0; v < ct.vertex_count(); ++v)
    if (ct.VC[v] != kNone)
      alive.push_back(v);
  const double initial = static_cast<double>(alive.size());
  Decimator d(ct, q, options);
  while (result.levels.size() < options.max_levels) {
    const size_t before = alive.size();
    std::vector<Collapse> level = d.run_level(alive);
    if (level.empty())
      break;
    result.levels.push_back(std::move(level));
    if (progress)
      progress(std::min(1.0, std::log(initial / double(alive.size())) /
                                 std::max(1.0, std::log(initial / 16.0))),
               "decimate");
    if (double(result.levels.back().size()) < options.min_level_fraction * double(before))
      break;
  }
  for (uint32_t f = 0; f < ct.face_count(); ++f)
    if (ct.V[3 * f] != kNone)
      result.base_triangles.insert(result.base_triangles.end(), &ct.V[3 * f], &ct.V[3 * f] + 3);
  return result;
}

} // namespace pomar
