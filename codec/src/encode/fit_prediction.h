// The encoder's choice of each level's normal predictor (format version 5, section GEOP,
// docs/format.md): fitted on the level's own splits before the level is coded.
#pragma once

#include <cstdint>

#include "encode/encoder_codec.h"
#include "geometry/predict.h"

namespace pomar {

/// The normal predictor for refinement level `level` (the next one the rebuild codes; the
/// rebuilt mesh is the level before it, with nothing of `level` applied): the features of
/// every collapse of the level (the heights of geometry/predict.h's normal_vectors) on that mesh,
/// the coefficients fitted by weighted least squares (a few reweighted rounds, which favour small
/// residuals as the magnitude-class code does), kept only if the estimated cost of the normal
/// residuals, with the 8 bytes of coefficients (and, unless `section_written`, the level's share of
/// the section's own bytes), is below the curvature term's. `clustered`: ties in the choice of
/// v_ref by cluster key (as the clustered traversal).
NormalPredictor fit_normal_predictor(const Rebuild &rb, uint32_t level, bool clustered,
                                     bool section_written);

} // namespace pomar
