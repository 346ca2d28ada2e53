// Generated per-vertex attributes for tests: with_attributes() gives a mesh smooth colours,
// normals, two scalars and texture coordinates (with texture file names), deterministic.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>

#include "pomar/pomar.h"

namespace pomar {

/// Which attributes with_attributes adds.
enum Has : int { kColour = 1, kAlpha = 2, kNormals = 4, kScalars = 8, kTexcoords = 16, kAll = 31 };

/// `m` with smooth colours (plus noise in the low bits), normals (the radial direction,
/// plus noise), scalars "quality" (smooth) and "confidence" (random), spherical UVs.
inline Mesh with_attributes(Mesh m, int has, uint32_t seed = 1) {
  const size_t nv = m.vertex_count();
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> noise(-3, 3);
  std::uniform_real_distribution<float> unit(0, 1);
  auto p = [&](size_t v, int k) { return m.positions[3 * v + k]; };
  auto make = [](AttributeKind kind, const char *name, uint32_t components) {
    VertexAttribute a;
    a.kind = kind;
    a.name = name;
    a.components = components;
    return a;
  };
  if (has & kColour) {
    VertexAttribute a = make(AttributeKind::Colour, "colour", (has & kAlpha) ? 4 : 3);
    for (size_t v = 0; v < nv; ++v)
      for (uint32_t k = 0; k < a.components; ++k) {
        const int c = int(127.5 + 120 * std::sin(2.0 * p(v, k % 3) + k)) + noise(rng);
        a.colour.push_back(static_cast<uint8_t>(std::max(0, std::min(255, c))));
      }
    m.attributes.push_back(a);
  }
  if (has & kNormals) {
    VertexAttribute a = make(AttributeKind::Normal, "normal", 3);
    for (size_t v = 0; v < nv; ++v)
      for (int k = 0; k < 3; ++k)
        a.values.push_back(p(v, k) + 0.05f * (unit(rng) - 0.5f));
    m.attributes.push_back(a);
  }
  if (has & kScalars) {
    VertexAttribute q = make(AttributeKind::Scalar, "quality", 1);
    VertexAttribute c = make(AttributeKind::Scalar, "confidence", 1);
    for (size_t v = 0; v < nv; ++v) {
      q.values.push_back(100.0f * p(v, 0) * p(v, 1) + 3.0f * p(v, 2));
      c.values.push_back(unit(rng));
    }
    m.attributes.push_back(q);
    m.attributes.push_back(c);
  }
  if (has & kTexcoords) {
    VertexAttribute a = make(AttributeKind::TexCoord, "texcoord", 2);
    for (size_t v = 0; v < nv; ++v) {
      a.values.push_back(0.5f + std::atan2(p(v, 1), p(v, 0)) / 6.2831853f);
      a.values.push_back(0.5f + 0.5f * p(v, 2));
    }
    m.attributes.push_back(a);
    m.texture_files = {"skin.png", "detail map.jpg"};
  }
  return m;
}

/// The cube-map atlas of with_cube_map_texture: kCubeMapCellsU x kCubeMapCellsV cells.
constexpr int kCubeMapCellsU = 3, kCubeMapCellsV = 2;

/// `m` with a cube-map atlas: each face goes to the chart of its normal's dominant axis and
/// sign, its corners projected onto that chart's plane in its cell of the atlas (seams
/// between the charts); charts 0-2 are material 0, charts 3-5 material 1 (two textures).
inline Mesh with_cube_map_texture(Mesh m) {
  const size_t nf = m.triangle_count();
  m.corner_texcoords.resize(6 * nf);
  m.face_materials.resize(nf);
  m.texture_files = {"atlas_a.png", "atlas b.jpg"};
  m.materials = {{"front", 0, "Kd 1 1 1\nNs 10"}, {"back", 1, "Kd 0.8 0.8 0.8"}};
  // (the corners' positions, as doubles)
  auto p = [&](uint32_t v) {
    return std::array<double, 3>{m.positions[3 * v], m.positions[3 * v + 1],
                                 m.positions[3 * v + 2]};
  };
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t *t = &m.triangles[3 * f];
    const std::array<double, 3> a = p(t[0]), b = p(t[1]), c = p(t[2]);
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
                         u[0] * w[1] - u[1] * w[0]};
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (std::fabs(n[k]) > std::fabs(n[axis]))
        axis = k;
    const int chart = axis + (n[axis] < 0 ? 3 : 0);
    m.face_materials[f] = chart < 3 ? 0 : 1;
    for (int c = 0; c < 3; ++c) {
      const std::array<double, 3> q = p(t[c]);
      const double x = q[(axis + 1) % 3], y = q[(axis + 2) % 3]; // about -1.3..1.3
      const double s = 0.5 + 0.35 * std::max(-1.4, std::min(1.4, x)) / 1.4;
      const double r = 0.5 + 0.35 * std::max(-1.4, std::min(1.4, y)) / 1.4;
      m.corner_texcoords[6 * f + 2 * c] = float((chart % kCubeMapCellsU + s) / kCubeMapCellsU);
      m.corner_texcoords[6 * f + 2 * c + 1] = float((chart / kCubeMapCellsU + r) / kCubeMapCellsV);
    }
  }
  return m;
}

} // namespace pomar
