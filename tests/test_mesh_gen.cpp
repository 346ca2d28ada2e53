// Tests of the procedural test meshes (tests/support/mesh_gen.h) and of analyze().
#include "support/mesh_gen.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

namespace {

using pomar::Mesh;
using pomar::gen::analyze;
using pomar::gen::TopologyReport;

/// Checks the rules every valid generator promises, plus its expected topology.
void expect_valid(const Mesh &mesh, long euler, size_t boundary_loops, size_t components) {
  const TopologyReport r = analyze(mesh);
  EXPECT_TRUE(r.manifold) << r.nonmanifold_edges << " edges, " << r.nonmanifold_vertices
                          << " vertices";
  EXPECT_TRUE(r.oriented) << r.misoriented_edges << " misoriented edges";
  EXPECT_FALSE(r.has_repeated_vertex_face);
  EXPECT_EQ(r.out_of_range_faces, 0u);
  EXPECT_EQ(r.duplicate_faces, 0u);
  EXPECT_EQ(r.unreferenced_vertices, 0u);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.vertices, mesh.vertex_count());
  EXPECT_EQ(r.faces, mesh.triangle_count());
  EXPECT_EQ(r.euler, euler);
  EXPECT_EQ(r.boundary_loops, boundary_loops);
  EXPECT_EQ(r.closed(), boundary_loops == 0);
  EXPECT_EQ(r.components, components);
}

/// A closed, outward-facing surface made of components of the given genera.
void expect_closed(const Mesh &mesh, long genus, size_t components = 1) {
  expect_valid(mesh, 2 * static_cast<long>(components) - 2 * genus, 0, components);
  EXPECT_GT(pomar::gen::signed_volume(mesh), 0.0) << "faces point inward";
}

/// Number of faces that use vertex v.
size_t valence(const Mesh &mesh, uint32_t v) {
  size_t count = 0;
  for (uint32_t w : mesh.triangles)
    count += w == v;
  return count;
}

TEST(MeshGen, Icosphere) {
  for (int s = 0; s <= 4; ++s) {
    SCOPED_TRACE(s);
    const Mesh mesh = pomar::gen::icosphere(s);
    const size_t f = size_t(1) << (2 * s); // 4^s
    EXPECT_EQ(mesh.vertex_count(), 10 * f + 2);
    EXPECT_EQ(mesh.triangle_count(), 20 * f);
    expect_closed(mesh, 0);
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
      const float *p = &mesh.positions[3 * v];
      ASSERT_NEAR(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]), 1.0, 1e-6);
    }
  }
}

TEST(MeshGen, GeodesicSphereAnyFrequency) {
  for (int n : {1, 2, 3, 5, 7}) {
    SCOPED_TRACE(n);
    const Mesh mesh = pomar::gen::geodesic_sphere(n);
    EXPECT_EQ(mesh.vertex_count(), size_t(10 * n * n + 2));
    EXPECT_EQ(mesh.triangle_count(), size_t(20 * n * n));
    expect_closed(mesh, 0);
  }
}

TEST(MeshGen, UvSphere) {
  for (auto [rings, segments] : {std::pair{2, 3}, {3, 4}, {8, 16}, {20, 7}}) {
    SCOPED_TRACE(std::to_string(rings) + "x" + std::to_string(segments));
    const Mesh mesh = pomar::gen::uv_sphere(rings, segments);
    EXPECT_EQ(mesh.vertex_count(), size_t(2 + (rings - 1) * segments));
    EXPECT_EQ(mesh.triangle_count(), size_t(2 * segments * (rings - 1)));
    expect_closed(mesh, 0);
    EXPECT_EQ(valence(mesh, 0), size_t(segments)); // north pole
    EXPECT_EQ(valence(mesh, uint32_t(mesh.vertex_count() - 1)), size_t(segments));
  }
}

TEST(MeshGen, Torus) {
  for (auto [major, minor] : {std::pair{3, 3}, {16, 8}, {40, 12}}) {
    SCOPED_TRACE(std::to_string(major) + "x" + std::to_string(minor));
    const Mesh mesh = pomar::gen::torus(major, minor);
    EXPECT_EQ(mesh.vertex_count(), size_t(major * minor));
    EXPECT_EQ(mesh.triangle_count(), size_t(2 * major * minor));
    expect_closed(mesh, 1);
  }
  expect_closed(pomar::gen::torus(24, 10, 2.0, 1.5), 1);
}

TEST(MeshGen, MultiTorus) {
  for (int genus = 0; genus <= 7; ++genus)
    for (int resolution = 1; resolution <= 3; ++resolution) {
      SCOPED_TRACE("genus " + std::to_string(genus) + " res " + std::to_string(resolution));
      expect_closed(pomar::gen::multi_torus(genus, resolution), genus);
    }
}

TEST(MeshGen, GridWithHoles) {
  for (auto [n, holes] :
       {std::pair{2, 0}, {5, 1}, {10, 0}, {10, 1}, {10, 3}, {16, 4}, {40, 9}, {64, 20}}) {
    SCOPED_TRACE(std::to_string(n) + " holes " + std::to_string(holes));
    const Mesh mesh = pomar::gen::grid_with_holes(n, holes);
    expect_valid(mesh, 1 - holes, size_t(1 + holes), 1);
    if (holes == 0) {
      EXPECT_EQ(mesh.vertex_count(), size_t(n * n));
      EXPECT_EQ(mesh.triangle_count(), size_t(2 * (n - 1) * (n - 1)));
    }
  }
  EXPECT_THROW(pomar::gen::grid_with_holes(4, 1), std::invalid_argument);
  EXPECT_THROW(pomar::gen::grid_with_holes(8, 16), std::invalid_argument);
}

TEST(MeshGen, Components) {
  for (int count = 1; count <= 6; ++count) {
    SCOPED_TRACE(count);
    const Mesh mesh = pomar::gen::components(count);
    const long spheres = (count + 1) / 2;
    expect_valid(mesh, 2 * spheres, 0, size_t(count));
    EXPECT_GT(pomar::gen::signed_volume(mesh), 0.0);
  }
}

TEST(MeshGen, SingleTriangle) {
  const Mesh mesh = pomar::gen::single_triangle();
  EXPECT_EQ(mesh.vertex_count(), 3u);
  EXPECT_EQ(mesh.triangle_count(), 1u);
  expect_valid(mesh, 1, 1, 1);
  EXPECT_EQ(analyze(mesh).boundary_edges, 3u);
}

TEST(MeshGen, Tetrahedron) {
  const Mesh mesh = pomar::gen::tetrahedron();
  EXPECT_EQ(mesh.vertex_count(), 4u);
  EXPECT_EQ(mesh.triangle_count(), 4u);
  expect_closed(mesh, 0);
  EXPECT_NEAR(pomar::gen::signed_volume(mesh), 8.0 / 3.0, 1e-9);
}

TEST(MeshGen, NoisySphere) {
  const Mesh mesh = pomar::gen::noisy_sphere(20'000, 7);
  EXPECT_NEAR(double(mesh.vertex_count()), 20'000.0, 400.0); // 10 f^2 + 2 steps
  expect_closed(mesh, 0);
  // Deterministic in the seed, different across seeds, and actually noisy.
  EXPECT_EQ(mesh.positions, pomar::gen::noisy_sphere(20'000, 7).positions);
  EXPECT_NE(mesh.positions, pomar::gen::noisy_sphere(20'000, 8).positions);
  double min_r = 2, max_r = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const float *p = &mesh.positions[3 * v];
    const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    min_r = std::min(min_r, r);
    max_r = std::max(max_r, r);
  }
  EXPECT_LT(min_r, 0.999);
  EXPECT_GT(max_r, 1.001);
  EXPECT_GT(min_r, 0.95);
  EXPECT_LT(max_r, 1.05);
}

TEST(MeshGen, NoisySphereMillion) {
  const auto start = std::chrono::steady_clock::now();
  const Mesh mesh = pomar::gen::noisy_sphere(1'000'000, 1);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("noisy_sphere(1'000'000): %zu vertices, %zu faces in %.3f s\n", mesh.vertex_count(),
              mesh.triangle_count(), seconds);
  EXPECT_NEAR(double(mesh.vertex_count()), 1e6, 1e4);
  EXPECT_EQ(mesh.triangle_count(), 2 * mesh.vertex_count() - 4); // closed genus 0
  EXPECT_LT(seconds, 5.0); // well under 1 s optimized; generous for debug builds
  const TopologyReport r = analyze(mesh);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.euler, 2);
  EXPECT_EQ(r.components, 1u);
  EXPECT_TRUE(r.closed());
}

TEST(MeshGen, FlatDisk) {
  for (int rings = 1; rings <= 12; rings += 3) {
    SCOPED_TRACE(rings);
    const Mesh mesh = pomar::gen::flat_disk(rings);
    EXPECT_EQ(mesh.vertex_count(), size_t(1 + 3 * rings * (rings + 1)));
    EXPECT_EQ(mesh.triangle_count(), size_t(6 * rings * rings));
    expect_valid(mesh, 1, 1, 1);
    for (size_t v = 0; v < mesh.vertex_count(); ++v)
      ASSERT_EQ(mesh.positions[3 * v + 2], 0.0f);
    const double area = pomar::gen::triangle_area(mesh, 0);
    for (size_t f = 0; f < mesh.triangle_count(); ++f) {
      ASSERT_NEAR(pomar::gen::triangle_area(mesh, f), area, 1e-6 * area);
      // Facing +z: the z component of the normal is positive.
      const uint32_t *t = &mesh.triangles[3 * f];
      const float *a = &mesh.positions[3 * t[0]], *b = &mesh.positions[3 * t[1]],
                  *c = &mesh.positions[3 * t[2]];
      ASSERT_GT((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]), 0.0f);
    }
  }
}

TEST(MeshGen, DegenerateStrip) {
  const Mesh mesh = pomar::gen::degenerate_strip();
  expect_valid(mesh, 1, 1, 1);
  size_t degenerate = 0;
  for (size_t f = 0; f < mesh.triangle_count(); ++f)
    degenerate += pomar::gen::triangle_area(mesh, f) == 0.0;
  EXPECT_GE(degenerate, 1u); // and no face repeats a vertex (checked above)
}

TEST(MeshGen, NonmanifoldEdge) {
  const TopologyReport r = analyze(pomar::gen::nonmanifold_edge());
  EXPECT_FALSE(r.manifold);
  EXPECT_EQ(r.nonmanifold_edges, 1u);
  EXPECT_FALSE(r.valid());
}

TEST(MeshGen, NonmanifoldVertex) {
  const Mesh mesh = pomar::gen::nonmanifold_vertex();
  const TopologyReport r = analyze(mesh);
  EXPECT_FALSE(r.manifold);
  EXPECT_EQ(r.nonmanifold_edges, 0u);
  EXPECT_EQ(r.nonmanifold_vertices, 1u);
  EXPECT_TRUE(r.oriented);
  EXPECT_TRUE(r.closed());
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.euler, 3); // 7 - 12 + 8
  EXPECT_EQ(mesh.vertex_count(), 7u);
  EXPECT_NEAR(pomar::gen::signed_volume(mesh), 16.0 / 3.0, 1e-9);
  EXPECT_FALSE(r.valid());
}

TEST(MeshGen, FlippedFace) {
  const TopologyReport r = analyze(pomar::gen::flipped_face());
  EXPECT_TRUE(r.manifold);
  EXPECT_FALSE(r.oriented);
  EXPECT_EQ(r.misoriented_edges, 3u);
  EXPECT_FALSE(r.valid());
}

TEST(MeshGen, RepeatedVertexFace) {
  const TopologyReport r = analyze(pomar::gen::repeated_vertex_face());
  EXPECT_TRUE(r.has_repeated_vertex_face);
  EXPECT_FALSE(r.valid());
}

// analyze() on small hand-made meshes with known answers.
TEST(Analyze, DetectsProblems) {
  Mesh two = pomar::gen::single_triangle();
  pomar::gen::append(two, pomar::gen::single_triangle(), 5, 0, 0);
  EXPECT_EQ(analyze(two).components, 2u);
  EXPECT_EQ(analyze(two).boundary_loops, 2u);
  EXPECT_EQ(analyze(two).euler, 2);

  Mesh unreferenced = pomar::gen::tetrahedron();
  unreferenced.positions.insert(unreferenced.positions.end(), {9.f, 9.f, 9.f});
  EXPECT_EQ(analyze(unreferenced).unreferenced_vertices, 1u);
  EXPECT_FALSE(analyze(unreferenced).valid());

  Mesh same_direction = pomar::gen::single_triangle(); // (0,1,2) and (0,1,3)
  same_direction.positions.insert(same_direction.positions.end(), {1.f, -1.f, 0.f});
  same_direction.triangles.insert(same_direction.triangles.end(), {0, 1, 3});
  EXPECT_TRUE(analyze(same_direction).manifold);
  EXPECT_FALSE(analyze(same_direction).oriented);

  Mesh doubled = pomar::gen::single_triangle(); // (0,1,2) and (0,2,1)
  doubled.triangles.insert(doubled.triangles.end(), {0, 2, 1});
  EXPECT_EQ(analyze(doubled).duplicate_faces, 1u);
  EXPECT_FALSE(analyze(doubled).valid());

  Mesh out_of_range = pomar::gen::single_triangle();
  out_of_range.triangles[2] = 7;
  EXPECT_EQ(analyze(out_of_range).out_of_range_faces, 1u);
  EXPECT_FALSE(analyze(out_of_range).valid());

  // Two fans touching at a vertex of an open mesh (a bowtie) are caught too.
  Mesh bowtie = pomar::gen::single_triangle();
  pomar::gen::append(bowtie, pomar::gen::single_triangle(), 0, 0, 0, -1);
  bowtie.positions.erase(bowtie.positions.begin() + 9, bowtie.positions.begin() + 12);
  bowtie.triangles = {0, 1, 2, 0, 3, 4};
  const TopologyReport r = analyze(bowtie);
  EXPECT_EQ(r.nonmanifold_vertices, 1u);
  EXPECT_FALSE(r.manifold);
  EXPECT_EQ(r.boundary_loops, 1u); // one boundary graph through the pinch vertex
}

} // namespace
