// Memory locality for the encoder: renumber vertices along a Morton (Z-order) curve of
// their quantized positions and sort faces by their vertices, so that the corner-table
// walks of decimation touch nearby memory. Pure permutation: connectivity is unchanged.
//
// The face order and the corner table do not depend on each other: the encoder builds the
// table on the renamed faces while it sorts them (two threads), then renumbers the table's
// faces (reorder_faces), which gives the table built on the sorted faces.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/corner_table.h"

namespace pomar {

/// Returns old->new vertex ids; permutes `q` (xyz) and renames the vertices of `triangles`
/// (their order unchanged).
std::vector<uint32_t> reorder_vertices(std::vector<int32_t> &q, std::vector<uint32_t> &triangles);

/// The faces of `triangles` sorted by their smallest vertex, as introsort leaves them
/// (ties included, the same on every platform: mesh/introsort.h): order[i] is the face
/// that goes i-th.
std::vector<uint32_t> face_order(const std::vector<uint32_t> &triangles);

/// Renumber the faces of `ct` (built by build_corner_table) so that face order[i] becomes
/// face i, corners keeping their place in the face: the table build_corner_table gives the
/// faces in that order (its VC included).
void reorder_faces(CornerTable &ct, const std::vector<uint32_t> &order);

} // namespace pomar
