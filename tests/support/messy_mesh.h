// Messy meshes for the repair and lossless tests: non-orientable surfaces and random
// broken meshes (pinches, edges of three or more faces, reversed, repeated and degenerate
// faces).
#pragma once

#include <cmath>
#include <cstdint>

#include "support/mesh_gen.h"

namespace pomar {
namespace gen {

/// A Moebius strip of n quads (2n triangles) around the z axis, half a twist.
inline Mesh moebius(int n) {
  Mesh m;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < n; ++i) {
    const double u = 2 * pi * i / n;
    for (double s : {-0.3, 0.3}) // vertex 2i: s = -0.3, vertex 2i+1: s = +0.3
      detail::add_vertex(m, (1 + s * std::cos(u / 2)) * std::cos(u),
                         (1 + s * std::cos(u / 2)) * std::sin(u), s * std::sin(u / 2));
  }
  for (int i = 0; i < n; ++i) {
    const uint32_t a = 2 * i, b = 2 * i + 1;
    // After a full turn the strip comes back upside down: the two sides swap.
    const bool last = i == n - 1;
    const uint32_t c = last ? 1 : 2 * i + 2, d = last ? 0 : 2 * i + 3;
    detail::add_face(m, a, c, d);
    detail::add_face(m, a, d, b);
  }
  return m;
}

/// A Klein bottle: an n x m grid of quads whose columns wrap around plainly and whose
/// last row is glued to the first one mirrored. Closed and not orientable.
inline Mesh klein_bottle(int n, int m) {
  Mesh k;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i)
      detail::add_vertex(k, i, j, (i * 7 + j * 3) % 5);
  auto id = [&](int i, int j) {
    i %= n;
    if (j == m) { // the mirrored seam
      j = 0;
      i = (n - i) % n;
    }
    return static_cast<uint32_t>(j * n + i);
  };
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i) {
      detail::add_face(k, id(i, j), id(i + 1, j), id(i + 1, j + 1));
      detail::add_face(k, id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return k;
}

/// Random triangle soup: `faces` triangles over `vertices` vertices (so edges and
/// vertices are shared in every possible wrong way), some degenerate and duplicate faces.
inline Mesh soup(uint32_t seed, uint32_t vertices, uint32_t faces) {
  Mesh m;
  uint64_t key = 0;
  auto pick = [&](uint32_t n) { return static_cast<uint32_t>(detail::unit_hash(seed, key++) * n); };
  for (uint32_t v = 0; v < vertices; ++v)
    detail::add_vertex(m, pick(1000) / 100.0, pick(1000) / 100.0, pick(1000) / 100.0);
  for (uint32_t f = 0; f < faces; ++f) {
    if (f > 0 && pick(10) == 0) { // repeat an earlier face, rotated or reversed
      const uint32_t g = pick(f);
      const uint32_t *t = &m.triangles[3 * g];
      if (pick(2))
        detail::add_face(m, t[1], t[2], t[0]);
      else
        detail::add_face(m, t[0], t[2], t[1]);
    } else {
      detail::add_face(m, pick(vertices), pick(vertices), pick(vertices));
    }
  }
  return m;
}

/// A mesh broken the way real files are: an open disk whose vertices are glued in random
/// pairs (pinches, edges of three or more faces, seams of either orientation, faces that
/// collapse), some faces reversed and some repeated.
inline Mesh glued_disk(uint32_t seed) {
  Mesh m = flat_disk(2 + seed % 2);
  uint64_t key = 1u << 20;
  auto pick = [&](uint32_t n) { return static_cast<uint32_t>(detail::unit_hash(seed, key++) * n); };
  const uint32_t nv = static_cast<uint32_t>(m.vertex_count());
  for (uint32_t k = 0, glues = 1 + seed % 5; k < glues; ++k) {
    const uint32_t from = pick(nv), to = pick(nv);
    for (uint32_t &v : m.triangles)
      if (v == from)
        v = to;
  }
  const size_t nf = m.triangle_count();
  for (size_t f = 0; f < nf; ++f)
    if (pick(8) == 0)
      std::swap(m.triangles[3 * f + 1], m.triangles[3 * f + 2]);
  for (uint32_t k = 0, repeats = seed % 3; k < repeats; ++k) {
    const uint32_t *t = &m.triangles[3 * pick(uint32_t(nf))];
    detail::add_face(m, t[1], t[2], t[0]);
  }
  return m;
}

} // namespace gen
} // namespace pomar
