// The clusters (paper section 5.2): how many levels stay global, and the clustered levels
// coded cluster by cluster into independent blocks.
#pragma once

#include <cstdint>
#include <vector>

#include "encode/cluster_error_measure.h"
#include "encode/encoder_codec.h"
#include "pomar/pomar.h"

namespace pomar {

/// How many levels stay global: the level whose vertex count is closest (in ratio) to the
/// wanted number of clusters. Returns `levels` when no level would be clustered.
size_t choose_global_levels(const Decimation &dec, uint32_t base_vertices, uint32_t vertices,
                            const EncodeOptions &o);

/// The clustered part of a file: model tables and one block per cluster.
struct ClusteredLevels {
  std::vector<uint8_t> tables;
  std::vector<std::vector<uint8_t>> blocks;
  /// Per cluster c and clustered level j: blocks[c]'s size once level j was coded, at
  /// [c * levels + j] (the last level's: the finished block's size).
  std::vector<uint32_t> level_ends;
};

/// Encode refinement levels global+1 .. last of `rebuild` (which holds the base clustered
/// mesh: every vertex roots a cluster) and fill the clustered fields and level entries of
/// `header`. Each cluster's splits of every clustered level are recorded, the level models
/// frozen on all clusters' symbols, then every cluster is coded into its own block.
/// The clusters of a level are recorded on `threads` threads (1: one after the other),
/// those of a level started on fewer than `min_parallel_vertices` vertices on the calling
/// thread; the file does not depend on either.
/// With `errors`, the stored error of each level is bounded before the level above it is
/// coded (the mesh is then the one a decoder holds at that level).
ClusteredLevels encode_clustered_levels(Rebuild &rebuild, size_t global, FileHeader &header,
                                        unsigned threads, uint32_t min_parallel_vertices,
                                        const Progress &progress,
                                        ClusterErrorMeasure *errors = nullptr);

} // namespace pomar
