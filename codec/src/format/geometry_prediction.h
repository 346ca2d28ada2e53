// The GEOP section (required, format version 5): each refinement level's normal predictor,
// the curvature term of versions 1-4 or a linear one with its coefficients
// (docs/format.md, "Section GEOP"; the predictor: geometry/predict.h).
#pragma once

#include <cstdint>
#include <vector>

#include "format/file_format.h"
#include "geometry/predict.h"

namespace pomar {

constexpr uint32_t kGeometryPredictionTag = section_tag("GEOP"); // required

/// The body for `levels` (one per refinement level, level 1 first).
std::vector<uint8_t> write_geometry_prediction(const std::vector<NormalPredictor> &levels);
/// Whether any level needs the section (a file without it has the curvature term everywhere).
bool needs_geometry_prediction(const std::vector<NormalPredictor> &levels);
/// One predictor per refinement level of the file: the section's, or the curvature term
/// for every level of a file without it. Throws a damaged-file error naming the section
/// if the body is not one this build reads.
std::vector<NormalPredictor> load_geometry_prediction(const uint8_t *global,
                                                      const FileLayout &layout);

} // namespace pomar
