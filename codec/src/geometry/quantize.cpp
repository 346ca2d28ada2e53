#include "geometry/quantize.h"

#include <algorithm>
#include <cmath>

namespace pomar {

double Quantizer::step() const {
  return extent > 0 ? double(extent) / double((uint32_t(1) << bits) - 1) : 0.0;
}

float Quantizer::dequantize(int axis, uint32_t q) const {
  return static_cast<float>(double(origin[axis]) + double(q) * step());
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
  std::vector<int32_t> q(3 * n);
  const double step = g.step();
  const double inv = step > 0 ? 1.0 / step : 0.0;
  const int32_t top = static_cast<int32_t>((uint32_t(1) << g.bits) - 1);
  for (size_t i = 0; i < 3 * n; ++i) {
    const double t = (double(p[i]) - double(g.origin[i % 3])) * inv;
    const int32_t v = static_cast<int32_t>(std::floor(t + 0.5));
    q[i] = std::clamp(v, int32_t(0), top);
  }
  return q;
}

} // namespace pomar
