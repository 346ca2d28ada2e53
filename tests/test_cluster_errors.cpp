// The stored error per cluster and level (section CERR), view-dependent requests
// (SelectiveDecoder::want_view) and the spatial block order (section BLKO).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "format/block_order.h"
#include "format/cluster_errors.h"
#include "format/file_format.h"
#include "pomar/pomar.h"
#include "pomar/random_access.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

std::vector<uint8_t> encode_with(const Mesh &m, bool layout, bool errors, double ratio = 0.02,
                                 int bits = 12) {
  EncodeOptions o;
  o.bits = bits;
  o.cluster_ratio = ratio;
  o.spatial_layout = layout;
  o.cluster_errors = errors;
  return encode(m, o);
}

const Mesh &sphere() {
  static const Mesh m = gen::noisy_sphere(12000, 7, 0.3);
  return m;
}
const std::vector<uint8_t> &sphere_file() {
  static const std::vector<uint8_t> f = encode_with(sphere(), true, true);
  return f;
}

std::unique_ptr<SelectiveDecoder> open(const std::vector<uint8_t> &f) {
  return std::make_unique<SelectiveDecoder>(std::make_unique<MemorySource>(f.data(), f.size()));
}

double distance_to_triangle(const float *p, const float *a, const float *b, const float *c) {
  // Brute force on a fine barycentric grid plus the exact edge and vertex cases is too
  // slow; use the projection onto the plane when inside, else the closest edge point.
  auto sub = [](const float *x, const float *y, double *o) {
    for (int k = 0; k < 3; ++k)
      o[k] = double(x[k]) - y[k];
  };
  auto dot = [](const double *x, const double *y) {
    return x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
  };
  double ab[3], ac[3], ap[3];
  sub(b, a, ab);
  sub(c, a, ac);
  sub(p, a, ap);
  const double n[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
                       ab[0] * ac[1] - ab[1] * ac[0]};
  const double nn = dot(n, n);
  auto segment = [&](const float *s, const float *t) {
    double st[3], sp[3];
    sub(t, s, st);
    sub(p, s, sp);
    const double len = dot(st, st);
    const double u = len > 0 ? std::clamp(dot(sp, st) / len, 0.0, 1.0) : 0.0;
    const double d[3] = {sp[0] - u * st[0], sp[1] - u * st[1], sp[2] - u * st[2]};
    return std::sqrt(dot(d, d));
  };
  double best = std::min({segment(a, b), segment(b, c), segment(c, a)});
  if (nn > 0) {
    const double t = dot(ap, n) / nn;
    const double q[3] = {ap[0] - t * n[0], ap[1] - t * n[1], ap[2] - t * n[2]}; // in plane, from a
    // Barycentric coordinates of q in (ab, ac).
    const double d00 = dot(ab, ab), d01 = dot(ab, ac), d11 = dot(ac, ac);
    const double d20 = dot(q, ab), d21 = dot(q, ac), den = d00 * d11 - d01 * d01;
    if (den > 0) {
      const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
      if (v >= 0 && w >= 0 && v + w <= 1)
        best = std::min(best, std::fabs(t) * std::sqrt(nn));
    }
  }
  return best;
}

/// Every 23rd vertex a level does not have yet (three levels): its distance to the whole
/// level surface (every face) against its cluster's stored bound; the bounds never grow
/// toward the finer levels. The sample must measure something (more than `min_nonzero` of
/// the distances above 0) and the bound must not be vacuous (the largest distance / bound
/// above `min_ratio`).
void expect_stored_bound_holds(const std::vector<uint8_t> &f, double min_nonzero,
                               double min_ratio) {
  auto full_d = open(f);
  full_d->want_all(full_d->finest_level());
  full_d->update();
  const Mesh full = full_d->mesh();
  const std::vector<uint32_t> cluster = full_d->vertex_cluster();
  auto d = open(f);
  ASSERT_TRUE(d->has_cluster_errors());
  const int base = d->base_clustered_level(), finest = d->finest_level();
  ASSERT_GT(finest, base + 2);
  size_t checked = 0, nonzero = 0;
  double worst_ratio = 0;
  for (int l : {base, (base + finest) / 2, finest - 1}) {
    d->clear_wanted();
    d->want_all(l);
    d->update();
    const Mesh m = d->mesh();
    const uint32_t n = static_cast<uint32_t>(m.vertex_count());
    // Every 23rd vertex the level does not have yet: its distance to the whole level-l
    // surface (every face) against its cluster's stored bound.
    for (uint32_t v = n; v < full.vertex_count(); v += 23) {
      double dist = INFINITY;
      for (size_t t = 0; t < m.triangle_count(); ++t)
        dist = std::min(dist, distance_to_triangle(&full.positions[3 * v],
                                                   &m.positions[3 * m.triangles[3 * t]],
                                                   &m.positions[3 * m.triangles[3 * t + 1]],
                                                   &m.positions[3 * m.triangles[3 * t + 2]]));
      const double bound = d->cluster_error(cluster[v], l);
      EXPECT_LE(dist, bound * (1 + 1e-6) + 1e-7) << "vertex " << v << " level " << l;
      ++checked;
      nonzero += dist > 0;
      if (bound > 0)
        worst_ratio = std::max(worst_ratio, dist / bound);
    }
    // Coarser levels never promise less; the finest level is exact.
    for (uint32_t c = 0; c < d->cluster_count(); c += 5)
      EXPECT_GE(d->cluster_error(c, l), d->cluster_error(c, l + 1));
  }
  EXPECT_EQ(d->cluster_error(0, finest), 0.0);
  EXPECT_GT(checked, 300u);
  EXPECT_GT(double(nonzero), min_nonzero * double(checked));
  EXPECT_GT(worst_ratio, min_ratio);
}

TEST(ClusterErrors, TheStoredBoundHoldsOnASample) {
  expect_stored_bound_holds(sphere_file(), 0.5, 0.2);
}

// A 4-bit grid: many faces of the levels are degenerate (their distance computations give
// NaN), which must settle no vertex's distance.
TEST(ClusterErrors, TheStoredBoundHoldsOnACoarseGrid) {
  expect_stored_bound_holds(encode_with(sphere(), true, true, 0.02, 4), 0.2, 0.05);
}

TEST(ClusterErrors, QuantizedCodesRoundUp) {
  const std::vector<double> errors = {0, 1e-9, 0.5, 1.0, 3.0, 0.0, 2.0, 7.0};
  const ClusterErrors q = quantize_cluster_errors(5, 4, errors);
  ASSERT_EQ(q.levels(), 2u);
  for (uint32_t k = 0; k < 2; ++k)
    for (uint32_t c = 0; c < 4; ++c) {
      const double e = errors[4 * k + c], b = q.bound(c, int(5 + k));
      EXPECT_GE(b, e);
      // One code step (2^(1/8)) at most, or the finer level's bound (never less than it).
      const double finer = k + 1 < 2 ? q.bound(c, int(6 + k)) : 0.0;
      EXPECT_LE(b, std::max({e * 1.0906, double(q.scale[k]), finer * 1.0906}));
    }
  EXPECT_EQ(q.bound(0, 7), 0.0); // the finest level
}

TEST(ClusterErrors, OctaveCodesRoundUpAndNeverGrowWithTheLevel) {
  // Level-major, 3 levels x 4 clusters; cluster 3 grows with the level (not what the
  // measure gives, but the codes must still bound it).
  const std::vector<double> errors = {0, 1e-30, 0.5, 1.0, 0, 1e-9, 3.0, 2.0, 0, 0, 7.0, 4.0};
  const ClusterErrors q = quantize_cluster_errors_octaves(5, 4, errors);
  ASSERT_EQ(q.levels(), 3u);
  EXPECT_EQ(q.version, 2);
  for (uint32_t k = 0; k < 3; ++k)
    for (uint32_t c = 0; c < 4; ++c) {
      const double e = errors[4 * k + c], b = q.bound(c, int(5 + k));
      EXPECT_GE(b, e) << k << " " << c;
      if (e == 0) {
        EXPECT_EQ(b, 0.0);
      }
      if (k + 1 < 3) {
        EXPECT_GE(b, q.bound(c, int(6 + k))); // never grows with the level
      }
      // One octave at most, or the smallest nonzero bound, or the finer level's.
      const double finer = k + 1 < 3 ? q.bound(c, int(6 + k)) : 0.0;
      EXPECT_LE(b, std::max({2 * e, octave_error_bound(q.scale[0], 1), finer}));
    }
  EXPECT_EQ(q.bound(2, 8), 0.0); // the finest level
  EXPECT_GE(octave_error_bound(q.scale[0], kOctaveCodes - 1), 7.0);
  // Written and read back: the same codes.
  const std::vector<uint8_t> body = write_cluster_errors(q);
  EXPECT_EQ(body[0], 2);
  FileLayout layout;
  layout.header.global_levels = 5;
  layout.header.clusters = 4;
  layout.header.levels.resize(8);
  layout.header.flags = kFlagClustered;
  const ClusterErrors r = read_cluster_errors(body.data(), body.size(), layout);
  EXPECT_EQ(r.version, 2);
  EXPECT_EQ(r.code, q.code);
  EXPECT_EQ(r.scale, q.scale);
  // Version 1 codes still write and read as version 1.
  const ClusterErrors v1 = quantize_cluster_errors(5, 4, errors);
  const std::vector<uint8_t> body1 = write_cluster_errors(v1);
  EXPECT_EQ(body1[0], 1);
  const ClusterErrors r1 = read_cluster_errors(body1.data(), body1.size(), layout);
  EXPECT_EQ(r1.code, v1.code);
  for (uint32_t c = 0; c < 4; ++c)
    EXPECT_EQ(r1.bound(c, 6), v1.bound(c, 6));
}

TEST(ClusterErrors, FilesWithoutTheSectionsStillOpenAndViewFallsBackToEdges) {
  const std::vector<uint8_t> plain = encode_with(sphere(), false, false);
  const FileLayout plain_layout = read_layout(plain.data(), plain.size());
  EXPECT_LT(find_section(plain_layout, kClusterErrorsTag), 0); // neither section
  EXPECT_LT(find_section(plain_layout, kBlockOrderTag), 0);
  auto d = open(plain);
  EXPECT_FALSE(d->has_cluster_errors());
  EXPECT_EQ(d->cluster_error(0, d->base_clustered_level()), -1.0);
  // The mesh decodes as the file with both sections decodes it, vertex for vertex.
  auto e = open(sphere_file());
  d->want_all(d->finest_level());
  e->want_all(e->finest_level());
  d->update();
  e->update();
  const Mesh a = d->mesh(), b = e->mesh();
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.triangles, b.triangles);
  const Mesh da = decode(plain.data(), plain.size()),
             db = decode(sphere_file().data(), sphere_file().size());
  EXPECT_EQ(da.positions, db.positions);
  EXPECT_EQ(da.triangles, db.triangles);
}

/// A camera at `eye` looking at `target` (OpenGL conventions, column-major).
ViewCamera look_at(const float eye[3], const float target[3], float fov_y, float w, float h) {
  ViewCamera cam;
  std::copy(eye, eye + 3, cam.eye);
  cam.fov_y = fov_y;
  cam.width = w;
  cam.height = h;
  cam.near_distance = 0.01f;
  double f[3] = {target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]};
  const double fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  for (double &x : f)
    x /= fl;
  const double up[3] = {0, 1, 0};
  double s[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2],
                 f[0] * up[1] - f[1] * up[0]};
  const double sl = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  for (double &x : s)
    x /= sl;
  const double u[3] = {s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2],
                       s[0] * f[1] - s[1] * f[0]};
  double view[16] = {s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0, 0, 0, 0, 1};
  view[12] = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
  view[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
  view[14] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
  const double t = 1 / std::tan(fov_y / 2), n = 0.01, fa = 100;
  const double proj[16] = {
      t * h / w, 0, 0, 0, 0, t, 0, 0, 0, 0, (fa + n) / (n - fa), -1, 0, 0, 2 * fa * n / (n - fa),
      0};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      double v = 0;
      for (int k = 0; k < 4; ++k)
        v += proj[4 * k + r] * view[4 * c + k];
      cam.view_proj[4 * c + r] = float(v);
    }
  return cam;
}

TEST(ClusterErrors, WantViewRefinesWhatIsNearAndInView) {
  for (bool stored : {true, false}) {
    const std::vector<uint8_t> f = stored ? sphere_file() : encode_with(sphere(), true, false);
    auto d = open(f);
    ASSERT_EQ(d->has_cluster_errors(), stored);
    const int base = d->base_clustered_level();
    const Mesh m = d->mesh();
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t i = 0; i < m.positions.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], m.positions[i]);
      hi[i % 3] = std::max(hi[i % 3], m.positions[i]);
    }
    const float size = hi[0] - lo[0];
    const float centre[3] = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
    // Close to the +Z side, looking at it.
    const float eye[3] = {centre[0], centre[1], hi[2] + 0.15f * size};
    const float at[3] = {centre[0], centre[1], hi[2]};
    const ViewCamera cam = look_at(eye, at, 0.8f, 800, 457);
    d->want_view(cam, 20); // (a noisy sphere: at 3 pixels every side in view is at the finest)
    d->update();
    const std::vector<int> levels = d->levels(), wanted = d->wanted();
    const std::vector<uint32_t> vc = d->vertex_cluster();
    // The root of each cluster: its side of the sphere.
    double front = 0, back = 0;
    int front_n = 0, back_n = 0;
    for (uint32_t c = 0; c < d->cluster_count(); ++c) {
      const float z = m.positions[3 * c + 2];
      if (z > hi[2] - 0.1f * size) {
        front += wanted[c];
        ++front_n;
      }
      if (z < lo[2] + 0.1f * size) { // (asked for: the level map rule may raise it)
        back += wanted[c];
        ++back_n;
      }
    }
    ASSERT_TRUE(front_n > 0 && back_n > 0);
    front /= front_n;
    back /= back_n;
    EXPECT_GT(front, base + 2) << (stored ? "stored" : "edge");
    EXPECT_LT(back + 1, front) << (stored ? "stored" : "edge"); // the far side, coarser
    EXPECT_GT(*std::max_element(levels.begin(), levels.end()), base + 2);
    // Looking away from the model: nothing in the frustum, everything at the base level.
    const float away[3] = {eye[0], eye[1], eye[2] + size};
    const std::vector<int> none = d->view_levels(look_at(eye, away, 0.8f, 800, 457), 3);
    EXPECT_TRUE(std::all_of(none.begin(), none.end(), [&](int l) { return l == base; }));
    // A larger budget never asks for more.
    const std::vector<int> fine = d->view_levels(cam, 5), coarse = d->view_levels(cam, 40);
    for (uint32_t c = 0; c < d->cluster_count(); ++c)
      EXPECT_LE(coarse[c], fine[c]);
    EXPECT_LT(std::accumulate(coarse.begin(), coarse.end(), 0L),
              std::accumulate(fine.begin(), fine.end(), 0L));
  }
}

TEST(ClusterErrors, BlocksLieInMortonOrderAndEveryReaderFindsThem) {
  const std::vector<uint8_t> &f = sphere_file();
  const FileLayout layout = read_layout(f.data(), f.size());
  ASSERT_GE(find_section(layout, kBlockOrderTag), 0);
  EXPECT_TRUE(layout.header.sections[size_t(find_section(layout, kBlockOrderTag))].flags &
              kSectionRequired);
  auto d = open(f);
  const uint32_t n = d->cluster_count();
  std::vector<uint32_t> by_offset(n);
  std::iota(by_offset.begin(), by_offset.end(), 0u);
  std::sort(by_offset.begin(), by_offset.end(),
            [&](uint32_t a, uint32_t b) { return d->block_offset(a) < d->block_offset(b); });
  EXPECT_FALSE(std::is_sorted(by_offset.begin(), by_offset.end())); // not in id order
  const Mesh base = d->mesh();
  std::vector<int32_t> q(3 * size_t(n));
  for (uint32_t i = 0; i < 3 * n; ++i)
    q[i] = int32_t(layout.header.grid.quantize(int(i % 3), base.positions[i]));
  EXPECT_EQ(by_offset, morton_block_order(q, n, layout.header.grid.bits));
  uint64_t at = layout.clusters_offset;
  for (uint32_t c : by_offset) { // contiguous, in that order
    EXPECT_EQ(d->block_offset(c), at);
    at += d->block_size(c);
  }
  EXPECT_EQ(at, f.size());
  EXPECT_TRUE(check_blocks(f.data(), f.size()).empty());
  // Sections added later keep the blocks where they are.
  const std::vector<uint8_t> g =
      with_sections(f.data(), f.size(), {{section_tag("ZZZZ"), 0, {1, 2, 3}}});
  EXPECT_TRUE(check_blocks(g.data(), g.size()).empty());
  const Mesh a = decode(f.data(), f.size()), b = decode(g.data(), g.size());
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.triangles, b.triangles);
}

std::vector<uint8_t> replaced(const std::vector<uint8_t> &f, uint32_t tag,
                              std::vector<uint8_t> body) {
  const FileLayout layout = read_layout(f.data(), f.size());
  const uint32_t flags = layout.header.sections[size_t(find_section(layout, tag))].flags;
  return with_sections(f.data(), f.size(), {{tag, flags, std::move(body)}});
}

void expect_refused(const std::vector<uint8_t> &f, const char *name) {
  try {
    // CERR is read when a stored error is first asked for, not at open (BLKO at open).
    auto d = open(f);
    d->cluster_error(0, d->base_clustered_level());
    ADD_FAILURE() << "read a file with a damaged " << name;
  } catch (const Error &e) {
    EXPECT_EQ(e.kind(), Error::Kind::DamagedFile) << e.what();
    EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
  }
  EXPECT_THROW(check_blocks(f.data(), f.size()), Error);
}

TEST(ClusterErrors, ADamagedSectionIsRefusedByName) {
  const std::vector<uint8_t> &f = sphere_file();
  const FileLayout layout = read_layout(f.data(), f.size());
  const int i = find_section(layout, kClusterErrorsTag);
  ASSERT_GE(i, 0);
  EXPECT_EQ(layout.header.sections[size_t(i)].flags, 0u); // optional
  std::vector<uint8_t> body(
      f.begin() + long(layout.section_offset[size_t(i)]),
      f.begin() + long(layout.section_offset[size_t(i)] + layout.header.sections[size_t(i)].bytes));
  // A flipped byte: the section's checksum fails.
  std::vector<uint8_t> flipped = f;
  flipped[layout.section_offset[size_t(i)] + body.size() / 2] ^= 0x40;
  expect_refused(flipped, "CERR");
  // Checksums right, contents wrong: another cluster count, a cut stream, a bad scale.
  std::vector<uint8_t> other = body;
  other[9] ^= 1; // the cluster count's low byte
  expect_refused(replaced(f, kClusterErrorsTag, other), "CERR");
  std::vector<uint8_t> cut(body.begin(), body.begin() + long(body.size() / 3));
  expect_refused(replaced(f, kClusterErrorsTag, cut), "CERR");
  std::vector<uint8_t> nan = body;
  nan[13] = nan[14] = nan[15] = nan[16] = 0xFF;
  expect_refused(replaced(f, kClusterErrorsTag, nan), "CERR");
  expect_refused(replaced(f, kBlockOrderTag, {1, 7}), "BLKO");
}

} // namespace
} // namespace pomar
