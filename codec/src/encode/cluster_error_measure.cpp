// The stored error per cluster and level; see cluster_error_measure.h.
#include "encode/cluster_error_measure.h"

#include <algorithm>
#include <cmath>

#include "format/cluster_errors.h"
#include "parallel/thread_pool.h"

namespace pomar {

namespace {

struct V3 {
  double x, y, z;
};
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
double norm2(V3 a) { return dot(a, a); }

V3 at(const std::vector<int32_t> &q, uint32_t v) {
  const int32_t *p = q.data() + 3 * size_t(v);
  return {double(p[0]), double(p[1]), double(p[2])};
}

/// Squared distance from p to the triangle abc (the closest point by its Voronoi region),
/// given ap = p - a.
[[gnu::always_inline]] inline double distance2_to_triangle(V3 p, V3 ap, V3 a, V3 b, V3 c) {
  const V3 ab = b - a, ac = c - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0)
    return norm2(ap);
  const V3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3)
    return norm2(bp);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
    return norm2(p - (a + (d1 / (d1 - d3)) * ab));
  const V3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6)
    return norm2(cp);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
    return norm2(p - (a + (d2 / (d2 - d6)) * ac));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return norm2(p - (b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b)));
  const double denom = va + vb + vc;
  if (!(denom > 0)) // degenerate triangle: its vertices
    return std::min({norm2(ap), norm2(bp), norm2(cp)});
  const double v = vb / denom, w = vc / denom;
  return norm2(p - (a + v * ab + w * ac));
}

/// Raise `worst` to the squared distance from p to the faces around vertex a of `mesh`
/// if it is larger. The distance is only computed as far as it can raise it: a face (or
/// a itself, a corner of each) within `worst` of p settles that it cannot. The walk starts
/// at corner `hint` if it is still a corner of a (the face that settled p's distance at the
/// level before lies often near the one that settles it now; any start visits the same
/// faces until one settles), and `hint` becomes the corner of the face that settled it.
/// Consecutive faces of the fan share an edge from a: each face's far vertex there is read
/// once, for both faces.
void raise_to_fan_distance(const LevelMesh &mesh, uint32_t a, V3 p, double &worst, uint32_t &hint) {
  const V3 va = at(mesh.q, a);
  const V3 pa = p - va;
  double best = norm2(pa);
  if (best <= worst)
    return;
  const CornerTable &ct = mesh.ct;
  const uint32_t *V = ct.V.data();
  const uint32_t first =
      hint < ct.V.size() && V[hint] == a ? hint : ct.VC[a]; // (VC: kNone if isolated)
  if (first != kNone) {
    // Counter-clockwise, face c = (a, b, d) is followed by the face across (a, d), whose b
    // is d.
    const V3 b_first = at(mesh.q, V[CornerTable::next(first)]);
    V3 b = b_first;
    uint32_t c = first;
    do {
      const V3 d = at(mesh.q, V[CornerTable::prev(c)]);
      const double e = distance2_to_triangle(p, pa, va, b, d);
      best = std::min(best, e);
      if (e <= worst) { // (not NaN, from a degenerate face: that does not settle it)
        hint = c;
        return;
      }
      b = d;
      c = ct.swing_ccw(c);
    } while (c != kNone && c != first);
    if (c == kNone) { // an open fan: the faces clockwise of the first, each (a, b, d) with
                      // d the b of the face before
      V3 d = b_first;
      for (c = ct.swing_cw(first); c != kNone; c = ct.swing_cw(c)) {
        b = at(mesh.q, V[CornerTable::next(c)]);
        const double e = distance2_to_triangle(p, pa, va, b, d);
        best = std::min(best, e);
        if (e <= worst) {
          hint = c;
          return;
        }
        d = b;
      }
    }
  }
  worst = best;
}

constexpr uint32_t kClustersPerItem = 64; // on the threads

} // namespace

ClusterErrorMeasure::ClusterErrorMeasure(const Rebuild &rb, size_t global, const Quantizer &grid)
    : global_(static_cast<uint32_t>(global)), clusters_(rb.mesh.vertex_count()),
      step_(grid.step()) {
  // The decoder's positions are the grid's rounded to floats: each coordinate within half
  // a float ulp of the grid position, so a point within sqrt(3) 2^-24 M of it (M: the
  // largest magnitude on the grid), and a distance from a point to a triangle within twice
  // that.
  double m = 0;
  for (int k = 0; k < 3; ++k)
    m = std::max({m, std::fabs(double(grid.origin[k])),
                  std::fabs(double(grid.origin[k]) + double(grid.extent))});
  margin_ = 2.0 * std::sqrt(3.0) * std::ldexp(m, -24);
  // The cluster of every vertex the clustered levels create (its v_to's), then the entries
  // grouped by cluster, each cluster's in creation order.
  const size_t nv = rb.q.size() / 3;
  std::vector<uint32_t> cluster(nv, kNone), entry(nv, kNone);
  std::vector<uint32_t> count(clusters_ + 1, 0);
  for (uint32_t c = 0; c < clusters_; ++c) {
    cluster[rb.dec_to_input[c]] = c;
    ++count[c + 1];
  }
  for (size_t r = global + 1; r <= rb.levels(); ++r)
    for (const Collapse &s : rb.collapses(r)) {
      cluster[s.v_from] = cluster[s.v_to];
      ++count[cluster[s.v_from] + 1];
    }
  for (uint32_t c = 0; c < clusters_; ++c)
    count[c + 1] += count[c];
  start_ = count;
  first_future_.assign(start_.begin(), start_.end() - 1);
  const size_t n = start_.back();
  created_.resize(n);
  parent_.resize(n);
  id_.resize(n);
  ancestor_.assign(n, kNone);
  hint_.assign(n, kNone);
  q_.resize(3 * n);
  const auto put = [&](uint32_t v, uint32_t level, uint32_t parent) {
    const uint32_t i = count[cluster[v]]++;
    entry[v] = i;
    created_[i] = static_cast<uint16_t>(level);
    parent_[i] = parent == kNone ? kNone : entry[parent];
    id_[i] = v;
    std::copy_n(&rb.q[3 * size_t(v)], 3, &q_[3 * size_t(i)]);
  };
  for (uint32_t c = 0; c < clusters_; ++c)
    put(rb.dec_to_input[c], uint32_t(global), kNone);
  for (size_t r = global + 1; r <= rb.levels(); ++r)
    for (const Collapse &s : rb.collapses(r))
      put(s.v_from, uint32_t(r), s.v_to);
}

void ClusterErrorMeasure::measure_cluster(const Rebuild &rb, uint32_t level, uint32_t c,
                                          double &worst) {
  const LevelMesh &mesh = rb.mesh;
  uint32_t i = first_future_[c];
  const uint32_t end = start_[c + 1];
  for (; i < end && created_[i] <= level; ++i) // present from this level on: decoder ids
    id_[i] = rb.input_to_dec[id_[i]];
  first_future_[c] = i;
  const uint32_t first = i;
  for (; i < end; ++i) { // the ancestors first (entry order: a parent's before its children)
    const uint32_t p = parent_[i];
    ancestor_[i] = created_[p] <= level ? id_[p] : ancestor_[p];
  }
  constexpr uint32_t kAhead = 8; // the fans read next are fetched meanwhile
  for (i = first; i < end; ++i) {
    if (i + kAhead < end) {
      const uint32_t b = ancestor_[i + kAhead], h = hint_[i + kAhead];
      __builtin_prefetch(&mesh.ct.VC[b]);
      __builtin_prefetch(&mesh.q[3 * size_t(b)]);
      if (h < mesh.ct.V.size())
        __builtin_prefetch(&mesh.ct.V[h]);
    }
    raise_to_fan_distance(mesh, ancestor_[i], at(q_, i), worst, hint_[i]);
  }
}

void ClusterErrorMeasure::measure(const Rebuild &rb, ThreadPool *pool) {
  const uint32_t level = global_ + measured_++;
  std::vector<double> worst(clusters_, -1.0); // -1: no vertex of the cluster is missing
  const auto clusters = [&](uint32_t begin, uint32_t end) {
    for (uint32_t c = begin; c < end; ++c)
      measure_cluster(rb, level, c, worst[c]);
  };
  const uint32_t items = (clusters_ + kClustersPerItem - 1) / kClustersPerItem;
  if (pool && items > 1)
    pool->run(items, [&](size_t i, unsigned) {
      const uint32_t begin = uint32_t(i) * kClustersPerItem;
      clusters(begin, std::min(clusters_, begin + kClustersPerItem));
    });
  else
    clusters(0, clusters_);
  for (uint32_t c = 0; c < clusters_; ++c)
    error_.push_back(worst[c] < 0 ? 0.0 : std::sqrt(worst[c]) * step_ * (1 + 1e-9) + margin_);
}
std::vector<uint8_t> ClusterErrorMeasure::section() const {
  std::vector<double> error = error_;
  const uint32_t levels = measured_;
  // A coarser level never promises less than a finer one.
  for (uint32_t k = levels; k-- > 1;)
    for (uint32_t c = 0; c < clusters_; ++c)
      error[size_t(k - 1) * clusters_ + c] =
          std::max(error[size_t(k - 1) * clusters_ + c], error[size_t(k) * clusters_ + c]);
  return write_cluster_errors(quantize_cluster_errors_octaves(global_, clusters_, error));
}

} // namespace pomar
