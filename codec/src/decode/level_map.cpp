// The level map (paper section 6): which level each cluster is decoded to, so that
// neighbouring clusters are at most one level apart; the cluster graph it is computed on.
#include "decode/level_map.h"

#include <algorithm>

#include "pomar/random_access.h"

namespace pomar {

ClusterGraph cluster_graph(const CornerTable &ct, uint32_t clusters) {
  ClusterGraph g;
  Ring ring;
  g.start.assign(clusters + 1, 0);
  for (uint32_t c = 0; c < clusters; ++c) {
    get_ring(ct, c, ring);
    g.adj.insert(g.adj.end(), ring.neighbour.begin(), ring.neighbour.end());
    g.start[c + 1] = static_cast<uint32_t>(g.adj.size());
  }
  return g;
}

std::vector<int> complete_level_map(const std::vector<int> &wanted,
                                    const std::vector<uint32_t> &start,
                                    const std::vector<uint32_t> &adj, int floor) {
  const size_t n = wanted.size();
  std::vector<int> m(n);
  int top = floor;
  for (size_t c = 0; c < n; ++c) {
    m[c] = std::max(wanted[c], floor);
    top = std::max(top, m[c]);
  }
  // Buckets by level, highest first: each cluster lowers its neighbours' floor to its
  // own level - 1 (the topological distance term of section 6).
  std::vector<std::vector<uint32_t>> bucket(size_t(top - floor + 1));
  for (size_t c = 0; c < n; ++c)
    if (m[c] > floor)
      bucket[size_t(m[c] - floor)].push_back(static_cast<uint32_t>(c));
  for (int lvl = top; lvl > floor; --lvl) {
    for (size_t i = 0; i < bucket[size_t(lvl - floor)].size(); ++i) {
      const uint32_t c = bucket[size_t(lvl - floor)][i];
      if (m[c] != lvl)
        continue;
      for (uint32_t k = start[c]; k < start[c + 1]; ++k) {
        const uint32_t nb = adj[k];
        if (m[nb] < lvl - 1) {
          m[nb] = lvl - 1;
          if (lvl - 1 > floor)
            bucket[size_t(lvl - 1 - floor)].push_back(nb);
        }
      }
    }
  }
  return m;
}

// limit[x] = min over clusters c of cap[c] + d(c, x): buckets by value, lowest first (a
// multi-source breadth-first search).
std::vector<int> cap_distance_map(const std::vector<int> &cap, const std::vector<uint32_t> &start,
                                  const std::vector<uint32_t> &adj, int top) {
  std::vector<int> limit(cap.size(), top);
  int low = top;
  for (size_t c = 0; c < cap.size(); ++c) {
    limit[c] = std::min(cap[c], top);
    low = std::min(low, limit[c]);
  }
  std::vector<std::vector<uint32_t>> bucket(size_t(top - low + 1));
  for (size_t c = 0; c < cap.size(); ++c)
    if (limit[c] < top)
      bucket[size_t(limit[c] - low)].push_back(static_cast<uint32_t>(c));
  for (int lvl = low; lvl < top; ++lvl) {
    for (size_t i = 0; i < bucket[size_t(lvl - low)].size(); ++i) {
      const uint32_t c = bucket[size_t(lvl - low)][i];
      if (limit[c] != lvl)
        continue;
      for (uint32_t k = start[c]; k < start[c + 1]; ++k)
        if (limit[adj[k]] > lvl + 1) {
          limit[adj[k]] = lvl + 1;
          bucket[size_t(lvl + 1 - low)].push_back(adj[k]);
        }
    }
  }
  return limit;
}

} // namespace pomar
