// Memory locality for the encoder: renumber vertices along a Morton (Z-order) curve of
// their quantized positions and sort faces by their vertices, so that the corner-table
// walks of decimation touch nearby memory. Pure permutation: connectivity is unchanged.
#pragma once

#include <cstdint>
#include <vector>

namespace pomar {

/// Returns old->new vertex ids; permutes `q` (xyz) and rewrites/sorts `triangles`.
std::vector<uint32_t> reorder_for_locality(std::vector<int32_t> &q,
                                           std::vector<uint32_t> &triangles);

} // namespace pomar
