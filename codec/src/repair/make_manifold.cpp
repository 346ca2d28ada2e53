// make_manifold(): cut a triangle mesh into a manifold, consistently oriented one.
//
// Everything works on corners (corner c = 3 * face + k, as in mesh/corner_table.h) and
// flat 32-bit arrays. The steps, each a small function below:
//   remove_bad_faces  faces repeating a vertex, then exact duplicates (same cyclic order);
//   find_mates        edge -> corners by counting sort; a two-face edge is "gluable",
//                     an edge of more than two faces is cut;
//   orient            BFS over gluable edges choosing a flip per face, fewest flips per piece;
//   cut_nonorientable after flipping, a gluable edge stays glued iff its two faces use it
//                     in opposite directions (the others are cut);
//   split_fans        union-find of the corners of each vertex across glued edges: one
//                     output vertex per class (= per fan of faces).
// The result is checked with the codec's own build_corner_table() (make_manifold; the
// lossless stage calls cut_to_manifold, repair/cut.h, and its encoder's table is the check).
//
// Why no face ever needs to be detached after split_fans: take two faces f, g that still
// share an edge (a, b) after the split. Their corners at a are in one class, so a chain of
// faces f = f0, f1, ..., fk = g around a links them across glued edges (a, x_i), none of
// them (a, b) (a glued (a, b) has only f and g, so the chain would be f, g across it, and
// then (a, b) is consistent). Glued edges are used in opposite directions, so writing
// f0 = (a, x0, x1) forces fi = (a, xi, xi+1): f uses the edge as a -> b, g as b -> a.
// Hence at most two faces share an output edge, in opposite directions; and a vertex
// class connected through edges of at most two faces is a single fan.
#include "pomar/repair.h"
#include "repair/cut.h"

#include <algorithm>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "mesh/corner_table.h"

namespace pomar {

namespace {

// ------------------------------------------------------------------ helpers

/// "1 face", "2 faces"; `many` overrides the plural ("vertices").
std::string plural(size_t n, const char *one, const char *many = nullptr) {
  return std::to_string(n) + " " + (n == 1 ? one : many ? many : std::string(one) + "s");
}

/// Disjoint sets over 0..n-1 with path halving; the root of a set is its smallest item,
/// so classes come out in a deterministic order.
struct DisjointSets {
  std::vector<uint32_t> parent;
  explicit DisjointSets(size_t n) : parent(n) {
    for (size_t i = 0; i < n; ++i)
      parent[i] = static_cast<uint32_t>(i);
  }
  uint32_t find(uint32_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a < b)
      parent[b] = a;
    else if (b < a)
      parent[a] = b;
  }
};

/// Calls visit(corners, count) once per undirected edge of the triangles `t` (over
/// `nv` vertices), with the corners facing that edge in increasing order. Corners are
/// bucketed by the lower vertex of their edge (counting sort) as 64-bit keys (upper
/// vertex, corner), and each short bucket is sorted: O(n) plus small sorts.
template <class Visit> void for_each_edge(const std::vector<uint32_t> &t, size_t nv, Visit visit) {
  const uint32_t nc = static_cast<uint32_t>(t.size());
  std::vector<uint32_t> start(nv + 1, 0);
  for (uint32_t c = 0; c < nc; ++c)
    ++start[std::min(t[CornerTable::next(c)], t[CornerTable::prev(c)]) + 1];
  for (size_t v = 0; v < nv; ++v)
    start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  std::vector<uint64_t> keys(nc);
  for (uint32_t c = 0; c < nc; ++c) {
    const uint32_t a = t[CornerTable::next(c)], b = t[CornerTable::prev(c)];
    keys[fill[std::min(a, b)]++] = uint64_t(std::max(a, b)) << 32 | c;
  }
  std::vector<uint32_t> corners;
  for (size_t v = 0; v < nv; ++v) {
    uint64_t *first = keys.data() + start[v], *last = keys.data() + start[v + 1];
    std::sort(first, last);
    for (uint64_t *run = first; run != last;) {
      corners.clear();
      const uint64_t edge = *run >> 32;
      for (; run != last && *run >> 32 == edge; ++run)
        corners.push_back(static_cast<uint32_t>(*run));
      visit(corners.data(), corners.size());
    }
  }
}

/// True if corners c and d (facing the same edge) see it in the same direction.
bool same_direction(const std::vector<uint32_t> &t, uint32_t c, uint32_t d) {
  return t[CornerTable::next(c)] == t[CornerTable::next(d)];
}

// ------------------------------------------------------------------ step 1: bad faces

/// Removes faces repeating a vertex and exact duplicates (same vertices in the same cyclic
/// order as an earlier face) from `t`; `origin[f]` is set to the input index of face f.
void remove_bad_faces(std::vector<uint32_t> &t, size_t nv, std::vector<uint32_t> &origin,
                      RepairReport &r) {
  const uint32_t nf = static_cast<uint32_t>(t.size() / 3);
  std::vector<uint8_t> drop(nf, 0);
  // Each valid face rotated to start at its smallest vertex: equal keys = exact duplicates.
  std::vector<uint32_t> key(t.size());
  for (uint32_t f = 0; f < nf; ++f) {
    const uint32_t *v = &t[3 * f];
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
      if (r.degenerate_faces_removed++ == 0) {
        r.degenerate_example = f;
        std::copy(v, v + 3, r.degenerate_vertices);
      }
      drop[f] = 1;
      continue;
    }
    const int k = v[0] < v[1] ? (v[0] < v[2] ? 0 : 2) : (v[1] < v[2] ? 1 : 2);
    for (int i = 0; i < 3; ++i)
      key[3 * f + i] = v[(k + i) % 3];
  }
  // Bucket the valid faces by their smallest vertex, sort each bucket by the rest.
  std::vector<uint32_t> start(nv + 1, 0), order;
  order.reserve(nf);
  for (uint32_t f = 0; f < nf; ++f)
    if (!drop[f])
      ++start[key[3 * f] + 1];
  for (size_t v = 0; v < nv; ++v)
    start[v + 1] += start[v];
  order.resize(start[nv]);
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (uint32_t f = 0; f < nf; ++f)
    if (!drop[f])
      order[fill[key[3 * f]]++] = f;
  auto less = [&](uint32_t a, uint32_t b) {
    const auto ka = std::make_tuple(key[3 * a + 1], key[3 * a + 2], a);
    const auto kb = std::make_tuple(key[3 * b + 1], key[3 * b + 2], b);
    return ka < kb;
  };
  for (size_t v = 0; v < nv; ++v) {
    std::sort(order.begin() + start[v], order.begin() + start[v + 1], less);
    for (uint32_t i = start[v] + 1; i < start[v + 1]; ++i) {
      const uint32_t f = order[i], prev = order[i - 1];
      if (key[3 * f + 1] != key[3 * prev + 1] || key[3 * f + 2] != key[3 * prev + 2])
        continue;
      drop[f] = 1;
      if (r.duplicate_faces_removed++ == 0 || f < r.duplicate_example) {
        r.duplicate_example = f;
        // The run shares one key; its first face is the one kept.
        uint32_t first = i - 1;
        while (first > start[v] && drop[order[first]])
          --first;
        r.duplicate_of = order[first];
      }
    }
  }
  // Compact, keeping the input order.
  origin.clear();
  size_t out = 0;
  for (uint32_t f = 0; f < nf; ++f) {
    if (drop[f])
      continue;
    origin.push_back(f);
    for (int i = 0; i < 3; ++i)
      t[out++] = t[3 * f + i];
  }
  t.resize(out);
}

// ------------------------------------------------------------------ step 2: orientation

/// mate[c] = the other corner facing c's edge if exactly two faces use it (a "gluable"
/// edge), else kNone. Edges of more than two faces are cut: counted here.
std::vector<uint32_t> find_mates(const std::vector<uint32_t> &t, size_t nv, RepairReport &r) {
  std::vector<uint32_t> mate(t.size(), kNone);
  for_each_edge(t, nv, [&](const uint32_t *c, size_t n) {
    if (n == 2) {
      mate[c[0]] = c[1];
      mate[c[1]] = c[0];
    } else if (n > 2 && r.edges_cut++ == 0) {
      r.nonmanifold_edge_example[0] = t[CornerTable::next(c[0])];
      r.nonmanifold_edge_example[1] = t[CornerTable::prev(c[0])];
      r.nonmanifold_edge_faces = n;
    }
  });
  return mate;
}

/// Chooses a flip per face so that faces on gluable edges use them in opposite
/// directions, by BFS over each connected piece (the first face reached decides; a cycle
/// that disagrees, as in a Moebius strip, is cut later by cut_nonorientable()). A piece where more
/// than half the faces would flip is flipped back: the fewest changes. Applies the flips to `t`
/// (and renumbers `mate` to follow the corners). Returns the flip of each face.
std::vector<uint8_t> orient(std::vector<uint32_t> &t, std::vector<uint32_t> &mate,
                            const std::vector<uint32_t> &origin, RepairReport &r) {
  const uint32_t nf = static_cast<uint32_t>(t.size() / 3);
  std::vector<uint8_t> flip(nf, 0), seen(nf, 0);
  std::vector<uint32_t> piece; // faces of the current piece, in BFS order
  for (uint32_t root = 0; root < nf; ++root) {
    if (seen[root])
      continue;
    piece.assign(1, root);
    seen[root] = 1;
    size_t flipped = 0;
    for (size_t i = 0; i < piece.size(); ++i) {
      const uint32_t f = piece[i];
      for (uint32_t c = 3 * f; c < 3 * f + 3; ++c) {
        const uint32_t m = mate[c];
        if (m == kNone || seen[m / 3])
          continue;
        const uint32_t g = m / 3;
        seen[g] = 1;
        flip[g] = flip[f] ^ uint8_t(same_direction(t, c, m));
        flipped += flip[g];
        piece.push_back(g);
      }
    }
    if (2 * flipped > piece.size())
      for (uint32_t f : piece)
        flip[f] ^= 1;
  }
  // Flipping face f swaps its corners 1 and 2: renumber the mates the same way.
  std::vector<uint32_t> renamed(mate.size());
  for (uint32_t c = 0; c < mate.size(); ++c)
    renamed[c] = flip[c / 3] && c % 3 != 0 ? (c % 3 == 1 ? c + 1 : c - 1) : c;
  std::vector<uint32_t> flipped_mate(mate.size(), kNone);
  for (uint32_t c = 0; c < mate.size(); ++c)
    if (mate[c] != kNone)
      flipped_mate[renamed[c]] = renamed[mate[c]];
  mate.swap(flipped_mate);
  for (uint32_t f = 0; f < nf; ++f) {
    if (!flip[f])
      continue;
    std::swap(t[3 * f + 1], t[3 * f + 2]);
    if (r.faces_flipped++ == 0)
      r.flipped_example = origin[f];
  }
  return flip;
}

/// After orient(): a gluable edge stays glued iff its two faces now use it in opposite
/// directions; the others cannot be oriented and are cut (counted), leaving `mate` as the
/// glue.
void cut_nonorientable(const std::vector<uint32_t> &t, std::vector<uint32_t> &mate,
                       RepairReport &r) {
  for (uint32_t c = 0; c < mate.size(); ++c) {
    const uint32_t m = mate[c];
    if (m == kNone || m < c || !same_direction(t, c, m))
      continue;
    mate[c] = mate[m] = kNone;
    ++r.edges_cut;
    if (r.edges_cut_nonorientable++ == 0) {
      r.nonorientable_edge_example[0] = t[CornerTable::next(c)];
      r.nonorientable_edge_example[1] = t[CornerTable::prev(c)];
    }
  }
}

// ------------------------------------------------------------------ step 3: fans

/// One output vertex per fan: corners of one vertex are joined across glued edges, and
/// each class gets a vertex (the first class, in corner order, keeps the input index;
/// the others are new copies at `nv`, `nv + 1`, ...). Returns the new triangles;
/// copy_of lists the input vertex of each copy.
std::vector<uint32_t> split_fans(const std::vector<uint32_t> &t, size_t nv,
                                 const std::vector<uint32_t> &mate,
                                 std::vector<uint32_t> &copy_of) {
  const uint32_t nc = static_cast<uint32_t>(t.size());
  DisjointSets sets(nc);
  for (uint32_t c = 0; c < nc; ++c) {
    const uint32_t m = mate[c];
    if (m == kNone || m < c)
      continue;
    // c's edge runs next(c) -> prev(c); m's runs the other way: next(m) = prev(c).
    sets.unite(CornerTable::next(c), CornerTable::prev(m));
    sets.unite(CornerTable::prev(c), CornerTable::next(m));
  }
  std::vector<uint8_t> taken(nv, 0);
  std::vector<uint32_t> vertex_of_root(nc, kNone), out(nc);
  copy_of.clear();
  for (uint32_t c = 0; c < nc; ++c) {
    const uint32_t root = sets.find(c);
    if (vertex_of_root[root] == kNone) {
      const uint32_t v = t[c];
      if (!taken[v]) {
        taken[v] = 1;
        vertex_of_root[root] = v;
      } else {
        if (nv + copy_of.size() >= kNone)
          throw Error(Error::Kind::InvalidMesh, "the repaired mesh would have too many vertices");
        vertex_of_root[root] = static_cast<uint32_t>(nv + copy_of.size());
        copy_of.push_back(v);
      }
    }
    out[c] = vertex_of_root[root];
  }
  return out;
}

} // namespace

// ------------------------------------------------------------------ report

bool RepairReport::changed() const {
  return degenerate_faces_removed || duplicate_faces_removed || faces_flipped || edges_cut ||
         vertices_split || vertices_added;
}

std::string RepairReport::summary() const {
  std::vector<std::string> lines;
  auto num = [](size_t n) { return std::to_string(n); };
  if (degenerate_faces_removed)
    lines.push_back("removed " + plural(degenerate_faces_removed, "face") +
                    " repeating a vertex (e.g. face " + num(degenerate_example) + " (" +
                    num(degenerate_vertices[0]) + ", " + num(degenerate_vertices[1]) + ", " +
                    num(degenerate_vertices[2]) + "))");
  if (duplicate_faces_removed)
    lines.push_back("removed " + plural(duplicate_faces_removed, "duplicate face") +
                    " (e.g. face " + num(duplicate_example) + " repeats face " + num(duplicate_of) +
                    ")");
  if (faces_flipped)
    lines.push_back("flipped " + plural(faces_flipped, "face") +
                    " to orient the mesh consistently (e.g. face " + num(flipped_example) + ")");
  auto edge = [&](const uint32_t *e) { return "edge (" + num(e[0]) + ", " + num(e[1]) + ")"; };
  if (edges_cut > edges_cut_nonorientable)
    lines.push_back("cut " + plural(edges_cut - edges_cut_nonorientable, "edge") +
                    " shared by more than two faces (e.g. " + edge(nonmanifold_edge_example) +
                    ", " + plural(nonmanifold_edge_faces, "face") + ")");
  if (edges_cut_nonorientable)
    lines.push_back("cut " + plural(edges_cut_nonorientable, "edge") +
                    " whose two faces cannot be oriented consistently (e.g. " +
                    edge(nonorientable_edge_example) + ")");
  if (vertices_split)
    lines.push_back("split " +
                    plural(vertices_split, "non-manifold vertex", "non-manifold vertices") +
                    " into " + num(vertices_split + vertices_added) + " (e.g. vertex " +
                    num(split_example) + " into " + num(split_example_fans) + ")");
  if (lines.empty())
    return "nothing to repair";
  std::string s = lines[0];
  for (size_t i = 1; i < lines.size(); ++i)
    s += "\n" + lines[i];
  return s;
}

// ------------------------------------------------------------------ make_manifold

RepairReport cut_to_manifold(Mesh &mesh, RepairMap *map) {
  RepairReport r;
  const size_t nv = mesh.vertex_count();
  if (mesh.positions.size() % 3 != 0 || mesh.triangles.size() % 3 != 0)
    throw Error(Error::Kind::InvalidMesh,
                "position and triangle arrays must hold multiples of 3 values");
  if (nv >= kNone || mesh.triangles.size() >= kNone)
    throw Error(Error::Kind::InvalidMesh, "the mesh is too large to repair (" +
                                              std::to_string(mesh.triangle_count()) +
                                              " triangles)");
  for (size_t c = 0; c < mesh.triangles.size(); ++c)
    if (mesh.triangles[c] >= nv)
      throw Error(Error::Kind::InvalidMesh, "face " + std::to_string(c / 3) + " uses vertex " +
                                                std::to_string(mesh.triangles[c]) +
                                                " but the mesh has only " + std::to_string(nv) +
                                                " vertices");

  std::vector<uint32_t> t = mesh.triangles, origin;
  remove_bad_faces(t, nv, origin, r);
  std::vector<uint32_t> mate = find_mates(t, nv, r);
  std::vector<uint8_t> flipped = orient(t, mate, origin, r);
  cut_nonorientable(t, mate, r);

  std::vector<uint32_t> copy_of;
  std::vector<uint32_t> split = split_fans(t, nv, mate, copy_of);

  // Count the split vertices: fans per input vertex = 1 + its copies.
  std::vector<uint32_t> fans(nv, 1);
  for (uint32_t v : copy_of)
    ++fans[v];
  r.vertices_added = copy_of.size();
  for (uint32_t v = 0; v < nv; ++v) {
    if (fans[v] < 2)
      continue;
    if (r.vertices_split++ == 0) {
      r.split_example = v;
      r.split_example_fans = fans[v];
    }
  }

  if (map) {
    map->copy_of = copy_of;
    map->face_origin = std::move(origin);
    map->flipped = std::move(flipped);
  }
  if (!r.changed())
    return r; // bit for bit unchanged
  mesh.triangles = std::move(split);
  mesh.positions.reserve(3 * (nv + copy_of.size()));
  for (uint32_t v : copy_of)
    for (int a = 0; a < 3; ++a)
      mesh.positions.push_back(mesh.positions[3 * v + a]);
  // A copy carries the attributes of its vertex (attributes of another length are left
  // alone: the encoder reports them).
  for (VertexAttribute &attr : mesh.attributes) {
    const size_t n = attr.components;
    const bool colour = attr.kind == AttributeKind::Colour;
    if (n == 0 || (colour ? attr.colour.size() : attr.values.size()) != n * nv)
      continue;
    for (uint32_t v : copy_of)
      for (size_t k = 0; k < n; ++k) {
        if (colour)
          attr.colour.push_back(attr.colour[n * v + k]);
        else
          attr.values.push_back(attr.values[n * v + k]);
      }
  }
  return r;
}

Error still_invalid(const Error &e) {
  return Error(Error::Kind::Internal,
               std::string("internal repair error: the repaired mesh is still invalid: ") +
                   e.what());
}

RepairReport make_manifold(Mesh &mesh, RepairMap *map) {
  const RepairReport r = cut_to_manifold(mesh, map);
  if (!r.changed())
    return r;
  // The codec's own check must accept the result (see the argument at the top of this
  // file); if it ever does not, say so rather than hand back a wrong mesh.
  try {
    CornerTable ct;
    build_corner_table(mesh.triangles.data(), mesh.triangle_count(), mesh.vertex_count(), ct);
  } catch (const Error &e) {
    if (mesh.triangle_count() != 0)
      throw still_invalid(e);
  }
  return r;
}

bool repair_would_change(const Mesh &mesh) {
  Mesh copy = mesh;
  try {
    return make_manifold(copy).changed();
  } catch (const Error &) {
    return false;
  }
}

} // namespace pomar
