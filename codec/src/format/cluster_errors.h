// The CERR section (optional): a stored geometric error per cluster and clustered level,
// what view-dependent decoding compares with a pixel budget (docs/format.md, "Section
// CERR").
#pragma once

#include <cstdint>
#include <vector>

#include "format/file_format.h"

namespace pomar {

constexpr uint32_t kClusterErrorsTag = section_tag("CERR"); // optional (flags 0)

/// Per clustered level l = first_level .. first_level + levels - 1 (the cluster decoded to
/// level l; the finest level has error 0 and is not stored) a scale, and per cluster a code
/// e. Version 1 (eighths of an octave): the cluster's deviation at that level is at most
/// scale * 2^(e/8). Version 2 (whole octaves, one scale for every level): at most
/// scale * 2^e for e >= 1, and 0 for e = 0 (no vertex of the cluster is missing).
struct ClusterErrors {
  uint8_t version = 2;      // the code's step: 1 eighths, 2 whole octaves
  uint32_t first_level = 0; // the base clustered level G
  uint32_t clusters = 0;
  std::vector<float> scale;  // per stored level (version 2: the same at every level)
  std::vector<uint8_t> code; // level-major: code[(l - first_level) * clusters + c]
  bool empty() const { return scale.empty(); }
  uint32_t levels() const { return static_cast<uint32_t>(scale.size()); }
  /// The stored bound of cluster c at level l (0 at or past the finest level).
  double bound(uint32_t c, int level) const;
};

/// The bound a version 1 code stands for (the decoder's formula; the encoder rounds up to it).
double error_bound(float scale, uint8_t code);
/// The bound a version 2 code stands for: 0 for code 0, otherwise scale * 2^code.
double octave_error_bound(float scale, uint8_t code);

/// Codes for measured errors (level-major, `levels` x `clusters`, each >= 0): per level the
/// scale maps the largest error to code 255 and every code is the smallest whose bound is
/// at least the error.
ClusterErrors quantize_cluster_errors(uint32_t first_level, uint32_t clusters,
                                      const std::vector<double> &errors);
/// Version 2 codes for the same errors: one scale maps the largest error of all levels to
/// code kOctaveCodes - 1, every other error to the smallest code whose bound is at least
/// it (code 1 for the errors below scale * 2), errors of 0 to code 0.
constexpr int kOctaveCodes = 64;
ClusterErrors quantize_cluster_errors_octaves(uint32_t first_level, uint32_t clusters,
                                              const std::vector<double> &errors);

/// The section body in `e.version`'s code.
std::vector<uint8_t> write_cluster_errors(const ClusterErrors &e);
/// Parse a CERR body against the file (its clustered levels and clusters); throws a
/// damaged-file error naming the section when it does not fit.
ClusterErrors read_cluster_errors(const uint8_t *body, uint64_t size, const FileLayout &layout);
/// The file's CERR section, checked (empty when the file has none).
ClusterErrors load_cluster_errors(const uint8_t *global, const FileLayout &layout);

} // namespace pomar
