#include "mesh/corner_table.h"
#include "memory/prefault.h"

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
  std::vector<uint32_t> start(nv + 1, 0), order = filled_vector<uint32_t>(nc);
  auto edge = [&](uint32_t c, uint32_t &a, uint32_t &b) {
    a = t[CornerTable::next(c)];
    b = t[CornerTable::prev(c)];
  };
  // Corner c of face f faces the edge (t[next(c)], t[prev(c)]): for the corners of a face
  // in turn, the edges (t1, t2), (t2, t0), (t0, t1).
  for (size_t f = 0; f < nt; ++f) {
    const uint32_t *v = &t[3 * f];
    ++start[std::min(v[1], v[2]) + 1];
    ++start[std::min(v[2], v[0]) + 1];
    ++start[std::min(v[0], v[1]) + 1];
  }
  for (size_t v = 0; v < nv; ++v)
    start[v + 1] += start[v];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (size_t f = 0; f < nt; ++f) {
    const uint32_t *v = &t[3 * f], c = static_cast<uint32_t>(3 * f);
    order[fill[std::min(v[1], v[2])]++] = c;
    order[fill[std::min(v[2], v[0])]++] = c + 1;
    order[fill[std::min(v[0], v[1])]++] = c + 2;
  }
  std::vector<uint32_t>().swap(fill);
  size_t nonmanifold = 0, flipped = 0;
  std::string nm_example, flip_example;
  // A bucket's corners with the other end of their edge, sorted by it. std::sort's moves
  // depend only on its comparisons, so sorting (end, corner) pairs by the end gives the
  // order sorting the corners by their edge's end does (ties too), one load a comparison.
  struct Facing {
    uint32_t hi, c;
  };
  std::vector<Facing> bucket;
  for (size_t v = 0; v < nv; ++v) {
    bucket.clear();
    for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
      uint32_t a, b;
      edge(order[i], a, b);
      bucket.push_back({std::max(a, b), order[i]});
    }
    std::sort(bucket.begin(), bucket.end(),
              [](const Facing &x, const Facing &y) { return x.hi < y.hi; });
    const Facing *first = bucket.data(), *last = first + bucket.size();
    for (const Facing *run = first; run != last;) {
      const Facing *end = run + 1;
      while (end != last && end->hi == run->hi)
        ++end;
      uint32_t a, b;
      edge(run[0].c, a, b);
      if (end - run > 2) {
        if (nonmanifold++ == 0)
          nm_example = "edge (" + std::to_string(a) + ", " + std::to_string(b) + ") is shared by " +
                       std::to_string(end - run) + " faces";
      } else if (end - run == 2) {
        uint32_t a2, b2;
        edge(run[1].c, a2, b2);
        if (a2 == a) {
          if (flipped++ == 0)
            flip_example = "edge (" + std::to_string(a) + ", " + std::to_string(b) +
                           ") is used in the same direction by two faces";
        } else {
          ct.O[run[0].c] = run[1].c;
          ct.O[run[1].c] = run[0].c;
        }
      }
      run = end;
    }
  }
  if (nonmanifold)
    throw TopologyError(Error::Kind::InvalidMesh,
                        "non-manifold mesh: " + std::to_string(nonmanifold) +
                            " edges are shared by more than two faces; e.g. " + nm_example);
  if (flipped)
    throw TopologyError(Error::Kind::InvalidMesh,
                        "inconsistently oriented mesh: " + std::to_string(flipped) +
                            " edges are used twice in the same direction; e.g. " + flip_example);
}

/// The faces of v's fan, counted as get_ring walks them (without storing the ring).
uint32_t fan_faces(const CornerTable &ct, uint32_t v) {
  const uint32_t start = ct.VC[v];
  uint32_t faces = 0, c = start;
  do {
    ++faces;
    c = ct.swing_ccw(c);
  } while (c != kNone && c != start);
  if (c == kNone) // a boundary vertex: the faces clockwise of start too
    for (uint32_t b = ct.swing_cw(start); b != kNone; b = ct.swing_cw(b))
      ++faces;
  return faces;
}

// A manifold vertex has a single fan of faces: walking it must reach every face.
void check_vertex_fans(const CornerTable &ct, const std::vector<uint32_t> &faces_at) {
  size_t bad = 0;
  uint32_t example = 0;
  for (uint32_t v = 0; v < ct.vertex_count(); ++v) {
    if (ct.VC[v] == kNone)
      continue;
    if (fan_faces(ct, v) != faces_at[v] && bad++ == 0)
      example = v;
  }
  if (bad)
    throw TopologyError(Error::Kind::InvalidMesh,
                        "non-manifold mesh: " + std::to_string(bad) +
                            " vertices join separate fans of faces; e.g. vertex " +
                            std::to_string(example) + " (" + std::to_string(faces_at[example]) +
                            " faces)");
}

} // namespace

void build_corner_table(const uint32_t *t, size_t nt, size_t nv, CornerTable &ct) {
  if (nt == 0)
    throw TopologyError(Error::Kind::InvalidMesh, "the mesh contains no triangles");
  if (nt > (size_t(1) << 30) || nv >= kNone)
    throw TopologyError(Error::Kind::InvalidMesh,
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
    throw TopologyError(Error::Kind::InvalidMesh,
                        std::to_string(out_of_range) +
                            " faces use a vertex index >= the vertex count " + std::to_string(nv) +
                            "; e.g. " + face_text(t, oor_example));
  if (repeated)
    throw TopologyError(Error::Kind::InvalidMesh, "degenerate faces: " + std::to_string(repeated) +
                                                      " faces repeat a vertex; e.g. " +
                                                      face_text(t, rep_example));
  // (Large arrays written whole: their memory is mapped first, memory/prefault.h.)
  reserve_prefaulted(ct.V, 3 * nt);
  reserve_prefaulted(ct.O, 3 * nt);
  reserve_prefaulted(ct.VC, nv);
  ct.V.assign(t, t + 3 * nt);
  ct.O.assign(3 * nt, kNone);
  ct.VC.assign(nv, kNone);
  std::vector<uint32_t> faces_at = filled_vector<uint32_t>(nv);
  for (uint32_t c = 0; c < 3 * nt; ++c) {
    ct.VC[t[c]] = c;
    ++faces_at[t[c]];
  }
  match_opposites(t, nt, nv, ct);
  check_vertex_fans(ct, faces_at);
}

} // namespace pomar
