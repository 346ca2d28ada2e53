// Generated per-vertex attributes for tests: with_attributes() gives a mesh smooth colours,
// normals, two scalars and texture coordinates (with texture file names), deterministic.
#pragma once

#include <algorithm>
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

} // namespace pomar
