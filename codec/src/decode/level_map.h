// The level map (paper section 6) on the cluster graph; complete_level_map itself is
// public (pomar/random_access.h).
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/corner_table.h"

namespace pomar {

/// The cluster graph = the base clustered mesh's edges, as CSR: the neighbours of
/// cluster c are adj[start[c] .. start[c + 1]).
struct ClusterGraph {
  std::vector<uint32_t> start, adj;
};

/// The cluster graph of a base clustered mesh whose vertex c roots cluster c.
ClusterGraph cluster_graph(const CornerTable &ct, uint32_t clusters);

/// limit[x] = min over clusters c of cap[c] + d(c, x) (d = edge distance in the cluster
/// graph), at most `top`: the finest level map that respects every cap and the level map
/// rule (used around damaged blocks, whose cluster is capped).
std::vector<int> cap_distance_map(const std::vector<int> &cap, const std::vector<uint32_t> &start,
                                  const std::vector<uint32_t> &adj, int top);

} // namespace pomar
