#include "geometry/quantize.h"

#include <algorithm>
#include <cmath>

#include "memory/prefault.h"

namespace pomar {

double Quantizer::step() const {
  return extent > 0 ? double(extent) / double((uint32_t(1) << bits) - 1) : 0.0;
}

float Quantizer::dequantize(int axis, uint32_t q) const {
  return static_cast<float>(double(origin[axis]) + double(q) * step());
}

uint32_t Quantizer::quantize(int axis, float x) const {
  const double s = step();
  const double t = s > 0 ? (double(x) - double(origin[axis])) / s : 0.0;
  const double top = double((uint32_t(1) << bits) - 1);
  return static_cast<uint32_t>(std::clamp(std::floor(t + 0.5), 0.0, top));
}

Quantizer make_quantizer(const float *p, size_t n, int bits) {
  Quantizer g;
  g.bits = bits;
  float lo[3] = {p[0], p[1], p[2]}, hi[3] = {p[0], p[1], p[2]};
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[3 * i + k]);
      hi[k] = std::max(hi[k], p[3 * i + k]);
    }
  double extent = 0;
  for (int k = 0; k < 3; ++k) {
    g.origin[k] = lo[k];
    extent = std::max(extent, double(hi[k]) - double(lo[k]));
  }
  g.extent = static_cast<float>(extent);
  if (double(g.extent) < extent) // round the extent up so the grid covers the box
    g.extent = std::nextafter(g.extent, INFINITY);
  return g;
}

std::vector<int32_t> quantize(const Quantizer &g, const float *p, size_t n) {
  // Quantizer::quantize for every coordinate, the step and the grid's top computed once
  // (the same doubles, so the same values).
  std::vector<int32_t> q = filled_vector<int32_t>(3 * n);
  const double s = g.step();
  const double top = double((uint32_t(1) << g.bits) - 1);
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      const double t = s > 0 ? (double(p[3 * i + k]) - double(g.origin[k])) / s : 0.0;
      q[3 * i + k] = static_cast<int32_t>(std::clamp(std::floor(t + 0.5), 0.0, top));
    }
  return q;
}

std::vector<float> dequantize(const Quantizer &g, const std::vector<int32_t> &q) {
  // Quantizer::dequantize for every coordinate, the step computed once (same floats).
  std::vector<float> p = filled_vector<float>(q.size());
  const double step = g.step();
  const double origin[3] = {g.origin[0], g.origin[1], g.origin[2]};
  for (size_t i = 0; i < q.size(); ++i)
    p[i] = static_cast<float>(origin[i % 3] + double(static_cast<uint32_t>(q[i])) * step);
  return p;
}

} // namespace pomar
