// Ring walks (mesh/corner_table.h): get_ring on fans larger than a ring's first storage
// (32 corners), closed and open, whatever corner the walk starts from. And the encoder's
// face renumbering (mesh/reorder.h): a table built on the faces then renumbered is the
// table built on the renumbered faces.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "mesh/corner_table.h"
#include "mesh/reorder.h"
#include "support/mesh_gen.h"

namespace pomar {
namespace {

/// A fan of n faces (0, i, i+1) round vertex 0, closed (the last face wraps to vertex 1)
/// or open.
CornerTable fan(uint32_t n, bool closed) {
  std::vector<uint32_t> t;
  for (uint32_t i = 1; i <= n; ++i)
    t.insert(t.end(), {0, i, closed && i == n ? 1 : i + 1});
  CornerTable ct;
  build_corner_table(t.data(), n, closed ? n + 1 : n + 2, ct);
  return ct;
}

/// The ring's corners are vertex 0's, counter-clockwise, with the neighbours they name.
void expect_consistent(const CornerTable &ct, const Ring &ring) {
  for (uint32_t i = 0; i < ring.faces(); ++i) {
    const uint32_t c = ring.corner[i];
    EXPECT_EQ(ct.V[c], 0u);
    EXPECT_EQ(ct.V[CornerTable::next(c)], ring.neighbour[i]);
    EXPECT_EQ(ct.V[CornerTable::prev(c)], ring.neighbour[(i + 1) % ring.size()]);
  }
}

// Every refusal of build_corner_table is a TopologyError (kind InvalidMesh): the lossless
// stage cuts the mesh on that type alone, without building the table again to check.
TEST(CornerTable, EveryRefusalIsATopologyError) {
  Mesh out_of_range = gen::tetrahedron();
  out_of_range.triangles[5] = 99;
  for (const Mesh &m : {gen::nonmanifold_edge(), gen::nonmanifold_vertex(), gen::flipped_face(),
                        gen::repeated_vertex_face(), out_of_range, Mesh{}}) {
    CornerTable ct;
    try {
      build_corner_table(m.triangles.data(), m.triangle_count(), m.vertex_count(), ct);
      ADD_FAILURE() << "accepted a mesh of " << m.triangle_count() << " faces";
    } catch (const TopologyError &e) {
      EXPECT_EQ(e.kind(), Error::Kind::InvalidMesh) << e.what();
    }
  }
  CornerTable ct;
  const Mesh valid = gen::tetrahedron();
  EXPECT_NO_THROW(
      build_corner_table(valid.triangles.data(), valid.triangle_count(), valid.vertex_count(), ct));
}

TEST(Ring, LargeClosedFanFromEveryCorner) {
  for (uint32_t n : {3u, 31u, 32u, 33u, 100u}) {
    CornerTable ct = fan(n, true);
    Ring ring;
    for (uint32_t f = 0; f < n; ++f) {
      ct.VC[0] = 3 * f; // start the walk in face f
      get_ring(ct, 0, ring);
      ASSERT_TRUE(ring.closed);
      ASSERT_EQ(ring.size(), n);
      ASSERT_EQ(ring.faces(), n);
      EXPECT_EQ(ring.corner[0], 3 * f);
      EXPECT_EQ(ring.neighbour[0], f + 1);
      expect_consistent(ct, ring);
    }
  }
}

TEST(Ring, LargeOpenFanStartsAtItsClockwiseEnd) {
  for (uint32_t n : {1u, 31u, 32u, 33u, 100u}) {
    CornerTable ct = fan(n, false);
    Ring ring;
    for (uint32_t f = 0; f < n; ++f) {
      ct.VC[0] = 3 * f;
      get_ring(ct, 0, ring);
      ASSERT_FALSE(ring.closed);
      ASSERT_EQ(ring.size(), n + 1);
      ASSERT_EQ(ring.faces(), n);
      for (uint32_t i = 0; i <= n; ++i)
        EXPECT_EQ(ring.neighbour[i], i + 1);
      expect_consistent(ct, ring);
    }
  }
}

TEST(Ring, VertexWithoutFacesHasAnEmptyRing) {
  CornerTable ct = fan(40, true);
  Ring ring;
  get_ring(ct, 0, ring); // storage grown by a large fan first
  ct.VC[0] = kNone;
  get_ring(ct, 0, ring);
  EXPECT_EQ(ring.size(), 0u);
  EXPECT_EQ(ring.faces(), 0u);
  EXPECT_TRUE(ring.closed);
}

/// reorder_faces(table of t, order) == table of t's faces taken in `order`.
void expect_reorder_matches_build(const std::vector<uint32_t> &t, uint32_t vertices,
                                  const std::vector<uint32_t> &order) {
  const uint32_t nf = static_cast<uint32_t>(t.size() / 3);
  CornerTable renumbered;
  build_corner_table(t.data(), nf, vertices, renumbered);
  reorder_faces(renumbered, order);
  std::vector<uint32_t> sorted;
  for (uint32_t f : order)
    sorted.insert(sorted.end(), &t[3 * size_t(f)], &t[3 * size_t(f)] + 3);
  CornerTable built;
  build_corner_table(sorted.data(), nf, vertices, built);
  EXPECT_EQ(renumbered.V, built.V);
  EXPECT_EQ(renumbered.O, built.O);
  EXPECT_EQ(renumbered.VC, built.VC);
}

TEST(Reorder, RenumberedTableIsTheSortedFacesTable) {
  // A closed sphere and a grid with holes (boundary corners: O = kNone), with the encoder's
  // face order and with a scrambled one; an unreferenced vertex keeps VC = kNone.
  for (const Mesh &m : {gen::icosphere(3), gen::grid_with_holes(12, 3)}) {
    const uint32_t nv = static_cast<uint32_t>(m.vertex_count()) + 1;
    expect_reorder_matches_build(m.triangles, nv, face_order(m.triangles));
    std::vector<uint32_t> scrambled(m.triangle_count());
    for (uint32_t i = 0; i < scrambled.size(); ++i)
      scrambled[i] = static_cast<uint32_t>((uint64_t(i) * 7919) % scrambled.size());
    ASSERT_NE(scrambled.size() % 7919, 0u); // 7919 is prime: i -> 7919 i mod n permutes
    expect_reorder_matches_build(m.triangles, nv, scrambled);
  }
}

} // namespace
} // namespace pomar
