// The stored error per cluster and level; see cluster_error_measure.h.
#include "encode/cluster_error_measure.h"

#include <algorithm>
#include <cmath>

#include "format/cluster_errors.h"
#include "pomar/limits.h"
#include "pomar/random_access.h"

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

/// Squared distance from p to the triangle abc (the closest point by its Voronoi region).
double distance2_to_triangle(V3 p, V3 a, V3 b, V3 c) {
  const V3 ab = b - a, ac = c - a, ap = p - a;
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

/// CSR lists of `items` grouped by key (keys < groups).
void group(const std::vector<uint32_t> &key, uint32_t begin, uint32_t end, uint32_t groups,
           std::vector<uint32_t> &start, std::vector<uint32_t> &list) {
  start.assign(groups + 1, 0);
  for (uint32_t v = begin; v < end; ++v)
    ++start[key[v] + 1];
  for (uint32_t g = 0; g < groups; ++g)
    start[g + 1] += start[g];
  list.resize(end - begin);
  std::vector<uint32_t> at(start.begin(), start.end() - 1);
  for (uint32_t v = begin; v < end; ++v)
    list[at[key[v]]++] = v;
}

} // namespace

std::vector<uint8_t> measure_cluster_errors(const std::vector<uint8_t> &file, unsigned threads) {
  SelectiveOptions options;
  options.attributes = AttributeMask::none();
  options.memory_limit = kNoMemoryLimit;
  options.threads = threads;
  SelectiveDecoder d(std::make_unique<MemorySource>(file.data(), file.size()), options);
  const uint32_t clusters = d.cluster_count();
  const int base = d.base_clustered_level(), finest = d.finest_level();
  const uint32_t levels = uint32_t(finest - base);
  // The faces of every stored level (the mesh decoded uniformly to it); the positions are
  // those of the full decode (a vertex keeps its position from the level that creates it).
  std::vector<std::vector<uint32_t>> faces(levels);
  std::vector<uint32_t> vertices(levels);
  for (int l = base; l <= finest; ++l) {
    if (l > base) {
      d.want_all(l);
      d.update();
    }
    if (l < finest) {
      Mesh m = d.mesh();
      vertices[size_t(l - base)] = static_cast<uint32_t>(m.vertex_count());
      faces[size_t(l - base)] = std::move(m.triangles);
    }
  }
  const Mesh full = d.mesh();
  const std::vector<uint32_t> cluster = d.vertex_cluster();
  const uint32_t nv = static_cast<uint32_t>(full.vertex_count());
  const auto at = [&](uint32_t v) {
    const float *p = full.positions.data() + 3 * size_t(v);
    return V3{p[0], p[1], p[2]};
  };
  std::vector<double> error(size_t(levels) * clusters, 0);
  std::vector<uint32_t> fan_start, fan, present_start, present, future_start, future;
  for (uint32_t k = 0; k < levels; ++k) {
    const std::vector<uint32_t> &t = faces[k];
    const uint32_t n = vertices[k];
    // The faces around each vertex of level l.
    fan_start.assign(n + 1, 0);
    for (uint32_t v : t)
      ++fan_start[v + 1];
    for (uint32_t v = 0; v < n; ++v)
      fan_start[v + 1] += fan_start[v];
    fan.resize(t.size());
    {
      std::vector<uint32_t> put(fan_start.begin(), fan_start.end() - 1);
      for (size_t i = 0; i < t.size(); ++i)
        fan[put[t[i]]++] = static_cast<uint32_t>(i / 3);
    }
    group(cluster, 0, n, clusters, present_start, present);
    group(cluster, n, nv, clusters, future_start, future);
    for (uint32_t c = 0; c < clusters; ++c) {
      double worst = 0;
      for (uint32_t i = future_start[c]; i < future_start[c + 1]; ++i) {
        const V3 p = at(future[i]);
        uint32_t nearest = UINT32_MAX;
        double best = INFINITY;
        for (uint32_t j = present_start[c]; j < present_start[c + 1]; ++j) {
          const double d2 = norm2(p - at(present[j]));
          if (d2 < best) {
            best = d2;
            nearest = present[j];
          }
        }
        if (nearest == UINT32_MAX)
          continue; // (every cluster holds its root)
        for (uint32_t j = fan_start[nearest]; j < fan_start[nearest + 1]; ++j) {
          const uint32_t *f = t.data() + 3 * size_t(fan[j]);
          best = std::min(best, distance2_to_triangle(p, at(f[0]), at(f[1]), at(f[2])));
        }
        worst = std::max(worst, best);
      }
      error[size_t(k) * clusters + c] = std::sqrt(worst);
    }
  }
  // A coarser level never promises less than a finer one.
  for (uint32_t k = levels; k-- > 1;)
    for (uint32_t c = 0; c < clusters; ++c)
      error[size_t(k - 1) * clusters + c] =
          std::max(error[size_t(k - 1) * clusters + c], error[size_t(k) * clusters + c]);
  return write_cluster_errors(quantize_cluster_errors(uint32_t(base), clusters, error));
}

} // namespace pomar
