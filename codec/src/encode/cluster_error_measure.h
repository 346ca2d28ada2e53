// The stored error per cluster and level (section CERR): measured on the file the encoder
// has just written, decoded level by level as every decoder sees it.
#pragma once

#include <cstdint>
#include <vector>

namespace pomar {

/// The CERR section body for a clustered file image: for every cluster c and clustered
/// level l below the finest, a bound of the distance from each full-resolution vertex of
/// c that level l does not have yet to the surface of the mesh decoded uniformly to level
/// l (the distance to the faces around the nearest vertex of c at level l, which bounds
/// the distance to the whole surface), made non-increasing in l, rounded up to its code.
/// `threads`: the decoder's.
std::vector<uint8_t> measure_cluster_errors(const std::vector<uint8_t> &file, unsigned threads);

} // namespace pomar
