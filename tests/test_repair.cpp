// make_manifold() (codec/src/repair): exact counts on small cases, validity of the result
// (the codec's own check and the independent checker of mesh_gen.h) and a lossless
// round trip of the repaired mesh through encode/decode.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "mesh/corner_table.h"
#include "pomar/pomar.h"
#include "pomar/repair.h"
#include "support/mesh_compare.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

using gen::detail::add_face;
using gen::detail::add_vertex;

/// The counts of a report as one comparable tuple: degenerate, duplicate, flipped,
/// cut (of which non-orientable), split, added.
std::vector<size_t> counts(const RepairReport &r) {
  return {r.degenerate_faces_removed, r.duplicate_faces_removed, r.faces_flipped, r.edges_cut,
          r.edges_cut_nonorientable,  r.vertices_split,          r.vertices_added};
}

/// The repaired mesh is valid for the codec and for the independent checker, and it
/// round-trips losslessly: the decoded triangles are the repaired ones on the file's grid.
void expect_valid_and_lossless(const Mesh &repaired) {
  CornerTable ct;
  ASSERT_NO_THROW(build_corner_table(repaired.triangles.data(), repaired.triangle_count(),
                                     repaired.vertex_count(), ct));
  const gen::TopologyReport topo = gen::analyze(repaired);
  EXPECT_TRUE(topo.manifold);
  EXPECT_TRUE(topo.oriented);
  EXPECT_FALSE(topo.has_repeated_vertex_face);

  const std::vector<uint8_t> file = encode(repaired);
  const Mesh out = decode(file.data(), file.size());
  const FileInfo info = inspect(file.data(), file.size());
  Mesh snapped = repaired;
  for (size_t i = 0; i < snapped.positions.size(); ++i) {
    const int axis = static_cast<int>(i % 3);
    snapped.positions[i] =
        info.grid.dequantize(axis, info.grid.quantize(axis, snapped.positions[i]));
  }
  EXPECT_EQ(test::canonical(out), test::canonical(snapped));
}

/// Copies of split vertices keep the exact position of their input vertex: the
/// unoriented triangles of positions are the input's (minus the removed faces).
using Unoriented = std::array<std::array<float, 3>, 3>;
std::multiset<Unoriented> unoriented(const Mesh &m) {
  std::multiset<Unoriented> out;
  for (size_t f = 0; f < m.triangle_count(); ++f) {
    Unoriented t;
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a)
        t[k][a] = m.positions[3 * m.triangles[3 * f + k] + a];
    std::sort(t.begin(), t.end());
    out.insert(t);
  }
  return out;
}

// ---------------------------------------------------------------- small cases

TEST(Repair, AlreadyManifoldMeshesAreUnchangedBitForBit) {
  for (const Mesh &m : {gen::icosphere(2), gen::torus(12, 8), gen::grid_with_holes(9, 2),
                        gen::degenerate_strip(), gen::components(3), gen::single_triangle()}) {
    Mesh copy = m;
    const RepairReport r = make_manifold(copy);
    EXPECT_FALSE(r.changed());
    EXPECT_EQ(counts(r), std::vector<size_t>(7, 0));
    EXPECT_EQ(r.summary(), "nothing to repair");
    EXPECT_EQ(copy.positions, m.positions);
    EXPECT_EQ(copy.triangles, m.triangles);
  }
}

/// Two fans of two triangles each around vertex 0, touching only there.
Mesh bowtie() {
  Mesh m;
  add_vertex(m, 0, 0, 0);
  add_vertex(m, 1, 0, 0);
  add_vertex(m, 1, 1, 0);
  add_vertex(m, 0, 1, 0);
  add_vertex(m, -1, 0, 0);
  add_vertex(m, -1, -1, 0);
  add_vertex(m, 0, -1, 0);
  add_face(m, 0, 1, 2);
  add_face(m, 0, 2, 3);
  add_face(m, 0, 4, 5);
  add_face(m, 0, 5, 6);
  return m;
}

TEST(Repair, BowtieVertexIsSplitIntoTwo) {
  Mesh m = bowtie();
  const Mesh input = m;
  const RepairReport r = make_manifold(m);
  EXPECT_EQ(counts(r), (std::vector<size_t>{0, 0, 0, 0, 0, 1, 1}));
  EXPECT_EQ(r.summary(), "split 1 non-manifold vertex into 2 (e.g. vertex 0 into 2)");
  ASSERT_EQ(m.vertex_count(), 8u);
  EXPECT_EQ(m.triangle_count(), 4u);
  // The first fan keeps vertex 0, the second gets the copy 7 at the same position.
  EXPECT_EQ(std::vector<uint32_t>(m.triangles.begin(), m.triangles.begin() + 6),
            (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_EQ(m.triangles[6], 7u);
  EXPECT_EQ(m.triangles[9], 7u);
  EXPECT_EQ(unoriented(m), unoriented(input));
  expect_valid_and_lossless(m);
}

TEST(Repair, CopiesCarryTheAttributesOfTheirVertex) {
  Mesh m = bowtie();
  VertexAttribute c;
  c.kind = AttributeKind::Colour;
  c.name = "colour";
  c.components = 3;
  for (uint8_t v = 0; v < 7; ++v)
    c.colour.insert(c.colour.end(), {v, uint8_t(v + 10), uint8_t(v + 20)});
  VertexAttribute q;
  q.kind = AttributeKind::Scalar;
  q.name = "quality";
  q.values = {0.5f, 1, 2, 3, 4, 5, 6};
  m.attributes = {c, q};
  make_manifold(m);
  ASSERT_EQ(m.vertex_count(), 8u);
  EXPECT_NO_THROW(validate_attributes(m, true));
  EXPECT_EQ(std::vector<uint8_t>(m.attributes[0].colour.end() - 3, m.attributes[0].colour.end()),
            (std::vector<uint8_t>{0, 10, 20}));
  EXPECT_EQ(m.attributes[1].values.back(), 0.5f);
}

TEST(Repair, TwoTetrahedraOnOneEdgeBecomeTwoTetrahedra) {
  // samples/tetra_nonmanifold.off: edge (0, 1) has four faces.
  Mesh m;
  const float p[6][3] = {{0, 0, 0},       {1, 0, 0},     {0.5f, 1, 0},
                         {0.5f, 0.5f, 1}, {0.5f, -1, 0}, {0.5f, -0.5f, -1}};
  for (const auto &q : p)
    add_vertex(m, q[0], q[1], q[2]);
  const uint32_t f[8][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2},
                            {0, 1, 4}, {0, 5, 1}, {1, 5, 4}, {0, 4, 5}};
  for (const auto &t : f)
    add_face(m, t[0], t[1], t[2]);
  const Mesh input = m;
  const RepairReport r = make_manifold(m);
  EXPECT_EQ(counts(r), (std::vector<size_t>{0, 0, 0, 1, 0, 2, 2}));
  EXPECT_EQ(r.nonmanifold_edge_faces, 4u);
  EXPECT_EQ(m.vertex_count(), 8u);
  EXPECT_EQ(m.triangle_count(), 8u);
  const gen::TopologyReport topo = gen::analyze(m);
  EXPECT_EQ(topo.components, 2u);
  EXPECT_TRUE(topo.closed());
  EXPECT_EQ(unoriented(m), unoriented(input));
  expect_valid_and_lossless(m);
}

TEST(Repair, BookOfThreePagesFallsApartIntoThreeTriangles) {
  Mesh m = gen::nonmanifold_edge(); // faces (0,1,2), (1,0,3), (1,0,4) on edge (0, 1)
  const Mesh input = m;
  const RepairReport r = make_manifold(m);
  EXPECT_EQ(counts(r), (std::vector<size_t>{0, 0, 0, 1, 0, 2, 4}));
  EXPECT_EQ(r.summary(), "cut 1 edge shared by more than two faces (e.g. edge (0, 1), 3 faces)\n"
                         "split 2 non-manifold vertices into 6 (e.g. vertex 0 into 3)");
  EXPECT_EQ(m.vertex_count(), 9u);
  EXPECT_EQ(gen::analyze(m).components, 3u);
  EXPECT_EQ(unoriented(m), unoriented(input));
  expect_valid_and_lossless(m);
}

TEST(Repair, ExactDuplicateFaceIsRemoved) {
  Mesh m = gen::tetrahedron();
  const Mesh tet = m;
  // Face 0 again, rotated: the same oriented triangle.
  add_face(m, m.triangles[1], m.triangles[2], m.triangles[0]);
  const RepairReport r = make_manifold(m);
  EXPECT_EQ(counts(r), (std::vector<size_t>{0, 1, 0, 0, 0, 0, 0}));
  EXPECT_EQ(r.summary(), "removed 1 duplicate face (e.g. face 4 repeats face 0)");
  EXPECT_EQ(m.triangles, tet.triangles);
  EXPECT_EQ(m.positions, tet.positions);
  expect_valid_and_lossless(m);
}

TEST(Repair, FaceRepeatingAVertexIsRemoved) {
  Mesh m = gen::repeated_vertex_face(); // (1, 2, 3) and (0, 0, 1)
  const RepairReport r = make_manifold(m);
  EXPECT_EQ(counts(r), (std::vector<size_t>{1, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(r.summary(), "removed 1 face repeating a vertex (e.g. face 1 (0, 0, 1))");
  EXPECT_EQ(m.triangles, (std::vector<uint32_t>{1, 2, 3}));
  EXPECT_EQ(m.vertex_count(), 4u); // vertex 0 is left unreferenced; the encoder drops it
  expect_valid_and_lossless(m);
}

TEST(Repair, OneReversedFaceOfAClosedMeshIsFlippedBack) {
  Mesh m = gen::flipped_face();
  const RepairReport r = make_manifold(m);
  // Flipping the one face back beats flipping the 79 others.
  EXPECT_EQ(counts(r), (std::vector<size_t>{0, 0, 1, 0, 0, 0, 0}));
  EXPECT_EQ(r.flipped_example, 0u);
  EXPECT_EQ(test::canonical(m), test::canonical(gen::icosphere(1)));
  expect_valid_and_lossless(m);
}

TEST(Repair, ClosedMeshWithMostFacesReversedKeepsTheMajority) {
  // Reverse every face but three: orienting the piece flips the three, not the rest.
  Mesh m = gen::icosphere(1);
  for (size_t f = 3; f < m.triangle_count(); ++f)
    std::swap(m.triangles[3 * f + 1], m.triangles[3 * f + 2]);
  const RepairReport r = make_manifold(m);
  EXPECT_EQ(counts(r), (std::vector<size_t>{0, 0, 3, 0, 0, 0, 0}));
  EXPECT_LT(gen::signed_volume(m), 0.0); // inside out, as most of the input was
  expect_valid_and_lossless(m);
}

/// A Moebius strip of n quads (2n triangles) around the z axis, half a twist.
Mesh moebius(int n) {
  Mesh m;
  const double pi = 3.14159265358979323846;
  for (int i = 0; i < n; ++i) {
    const double u = 2 * pi * i / n;
    for (double s : {-0.3, 0.3}) // vertex 2i: s = -0.3, vertex 2i+1: s = +0.3
      add_vertex(m, (1 + s * std::cos(u / 2)) * std::cos(u),
                 (1 + s * std::cos(u / 2)) * std::sin(u), s * std::sin(u / 2));
  }
  for (int i = 0; i < n; ++i) {
    const uint32_t a = 2 * i, b = 2 * i + 1;
    // After a full turn the strip comes back upside down: the two sides swap.
    const bool last = i == n - 1;
    const uint32_t c = last ? 1 : 2 * i + 2, d = last ? 0 : 2 * i + 3;
    add_face(m, a, c, d);
    add_face(m, a, d, b);
  }
  return m;
}

TEST(Repair, MoebiusStripIsCutOnceIntoAnOrientedBand) {
  const int n = 12;
  Mesh m = moebius(n);
  ASSERT_FALSE(gen::analyze(m).oriented);
  const Mesh input = m;
  const RepairReport r = make_manifold(m);
  // One edge cannot be oriented; both its ends lie on the boundary, so cutting it
  // splits each of them into two.
  EXPECT_EQ(r.edges_cut, 1u);
  EXPECT_EQ(r.edges_cut_nonorientable, 1u);
  EXPECT_EQ(r.vertices_split, 2u);
  EXPECT_EQ(r.vertices_added, 2u);
  EXPECT_EQ(r.degenerate_faces_removed + r.duplicate_faces_removed, 0u);
  EXPECT_NE(r.summary().find("cut 1 edge whose two faces cannot be oriented consistently (e.g. "
                             "edge ("),
            std::string::npos)
      << r.summary();
  // Some faces must flip, at most half of them.
  EXPECT_GT(r.faces_flipped, 0u);
  EXPECT_LE(r.faces_flipped, size_t(n));
  const gen::TopologyReport topo = gen::analyze(m);
  EXPECT_EQ(topo.components, 1u);
  EXPECT_EQ(topo.boundary_loops, 1u); // the cut band is a disk
  EXPECT_EQ(topo.euler, 1);
  EXPECT_EQ(unoriented(m), unoriented(input));
  expect_valid_and_lossless(m);
}

/// A Klein bottle: an n x m grid of quads whose columns wrap around plainly and whose
/// last row is glued to the first one mirrored. Closed and not orientable.
Mesh klein_bottle(int n, int m) {
  Mesh k;
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < n; ++i)
      add_vertex(k, i, j, (i * 7 + j * 3) % 5);
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
      add_face(k, id(i, j), id(i + 1, j), id(i + 1, j + 1));
      add_face(k, id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return k;
}

TEST(Repair, KleinBottleIsCutIntoAnOrientedSurface) {
  Mesh m = klein_bottle(6, 5);
  ASSERT_FALSE(gen::analyze(m).oriented);
  ASSERT_TRUE(gen::analyze(m).closed());
  const Mesh input = m;
  const RepairReport r = make_manifold(m);
  // Only orientation cuts: every edge had two faces.
  EXPECT_GT(r.edges_cut_nonorientable, 0u);
  EXPECT_EQ(r.edges_cut, r.edges_cut_nonorientable);
  EXPECT_GT(r.vertices_split, 0u);
  EXPECT_EQ(r.degenerate_faces_removed + r.duplicate_faces_removed, 0u);
  EXPECT_FALSE(gen::analyze(m).closed());
  EXPECT_EQ(unoriented(m), unoriented(input));
  expect_valid_and_lossless(m);
}

TEST(Repair, LoneOppositePairIsAValidClosedPillow) {
  // Decision (see repair.h): a face and its reverse are not exact duplicates. Alone they
  // form a closed two-face surface, which is already manifold and oriented.
  Mesh m;
  add_vertex(m, 0, 0, 0);
  add_vertex(m, 1, 0, 0);
  add_vertex(m, 0, 1, 0);
  add_face(m, 0, 1, 2);
  add_face(m, 0, 2, 1);
  const Mesh input = m;
  const RepairReport r = make_manifold(m);
  EXPECT_FALSE(r.changed());
  EXPECT_EQ(m.triangles, input.triangles);
  expect_valid_and_lossless(m);
}

TEST(Repair, OppositePairInsideASurfaceIsCutOff) {
  // A tetrahedron plus the reverse of its face 0: the three edges of face 0 get three
  // faces each and are cut, so face 0 and its reverse become isolated triangles and the
  // rest an open three-face cap; each of the three vertices of face 0 ends up in 3 fans.
  Mesh m = gen::tetrahedron();
  add_face(m, m.triangles[0], m.triangles[2], m.triangles[1]);
  const Mesh input = m;
  const RepairReport r = make_manifold(m);
  EXPECT_EQ(counts(r), (std::vector<size_t>{0, 0, 0, 3, 0, 3, 6}));
  const gen::TopologyReport topo = gen::analyze(m);
  EXPECT_EQ(topo.components, 3u);
  EXPECT_EQ(m.triangle_count(), 5u);
  EXPECT_EQ(unoriented(m), unoriented(input));
  expect_valid_and_lossless(m);
}

TEST(Repair, SummaryNamesEveryKindOfChange) {
  Mesh m = gen::tetrahedron();
  add_face(m, 0, 0, 1);                                        // degenerate
  add_face(m, m.triangles[0], m.triangles[1], m.triangles[2]); // duplicate
  const RepairReport r = make_manifold(m);
  const std::string s = r.summary();
  EXPECT_NE(s.find("removed 1 face repeating a vertex (e.g. face 4 (0, 0, 1))"), std::string::npos);
  EXPECT_NE(s.find("removed 1 duplicate face (e.g. face 5 repeats face 0)"), std::string::npos);
  EXPECT_EQ(std::count(s.begin(), s.end(), '\n'), 1);
}

TEST(Repair, OutOfRangeIndexIsAClearError) {
  Mesh m = gen::single_triangle();
  m.triangles[2] = 7;
  try {
    make_manifold(m);
    FAIL() << "expected pomar::Error";
  } catch (const Error &e) {
    EXPECT_NE(std::string(e.what()).find("vertex 7"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------- property test

/// Random triangle soup: `faces` triangles over `vertices` vertices (so edges and
/// vertices are shared in every possible wrong way), some degenerate and duplicate faces.
Mesh soup(uint32_t seed, uint32_t vertices, uint32_t faces) {
  Mesh m;
  uint64_t key = 0;
  auto pick = [&](uint32_t n) {
    return static_cast<uint32_t>(gen::detail::unit_hash(seed, key++) * n);
  };
  for (uint32_t v = 0; v < vertices; ++v)
    add_vertex(m, pick(1000) / 100.0, pick(1000) / 100.0, pick(1000) / 100.0);
  for (uint32_t f = 0; f < faces; ++f) {
    if (f > 0 && pick(10) == 0) { // repeat an earlier face, rotated or reversed
      const uint32_t g = pick(f);
      const uint32_t *t = &m.triangles[3 * g];
      if (pick(2))
        add_face(m, t[1], t[2], t[0]);
      else
        add_face(m, t[0], t[2], t[1]);
    } else {
      add_face(m, pick(vertices), pick(vertices), pick(vertices));
    }
  }
  return m;
}

/// A mesh broken the way real files are: an open disk whose vertices are glued in random
/// pairs (pinches, edges of three or more faces, seams of either orientation, faces that
/// collapse), some faces reversed and some repeated.
Mesh glued_disk(uint32_t seed) {
  Mesh m = gen::flat_disk(2 + seed % 2);
  uint64_t key = 1u << 20;
  auto pick = [&](uint32_t n) {
    return static_cast<uint32_t>(gen::detail::unit_hash(seed, key++) * n);
  };
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
    add_face(m, t[1], t[2], t[0]);
  }
  return m;
}

/// The properties every repair must have, whatever the input.
void check_repair_properties(const Mesh &input, Mesh &m, const RepairReport &r) {
  // Only degenerate and exact duplicate faces are dropped; copies are appended.
  EXPECT_EQ(m.triangle_count(),
            input.triangle_count() - r.degenerate_faces_removed - r.duplicate_faces_removed);
  EXPECT_EQ(m.vertex_count(), input.vertex_count() + r.vertices_added);
  EXPECT_EQ(r.vertices_added == 0, r.vertices_split == 0);
  EXPECT_LE(r.edges_cut_nonorientable, r.edges_cut);
  // Every kept face is an input face on the same positions (possibly reversed).
  std::multiset<Unoriented> all = unoriented(input);
  for (const Unoriented &t : unoriented(m)) {
    auto it = all.find(t);
    ASSERT_TRUE(it != all.end());
    all.erase(it);
  }
  // A second repair has nothing left to do.
  Mesh again = m;
  EXPECT_FALSE(make_manifold(again).changed());
  if (m.triangle_count() != 0)
    expect_valid_and_lossless(m);
}

TEST(Repair, RandomBrokenMeshesAlwaysBecomeValid) {
  RepairReport total;
  auto add = [&](const RepairReport &r) {
    total.faces_flipped += r.faces_flipped;
    total.edges_cut_nonorientable += r.edges_cut_nonorientable;
    total.edges_cut += r.edges_cut;
    total.vertices_split += r.vertices_split;
    total.duplicate_faces_removed += r.duplicate_faces_removed;
    total.degenerate_faces_removed += r.degenerate_faces_removed;
  };
  for (uint32_t seed = 1; seed <= 300; ++seed) {
    for (int kind = 0; kind < 2; ++kind) {
      Mesh m = kind == 0 ? soup(seed, 6 + seed % 20, 4 + (seed * 7) % 60) : glued_disk(seed);
      const Mesh input = m;
      RepairReport r;
      ASSERT_NO_THROW(r = make_manifold(m)) << "seed " << seed << " kind " << kind;
      SCOPED_TRACE("seed " + std::to_string(seed) + " kind " + std::to_string(kind) + ": " +
                   r.summary());
      check_repair_properties(input, m, r);
      add(r);
    }
  }
  // The inputs exercise every step.
  EXPECT_GT(total.faces_flipped, 0u);
  EXPECT_GT(total.edges_cut_nonorientable, 0u);
  EXPECT_GT(total.edges_cut, total.edges_cut_nonorientable);
  EXPECT_GT(total.vertices_split, 0u);
  EXPECT_GT(total.duplicate_faces_removed, 0u);
  EXPECT_GT(total.degenerate_faces_removed, 0u);
  std::printf("300 soups + 300 glued disks: %zu flipped, %zu edges cut (%zu not orientable), "
              "%zu vertices split\n",
              total.faces_flipped, total.edges_cut, total.edges_cut_nonorientable,
              total.vertices_split);
}

} // namespace
} // namespace pomar
