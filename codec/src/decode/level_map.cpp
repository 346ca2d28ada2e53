// The level map (paper section 6): which level each cluster is decoded to, so that
// neighbouring clusters are at most one level apart; the cluster graph it is computed on.
#include "decode/level_map.h"

#include <algorithm>
#include <array>

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

void link_coincident_clusters(const std::vector<int32_t> &q, uint32_t clusters, ClusterGraph &g) {
  std::vector<std::pair<std::array<int32_t, 3>, uint32_t>> at(clusters);
  for (uint32_t c = 0; c < clusters; ++c)
    at[c] = {{q[3 * size_t(c)], q[3 * size_t(c) + 1], q[3 * size_t(c) + 2]}, c};
  std::sort(at.begin(), at.end());
  std::vector<std::vector<uint32_t>> links(clusters);
  for (size_t i = 0, j; i < at.size(); i = j) {
    for (j = i + 1; j < at.size() && at[j].first == at[i].first; ++j)
      ;
    for (size_t a = i; a < j; ++a)
      for (size_t b = i; b < j; ++b)
        if (a != b)
          links[at[a].second].push_back(at[b].second);
  }
  g.link_start.assign(clusters + 1, 0);
  g.link.clear();
  for (uint32_t c = 0; c < clusters; ++c) {
    g.link.insert(g.link.end(), links[c].begin(), links[c].end());
    g.link_start[c + 1] = static_cast<uint32_t>(g.link.size());
  }
}

std::vector<int> complete_level_map(const std::vector<int> &wanted,
                                    const std::vector<uint32_t> &start,
                                    const std::vector<uint32_t> &adj, int floor) {
  return complete_level_map(wanted, start, adj, floor, {}, {});
}

std::vector<int> complete_level_map(const std::vector<int> &wanted,
                                    const std::vector<uint32_t> &start,
                                    const std::vector<uint32_t> &adj, int floor,
                                    const std::vector<uint32_t> &link_start,
                                    const std::vector<uint32_t> &link) {
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
      if (!link_start.empty()) // linked clusters: the same level (this bucket grows)
        for (uint32_t k = link_start[c]; k < link_start[c + 1]; ++k)
          if (m[link[k]] < lvl) {
            m[link[k]] = lvl;
            bucket[size_t(lvl - floor)].push_back(link[k]);
          }
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
                                  const std::vector<uint32_t> &adj, int top,
                                  const std::vector<uint32_t> &link_start,
                                  const std::vector<uint32_t> &link) {
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
      if (!link_start.empty()) // linked clusters: capped alike (this bucket grows)
        for (uint32_t k = link_start[c]; k < link_start[c + 1]; ++k)
          if (limit[link[k]] > lvl) {
            limit[link[k]] = lvl;
            bucket[size_t(lvl - low)].push_back(link[k]);
          }
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
