// The encoder's normal predictor per level; see fit_prediction.h.
#include "encode/fit_prediction.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "refine/level_traversal.h"
#include "refine/patch_rank.h"

namespace pomar {
namespace {

/// The normal component of v in `frame`: to_local's third, which its last rotation (in the
/// tangent plane) leaves as it is.
[[gnu::always_inline]] inline int64_t height(const FrenetFrame &frame, const int64_t v[3]) {
  using namespace frenet_detail;
  int64_t w[3] = {v[0], v[1], v[2]};
  apply<kPlane[0][0], kPlane[0][1]>(frame.g[0], w);
  apply<kPlane[1][0], kPlane[1][1]>(frame.g[1], w);
  return w[2];
}
static_assert(kPlane[2][0] != 2 && kPlane[2][1] != 2, "the last rotation keeps the normal");

/// One split of the level as the decoder will see it: the predictor's vectors and frame,
/// the features the fit uses (the vectors' heights), the normal component of the residual
/// to the barycentre, the curvature term's offset and the model context.
struct NormalSample {
  int64_t x[kNormalFeatures][3];
  FrenetFrame frame;
  double f[kNormalFeatures];
  int64_t target, legacy;
  int context;
};

template <class Key>
void collect(const Rebuild &rb, uint32_t level, const Key &key, std::vector<NormalSample> &out) {
  const LevelMesh &mesh = rb.mesh;
  Ring ring;
  std::vector<Spoke> spokes;
  const NormalPredictor legacy;
  for (const Collapse &c : rb.collapses(level)) {
    const uint32_t v = rb.input_to_dec[c.v_to];
    get_ring(mesh.ct, v, ring);
    const uint32_t m = ring.size();
    const auto index = [&](uint32_t input) {
      return input == kNone ? -1 : ring.index_of(rb.input_to_dec[input]);
    };
    const int il = index(c.v_l), ir = index(c.v_r);
    if (m < 2 || (c.v_l != kNone && il < 0) || (c.v_r != kNone && ir < 0) ||
        (ring.closed && (il < 0 || ir < 0)))
      continue; // (not a split the traversal codes this way: left out of the fit)
    const int32_t l = il, r = ir < 0 ? int32_t(m) : ir;
    const uint32_t faces = ring.closed ? uint32_t(ir + int(m) - il) % m : uint32_t(r - l);
    if (faces == 0 || (!ring.closed && (il < 0 && ir < 0)))
      continue;
    load_spokes(mesh.q, v, ring, spokes);
    uint32_t j;
    SplitSymbols sym;
    patch_symbols(ring, spokes.data(), l, faces, key, j, sym);
    PatchRange p;
    if (!resolve_patch(ring, j, sym, p))
      continue;
    const int32_t *at = &mesh.q[3 * size_t(v)];
    Prediction pred;
    predict(at, ring, spokes.data(), p, legacy, pred);
    NormalSample s;
    normal_vectors(at, ring, spokes.data(), p, pred, s.x);
    s.frame = pred.frame;
    for (int k = 0; k < kNormalFeatures; ++k)
      s.f[k] = double(height(pred.frame, s.x[k]));
    int64_t res[3];
    for (int k = 0; k < 3; ++k)
      res[k] = int64_t(rb.q[3 * size_t(c.v_from) + k]) - pred.barycentre[k];
    s.target = height(pred.frame, res);
    s.legacy = pred.offset[2];
    s.context = pred.context;
    out.push_back(s);
  }
}

/// Estimated bits of coding residuals `r` (the normal kind's code: a magnitude class per
/// context, adaptive, then sign and mantissa bits): the classes' empirical entropy per
/// context plus one bit per bit of magnitude.
double estimate_bits(const std::vector<NormalSample> &samples, const std::vector<int64_t> &r) {
  std::vector<uint32_t> counts(size_t(kGeomContexts) * kMagnitudeSymbols, 0);
  std::vector<uint32_t> totals(kGeomContexts, 0);
  double bits = 0;
  for (size_t i = 0; i < r.size(); ++i) {
    const int n = std::min(bit_length(uint64_t(r[i] < 0 ? -r[i] : r[i])), kMagnitudeSymbols - 1);
    ++counts[size_t(samples[i].context) * kMagnitudeSymbols + size_t(n)];
    ++totals[size_t(samples[i].context)];
    bits += n;
  }
  for (int c = 0; c < kGeomContexts; ++c)
    for (int n = 0; n < kMagnitudeSymbols; ++n)
      if (const uint32_t k = counts[size_t(c) * kMagnitudeSymbols + size_t(n)])
        bits -= double(k) * std::log2(double(k) / double(totals[size_t(c)]));
  return bits;
}

std::vector<int64_t> residuals(const std::vector<NormalSample> &samples, const NormalPredictor &p) {
  std::vector<int64_t> r(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    const NormalSample &s = samples[i];
    if (!p.linear) {
      r[i] = s.target - s.legacy;
      continue;
    }
    int64_t v[3]; // (normal_offset's terms)
    combine_normal_vectors(p, s.x, v);
    r[i] = s.target - linear_normal_offset(height(s.frame, v));
  }
  return r;
}

/// Weighted least squares of the targets on the features (normal equations, ridge-damped),
/// rounded to the section's fixed point; false when the system is singular.
bool fit(const std::vector<NormalSample> &samples, const std::vector<double> &w,
         NormalPredictor &out) {
  constexpr int K = kNormalFeatures;
  double a[K][K + 1] = {};
  for (size_t i = 0; i < samples.size(); ++i) {
    const NormalSample &s = samples[i];
    for (int x = 0; x < K; ++x) {
      for (int y = 0; y < K; ++y)
        a[x][y] += w[i] * s.f[x] * s.f[y];
      a[x][K] += w[i] * s.f[x] * double(s.target);
    }
  }
  for (int x = 0; x < K; ++x)
    a[x][x] = a[x][x] * (1 + 1e-9) + 1e-9;
  for (int col = 0; col < K; ++col) { // Gauss-Jordan with partial pivoting
    int pivot = col;
    for (int row = col + 1; row < K; ++row)
      if (std::fabs(a[row][col]) > std::fabs(a[pivot][col]))
        pivot = row;
    if (std::fabs(a[pivot][col]) < 1e-12)
      return false;
    std::swap(a[pivot], a[col]);
    for (int row = 0; row < K; ++row) {
      if (row == col)
        continue;
      const double factor = a[row][col] / a[col][col];
      for (int k = col; k <= K; ++k)
        a[row][k] -= factor * a[col][k];
    }
  }
  out.linear = true;
  for (int x = 0; x < K; ++x) {
    const double c = std::round(a[x][K] / a[x][x] * double(1 << kNormalShift));
    out.c[x] =
        int32_t(std::clamp(c, double(-kNormalCoefficientMax), double(kNormalCoefficientMax)));
  }
  return true;
}

/// The estimate fits the coefficients on the very residuals it measures: a predictor must
/// gain this fraction of the bits before it is kept.
constexpr double kMargin = 0.01;
constexpr size_t kManySplits = 8192;

} // namespace

NormalPredictor fit_normal_predictor(const Rebuild &rb, uint32_t level, bool clustered,
                                     bool section_written) {
  std::vector<NormalSample> samples;
  samples.reserve(rb.collapses(level).size());
  if (clustered)
    collect(
        rb, level, [&](uint32_t v) { return rb.mesh.key(v); }, samples);
  else
    collect(
        rb, level, [](uint32_t v) { return uint64_t(v); }, samples);
  NormalPredictor best; // the curvature term of versions 1-4
  // The coefficients cost 64 bits. The section's table entry and fixed part, about 256 bits
  // more if no earlier level wrote it, are charged to the levels by their share of the
  // splits in a file of many splits (whose finest levels gain far more), else to this level.
  size_t splits = 0;
  for (const std::vector<Collapse> &l : rb.dec.levels)
    splits += l.size();
  const double section = section_written         ? 0.0
                         : splits >= kManySplits ? 256.0 * double(samples.size()) / double(splits)
                                                 : 256.0;
  const double cost = 8.0 * double(kNormalPredictorBytes) + section;
  if (samples.size() < 64)
    return best;
  double best_bits = estimate_bits(samples, residuals(samples, best));
  std::vector<double> w(samples.size(), 1.0);
  NormalPredictor last;
  for (int round = 0; round < 5; ++round) {
    NormalPredictor p;
    if (!fit(samples, w, p))
      break;
    // The same coefficients as the round before: the same residuals, so the same weights
    // and the same fit in every later round.
    if (round > 0 && std::equal(p.c, p.c + kNormalFeatures, last.c))
      break;
    last = p;
    const std::vector<int64_t> r = residuals(samples, p);
    const double bits = estimate_bits(samples, r) * (1.0 + kMargin) + cost;
    if (bits < best_bits) {
      best = p;
      best_bits = bits;
    }
    for (size_t i = 0; i < r.size(); ++i) // toward least absolute residuals
      w[i] = 1.0 / (std::fabs(double(r[i])) + 0.5);
  }
  return best;
}

} // namespace pomar
