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
  /// Linked clusters (one level for all: SelectiveDecoder::cluster_links), CSR; empty
  /// link_start: none.
  std::vector<uint32_t> link_start, link;
};

/// The cluster graph of a base clustered mesh whose vertex c roots cluster c.
ClusterGraph cluster_graph(const CornerTable &ct, uint32_t clusters);

/// Link the clusters whose roots share a quantized position (`q`: xyz per vertex).
void link_coincident_clusters(const std::vector<int32_t> &q, uint32_t clusters, ClusterGraph &g);

/// limit[x] = min over clusters c of cap[c] + d(c, x) (d = edge distance in the cluster
/// graph), at most `top`: the finest level map that respects every cap and the level map
/// rule (used around damaged blocks, whose cluster is capped).
std::vector<int> cap_distance_map(const std::vector<int> &cap, const std::vector<uint32_t> &start,
                                  const std::vector<uint32_t> &adj, int top,
                                  const std::vector<uint32_t> &link_start = {},
                                  const std::vector<uint32_t> &link = {});

} // namespace pomar
