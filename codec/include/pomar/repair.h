// pomar: an explicit, opt-in repair that turns a non-manifold or inconsistently oriented
// triangle mesh into one the encoder accepts, by cutting it (never by moving a vertex).
//
// The codec itself never repairs anything: pomar::encode() refuses such meshes with a
// clear message. Callers that want the cut mesh instead call make_manifold() first and
// show the returned report, which counts every change with one example of each kind.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "pomar/pomar.h"

namespace pomar {

/// What make_manifold() changed. Every count is zero when the mesh was already a
/// manifold, consistently oriented mesh without degenerate or duplicate faces. Face and
/// vertex indices of the examples refer to the INPUT mesh.
struct RepairReport {
  /// Faces repeating a vertex index, e.g. (4, 5, 4): removed.
  size_t degenerate_faces_removed = 0;
  /// Faces with the same three vertex indices as an earlier face, in the same cyclic
  /// order (same orientation): removed. A face with the same vertices in the opposite
  /// order is NOT an exact duplicate: it is kept (the cutting separates it if needed).
  size_t duplicate_faces_removed = 0;
  /// Faces whose vertex order was reversed so that neighbours agree on the orientation.
  size_t faces_flipped = 0;
  /// Edges no longer glued: shared by more than two faces, plus two-face edges that
  /// cannot be oriented consistently (e.g. the seam of a Moebius strip).
  size_t edges_cut = 0;
  size_t edges_cut_nonorientable = 0; ///< the second kind (included in edges_cut)
  /// Input vertices whose faces fell apart into several fans, each fan getting its own
  /// vertex (same position). vertices_added copies were appended to the vertex array.
  size_t vertices_split = 0;
  size_t vertices_added = 0;

  // One example of each kind (valid when its count is non-zero).
  size_t degenerate_example = 0; ///< input face index
  uint32_t degenerate_vertices[3] = {0, 0, 0};
  size_t duplicate_example = 0;                  ///< input face index
  size_t duplicate_of = 0;                       ///< the earlier input face it repeats
  size_t flipped_example = 0;                    ///< input face index
  uint32_t nonmanifold_edge_example[2] = {0, 0}; ///< input vertices of a cut edge
  size_t nonmanifold_edge_faces = 0;             ///< faces on that edge (> 2)
  uint32_t nonorientable_edge_example[2] = {0, 0};
  uint32_t split_example = 0;    ///< input vertex index
  size_t split_example_fans = 0; ///< fans it was split into

  bool changed() const;
  /// One line per kind of change ("split 2 non-manifold vertices into 4 (e.g. vertex 18
  /// into 2)"), separated by '\n', no trailing newline; "nothing to repair" if unchanged.
  std::string summary() const;
};

/// Cut `mesh` into a manifold, consistently oriented mesh that pomar::encode() accepts:
///  1. remove faces repeating a vertex and exact duplicate faces (see RepairReport);
///  2. orient each connected piece consistently, flipping as few faces as the traversal
///     allows; edges that cannot be made consistent are cut;
///  3. cut edges shared by more than two faces;
///  4. split every vertex whose faces now form several fans, one vertex per fan (copies
///     keep the exact position; the first fan keeps the original index, copies are
///     appended after the input vertices);
/// After steps 3 and 4 no edge can be shared wrongly any more (the argument is in
/// codec/src/repair/make_manifold.cpp), so no face is ever detached from its neighbours
/// beyond the cut edges. Every other face is kept, in input order (zero-area faces with three
/// distinct vertices are valid and kept); unreferenced vertices are left alone (the encoder drops
/// them). A mesh that needs nothing is left bit for bit unchanged. Throws pomar::Error if a face
/// refers to a vertex index >= the vertex count.
RepairReport make_manifold(Mesh &mesh);

/// True if make_manifold() would change `mesh` (run on a copy; false if it throws): when an
/// encode fails, whether the repair is worth suggesting.
bool repair_would_change(const Mesh &mesh);

} // namespace pomar
