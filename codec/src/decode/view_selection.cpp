// View-dependent requests (SelectiveDecoder::want_view, view_levels): the level each
// cluster needs so that its error, projected to the screen, stays within a pixel budget.
// The error is the file's stored bound (section CERR, format/cluster_errors.h) or, without
// one, the longest edge of the cluster's faces, the web client's proxy (web/view_refine.js).
#include <algorithm>
#include <cmath>

#include "pomar/random_access.h"

namespace pomar {

namespace {

struct Box {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  void add(const float *p) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], double(p[k]));
      hi[k] = std::max(hi[k], double(p[k]));
    }
  }
  bool empty() const { return lo[0] > hi[0]; }
};

/// Does the box lie entirely outside one plane of the clip volume of `m`?
bool outside_frustum(const float *m, const double *lo, const double *hi) {
  for (int axis = 0; axis < 3; ++axis)
    for (int sign = -1; sign <= 1; sign += 2) {
      double p[4];
      for (int col = 0; col < 4; ++col)
        p[col] = double(m[4 * col + 3]) + sign * double(m[4 * col + axis]);
      const double x = p[0] >= 0 ? hi[0] : lo[0];
      const double y = p[1] >= 0 ? hi[1] : lo[1];
      const double z = p[2] >= 0 ? hi[2] : lo[2];
      if (p[0] * x + p[1] * y + p[2] * z + p[3] < 0)
        return true;
    }
  return false;
}

double distance_to_box(const float *eye, const double *lo, const double *hi) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({lo[k] - double(eye[k]), 0.0, double(eye[k]) - hi[k]});
    d2 += d * d;
  }
  return std::sqrt(d2);
}

} // namespace

std::vector<int> SelectiveDecoder::view_levels(const ViewCamera &camera, float pixel_error) const {
  const uint32_t n = cluster_count();
  const int base = base_clustered_level(), finest = finest_level();
  if (n == 0)
    return {finest};
  const Mesh m = mesh();
  const std::vector<uint32_t> cluster = vertex_cluster();
  const std::vector<int> &current = levels();
  // Per cluster: the box of the faces touching it and (no stored error) its longest edge.
  std::vector<Box> box(n);
  std::vector<double> edge(n, 0);
  const float *p = m.positions.data();
  for (size_t f = 0; f + 2 < m.triangles.size(); f += 3) {
    const uint32_t v[3] = {m.triangles[f], m.triangles[f + 1], m.triangles[f + 2]};
    double longest = 0;
    for (int k = 0; k < 3; ++k) {
      const float *a = p + 3 * size_t(v[k]), *b = p + 3 * size_t(v[(k + 1) % 3]);
      const double dx = double(a[0]) - b[0], dy = double(a[1]) - b[1], dz = double(a[2]) - b[2];
      longest = std::max(longest, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t c = cluster[v[k]];
      for (int j = 0; j < 3; ++j)
        box[c].add(p + 3 * size_t(v[j]));
      edge[c] = std::max(edge[c], longest);
    }
  }
  for (uint32_t v = 0; v < cluster.size(); ++v)
    box[cluster[v]].add(p + 3 * size_t(v));
  const bool stored = has_cluster_errors();
  const std::vector<LevelInfo> &table = info().levels;
  const auto faces = [&](int l) { return double(l == 0 ? info().base_faces : table[l - 1].faces); };
  const auto error = [&](uint32_t c, int l) {
    if (l >= finest)
      return 0.0;
    if (stored)
      return cluster_error(c, l);
    return edge[c] * std::sqrt(faces(current[c]) / faces(l));
  };
  const double pixels_per_unit = double(camera.height) / (2 * std::tan(double(camera.fov_y) / 2));
  std::vector<int> out(n, base);
  for (uint32_t c = 0; c < n; ++c) {
    if (box[c].empty())
      continue;
    const double grow = error(c, current[c]);
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = box[c].lo[k] - grow;
      hi[k] = box[c].hi[k] + grow;
    }
    if (outside_frustum(camera.view_proj, lo, hi))
      continue;
    const double to_pixels = pixels_per_unit / std::max(double(camera.near_distance),
                                                        distance_to_box(camera.eye, lo, hi));
    int l = base;
    while (l < finest && error(c, l) * to_pixels > double(pixel_error))
      ++l;
    out[c] = l;
  }
  return out;
}

void SelectiveDecoder::want_view(const ViewCamera &camera, float pixel_error) {
  if (cluster_count() == 0) {
    want_all(finest_level());
    return;
  }
  set_wanted(view_levels(camera, pixel_error));
}

} // namespace pomar
