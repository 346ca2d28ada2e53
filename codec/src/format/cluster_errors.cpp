// The CERR section; see cluster_errors.h and docs/format.md.
#include "format/cluster_errors.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "entropy/models.h"
#include "entropy/range_coder.h"
#include "format/bit_io.h"

namespace pomar {

namespace {

constexpr int kClasses = 10; // bit lengths 0..8 of a code difference (|d| <= 255), + spare

/// The code models: one set for the first stored level (each code from the previous
/// cluster's), one for the others (version 1: each code from the same cluster's at the
/// level before). Version 2 codes the others as the drop from the same cluster's code at
/// the level before (codes never grow with the level), one adaptive model per level; a
/// cluster whose code is 0 there (nothing missing) is 0 at every later level, uncoded.
struct CodeModels {
  explicit CodeModels(uint32_t levels)
      : drop(levels > 1 ? levels - 1 : 0, FrequencyModel(kOctaveCodes)) {}
  FrequencyModel classes[2] = {FrequencyModel(kClasses), FrequencyModel(kClasses)};
  BitModel top[2][kClasses];
  std::vector<FrequencyModel> drop; // version 2, per stored level after the first
};

/// The code entry (k, c) is coded against.
int reference(const ClusterErrors &e, uint32_t k, uint32_t c) {
  const size_t i = size_t(k) * e.clusters + c;
  if (k == 0)
    return c == 0 ? 0 : e.code[i - 1];
  return e.code[i - e.clusters];
}

[[noreturn]] void damaged(const std::string &what) {
  throw Error(Error::Kind::DamagedFile, "damaged .pomar file: section 'CERR': " + what);
}

} // namespace

double error_bound(float scale, uint8_t code) {
  // 2^(k/8) for k = 0..7, as literals: every platform (native, WebAssembly) gets the same
  // bits, which a library exp2 does not promise.
  static constexpr double kEighths[8] = {1.0,
                                         1.0905077326652577,
                                         1.1892071150027210,
                                         1.2968395546510096,
                                         1.4142135623730951,
                                         1.5422108254079407,
                                         1.6817928305074290,
                                         1.8340080864093424};
  return std::ldexp(double(scale) * kEighths[code & 7], code >> 3);
}

double octave_error_bound(float scale, uint8_t code) {
  return code == 0 ? 0.0 : std::ldexp(double(scale), code);
}

double ClusterErrors::bound(uint32_t c, int level) const {
  if (level < int(first_level))
    level = int(first_level);
  const uint32_t k = uint32_t(level) - first_level;
  if (k >= levels())
    return 0;
  const uint8_t e = code[size_t(k) * clusters + c];
  return version == 1 ? error_bound(scale[k], e) : octave_error_bound(scale[k], e);
}

ClusterErrors quantize_cluster_errors(uint32_t first_level, uint32_t clusters,
                                      const std::vector<double> &errors) {
  ClusterErrors out;
  out.version = 1;
  out.first_level = first_level;
  out.clusters = clusters;
  const size_t levels = clusters ? errors.size() / clusters : 0;
  out.scale.resize(levels);
  out.code.resize(errors.size());
  for (size_t k = 0; k < levels; ++k) {
    const double *e = errors.data() + k * clusters;
    const double top = *std::max_element(e, e + clusters);
    // The largest error at code 255, the scale rounded up so that code 255 covers it.
    float scale = static_cast<float>(top * std::exp2(-255.0 / 8.0));
    while (error_bound(scale, 255) < top)
      scale = std::nextafter(scale, INFINITY);
    out.scale[k] = scale;
    for (uint32_t c = 0; c < clusters; ++c) {
      int code = 0;
      if (e[c] > 0 && scale > 0)
        code = std::clamp(int(std::floor(8.0 * std::log2(e[c] / double(scale)))), 0, 255);
      while (code < 255 && error_bound(scale, uint8_t(code)) < e[c])
        ++code;
      out.code[k * clusters + c] = uint8_t(code);
    }
  }
  // Rounded up on different scales, a coarser level's bound could fall just under a finer
  // one's: raise it, so that the bounds never grow with the level where the errors do not.
  for (size_t k = levels; k-- > 1;)
    for (uint32_t c = 0; c < clusters; ++c) {
      uint8_t &code = out.code[(k - 1) * clusters + c];
      const double finer = error_bound(out.scale[k], out.code[k * clusters + c]);
      while (code < 255 && errors[(k - 1) * clusters + c] >= errors[k * clusters + c] &&
             error_bound(out.scale[k - 1], code) < finer)
        ++code;
    }
  return out;
}

ClusterErrors quantize_cluster_errors_octaves(uint32_t first_level, uint32_t clusters,
                                              const std::vector<double> &errors) {
  ClusterErrors out;
  out.version = 2;
  out.first_level = first_level;
  out.clusters = clusters;
  const size_t levels = clusters ? errors.size() / clusters : 0;
  const double top = errors.empty() ? 0.0 : *std::max_element(errors.begin(), errors.end());
  // The largest error at the top code, the scale rounded up so that the top code covers it.
  constexpr int kTop = kOctaveCodes - 1;
  float scale = static_cast<float>(std::ldexp(top, -kTop));
  while (octave_error_bound(scale, kTop) < top)
    scale = std::nextafter(scale, INFINITY);
  out.scale.assign(levels, scale);
  out.code.resize(errors.size());
  for (size_t i = 0; i < errors.size(); ++i) {
    const double e = errors[i];
    if (!(e > 0))
      continue; // code 0: nothing missing
    int code = 1;
    if (scale > 0)
      code = std::clamp(int(std::floor(std::log2(e / double(scale)))), 1, kTop);
    while (code < kTop && octave_error_bound(scale, uint8_t(code)) < e)
      ++code;
    out.code[i] = uint8_t(code);
  }
  // A coarser level's code at least the finer one's (the section cannot code a growth;
  // the measure's errors never grow with the level, so this changes nothing there).
  for (size_t k = levels; k-- > 1;)
    for (uint32_t c = 0; c < clusters; ++c) {
      uint8_t &coarser = out.code[(k - 1) * clusters + c];
      coarser = std::max(coarser, out.code[k * clusters + c]);
    }
  return out;
}

std::vector<uint8_t> write_cluster_errors(const ClusterErrors &e) {
  std::vector<uint8_t> out;
  ByteWriter w(out);
  w.u8(e.version);
  w.u32(e.first_level);
  w.u32(e.levels());
  w.u32(e.clusters);
  if (e.version == 1)
    for (float s : e.scale)
      w.f32(s);
  else
    w.f32(e.scale.empty() ? 0.0f : e.scale[0]);
  std::vector<uint8_t> stream;
  RangeEncoder rc(&stream);
  CodeModels m(e.levels());
  for (uint32_t k = 0; k < e.levels(); ++k)
    for (uint32_t c = 0; c < e.clusters; ++c) {
      const int ref = reference(e, k, c), code = e.code[size_t(k) * e.clusters + c];
      if (e.version == 1 || k == 0) {
        const int j = k == 0 ? 0 : 1;
        put_signed(rc, m.classes[j], m.top[j], int64_t(code) - ref);
      } else if (ref != 0) {
        if (code > ref)
          throw Error(Error::Kind::Internal, "CERR version 2: a code grows with the level");
        rc.encode(m.drop[k - 1], ref - code);
      }
    }
  rc.finish();
  w.bytes(stream.data(), stream.size());
  return out;
}

ClusterErrors read_cluster_errors(const uint8_t *body, uint64_t size, const FileLayout &layout) {
  const FileHeader &h = layout.header;
  if (!h.clustered())
    damaged("present in a file without clusters");
  ByteReader r(body, size, "damaged .pomar file: section 'CERR'");
  ClusterErrors e;
  e.version = r.u8();
  if (e.version != 1 && e.version != 2)
    damaged("unknown section version " + std::to_string(e.version) +
            " (this build reads versions 1 and 2)");
  e.first_level = r.u32();
  const uint32_t levels = r.u32();
  e.clusters = r.u32();
  if (e.first_level != h.global_levels || levels != h.levels.size() - h.global_levels ||
      e.clusters != h.clusters)
    damaged("its levels " + std::to_string(e.first_level) + "+" + std::to_string(levels) + " and " +
            std::to_string(e.clusters) + " clusters do not match the file's");
  e.scale.resize(levels);
  for (uint32_t k = 0; k < levels; ++k) {
    const float s = e.version == 1 || k == 0 ? r.f32() : e.scale[0];
    if (!std::isfinite(s) || s < 0)
      damaged("a level's scale is not a finite non-negative number");
    e.scale[k] = s;
  }
  if (levels == 0 && e.version == 2)
    r.f32();
  const int top = e.version == 1 ? 255 : kOctaveCodes - 1;
  const size_t at = r.position();
  // Every code costs at least a fraction of a bit: bound the count by the stream before
  // allocating (at most 2^16 codes per byte and a few bytes of slack).
  const uint64_t codes = uint64_t(levels) * e.clusters;
  if (codes > (size - at + 8) * 65536)
    damaged(std::to_string(codes) + " codes cannot be stored in " + std::to_string(size - at) +
            " bytes");
  e.code.resize(codes);
  RangeDecoder rc(body + at, size - at);
  CodeModels m(levels);
  for (uint32_t k = 0; k < levels; ++k)
    for (uint32_t c = 0; c < e.clusters; ++c) {
      const int ref = reference(e, k, c);
      int64_t v = 0;
      if (e.version == 1 || k == 0) {
        const int j = k == 0 ? 0 : 1;
        v = ref + get_signed(rc, m.classes[j], m.top[j]);
      } else if (ref != 0) {
        v = ref - rc.decode(m.drop[k - 1]);
      }
      if (v < 0 || v > top || rc.overrun())
        damaged("the code of cluster " + std::to_string(c) + " at level " +
                std::to_string(e.first_level + k) + " is out of range");
      e.code[size_t(k) * e.clusters + c] = uint8_t(v);
    }
  if (rc.overrun())
    damaged("the codes end early");
  return e;
}

ClusterErrors load_cluster_errors(const uint8_t *global, const FileLayout &layout) {
  const int i = find_section(layout, kClusterErrorsTag);
  if (i < 0)
    return {};
  const uint8_t *body = section_body(global, layout, size_t(i));
  return read_cluster_errors(body, layout.header.sections[size_t(i)].bytes, layout);
}

} // namespace pomar
