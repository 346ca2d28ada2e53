// The GEOP section; see geometry_prediction.h.
#include "format/geometry_prediction.h"

#include <string>

namespace pomar {
namespace {

constexpr uint8_t kGeometryPredictionVersion = 1;
constexpr size_t kFixedBytes = 8; // version, features, shift, reserved, u32 levels

[[noreturn]] void damaged(const std::string &why) {
  throw Error(Error::Kind::DamagedFile, "damaged .pomar file: section 'GEOP' " + why);
}

} // namespace

bool needs_geometry_prediction(const std::vector<NormalPredictor> &levels) {
  for (const NormalPredictor &p : levels)
    if (p.linear)
      return true;
  return false;
}

std::vector<uint8_t> write_geometry_prediction(const std::vector<NormalPredictor> &levels) {
  const uint32_t n = static_cast<uint32_t>(levels.size());
  std::vector<uint8_t> out = {kGeometryPredictionVersion,
                              uint8_t(kNormalFeatures),
                              uint8_t(kNormalShift),
                              0,
                              uint8_t(n),
                              uint8_t(n >> 8),
                              uint8_t(n >> 16),
                              uint8_t(n >> 24)};
  out.resize(kFixedBytes + (n + 7) / 8, 0);
  for (uint32_t i = 0; i < n; ++i)
    if (levels[i].linear)
      out[kFixedBytes + i / 8] |= uint8_t(1u << (i % 8));
  for (const NormalPredictor &p : levels)
    if (p.linear)
      for (int32_t c : p.c) {
        const uint16_t u = static_cast<uint16_t>(static_cast<int16_t>(c));
        out.push_back(uint8_t(u));
        out.push_back(uint8_t(u >> 8));
      }
  return out;
}

std::vector<NormalPredictor> load_geometry_prediction(const uint8_t *global,
                                                      const FileLayout &layout) {
  const size_t levels = layout.header.levels.size();
  std::vector<NormalPredictor> out(levels);
  const int i = find_section(layout, kGeometryPredictionTag);
  if (i < 0)
    return out;
  const uint8_t *body = section_body(global, layout, size_t(i));
  const uint64_t bytes = layout.header.sections[size_t(i)].bytes;
  if (bytes < kFixedBytes || body[0] != kGeometryPredictionVersion || body[1] != kNormalFeatures ||
      body[2] != kNormalShift || body[3] != 0)
    damaged("is not a geometry prediction this build reads (version 1, 4 features, 12 "
            "fraction bits)");
  const uint32_t n = uint32_t(body[4]) | uint32_t(body[5]) << 8 | uint32_t(body[6]) << 16 |
                     uint32_t(body[7]) << 24;
  if (n != levels)
    damaged("describes " + std::to_string(n) + " levels, the file has " + std::to_string(levels));
  const uint64_t mask_bytes = (uint64_t(n) + 7) / 8;
  if (bytes < kFixedBytes + mask_bytes)
    damaged("ends inside its level mask");
  const uint8_t *mask = body + kFixedBytes;
  uint64_t linear = 0;
  for (uint32_t l = 0; l < n; ++l)
    linear += (mask[l / 8] >> (l % 8)) & 1;
  if (bytes != kFixedBytes + mask_bytes + linear * kNormalPredictorBytes)
    damaged("has " + std::to_string(bytes) + " bytes where its level mask needs " +
            std::to_string(kFixedBytes + mask_bytes + linear * kNormalPredictorBytes));
  const uint8_t *c = mask + mask_bytes;
  for (uint32_t l = 0; l < n; ++l) {
    if (!((mask[l / 8] >> (l % 8)) & 1))
      continue;
    out[l].linear = true;
    for (int k = 0; k < kNormalFeatures; ++k, c += 2)
      out[l].c[k] = static_cast<int16_t>(uint16_t(c[0]) | uint16_t(c[1]) << 8);
  }
  return out;
}

} // namespace pomar
