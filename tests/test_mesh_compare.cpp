// The library's mesh comparer (mesh/mesh_compare.h), which `pomar verify` and the tests use:
// blind to the order of vertices and faces and to where a face's corners start, not to
// orientation, positions, attribute values or corner data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mesh/mesh_compare.h"
#include "support/mesh_attributes.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

/// `m` with its vertices renumbered (reversed), its faces reversed in order and each
/// face's corners rotated by one: the same mesh to the comparer.
Mesh shuffled(const Mesh &m) {
  const uint32_t n = uint32_t(m.vertex_count());
  Mesh out = m;
  for (uint32_t v = 0; v < n; ++v) {
    for (int a = 0; a < 3; ++a)
      out.positions[3 * (n - 1 - v) + a] = m.positions[3 * v + a];
    for (size_t i = 0; i < m.attributes.size(); ++i) {
      VertexAttribute &b = out.attributes[i];
      const VertexAttribute &a = m.attributes[i];
      for (uint32_t k = 0; k < a.components; ++k)
        if (a.kind == AttributeKind::Colour)
          b.colour[(n - 1 - v) * a.components + k] = a.colour[v * a.components + k];
        else
          b.values[(n - 1 - v) * a.components + k] = a.values[v * a.components + k];
    }
  }
  const size_t nf = m.triangle_count();
  for (size_t f = 0; f < nf; ++f) {
    const size_t g = nf - 1 - f;
    for (int k = 0; k < 3; ++k) {
      out.triangles[3 * g + k] = n - 1 - m.triangles[3 * f + (k + 1) % 3];
      if (!m.corner_texcoords.empty())
        for (int c = 0; c < 2; ++c)
          out.corner_texcoords[6 * g + 2 * k + c] =
              m.corner_texcoords[6 * f + 2 * ((k + 1) % 3) + c];
    }
    if (!m.face_materials.empty())
      out.face_materials[g] = m.face_materials[f];
  }
  return out;
}

TEST(MeshCompare, GeometryIgnoresOrderButNotOrientationOrPositions) {
  const Mesh m = gen::icosphere(2);
  const Mesh s = shuffled(m);
  EXPECT_NE(s.triangles, m.triangles);
  EXPECT_EQ(canonical_triangles(s), canonical_triangles(m));
  EXPECT_TRUE(same_geometry(m, s, false));

  Mesh flipped = m;
  std::swap(flipped.triangles[1], flipped.triangles[2]);
  EXPECT_FALSE(same_geometry(m, flipped, false));

  Mesh moved = m;
  moved.positions[4] += 1e-3f;
  EXPECT_FALSE(same_geometry(m, moved, false));

  Mesh extra = m; // one more vertex, no face uses it: only triangles_only ignores it
  extra.positions.insert(extra.positions.end(), {5, 5, 5});
  EXPECT_FALSE(same_geometry(m, extra, false));
  EXPECT_TRUE(same_geometry(m, extra, true));
}

TEST(MeshCompare, AttributeErrorsByPosition) {
  const Mesh m = with_attributes(gen::icosphere(2), kColour | kNormals | kScalars);
  const Mesh s = shuffled(m);
  const VerticesByPosition at = vertices_by_position(m);
  for (const VertexAttribute &a : m.attributes) {
    const VertexAttribute *b = s.find(a.kind, a.name);
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(worst_attribute_error(at, a, s, *b, true), 0) << a.name;
  }
  Mesh off = s;
  VertexAttribute *normal = off.find(AttributeKind::Normal);
  ASSERT_NE(normal, nullptr);
  // One normal turned by 1 degree about z: at most 1 degree off (less out of the xy plane).
  const double angle = M_PI / 180.0;
  float *x = &normal->values[3 * 7];
  const float nx = x[0], ny = x[1];
  x[0] = float(nx * std::cos(angle) - ny * std::sin(angle));
  x[1] = float(nx * std::sin(angle) + ny * std::cos(angle));
  const double worst =
      worst_attribute_error(at, *m.find(AttributeKind::Normal), off, *normal, false);
  EXPECT_GT(worst, 0.0);
  EXPECT_LE(worst, 1.0 + 1e-3);
  // Compared as exact values: the largest component difference.
  EXPECT_EQ(worst_attribute_error(at, *m.find(AttributeKind::Normal), off, *normal, true),
            std::max(std::fabs(double(x[0]) - double(nx)), std::fabs(double(x[1]) - double(ny))));
  VertexAttribute *colour = off.find(AttributeKind::Colour);
  colour->colour[0] = uint8_t(colour->colour[0] ^ 0x04);
  EXPECT_EQ(worst_attribute_error(at, *m.find(AttributeKind::Colour), off, *colour, true), 4.0);
}

TEST(MeshCompare, CornersMatchedThroughTheRotationOfTheirFace) {
  const Mesh m = with_cube_map_texture(gen::icosphere(2));
  const Mesh s = shuffled(m);
  CornerDifference d = compare_corners(m, corner_uvs(m), s, corner_uvs(s), true, true);
  EXPECT_EQ(d.worst_uv_error, 0);
  EXPECT_EQ(d.material_mismatches, 0u);

  Mesh off = s;
  off.corner_texcoords[3] += 0.25f;
  off.face_materials[5] = 1 - off.face_materials[5];
  d = compare_corners(m, corner_uvs(m), off, corner_uvs(off), false, true);
  EXPECT_NEAR(d.worst_uv_error, 0.25, 1e-6);
  EXPECT_EQ(d.material_mismatches, 1u);
  // Without names, materials count by their texture file (the two charts have different ones).
  EXPECT_EQ(compare_corners(m, {}, off, {}, false, false).material_mismatches, 1u);
}

} // namespace
} // namespace pomar
