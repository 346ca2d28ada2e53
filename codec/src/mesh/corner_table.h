// Connectivity of a manifold, consistently oriented triangle mesh as a corner table
// (flat 32-bit arrays). Corner c = 3*face + k is vertex V[c] of face c/3; O[c] is the
// corner facing c across the edge opposite to c (kNone on a boundary edge).
//
// For corner c of face (v, a, b) at v:  a = V[next(c)], b = V[prev(c)], and the
// neighbours of v in counter-clockwise order go ... a, b ... .
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pomar {

constexpr uint32_t kNone = 0xFFFFFFFFu;

struct CornerTable {
  std::vector<uint32_t> V;  // corner -> vertex
  std::vector<uint32_t> O;  // corner -> opposite corner, kNone on a boundary
  std::vector<uint32_t> VC; // vertex -> one of its corners, kNone if it has no face

  static uint32_t next(uint32_t c) { return c % 3 == 2 ? c - 2 : c + 1; }
  static uint32_t prev(uint32_t c) { return c % 3 == 0 ? c + 2 : c - 1; }
  uint32_t face_count() const { return static_cast<uint32_t>(V.size() / 3); }
  uint32_t vertex_count() const { return static_cast<uint32_t>(VC.size()); }

  /// Next corner of the same vertex counter-clockwise (kNone at a boundary).
  uint32_t swing_ccw(uint32_t c) const {
    const uint32_t o = O[next(c)];
    return o == kNone ? kNone : next(o);
  }
  /// Next corner of the same vertex clockwise (kNone at a boundary).
  uint32_t swing_cw(uint32_t c) const {
    const uint32_t o = O[prev(c)];
    return o == kNone ? kNone : prev(o);
  }
  /// Link c and d as opposite corners (either may be kNone).
  void link(uint32_t c, uint32_t d) {
    if (c != kNone)
      O[c] = d;
    if (d != kNone)
      O[d] = c;
  }
};

/// The one-ring of a vertex in counter-clockwise order. For a closed ring there are as
/// many faces as neighbours; an open ring (boundary vertex) has one face less and a gap
/// between its last and first neighbour. corner[i] is the corner of the vertex in the
/// face (v, neighbour[i], neighbour[i+1]).
struct Ring {
  std::vector<uint32_t> neighbour;
  std::vector<uint32_t> corner;
  bool closed = true;
  uint32_t size() const { return static_cast<uint32_t>(neighbour.size()); }
  uint32_t faces() const { return static_cast<uint32_t>(corner.size()); }
  int index_of(uint32_t v) const {
    for (uint32_t i = 0; i < neighbour.size(); ++i)
      if (neighbour[i] == v)
        return static_cast<int>(i);
    return -1;
  }
};

/// Fill `ring` with the one-ring of vertex v (empty if v has no face).
void get_ring(const CornerTable &ct, uint32_t v, Ring &ring);

/// Build the corner table of `triangle_count` triangles over `vertex_count` vertices.
/// Throws pomar::Error naming the problem (with counts and one example) when the mesh is
/// not a manifold, consistently oriented triangle mesh or a face repeats a vertex.
void build_corner_table(const uint32_t *triangles, size_t triangle_count, size_t vertex_count,
                        CornerTable &ct);

} // namespace pomar
