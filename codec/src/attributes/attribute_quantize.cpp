// Attribute quantizers and the checks of attribute arrays (see attribute_quantize.h).
#include "attributes/attribute_quantize.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace pomar {

const char *kind_name(AttributeKind kind) {
  switch (kind) {
  case AttributeKind::Colour:
    return "colour";
  case AttributeKind::Normal:
    return "normal";
  case AttributeKind::Scalar:
    return "scalar";
  case AttributeKind::TexCoord:
    return "texcoord";
  }
  return "unknown";
}

bool AttributeMask::keeps(AttributeKind kind) const {
  switch (kind) {
  case AttributeKind::Colour:
    return colour;
  case AttributeKind::Normal:
    return normals;
  case AttributeKind::Scalar:
    return scalars;
  case AttributeKind::TexCoord:
    return texcoords;
  }
  return false;
}

double normal_error_bound(int bits) {
  // Largest angle measured over 2 million normals (uniform on the sphere plus the axes,
  // the octahedron's edges and its folds) plus 5%: tests/test_attributes.cpp checks it.
  static const double kBound[] = {/*4*/ 11.9,    /*5*/ 5.6,     /*6*/ 2.75,    /*7*/ 1.34,
                                  /*8*/ 0.67,    /*9*/ 0.332,   /*10*/ 0.166,  /*11*/ 0.083,
                                  /*12*/ 0.0415, /*13*/ 0.0207, /*14*/ 0.0104, /*15*/ 0.0052,
                                  /*16*/ 0.0026};
  if (bits < 4 || bits > 16)
    throw Error(Error::Kind::Usage,
                "normal bits must be between 4 and 16 (got " + std::to_string(bits) + ")");
  return kBound[bits - 4];
}

const VertexAttribute *Mesh::find(AttributeKind kind, const std::string &name) const {
  for (const VertexAttribute &a : attributes)
    if (a.kind == kind && (name.empty() || a.name == name))
      return &a;
  return nullptr;
}

VertexAttribute *Mesh::find(AttributeKind kind, const std::string &name) {
  return const_cast<VertexAttribute *>(static_cast<const Mesh *>(this)->find(kind, name));
}

void validate_attributes(const Mesh &mesh, bool quantized, const AttributeMask &mask) {
  const size_t nv = mesh.vertex_count();
  for (size_t i = 0; i < mesh.attributes.size(); ++i) {
    const VertexAttribute &a = mesh.attributes[i];
    if (!mask.keeps(a.kind))
      continue;
    const std::string what = std::string(kind_name(a.kind)) + " attribute '" + a.name + "'";
    if (a.name.empty() || a.name.size() > 255)
      throw Error(Error::Kind::InvalidMesh, std::string(kind_name(a.kind)) + " attribute " +
                                                std::to_string(i) +
                                                ": a name of 1 to 255 bytes is required");
    for (size_t j = 0; j < i; ++j)
      if (mesh.attributes[j].name == a.name)
        throw Error(Error::Kind::InvalidMesh, "two attributes are named '" + a.name + "'");
    uint32_t want = 1;
    switch (a.kind) {
    case AttributeKind::Colour:
      want = a.components == 4 ? 4 : 3;
      break;
    case AttributeKind::Normal:
      want = 3;
      break;
    case AttributeKind::Scalar:
      want = 1;
      break;
    case AttributeKind::TexCoord:
      want = 2;
      break;
    default:
      throw Error(Error::Kind::InvalidMesh,
                  "attribute '" + a.name + "' has an unknown kind " + std::to_string(int(a.kind)));
    }
    if (a.components != want)
      throw Error(Error::Kind::InvalidMesh,
                  what + " has " + std::to_string(a.components) + " components per vertex, " +
                      (a.kind == AttributeKind::Colour
                           ? std::string("colour needs 3 (RGB) or 4 (RGBA)")
                           : "it needs " + std::to_string(want)));
    const bool colour = a.kind == AttributeKind::Colour;
    const size_t have = colour ? a.colour.size() : a.values.size();
    if (have != size_t(a.components) * nv || (colour ? !a.values.empty() : !a.colour.empty()))
      throw Error(Error::Kind::InvalidMesh,
                  what + " has " + std::to_string(have) + " values, the mesh has " +
                      std::to_string(nv) + " vertices x " + std::to_string(a.components) + " = " +
                      std::to_string(size_t(a.components) * nv) +
                      (colour ? " (colours are 8-bit bytes in VertexAttribute::colour)"
                              : " (floats in VertexAttribute::values)"));
    if (!quantized || colour)
      continue;
    for (size_t k = 0; k < a.values.size(); ++k)
      if (!std::isfinite(a.values[k]))
        throw Error(Error::Kind::InvalidMesh,
                    what + " of vertex " + std::to_string(k / a.components) + " is " +
                        (std::isnan(a.values[k]) ? "NaN" : "infinite") +
                        ": quantized attributes must be finite (--exact-attributes keeps every "
                        "float bit for bit)");
  }
}

// ---------------------------------------------------------------- building blocks

namespace {
int32_t floor_half(int32_t x) { return (x - (x & 1)) / 2; }
float sign_of(float x) { return x < 0 ? -1.0f : 1.0f; }
} // namespace

void rgb_to_ycocg(const uint8_t rgb[3], int32_t out[3]) {
  const int32_t r = rgb[0], g = rgb[1], b = rgb[2];
  const int32_t co = r - b;
  const int32_t t = b + floor_half(co);
  const int32_t cg = g - t;
  out[0] = t + floor_half(cg);
  out[1] = co;
  out[2] = cg;
}

void ycocg_to_rgb(const int32_t c[3], uint8_t rgb[3]) {
  const int32_t t = c[0] - floor_half(c[2]);
  const int32_t g = c[2] + t;
  const int32_t b = t - floor_half(c[1]);
  const int32_t r = b + c[1];
  rgb[0] = static_cast<uint8_t>(r);
  rgb[1] = static_cast<uint8_t>(g);
  rgb[2] = static_cast<uint8_t>(b);
}

namespace {
/// The unit vector of an octahedral code, in double.
void octahedral_unit(uint32_t u, uint32_t v, int bits, double n[3]) {
  const double m = double((1u << bits) - 2); // codes 0..m, m even: 0 and +-1 exact
  double x = double(u) / m * 2.0 - 1.0, y = double(v) / m * 2.0 - 1.0;
  const double z = 1.0 - std::fabs(x) - std::fabs(y);
  if (z < 0) {
    const double fx = (1.0 - std::fabs(y)) * (x < 0 ? -1.0 : 1.0);
    const double fy = (1.0 - std::fabs(x)) * (y < 0 ? -1.0 : 1.0);
    x = fx;
    y = fy;
  }
  const double len = std::sqrt(x * x + y * y + z * z); // >= 1/sqrt(3)
  n[0] = x / len;
  n[1] = y / len;
  n[2] = z / len;
}
} // namespace

void octahedral_decode(uint32_t u, uint32_t v, int bits, float n[3]) {
  double d[3];
  octahedral_unit(u, v, bits, d);
  for (int k = 0; k < 3; ++k)
    n[k] = static_cast<float>(d[k]);
}

void octahedral_encode(const float n[3], int bits, uint32_t &u, uint32_t &v) {
  const double l1 = std::fabs(double(n[0])) + std::fabs(double(n[1])) + std::fabs(double(n[2]));
  double x = n[0] / l1, y = n[1] / l1;
  if (n[2] < 0) {
    const double fx = (1.0 - std::fabs(y)) * sign_of(float(x));
    const double fy = (1.0 - std::fabs(x)) * sign_of(float(y));
    x = fx;
    y = fy;
  }
  const uint32_t m = (1u << bits) - 2;
  const double su = (x + 1.0) * 0.5 * m, sv = (y + 1.0) * 0.5 * m;
  const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
  const double unit[3] = {n[0] / len, n[1] / len, n[2] / len};
  double best = 1e300;
  // The 4 grid points around the projection: keep the one that decodes closest (distance
  // in double: a float dot product cannot tell apart angles below ~0.02 degrees).
  for (int du = 0; du < 2; ++du)
    for (int dv = 0; dv < 2; ++dv) {
      const uint32_t cu = std::min<uint32_t>(m, uint32_t(std::max(0.0, std::floor(su))) + du);
      const uint32_t cv = std::min<uint32_t>(m, uint32_t(std::max(0.0, std::floor(sv))) + dv);
      double d[3];
      octahedral_unit(cu, cv, bits, d);
      const double e = (d[0] - unit[0]) * (d[0] - unit[0]) + (d[1] - unit[1]) * (d[1] - unit[1]) +
                       (d[2] - unit[2]) * (d[2] - unit[2]);
      if (e < best) {
        best = e;
        u = cu;
        v = cv;
      }
    }
}

int64_t float_code(float x) {
  uint32_t b;
  std::memcpy(&b, &x, 4);
  return (b & 0x80000000u) ? int64_t(~b) : int64_t(b | 0x80000000u);
}

float code_float(int64_t code) {
  uint32_t c = static_cast<uint32_t>(code);
  const uint32_t b = (c & 0x80000000u) ? (c & 0x7FFFFFFFu) : ~c;
  float x;
  std::memcpy(&x, &b, 4);
  return x;
}

// ---------------------------------------------------------------- attributes

double StoredAttribute::bound() const {
  if (kind == AttributeKind::Colour || bits == 0)
    return 0;
  if (kind == AttributeKind::Normal)
    return normal_error_bound(bits);
  double b = 0;
  for (size_t k = 0; k < lo.size(); ++k) {
    const double step = (double(hi[k]) - double(lo[k])) / double((1u << bits) - 1);
    // half a step, plus the rounding of the decoded value to float
    b = std::max(b, step * 0.5 + std::max(std::fabs(lo[k]), std::fabs(hi[k])) * 0x1p-24);
  }
  return b;
}

namespace {
bool is_zero_length(const float n[3]) { return n[0] == 0 && n[1] == 0 && n[2] == 0; }
} // namespace

StoredAttribute describe(const VertexAttribute &a, const AttributeOptions &o) {
  StoredAttribute s;
  s.kind = a.kind;
  s.name = a.name;
  s.components = a.components;
  if (a.kind == AttributeKind::Colour || o.exact)
    return s;
  s.bits = a.kind == AttributeKind::Normal     ? o.normal_bits
           : a.kind == AttributeKind::TexCoord ? o.texcoord_bits
                                               : o.scalar_bits;
  const int max_bits = a.kind == AttributeKind::Normal ? 16 : 24;
  const int min_bits = a.kind == AttributeKind::Normal ? 4 : 1;
  if (s.bits < min_bits || s.bits > max_bits)
    throw Error(Error::Kind::Usage, std::string(kind_name(a.kind)) + " bits must be between " +
                                        std::to_string(min_bits) + " and " +
                                        std::to_string(max_bits) + " (got " +
                                        std::to_string(s.bits) + ")");
  if (a.kind == AttributeKind::Normal) {
    for (size_t v = 0; v < a.vertex_count() && !s.zero_normals; ++v)
      s.zero_normals = is_zero_length(&a.values[3 * v]);
    return s;
  }
  s.lo.assign(a.components, 0.0f);
  s.hi.assign(a.components, 0.0f);
  const size_t nv = a.vertex_count();
  for (uint32_t k = 0; k < a.components; ++k) {
    float lo = nv ? a.values[k] : 0.0f, hi = lo;
    for (size_t v = 1; v < nv; ++v) {
      lo = std::min(lo, a.values[v * a.components + k]);
      hi = std::max(hi, a.values[v * a.components + k]);
    }
    s.lo[k] = lo;
    s.hi[k] = hi;
  }
  return s;
}

namespace {
double step_of(const StoredAttribute &s, uint32_t k) {
  return (double(s.hi[k]) - double(s.lo[k])) / double((1u << s.bits) - 1);
}
} // namespace

void code_range(const StoredAttribute &s, uint32_t k, int64_t &lo, int64_t &hi) {
  if (s.kind == AttributeKind::Colour) {
    lo = k == 0 || k == 3 ? 0 : -255;
    hi = 255;
  } else if (s.bits == 0) {
    lo = 0;
    hi = 0xFFFFFFFFll;
  } else if (s.kind == AttributeKind::Normal) {
    lo = 0;
    hi = (1 << s.bits) - (s.zero_normals ? 1 : 2);
  } else {
    lo = 0;
    hi = (1 << s.bits) - 1;
  }
}

void to_codes(const StoredAttribute &s, const VertexAttribute &a, size_t v, int64_t *codes) {
  const uint32_t c = a.components;
  if (s.kind == AttributeKind::Colour) {
    int32_t ycocg[3];
    rgb_to_ycocg(&a.colour[v * c], ycocg);
    for (int k = 0; k < 3; ++k)
      codes[k] = ycocg[k];
    if (c == 4)
      codes[3] = a.colour[v * c + 3];
    return;
  }
  const float *x = &a.values[v * c];
  if (s.bits == 0) {
    for (uint32_t k = 0; k < c; ++k)
      codes[k] = float_code(x[k]);
    return;
  }
  if (s.kind == AttributeKind::Normal) {
    uint32_t u, w;
    if (s.zero_normals && is_zero_length(x))
      u = w = octahedral_zero_code(s.bits);
    else
      octahedral_encode(x, s.bits, u, w);
    codes[0] = u;
    codes[1] = w;
    return;
  }
  const int64_t top = (int64_t(1) << s.bits) - 1;
  for (uint32_t k = 0; k < c; ++k) {
    const double step = step_of(s, k);
    const int64_t q = step > 0 ? std::llround((double(x[k]) - double(s.lo[k])) / step) : 0;
    codes[k] = std::min(top, std::max<int64_t>(0, q));
  }
}

void from_codes(const StoredAttribute &s, const int64_t *codes, VertexAttribute &out, size_t v) {
  const uint32_t c = s.components;
  if (s.kind == AttributeKind::Colour) {
    const int32_t ycocg[3] = {int32_t(codes[0]), int32_t(codes[1]), int32_t(codes[2])};
    ycocg_to_rgb(ycocg, &out.colour[v * c]);
    if (c == 4)
      out.colour[v * c + 3] = static_cast<uint8_t>(codes[3]);
    return;
  }
  float *x = &out.values[v * c];
  if (s.bits == 0) {
    for (uint32_t k = 0; k < c; ++k)
      x[k] = code_float(codes[k]);
    return;
  }
  if (s.kind == AttributeKind::Normal) {
    const int64_t zero = octahedral_zero_code(s.bits);
    if (s.zero_normals && (codes[0] == zero || codes[1] == zero)) {
      if (codes[0] != codes[1])
        throw Error(Error::Kind::DamagedFile, "damaged .pomar file: normal attribute '" + s.name +
                                                  "' of vertex " + std::to_string(v) +
                                                  " has half of the zero-normal code");
      x[0] = x[1] = x[2] = 0.0f;
      return;
    }
    octahedral_decode(uint32_t(codes[0]), uint32_t(codes[1]), s.bits, x);
    return;
  }
  for (uint32_t k = 0; k < c; ++k)
    x[k] = static_cast<float>(double(s.lo[k]) + double(codes[k]) * step_of(s, k));
}

} // namespace pomar
