// How one level predicts the normal component of v_from's residual (format version 5,
// section GEOP, chosen per level by the encoder: encode/fit_prediction.h): the curvature
// term of versions 1-4, or the height of a linear combination of kNormalFeatures vectors
// (geometry/predict.h, normal_vectors) with coefficients in units of 2^-kNormalShift.
#pragma once

#include <cstddef>
#include <cstdint>

namespace pomar {

constexpr int kNormalFeatures = 4;
constexpr int kNormalShift = 12;
constexpr int32_t kNormalCoefficientMax = 32767;              // stored as int16
constexpr size_t kNormalPredictorBytes = 2 * kNormalFeatures; // per linear level

struct NormalPredictor {
  bool linear = false;
  int32_t c[kNormalFeatures] = {0, 0, 0, 0};
};

} // namespace pomar
