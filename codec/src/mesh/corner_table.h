// Connectivity of a manifold, consistently oriented triangle mesh as a corner table
// (flat 32-bit arrays). Corner c = 3*face + k is vertex V[c] of face c/3; O[c] is the
// corner facing c across the edge opposite to c (kNone on a boundary edge).
//
// For corner c of face (v, a, b) at v:  a = V[next(c)], b = V[prev(c)], and the
// neighbours of v in counter-clockwise order go ... a, b ... .
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pomar/pomar.h"

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
  /// Start fetching corner c's entries of V and O into the cache (nothing for kNone).
  /// Always inlined, like every function whose only effect is a prefetch: GCC counts a
  /// prefetch as no side effect, finds such a function const and deletes its calls.
  [[gnu::always_inline]] void prefetch(uint32_t c) const {
    if (c != kNone) {
      __builtin_prefetch(&V[c]);
      __builtin_prefetch(&O[c]);
    }
  }
  /// Link c and d as opposite corners (either may be kNone).
  void link(uint32_t c, uint32_t d) {
    if (c != kNone)
      O[c] = d;
    if (d != kNone)
      O[d] = c;
  }
};

/// A growable array of trivially copyable elements: storage that only grows (an array
/// reused vertex after vertex stops allocating once it has seen the largest count) and a
/// count. The walks that fill one write through `grow_to` + `data()` and set the count
/// once (no per-element capacity bookkeeping); the rest reads it like a vector. (A ring's
/// arrays, RingArray; the traversal's queue, refine/traversal_marks.h.)
template <class T> class GrowArray {
public:
  uint32_t size() const { return n_; }
  bool empty() const { return n_ == 0; }
  const T *begin() const { return buf_.data(); }
  const T *end() const { return buf_.data() + n_; }
  T *data() { return buf_.data(); }
  const T *data() const { return buf_.data(); }
  const T &operator[](size_t i) const { return buf_[i]; }
  T &operator[](size_t i) { return buf_[i]; }
  const T &back() const { return buf_[n_ - 1]; }
  void clear() { n_ = 0; }
  void pop_back() { --n_; }
  void push_back(const T &x) {
    grow_to(n_ + 1);
    buf_[n_++] = x;
  }
  /// Room for at least `n` elements (the count is unchanged); returns the storage.
  T *grow_to(size_t n) {
    if (n > cap_) {
      buf_.resize(std::max<size_t>(2 * buf_.size(), std::max<size_t>(n, 32)));
      cap_ = buf_.size();
    }
    return buf_.data();
  }
  /// Set the count (elements past the old count must have been written).
  void resize(uint32_t n) {
    grow_to(n);
    n_ = n;
  }
  size_t capacity() const { return cap_; }

private:
  std::vector<T> buf_;
  uint32_t n_ = 0;
  size_t cap_ = 0; // buf_.size(), kept beside it (read by every walk)
};
using RingArray = GrowArray<uint32_t>;

/// The one-ring of a vertex in counter-clockwise order. For a closed ring there are as
/// many faces as neighbours; an open ring (boundary vertex) has one face less and a gap
/// between its last and first neighbour. corner[i] is the corner of the vertex in the
/// face (v, neighbour[i], neighbour[i+1]).
struct Ring {
  RingArray neighbour;
  RingArray corner;
  bool closed = true;
  uint32_t size() const { return neighbour.size(); }
  uint32_t faces() const { return corner.size(); }
  int index_of(uint32_t v) const {
    for (uint32_t i = 0; i < neighbour.size(); ++i)
      if (neighbour[i] == v)
        return static_cast<int>(i);
    return -1;
  }
};

/// next(c) - c and prev(c) - c by c % 3 (the walks step without branches).
inline constexpr int32_t kNextStep[3] = {1, 1, -2}, kPrevStep[3] = {2, -1, -1};

/// One counter-clockwise walk round a fan from its corner `first`, in one pass: each face
/// (corner c) gives its corner and the name of its second neighbour V[prev(c)], through
/// `name` (the vertex itself for the mesh; the level-(l-1) view maps new vertices to
/// their parents, refine/level_traversal.h). A face whose two neighbours get one name is
/// left out. Returns kOpen if the walk ran into the fan's boundary (the ring is whole
/// only if `first` was the fan's clockwise end), kNoRoom if the fan is larger than the
/// ring's room (walk_fan grows it and walks again).
enum class FanWalk { kClosed, kOpen, kNoRoom };
template <class Name>
[[gnu::always_inline]] inline FanWalk walk_fan_once(const CornerTable &ct, uint32_t first,
                                                    const Name &name_of, Ring &ring) {
  // (Locals, the naming function's copy too: the stores below are uint32_t and could
  // alias what the caller holds, which would then be read again at every face.)
  const Name name = name_of;
  const uint32_t *V = ct.V.data(), *O = ct.O.data();
  uint32_t *corner = ring.corner.grow_to(32);
  uint32_t *neighbour = ring.neighbour.grow_to(ring.corner.capacity() + 1);
  const uint32_t room = static_cast<uint32_t>(ring.corner.capacity());
  uint32_t before = name(V[CornerTable::next(first)]);
  neighbour[0] = before;
  uint32_t kept = 0; // faces kept; neighbour[0..kept] are named
  bool closed = true;
  // Face c = (v, a, b) of the fan gives corner c and neighbour b; the next face is the one
  // across edge (v, b): corner next(o) for o = O[next(c)], and its b is V[prev(next(o))]
  // = V[o]. So each step takes one `% 3`, of o.
  uint32_t c = first, b = V[CornerTable::prev(first)], o = O[CornerTable::next(first)];
  for (;;) {
    if (kept == room) // a fan larger than any seen so far: walk it again with room
      return FanWalk::kNoRoom;
    // The face beyond edge (a, b) is in the fans of a and b, which a breadth-first walk
    // visits soon: fetch it now.
    const uint32_t across = O[c]; // (ct.prefetch, on the local arrays)
    if (across != kNone) {
      __builtin_prefetch(V + across);
      __builtin_prefetch(O + across);
    }
    const uint32_t after = name(b);
    if (after != before) {
      corner[kept++] = c;
      neighbour[kept] = after;
    }
    before = after;
    if (o == kNone) {
      closed = false;
      break;
    }
    const uint32_t k = o % 3;
    c = o + kNextStep[k]; // next(o)
    if (c == first)
      break;
    b = V[o];
    o = O[o + kPrevStep[k]]; // O[next(c)] = O[prev(o)]
  }
  ring.corner.resize(kept);
  // (a closed fan's wrap-around repeats the first neighbour)
  ring.neighbour.resize(closed && kept > 0 ? kept : kept + 1);
  ring.closed = closed;
  return closed ? FanWalk::kClosed : FanWalk::kOpen;
}
/// walk_fan_once until the ring has room; false if the walk ran into the fan's boundary.
/// (Always inlined: a call per ring cost about 20 instructions of the walk's 400, and
/// get_named_ring's first walk is the traversals' inner loop.)
template <class Name>
[[gnu::always_inline]] inline bool walk_fan(const CornerTable &ct, uint32_t first, const Name &name,
                                            Ring &ring) {
  FanWalk r;
  while ((r = walk_fan_once(ct, first, name, ring)) == FanWalk::kNoRoom)
    ring.corner.grow_to(ring.corner.capacity() + 1);
  return r == FanWalk::kClosed;
}
/// walk_fan, called (an open fan's second walk, from its clockwise end).
template <class Name>
[[gnu::noinline]] bool walk_fan_again(const CornerTable &ct, uint32_t first, const Name &name,
                                      Ring &ring) {
  return walk_fan(ct, first, name, ring);
}

/// The one-ring of vertex v with neighbours named by `name` (see walk_fan); empty if v
/// has no face. A closed fan is walked once from VC[v]; an open one from its clockwise
/// end, found by swinging clockwise once the first walk met the boundary.
template <class Name>
void get_named_ring(const CornerTable &ct, uint32_t v, const Name &name, Ring &ring) {
  const uint32_t start = ct.VC[v];
  if (start == kNone) {
    ring.neighbour.clear();
    ring.corner.clear();
    ring.closed = true;
    return;
  }
  if (walk_fan(ct, start, name, ring))
    return;
  uint32_t first = start;
  for (uint32_t b = ct.swing_cw(start); b != kNone; b = ct.swing_cw(b))
    first = b;
  if (first != start)
    walk_fan_again(ct, first, name, ring);
}

/// Fill `ring` with the one-ring of vertex v (empty if v has no face).
inline void get_ring(const CornerTable &ct, uint32_t v, Ring &ring) {
  get_named_ring(
      ct, v, [](uint32_t n) { return n; }, ring);
}

/// What build_corner_table throws (kind InvalidMesh): a topology the corner table cannot
/// hold. The lossless stage cuts such a mesh instead of refusing it, and knows from this type
/// that the manifold encoder refused the topology, not something else.
class TopologyError : public Error {
public:
  using Error::Error;
};

/// Build the corner table of `triangle_count` triangles over `vertex_count` vertices.
/// Throws TopologyError naming the problem (with counts and one example) when the mesh is
/// not a manifold, consistently oriented triangle mesh, a face repeats a vertex or uses an
/// index out of range, or there is no triangle.
void build_corner_table(const uint32_t *triangles, size_t triangle_count, size_t vertex_count,
                        CornerTable &ct);

} // namespace pomar
