#include "mesh/corner_table.h"

#include <algorithm>
#include <string>

#include "pomar/pomar.h"

namespace pomar {

namespace {

std::string face_text(const uint32_t *t, size_t f) {
  return "face " + std::to_string(f) + " (" + std::to_string(t[3 * f]) + ", " +
         std::to_string(t[3 * f + 1]) + ", " + std::to_string(t[3 * f + 2]) + ")";
}

// Group the corners by the smaller vertex of the edge they face (counting sort), so that
// the two corners facing one edge can be matched in a short list.
void match_opposites(const uint32_t *t, size_t nt, size_t nv, CornerTable &ct) {
  const size_t nc = 3 * nt;
  std::vector<uint32_t> start(nv + 1, 0), order(nc);
  auto edge = [&](uint32_t c, uint32_t &a, uint32_t &b) {
    a = t[CornerTable::next(c)];
    b = t[CornerTable::prev(c)];
  };
  for (uint32_t c = 0; c < nc; ++c) {
    uint32_t a, b;
    edge(c, a, b);
    ++start[std::min(a, b) + 1];
  }
  for (size_t v = 0; v < nv; ++v)
    start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (uint32_t c = 0; c < nc; ++c) {
    uint32_t a, b;
    edge(c, a, b);
    order[fill[std::min(a, b)]++] = c;
  }
  size_t nonmanifold = 0, flipped = 0;
  std::string nm_example, flip_example;
  auto hi_of = [&](uint32_t c) {
    uint32_t a, b;
    edge(c, a, b);
    return std::max(a, b);
  };
  for (size_t v = 0; v < nv; ++v) {
    // Sort the bucket by the other end of the edge, then look at runs of one edge.
    uint32_t *first = order.data() + start[v], *last = order.data() + start[v + 1];
    std::sort(first, last, [&](uint32_t x, uint32_t y) { return hi_of(x) < hi_of(y); });
    for (uint32_t *run = first; run != last;) {
      uint32_t *end = run + 1;
      while (end != last && hi_of(*end) == hi_of(*run))
        ++end;
      uint32_t a, b;
      edge(run[0], a, b);
      if (end - run > 2) {
        if (nonmanifold++ == 0)
          nm_example = "edge (" + std::to_string(a) + ", " + std::to_string(b) +
                       ") is shared by " + std::to_string(end - run) + " faces";
      } else if (end - run == 2) {
        uint32_t a2, b2;
        edge(run[1], a2, b2);
        if (a2 == a) {
          if (flipped++ == 0)
            flip_example = "edge (" + std::to_string(a) + ", " + std::to_string(b) +
                           ") is used in the same direction by two faces";
        } else {
          ct.O[run[0]] = run[1];
          ct.O[run[1]] = run[0];
        }
      }
      run = end;
    }
  }
  if (nonmanifold)
    throw Error(Error::Kind::InvalidMesh, "non-manifold mesh: " + std::to_string(nonmanifold) +
                                              " edges are shared by more than two faces; e.g. " +
                                              nm_example);
  if (flipped)
    throw Error(Error::Kind::InvalidMesh,
                "inconsistently oriented mesh: " + std::to_string(flipped) +
                    " edges are used twice in the same direction; e.g. " + flip_example);
}

// A manifold vertex has a single fan of faces: walking it must reach every face.
void check_vertex_fans(const CornerTable &ct, const std::vector<uint32_t> &faces_at) {
  size_t bad = 0;
  uint32_t example = 0;
  Ring ring;
  for (uint32_t v = 0; v < ct.vertex_count(); ++v) {
    if (ct.VC[v] == kNone)
      continue;
    get_ring(ct, v, ring);
    if (ring.faces() != faces_at[v] && bad++ == 0)
      example = v;
  }
  if (bad)
    throw Error(Error::Kind::InvalidMesh,
                "non-manifold mesh: " + std::to_string(bad) +
                    " vertices join separate fans of faces; e.g. vertex " +
                    std::to_string(example) + " (" + std::to_string(faces_at[example]) + " faces)");
}

} // namespace

void build_corner_table(const uint32_t *t, size_t nt, size_t nv, CornerTable &ct) {
  if (nt == 0)
    throw Error(Error::Kind::InvalidMesh, "the mesh contains no triangles");
  if (nt > (size_t(1) << 30) || nv >= kNone)
    throw Error(Error::Kind::InvalidMesh,
                "the mesh is too large (" + std::to_string(nt) + " triangles)");
  size_t repeated = 0, out_of_range = 0, rep_example = 0, oor_example = 0;
  for (size_t f = 0; f < nt; ++f) {
    const uint32_t a = t[3 * f], b = t[3 * f + 1], c = t[3 * f + 2];
    if (a >= nv || b >= nv || c >= nv) {
      if (out_of_range++ == 0)
        oor_example = f;
    } else if (a == b || b == c || a == c) {
      if (repeated++ == 0)
        rep_example = f;
    }
  }
  if (out_of_range)
    throw Error(Error::Kind::InvalidMesh,
                std::to_string(out_of_range) + " faces use a vertex index >= the vertex count " +
                    std::to_string(nv) + "; e.g. " + face_text(t, oor_example));
  if (repeated)
    throw Error(Error::Kind::InvalidMesh, "degenerate faces: " + std::to_string(repeated) +
                                              " faces repeat a vertex; e.g. " +
                                              face_text(t, rep_example));
  ct.V.assign(t, t + 3 * nt);
  ct.O.assign(3 * nt, kNone);
  ct.VC.assign(nv, kNone);
  std::vector<uint32_t> faces_at(nv, 0);
  for (uint32_t c = 0; c < 3 * nt; ++c) {
    ct.VC[t[c]] = c;
    ++faces_at[t[c]];
  }
  match_opposites(t, nt, nv, ct);
  check_vertex_fans(ct, faces_at);
}

} // namespace pomar
