// Procedural test meshes for pomar, and an independent topology checker.
//
// Every generator in namespace pomar::gen returns a pomar::Mesh that is manifold and
// consistently oriented (each directed edge used at most once, closed surfaces facing
// outward, counter-clockwise seen from outside), with no face repeating a vertex, no
// duplicate faces and no unreferenced vertices -- except the generators in the
// "invalid inputs" section, which break exactly one of these rules on purpose.
//
// analyze() recomputes the topology of any mesh from scratch (sorted edge keys,
// union-find, per-vertex fan connectivity) so tests can check the generators and the
// codec's output without trusting either.
//
// Header-only, C++17, no dependencies beyond pomar/pomar.h and the standard library.
#pragma once

#include "pomar/pomar.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pomar {
namespace gen {

// ---------------------------------------------------------------------------------
// Small helpers
// ---------------------------------------------------------------------------------

namespace detail {

using Vec3 = std::array<double, 3>;

constexpr double kPi = 3.14159265358979323846;

/// Throws std::invalid_argument with `message` unless `condition` holds.
inline void require(bool condition, const char *message) {
  if (!condition)
    throw std::invalid_argument(std::string("pomar::gen: ") + message);
}

inline uint32_t add_vertex(Mesh &mesh, double x, double y, double z) {
  const auto index = static_cast<uint32_t>(mesh.vertex_count());
  mesh.positions.push_back(static_cast<float>(x));
  mesh.positions.push_back(static_cast<float>(y));
  mesh.positions.push_back(static_cast<float>(z));
  return index;
}

inline uint32_t add_vertex(Mesh &mesh, const Vec3 &p) { return add_vertex(mesh, p[0], p[1], p[2]); }

inline void add_face(Mesh &mesh, uint32_t a, uint32_t b, uint32_t c) {
  mesh.triangles.push_back(a);
  mesh.triangles.push_back(b);
  mesh.triangles.push_back(c);
}

/// Adds the quad a,b,c,d (counter-clockwise) as the triangles (a,b,c) and (a,c,d).
inline void add_quad(Mesh &mesh, uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  add_face(mesh, a, b, c);
  add_face(mesh, a, c, d);
}

inline Vec3 sub(const Vec3 &a, const Vec3 &b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

inline Vec3 cross(const Vec3 &a, const Vec3 &b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

inline double dot(const Vec3 &a, const Vec3 &b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

inline Vec3 normalized(const Vec3 &a) {
  const double length = std::sqrt(dot(a, a));
  return {a[0] / length, a[1] / length, a[2] / length};
}

/// a + t * (b - a)
inline Vec3 lerp(const Vec3 &a, const Vec3 &b, double t) {
  return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
}

inline Vec3 position(const Mesh &mesh, uint32_t v) {
  const float *p = &mesh.positions[3 * static_cast<size_t>(v)];
  return {p[0], p[1], p[2]};
}

/// SplitMix64 finalizer: a well-mixed 64-bit hash, identical on every platform.
inline uint64_t mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// Deterministic uniform value in [0, 1) for (seed, key).
inline double unit_hash(uint32_t seed, uint64_t key) {
  const uint64_t h = mix64(mix64(key) ^ (static_cast<uint64_t>(seed) << 32 | seed));
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); // 53 bits
}

/// Disjoint-set forest with path halving and union by index (good enough here).
class UnionFind {
public:
  explicit UnionFind(size_t n = 0) { reset(n); }
  /// Back to n singletons (reuses the storage).
  void reset(size_t n) {
    parent_.resize(n);
    for (size_t i = 0; i < n; ++i)
      parent_[i] = static_cast<uint32_t>(i);
  }
  uint32_t find(uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b)
      parent_[std::max(a, b)] = std::min(a, b);
  }

private:
  std::vector<uint32_t> parent_;
};

/// Packs an ordered pair of vertex indices into one sortable key.
inline uint64_t edge_key(uint32_t from, uint32_t to) {
  return static_cast<uint64_t>(from) << 32 | to;
}

/// The 12 unit vectors of a regular icosahedron and its 20 faces, oriented outward.
/// The faces are found rather than typed in: they are exactly the triples of mutually
/// adjacent vertices (edge length 2 before normalization).
struct Icosahedron {
  std::array<Vec3, 12> vertices;
  std::vector<std::array<uint32_t, 3>> faces;
};

inline Icosahedron make_icosahedron() {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  Icosahedron ico;
  int k = 0;
  for (double s : {-1.0, 1.0})
    for (double t : {-phi, phi}) {
      ico.vertices[k++] = {0.0, s, t}; // (0, +-1, +-phi)
      ico.vertices[k++] = {s, t, 0.0}; // (+-1, +-phi, 0)
      ico.vertices[k++] = {t, 0.0, s}; // (+-phi, 0, +-1)
    }
  auto adjacent = [&](int a, int b) {
    const Vec3 d = sub(ico.vertices[a], ico.vertices[b]);
    return std::abs(dot(d, d) - 4.0) < 1e-9;
  };
  for (uint32_t a = 0; a < 12; ++a)
    for (uint32_t b = a + 1; b < 12; ++b)
      for (uint32_t c = b + 1; c < 12; ++c) {
        if (!adjacent(a, b) || !adjacent(b, c) || !adjacent(a, c))
          continue;
        // The solid is centered on the origin: outward means the normal points away
        // from it.
        const Vec3 &pa = ico.vertices[a];
        const Vec3 n = cross(sub(ico.vertices[b], pa), sub(ico.vertices[c], pa));
        if (dot(n, pa) > 0)
          ico.faces.push_back({a, b, c});
        else
          ico.faces.push_back({a, c, b});
      }
  for (Vec3 &v : ico.vertices)
    v = normalized(v);
  return ico;
}

} // namespace detail

// ---------------------------------------------------------------------------------
// Utilities usable by tests
// ---------------------------------------------------------------------------------

/// Appends `src` to `dst`, scaling its positions by `scale` and then translating them.
inline void append(Mesh &dst, const Mesh &src, double dx = 0, double dy = 0, double dz = 0,
                   double scale = 1) {
  const auto offset = static_cast<uint32_t>(dst.vertex_count());
  const double shift[3] = {dx, dy, dz};
  for (size_t i = 0; i < src.positions.size(); ++i)
    dst.positions.push_back(static_cast<float>(src.positions[i] * scale + shift[i % 3]));
  for (uint32_t v : src.triangles)
    dst.triangles.push_back(v + offset);
}

/// Area of triangle `face` (computed in double from the float positions).
inline double triangle_area(const Mesh &mesh, size_t face) {
  using namespace detail;
  const uint32_t *t = &mesh.triangles[3 * face];
  const Vec3 a = position(mesh, t[0]);
  const Vec3 n = cross(sub(position(mesh, t[1]), a), sub(position(mesh, t[2]), a));
  return 0.5 * std::sqrt(dot(n, n));
}

/// Signed enclosed volume (divergence theorem). Positive for a closed mesh whose faces
/// are counter-clockwise seen from outside.
inline double signed_volume(const Mesh &mesh) {
  using namespace detail;
  double six_volume = 0;
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    const uint32_t *t = &mesh.triangles[3 * f];
    six_volume += dot(position(mesh, t[0]), cross(position(mesh, t[1]), position(mesh, t[2])));
  }
  return six_volume / 6.0;
}

// ---------------------------------------------------------------------------------
// Closed surfaces
// ---------------------------------------------------------------------------------

/// Geodesic sphere of the given frequency: every icosahedron face is split into
/// frequency^2 triangles on a regular barycentric grid, then all vertices are projected
/// onto the unit sphere. Vertices on icosahedron edges and corners are shared.
/// 10 * frequency^2 + 2 vertices, 20 * frequency^2 faces; valence 6 except 12 vertices
/// of valence 5.
inline Mesh geodesic_sphere(int frequency) {
  using namespace detail;
  require(frequency >= 1, "geodesic_sphere: frequency must be >= 1");
  const Icosahedron ico = make_icosahedron();
  const auto n = static_cast<uint32_t>(frequency);

  Mesh mesh;
  mesh.positions.reserve(3 * (10 * static_cast<size_t>(n) * n + 2));
  mesh.triangles.reserve(3 * 20 * static_cast<size_t>(n) * n);

  // Corners: indices 0..11.
  for (const Vec3 &v : ico.vertices)
    add_vertex(mesh, v);

  // Edges: n-1 interior points each, stored from the lower to the higher corner index.
  std::array<std::array<uint32_t, 12>, 12> edge_base{};
  for (const auto &f : ico.faces)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = std::min(f[k], f[(k + 1) % 3]);
      const uint32_t b = std::max(f[k], f[(k + 1) % 3]);
      if (edge_base[a][b] != 0)
        continue; // already created from the neighbouring face
      edge_base[a][b] = static_cast<uint32_t>(mesh.vertex_count());
      for (uint32_t t = 1; t < n; ++t)
        add_vertex(mesh, normalized(lerp(ico.vertices[a], ico.vertices[b], double(t) / n)));
    }
  // Index of the point at parameter t (0 < t < n) on the edge from corner `from`.
  auto edge_point = [&](uint32_t from, uint32_t to, uint32_t t) {
    return from < to ? edge_base[from][to] + (t - 1) : edge_base[to][from] + (n - t - 1);
  };

  // Faces: grid point (i, j) is A + i/n (B - A) + j/n (C - A), for i + j <= n.
  std::vector<uint32_t> grid(static_cast<size_t>(n + 1) * (n + 1));
  auto at = [&](uint32_t i, uint32_t j) -> uint32_t & { return grid[i * (n + 1) + j]; };
  for (const auto &f : ico.faces) {
    const uint32_t A = f[0], B = f[1], C = f[2];
    for (uint32_t i = 0; i <= n; ++i)
      for (uint32_t j = 0; i + j <= n; ++j) {
        if (i == 0 && j == 0)
          at(i, j) = A;
        else if (i == n)
          at(i, j) = B;
        else if (j == n)
          at(i, j) = C;
        else if (j == 0)
          at(i, j) = edge_point(A, B, i);
        else if (i == 0)
          at(i, j) = edge_point(A, C, j);
        else if (i + j == n)
          at(i, j) = edge_point(B, C, j);
        else {
          const Vec3 &a = ico.vertices[A], &b = ico.vertices[B], &c = ico.vertices[C];
          const double s = double(i) / n, t = double(j) / n;
          const Vec3 q = {a[0] + s * (b[0] - a[0]) + t * (c[0] - a[0]),
                          a[1] + s * (b[1] - a[1]) + t * (c[1] - a[1]),
                          a[2] + s * (b[2] - a[2]) + t * (c[2] - a[2])};
          at(i, j) = add_vertex(mesh, normalized(q));
        }
      }
    // "Up" triangles have the orientation of (A, B, C); so do the "down" ones.
    for (uint32_t i = 0; i < n; ++i)
      for (uint32_t j = 0; i + j < n; ++j) {
        add_face(mesh, at(i, j), at(i + 1, j), at(i, j + 1));
        if (i + j + 2 <= n)
          add_face(mesh, at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
  }
  return mesh;
}

/// Subdivided icosahedron on the unit sphere: 10 * 4^s + 2 vertices, 20 * 4^s faces
/// (the connectivity of s rounds of 1-to-4 midpoint subdivision).
inline Mesh icosphere(int subdivisions) {
  detail::require(subdivisions >= 0 && subdivisions <= 12,
                  "icosphere: subdivisions must be in 0..12");
  return geodesic_sphere(1 << subdivisions);
}

/// Latitude/longitude sphere of radius 1: `rings` latitude bands (>= 2) and `segments`
/// meridians (>= 3). The poles have valence `segments`.
/// 2 + (rings - 1) * segments vertices, 2 * segments * (rings - 1) faces.
inline Mesh uv_sphere(int rings, int segments) {
  using namespace detail;
  require(rings >= 2 && segments >= 3, "uv_sphere: needs rings >= 2 and segments >= 3");
  const auto nr = static_cast<uint32_t>(rings), ns = static_cast<uint32_t>(segments);
  Mesh mesh;
  const uint32_t north = add_vertex(mesh, 0, 0, 1);
  for (uint32_t i = 1; i < nr; ++i) { // ring i at polar angle i * pi / rings
    const double theta = kPi * i / nr;
    for (uint32_t j = 0; j < ns; ++j) {
      const double phi = 2 * kPi * j / ns;
      add_vertex(mesh, std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                 std::cos(theta));
    }
  }
  const uint32_t south = add_vertex(mesh, 0, 0, -1);
  auto ring = [&](uint32_t i, uint32_t j) { return 1 + (i - 1) * ns + j % ns; };

  for (uint32_t j = 0; j < ns; ++j) // north cap, CCW seen from +z
    add_face(mesh, north, ring(1, j), ring(1, j + 1));
  for (uint32_t i = 1; i + 1 < nr; ++i) // bands: i above, i + 1 below
    for (uint32_t j = 0; j < ns; ++j)
      add_quad(mesh, ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1));
  for (uint32_t j = 0; j < ns; ++j) // south cap, CCW seen from -z
    add_face(mesh, south, ring(nr - 1, j + 1), ring(nr - 1, j));
  return mesh;
}

/// Torus around the z axis: major radius R, minor radius r (0 < r < R), an
/// n_major x n_minor quad grid split into triangles. n_major * n_minor vertices,
/// 2 * n_major * n_minor faces, genus 1.
inline Mesh torus(int n_major, int n_minor, double R = 1.0, double r = 0.35) {
  using namespace detail;
  require(n_major >= 3 && n_minor >= 3, "torus: needs n_major >= 3 and n_minor >= 3");
  require(r > 0 && r < R, "torus: needs 0 < r < R");
  const auto nu = static_cast<uint32_t>(n_major), nv = static_cast<uint32_t>(n_minor);
  Mesh mesh;
  for (uint32_t i = 0; i < nu; ++i) {
    const double u = 2 * kPi * i / nu;
    for (uint32_t j = 0; j < nv; ++j) {
      const double v = 2 * kPi * j / nv;
      const double w = R + r * std::cos(v);
      add_vertex(mesh, w * std::cos(u), w * std::sin(u), r * std::sin(v));
    }
  }
  auto id = [&](uint32_t i, uint32_t j) { return (i % nu) * nv + j % nv; };
  // d/du x d/dv points away from the tube's core circle, so (u, v)-CCW is outward.
  for (uint32_t i = 0; i < nu; ++i)
    for (uint32_t j = 0; j < nv; ++j)
      add_quad(mesh, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
  return mesh;
}

namespace detail {

/// Boundary surface of a set of unit voxels on an nx x ny x nz lattice, each exposed
/// voxel face split into two triangles, lattice points shared. `filled(x, y, z)` must
/// describe a solid without diagonal-only contacts (two voxels sharing only an edge or
/// a corner), which is what makes the surface manifold. Positions are lattice
/// coordinates times `scale`.
template <class Filled> Mesh voxel_surface(int nx, int ny, int nz, double scale, Filled filled) {
  const int dims[3] = {nx, ny, nz};
  auto inside = [&](const int p[3]) {
    for (int a = 0; a < 3; ++a)
      if (p[a] < 0 || p[a] >= dims[a])
        return false;
    return filled(p[0], p[1], p[2]);
  };
  Mesh mesh;
  std::vector<uint32_t> index(static_cast<size_t>(nx + 1) * (ny + 1) * (nz + 1), UINT32_MAX);
  auto lattice_vertex = [&](const int p[3]) {
    uint32_t &slot = index[(static_cast<size_t>(p[2]) * (ny + 1) + p[1]) * (nx + 1) + p[0]];
    if (slot == UINT32_MAX)
      slot = add_vertex(mesh, p[0] * scale, p[1] * scale, p[2] * scale);
    return slot;
  };
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        const int cell[3] = {x, y, z};
        if (!inside(cell))
          continue;
        for (int axis = 0; axis < 3; ++axis)
          for (int side : {-1, 1}) {
            int neighbour[3] = {x, y, z};
            neighbour[axis] += side;
            if (inside(neighbour))
              continue;
            // Face in the plane p[axis] = cell[axis] (+1 on the positive side), spanned
            // by e_u, e_v with e_u x e_v = e_axis.
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            int p[4][3];
            for (auto &corner : p)
              std::copy(cell, cell + 3, corner);
            for (auto &corner : p)
              corner[axis] += side > 0 ? 1 : 0;
            p[1][u] += 1;
            p[2][u] += 1;
            p[2][v] += 1;
            p[3][v] += 1;
            uint32_t q[4];
            for (int k = 0; k < 4; ++k)
              q[k] = lattice_vertex(p[k]);
            if (side > 0)
              add_quad(mesh, q[0], q[1], q[2], q[3]);
            else
              add_quad(mesh, q[0], q[3], q[2], q[1]);
          }
      }
  return mesh;
}

} // namespace detail

/// Closed surface of genus `genus`: the boundary of a thick plate pierced by `genus`
/// square through-holes laid out on a near-square grid. Built as a voxel surface, so
/// hole walls and the rim share their lattice vertices with the top and bottom faces
/// (no T-junctions). With s = resolution: holes are 2s cells wide, bars between and
/// around them s cells, the plate s cells thick; one cell = 1/s units.
inline Mesh multi_torus(int genus, int resolution) {
  using namespace detail;
  require(genus >= 0, "multi_torus: genus must be >= 0");
  require(resolution >= 1, "multi_torus: resolution must be >= 1");
  const int s = resolution, hole = 2 * s, bar = s, pitch = hole + bar;
  int cols = 1;
  while (cols * cols < genus)
    ++cols;
  const int rows = genus == 0 ? 1 : (genus + cols - 1) / cols;
  const int nx = cols * pitch + bar, ny = rows * pitch + bar, nz = s;

  // Returns the slot of coordinate c along an axis with `count` slots, or -1 on a bar.
  auto slot = [&](int c, int count) {
    const int offset = c - bar;
    if (offset < 0 || offset % pitch >= hole || offset / pitch >= count)
      return -1;
    return offset / pitch;
  };
  auto filled = [&](int x, int y, int) {
    const int sx = slot(x, cols), sy = slot(y, rows);
    return sx < 0 || sy < 0 || sy * cols + sx >= genus;
  };
  Mesh mesh = voxel_surface(nx, ny, nz, 1.0 / s, filled);
  // Center the plate on the origin.
  const double center[3] = {0.5 * nx / s, 0.5 * ny / s, 0.5 * nz / s};
  for (size_t i = 0; i < mesh.positions.size(); ++i)
    mesh.positions[i] = static_cast<float>(mesh.positions[i] - center[i % 3]);
  return mesh;
}

/// Several disjoint closed components in one mesh, placed along the x axis: even
/// positions hold icospheres (genus 0), odd ones tori (genus 1), all of different
/// sizes. Euler characteristic: 2 * ((count + 1) / 2).
inline Mesh components(int count) {
  detail::require(count >= 1, "components: count must be >= 1");
  Mesh mesh;
  for (int c = 0; c < count; ++c) {
    const double x = 3.0 * c;
    if (c % 2 == 0)
      append(mesh, icosphere(1 + c % 3), x, 0, 0, 0.6 + 0.1 * (c % 4));
    else
      append(mesh, torus(12 + 2 * (c % 3), 6 + c % 4, 1.0, 0.3), x, 0, 0, 0.7 + 0.05 * c);
  }
  return mesh;
}

/// One counter-clockwise triangle in the z = 0 plane (facing +z).
inline Mesh single_triangle() {
  Mesh mesh;
  detail::add_vertex(mesh, 0, 0, 0);
  detail::add_vertex(mesh, 1, 0, 0);
  detail::add_vertex(mesh, 0, 1, 0);
  detail::add_face(mesh, 0, 1, 2);
  return mesh;
}

/// Regular tetrahedron inscribed in the cube [-1, 1]^3, faces outward.
inline Mesh tetrahedron() {
  Mesh mesh;
  detail::add_vertex(mesh, 1, 1, 1);
  detail::add_vertex(mesh, 1, -1, -1);
  detail::add_vertex(mesh, -1, 1, -1);
  detail::add_vertex(mesh, -1, -1, 1);
  // det(v1 - v0, v2 - v0, v3 - v0) < 0, so these are the outward orientations.
  detail::add_face(mesh, 0, 1, 2);
  detail::add_face(mesh, 0, 3, 1);
  detail::add_face(mesh, 0, 2, 3);
  detail::add_face(mesh, 1, 3, 2);
  return mesh;
}

/// Large closed genus-0 mesh for benchmarks: a geodesic sphere with about
/// `target_vertices` vertices (exactly 10 f^2 + 2 for the nearest frequency f), each
/// vertex moved radially by a deterministic pseudo-random amount of up to
/// +-`relative_noise` times the mean edge length. Same (target, seed) -> same mesh.
inline Mesh noisy_sphere(size_t target_vertices, uint32_t seed, double relative_noise = 0.2) {
  const double f = std::sqrt(std::max(0.0, (double(target_vertices) - 2.0) / 10.0));
  const int frequency = std::max(1, static_cast<int>(std::lround(f)));
  Mesh mesh = geodesic_sphere(frequency);
  const double amplitude = relative_noise * 1.1 / frequency; // mean edge ~ 1.1 / f
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const double scale = 1.0 + amplitude * (2.0 * detail::unit_hash(seed, v) - 1.0);
    for (int a = 0; a < 3; ++a)
      mesh.positions[3 * v + a] = static_cast<float>(mesh.positions[3 * v + a] * scale);
  }
  return mesh;
}

// ---------------------------------------------------------------------------------
// Open surfaces
// ---------------------------------------------------------------------------------

/// n x n vertex grid over [0, 2 pi]^2 with z = 0.1 sin(x) cos(y), facing +z, with
/// `holes` square holes cut out (faces removed, unreferenced vertices dropped and the
/// rest renumbered). Holes sit on a near-square layout, separated from each other and
/// from the border by at least one intact cell, so the result is manifold with
/// 1 + holes boundary loops and Euler characteristic 1 - holes.
inline Mesh grid_with_holes(int n, int holes) {
  using namespace detail;
  require(n >= 2 && holes >= 0, "grid_with_holes: needs n >= 2 and holes >= 0");
  const int cells = n - 1;
  int layout = 0; // holes per row/column of the layout
  while (layout * layout < holes)
    ++layout;
  // Holes live in cells 1 .. cells - 2: each gets `pitch` cells, of which `side` are cut.
  const int pitch = layout == 0 ? 0 : (cells - 2) / layout;
  require(holes == 0 || pitch >= 2, "grid_with_holes: grid too small for that many holes");
  const int side = pitch / 2;
  auto slot = [&](int c) { // slot of cell coordinate c, or -1 if not in a hole
    const int offset = c - 1 - (pitch - side) / 2;
    if (layout == 0 || offset < 0 || offset % pitch >= side || offset / pitch >= layout)
      return -1;
    return offset / pitch;
  };
  auto cut = [&](int i, int j) {
    const int si = slot(i), sj = slot(j);
    return si >= 0 && sj >= 0 && sj * layout + si < holes;
  };

  // Faces over the full grid numbering, then compact.
  std::vector<uint32_t> triangles;
  auto id = [&](int i, int j) { return static_cast<uint32_t>(j * n + i); };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      if (cut(i, j))
        continue;
      const uint32_t q[4] = {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)};
      for (uint32_t v : {q[0], q[1], q[2], q[0], q[2], q[3]})
        triangles.push_back(v);
    }
  std::vector<uint32_t> remap(static_cast<size_t>(n) * n, UINT32_MAX);
  for (uint32_t v : triangles)
    remap[v] = 0;
  Mesh mesh;
  const double step = 2 * kPi / cells;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (remap[id(i, j)] == UINT32_MAX)
        continue;
      const double x = i * step, y = j * step;
      remap[id(i, j)] = add_vertex(mesh, x, y, 0.1 * std::sin(x) * std::cos(y));
    }
  mesh.triangles.reserve(triangles.size());
  for (uint32_t v : triangles)
    mesh.triangles.push_back(remap[v]);
  return mesh;
}

/// Perfectly flat disk (all z = 0): the triangular-lattice hexagon of radius `rings`
/// (scaled to radius 1), made of equilateral triangles facing +z.
/// 1 + 3 rings (rings + 1) vertices, 6 rings^2 faces, one boundary loop.
inline Mesh flat_disk(int rings) {
  using namespace detail;
  require(rings >= 1, "flat_disk: rings must be >= 1");
  const int N = rings, width = 2 * N + 1;
  // Axial lattice coordinates (q, r), |q|, |r|, |q + r| <= N.
  auto in_hexagon = [&](int q, int r) {
    return std::abs(q) <= N && std::abs(r) <= N && std::abs(q + r) <= N;
  };
  std::vector<uint32_t> index(static_cast<size_t>(width) * width, UINT32_MAX);
  auto at = [&](int q, int r) -> uint32_t & { return index[(r + N) * width + (q + N)]; };
  Mesh mesh;
  const double h = std::sqrt(3.0) / 2.0;
  for (int r = -N; r <= N; ++r)
    for (int q = -N; q <= N; ++q)
      if (in_hexagon(q, r))
        at(q, r) = add_vertex(mesh, (q + 0.5 * r) / N, h * r / N, 0.0);
  auto try_face = [&](int q0, int r0, int q1, int r1, int q2, int r2) {
    if (in_hexagon(q0, r0) && in_hexagon(q1, r1) && in_hexagon(q2, r2))
      add_face(mesh, at(q0, r0), at(q1, r1), at(q2, r2));
  };
  for (int r = -N; r < N; ++r)
    for (int q = -N; q <= N; ++q) {
      try_face(q, r, q + 1, r, q, r + 1);         // pointing up, CCW
      try_face(q + 1, r, q + 1, r + 1, q, r + 1); // pointing down, CCW
    }
  return mesh;
}

/// Small open manifold disk containing a zero-area triangle (A, B, C) with three
/// distinct collinear vertices (B is the midpoint of AC). Valid input: it must
/// round-trip. Layout (z = 0 except where noted):
///
///          D
///        /   \            (A, C, D) above the segment AC,
///   F - A - B - C - G     (A, B, C) degenerate, lying on AC,
///        \  |  /          (A, E, B), (B, E, C) below it,
///          E              plus a ring of ordinary faces through F and G.
inline Mesh degenerate_strip() {
  using namespace detail;
  Mesh mesh;
  const uint32_t A = add_vertex(mesh, 0, 0, 0);
  const uint32_t B = add_vertex(mesh, 1, 0, 0);
  const uint32_t C = add_vertex(mesh, 2, 0, 0);
  const uint32_t D = add_vertex(mesh, 1, 1, 0.1);
  const uint32_t E = add_vertex(mesh, 1, -1, -0.1);
  const uint32_t F = add_vertex(mesh, -1, 0, 0.05);
  const uint32_t G = add_vertex(mesh, 3, 0, 0.05);
  add_face(mesh, A, C, D); // above AC
  add_face(mesh, A, B, C); // zero area
  add_face(mesh, A, E, B); // below
  add_face(mesh, B, E, C);
  add_face(mesh, F, A, D); // left wing
  add_face(mesh, F, E, A);
  add_face(mesh, C, G, D); // right wing
  add_face(mesh, C, E, G);
  return mesh;
}

// ---------------------------------------------------------------------------------
// Invalid inputs (for error tests)
// ---------------------------------------------------------------------------------

/// Three triangles sharing the edge (0, 1): a non-manifold edge.
inline Mesh nonmanifold_edge() {
  using namespace detail;
  Mesh mesh;
  add_vertex(mesh, 0, 0, 0);
  add_vertex(mesh, 1, 0, 0);
  add_vertex(mesh, 0.5, 1, 0);
  add_vertex(mesh, 0.5, -1, 0);
  add_vertex(mesh, 0.5, 0, 1);
  add_face(mesh, 0, 1, 2);
  add_face(mesh, 1, 0, 3);
  add_face(mesh, 1, 0, 4);
  return mesh;
}

/// Two outward tetrahedra sharing exactly one vertex: every edge is manifold, the
/// shared vertex is not (its faces form two separate fans).
inline Mesh nonmanifold_vertex() {
  const Mesh tet = tetrahedron();
  Mesh mesh = tet;
  // Second copy reflected through vertex 0 = (1, 1, 1): p -> 2 * (1,1,1) - p. Vertex 0
  // maps onto itself and the copy lies in x + y + z >= 3, touching the first one only
  // there. A 3D point reflection reverses orientation, so each face is flipped back.
  const uint32_t remap[4] = {0, 4, 5, 6};
  for (uint32_t v = 1; v < 4; ++v)
    for (int a = 0; a < 3; ++a)
      mesh.positions.push_back(2.0f - tet.positions[3 * v + a]);
  for (size_t f = 0; f < tet.triangle_count(); ++f)
    for (int k : {0, 2, 1})
      mesh.triangles.push_back(remap[tet.triangles[3 * f + k]]);
  return mesh;
}

/// icosphere(1) with the orientation of its first face reversed.
inline Mesh flipped_face() {
  Mesh mesh = icosphere(1);
  std::swap(mesh.triangles[1], mesh.triangles[2]);
  return mesh;
}

/// A valid triangle (1, 2, 3) plus the face (0, 0, 1), which repeats vertex 0.
inline Mesh repeated_vertex_face() {
  using namespace detail;
  Mesh mesh;
  add_vertex(mesh, 0, 0, 0);
  add_vertex(mesh, 1, 0, 0);
  add_vertex(mesh, 1, 1, 0);
  add_vertex(mesh, 0, 1, 0);
  add_face(mesh, 1, 2, 3);
  add_face(mesh, 0, 0, 1);
  return mesh;
}

// ---------------------------------------------------------------------------------
// Topology checker
// ---------------------------------------------------------------------------------

/// Topology of a mesh, computed by analyze(). Faces that repeat a vertex or use an
/// out-of-range index are counted in `faces` and flagged, but left out of everything
/// else (edges, fans, components, Euler characteristic).
struct TopologyReport {
  size_t vertices = 0;       ///< vertex_count()
  size_t faces = 0;          ///< triangle_count()
  size_t boundary_edges = 0; ///< undirected edges with exactly one face
  size_t boundary_loops = 0; ///< connected components of the boundary-edge graph
  size_t components = 0;     ///< connected components of faces (sharing a vertex)
  long euler = 0;            ///< referenced vertices - edges + faces
  bool manifold = true;      ///< every edge in <= 2 faces, every vertex one fan
  bool oriented = true;      ///< every directed edge used at most once
  bool has_repeated_vertex_face = false;

  // Details beyond the basic report.
  size_t edges = 0;                 ///< undirected edges
  size_t nonmanifold_edges = 0;     ///< edges in 3 or more faces
  size_t nonmanifold_vertices = 0;  ///< vertices whose faces form several fans
  size_t misoriented_edges = 0;     ///< directed edges used more than once
  size_t unreferenced_vertices = 0; ///< vertices used by no (valid) face
  size_t duplicate_faces = 0;       ///< faces on the same vertex set as an earlier one
  size_t out_of_range_faces = 0;    ///< faces with an index >= vertices

  bool closed() const { return boundary_edges == 0; }
  /// What pomar::encode accepts as topologically valid input.
  bool valid() const {
    return manifold && oriented && !has_repeated_vertex_face && out_of_range_faces == 0 &&
           duplicate_faces == 0 && unreferenced_vertices == 0 && faces > 0;
  }
};

namespace detail {

using Faces = std::vector<std::array<uint32_t, 3>>;

/// Items 0..count-1 grouped by key(item) in [0, keys), by counting sort: the items of
/// key k are items[start[k] .. start[k + 1]). Linear time, which keeps analyze() fast
/// on million-face meshes even in unoptimized builds.
struct Buckets {
  std::vector<uint32_t> start, items;
  uint32_t size(size_t k) const { return start[k + 1] - start[k]; }
  const uint32_t *begin(size_t k) const { return items.data() + start[k]; }
  const uint32_t *end(size_t k) const { return items.data() + start[k + 1]; }
};

template <class KeyOf> Buckets bucket(size_t keys, size_t count, KeyOf key_of) {
  Buckets b;
  b.start.assign(keys + 1, 0);
  for (size_t i = 0; i < count; ++i)
    ++b.start[key_of(i) + 1];
  for (size_t k = 0; k < keys; ++k)
    b.start[k + 1] += b.start[k];
  b.items.resize(count);
  std::vector<uint32_t> fill(b.start.begin(), b.start.end() - 1);
  for (size_t i = 0; i < count; ++i)
    b.items[fill[key_of(i)]++] = static_cast<uint32_t>(i);
  return b;
}

/// Sorts a short vector (insertion sort up to 32 items, std::sort beyond).
inline void sort_small(std::vector<uint64_t> &v) {
  if (v.size() > 32) {
    std::sort(v.begin(), v.end());
    return;
  }
  for (size_t i = 1; i < v.size(); ++i)
    for (size_t j = i; j > 0 && v[j] < v[j - 1]; --j)
      std::swap(v[j], v[j - 1]);
}

/// Fills edges, boundary_edges, nonmanifold_edges, misoriented_edges and
/// boundary_loops. Half-edges are grouped by their lower vertex; within a group, equal
/// upper vertices are the faces of one undirected edge.
inline void analyze_edges(const Faces &faces, size_t vertex_count, TopologyReport &report) {
  auto from = [&](size_t h) { return faces[h / 3][h % 3]; };
  auto to = [&](size_t h) { return faces[h / 3][(h + 1) % 3]; };
  const Buckets by_low =
      bucket(vertex_count, 3 * faces.size(), [&](size_t h) { return std::min(from(h), to(h)); });

  UnionFind boundary(vertex_count);
  std::vector<bool> on_boundary(vertex_count, false);
  std::vector<uint64_t> group; // (upper vertex << 1) | (half-edge runs low -> high)
  for (uint32_t low = 0; low < vertex_count; ++low) {
    group.clear();
    for (const uint32_t *h = by_low.begin(low); h != by_low.end(low); ++h)
      group.push_back(uint64_t(std::max(from(*h), to(*h))) << 1 | (from(*h) == low));
    sort_small(group);
    for (size_t i = 0; i < group.size();) {
      const uint64_t high = group[i] >> 1;
      size_t forward = 0, backward = 0;
      for (; i < group.size() && group[i] >> 1 == high; ++i) {
        if (group[i] & 1)
          ++forward;
        else
          ++backward;
      }
      ++report.edges;
      report.misoriented_edges +=
          (forward > 1 ? forward - 1 : 0) + (backward > 1 ? backward - 1 : 0);
      if (forward + backward > 2)
        ++report.nonmanifold_edges;
      if (forward + backward == 1) {
        ++report.boundary_edges;
        boundary.unite(low, static_cast<uint32_t>(high));
        on_boundary[low] = on_boundary[high] = true;
      }
    }
  }
  for (uint32_t v = 0; v < vertex_count; ++v)
    if (on_boundary[v] && boundary.find(v) == v)
      ++report.boundary_loops;
}

/// Counts vertices whose incident faces do not form a single fan. Around vertex v each
/// face (v, a, b) contributes the link edge a-b; the faces form one fan (a disk or a
/// half-disk) exactly when this link graph is connected.
inline size_t count_nonmanifold_vertices(const Faces &faces, size_t vertex_count) {
  const Buckets incident =
      bucket(vertex_count, 3 * faces.size(), [&](size_t c) { return faces[c / 3][c % 3]; });
  size_t bad = 0;
  std::vector<uint64_t> link; // neighbours of v, sorted, unique
  UnionFind fans;
  for (uint32_t v = 0; v < vertex_count; ++v) {
    if (incident.size(v) == 0)
      continue;
    link.clear();
    for (const uint32_t *c = incident.begin(v); c != incident.end(v); ++c)
      for (uint32_t w : faces[*c / 3])
        if (w != v)
          link.push_back(w);
    sort_small(link);
    link.erase(std::unique(link.begin(), link.end()), link.end());
    auto local = [&](uint32_t w) {
      return static_cast<uint32_t>(std::lower_bound(link.begin(), link.end(), w) - link.begin());
    };
    fans.reset(link.size());
    for (const uint32_t *c = incident.begin(v); c != incident.end(v); ++c) {
      const auto &f = faces[*c / 3];
      const uint32_t at = *c % 3; // corner of v in f
      fans.unite(local(f[(at + 1) % 3]), local(f[(at + 2) % 3]));
    }
    size_t groups = 0;
    for (uint32_t i = 0; i < link.size(); ++i)
      groups += fans.find(i) == i;
    bad += groups != 1;
  }
  return bad;
}

/// Number of faces whose vertex set (ignoring order) equals that of an earlier face.
inline size_t count_duplicate_faces(const Faces &faces, size_t vertex_count) {
  auto sorted = [&](size_t f) {
    std::array<uint32_t, 3> t = faces[f];
    std::sort(t.begin(), t.end());
    return t;
  };
  const Buckets by_low = bucket(vertex_count, faces.size(), [&](size_t f) { return sorted(f)[0]; });
  size_t duplicates = 0;
  std::vector<uint64_t> rest; // the two higher vertices of each face in the bucket
  for (uint32_t low = 0; low < vertex_count; ++low) {
    rest.clear();
    for (const uint32_t *f = by_low.begin(low); f != by_low.end(low); ++f) {
      const auto t = sorted(*f);
      rest.push_back(edge_key(t[1], t[2]));
    }
    sort_small(rest);
    for (size_t i = 1; i < rest.size(); ++i)
      duplicates += rest[i] == rest[i - 1];
  }
  return duplicates;
}

} // namespace detail

/// Recomputes the topology of `mesh` from scratch, in linear time (counting sorts
/// plus small per-vertex sorts).
inline TopologyReport analyze(const Mesh &mesh) {
  using namespace detail;
  TopologyReport report;
  report.vertices = mesh.vertex_count();
  report.faces = mesh.triangle_count();
  const size_t nv = report.vertices;

  // Keep the faces the edge and fan analysis can use.
  Faces faces;
  faces.reserve(report.faces);
  for (size_t f = 0; f < report.faces; ++f) {
    const std::array<uint32_t, 3> t = {mesh.triangles[3 * f], mesh.triangles[3 * f + 1],
                                       mesh.triangles[3 * f + 2]};
    if (t[0] >= nv || t[1] >= nv || t[2] >= nv)
      ++report.out_of_range_faces;
    else if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      report.has_repeated_vertex_face = true;
    else
      faces.push_back(t);
  }

  analyze_edges(faces, nv, report);
  report.nonmanifold_vertices = count_nonmanifold_vertices(faces, nv);
  report.duplicate_faces = count_duplicate_faces(faces, nv);

  // Components and referenced vertices.
  UnionFind parts(nv);
  std::vector<bool> referenced(nv, false);
  for (const auto &f : faces) {
    parts.unite(f[0], f[1]);
    parts.unite(f[0], f[2]);
    referenced[f[0]] = referenced[f[1]] = referenced[f[2]] = true;
  }
  size_t used = 0;
  for (uint32_t v = 0; v < nv; ++v) {
    used += referenced[v];
    report.components += referenced[v] && parts.find(v) == v;
  }
  report.unreferenced_vertices = nv - used;

  report.euler =
      static_cast<long>(used) - static_cast<long>(report.edges) + static_cast<long>(faces.size());
  report.manifold = report.nonmanifold_edges == 0 && report.nonmanifold_vertices == 0;
  report.oriented = report.misoriented_edges == 0;
  return report;
}

} // namespace gen
} // namespace pomar
