// The stored error per cluster and level (section CERR), bounded while the encoder refines
// the clustered levels: the mesh it holds after level l is the mesh every decoder holds
// when it has decoded the whole file to level l.
#pragma once

#include <cstdint>
#include <vector>

#include "encode/encoder_codec.h"

namespace pomar {

class ThreadPool;

/// For every cluster c and clustered level l below the finest, a bound of the distance from
/// each full-resolution vertex of c that level l does not have yet to the surface of the
/// mesh decoded uniformly to level l: the distance to the level-l faces around the vertex's
/// ancestor at level l (the vertex of that level it descends from by splits; those faces
/// are part of the surface, so the distance bounds the distance to all of it). Made
/// non-increasing in l and rounded up to its code by the section (format/cluster_errors.h).
class ClusterErrorMeasure {
public:
  /// `rb` holds the base clustered mesh (level `global`, its vertices rooting the
  /// clusters); `grid` converts grid units into the file's units.
  ClusterErrorMeasure(const Rebuild &rb, size_t global, const Quantizer &grid);
  /// Bound the errors of the level `rb` holds now (global .. finest - 1, in order), on the
  /// pool's threads if one is given (the result does not depend on it).
  void measure(const Rebuild &rb, ThreadPool *pool);
  /// The CERR section body.
  std::vector<uint8_t> section() const;

private:
  void measure_cluster(const Rebuild &rb, uint32_t level, uint32_t c, double &worst);

  uint32_t global_, clusters_, measured_ = 0;
  double step_, margin_;
  // Every vertex, cluster by cluster (the root first, then in the order the levels create
  // them, so a parent comes before its children): [start_[c], start_[c + 1]). Per entry:
  // the level that creates it, its parent's entry, its id (the input's until the level
  // that creates it is measured, the decoder's from then on) and its ancestor at the level
  // being measured (a decoder id), the corner where the walk of its ancestor's fan starts
  // (the one that settled its distance at the level before, if any); and its position
  // (read in entry order, level after level).
  std::vector<uint32_t> start_, first_future_; // per cluster
  std::vector<uint16_t> created_;
  std::vector<uint32_t> parent_, id_, ancestor_, hint_;
  std::vector<int32_t> q_;
  std::vector<double> error_; // level-major, in the file's units
};

} // namespace pomar
