// Quantization of positions on a cubic grid over the bounding box (paper section 4:
// positions are quantized before reconstruction and encoding).
#pragma once

#include <cstdint>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

/// The grid for `positions` (xyz floats, all finite): origin = bbox min, extent = the
/// largest bbox side, 2^bits - 1 steps.
Quantizer make_quantizer(const float *positions, size_t vertex_count, int bits);

/// Quantize every position to the nearest grid point (clamped into the grid).
std::vector<int32_t> quantize(const Quantizer &grid, const float *positions, size_t count);

/// The positions of quantized xyz values `q` (Quantizer::dequantize on every coordinate).
std::vector<float> dequantize(const Quantizer &grid, const std::vector<int32_t> &q);

} // namespace pomar
