// Attribute values <-> the integer codes the ATTR section stores (exact for colour, on a
// stated grid or bit for bit for floats). Codes of one vertex are predicted from its
// parent's codes (attribute_section.cpp), so they are plain integers here.
//
//  colour    YCoCg-R (exactly invertible integer decorrelation) of R,G,B, then A: 3-4 codes
//  normal    quantized: octahedral (u, v) on a (2^bits - 1)-point grid per axis, the code
//            of the 4 around the projection that decodes closest to the normal: 2 codes;
//            a zero-length normal is (2^bits - 1, 2^bits - 1), outside the grid, in an
//            attribute whose descriptor allows it (zero_normals); exact: the 3 floats' bits
//            (ordered, see float_code)
//  scalar,   quantized: round((x - lo) / step), step = (hi - lo) / (2^bits - 1) per
//  texcoord  component over the input's range [lo, hi]; exact: the floats' bits (ordered)
#pragma once

#include <cstdint>
#include <vector>

#include "pomar/pomar.h"

namespace pomar {

/// How one attribute is stored (its descriptor in the ATTR section).
struct StoredAttribute {
  AttributeKind kind = AttributeKind::Scalar;
  std::string name;
  uint32_t components = 1;
  int bits = 0;              // 0 = exact
  std::vector<float> lo, hi; // quantized scalars / texture coordinates: range per component
  /// Quantized normals: some are zero-length (coded as octahedral_zero_code(bits) twice,
  /// decoded as exactly (0, 0, 0)). Without it the codes stay on the grid.
  bool zero_normals = false;
  /// The seam cut's wedge texture coordinate (quantized): predicted from the positions
  /// (attributes/wedge_prediction.h) instead of by its neighbours' mean, in every level
  /// (ATTR version 3) and in the base mesh.
  bool from_positions = false, base_from_positions = false;
  /// Or, per refinement level l = 1, 2, ... (index l - 1; ATTR version 4): 1 if level l
  /// predicts it from the positions (levels past the end: by the mean).
  std::vector<uint8_t> level_positions;
  /// Integer codes per vertex.
  uint32_t codes() const { return kind == AttributeKind::Normal && bits ? 2 : components; }
  /// Largest error of a decoded value (degrees for normals, absolute otherwise).
  double bound() const;
};

/// The descriptor for `a` under `options` (computes the ranges of quantized floats).
StoredAttribute describe(const VertexAttribute &a, const AttributeOptions &options);

/// Codes of vertex v (stored.codes() of them).
void to_codes(const StoredAttribute &stored, const VertexAttribute &a, size_t v, int64_t *codes);
/// Decoded values of one vertex from its codes into out (sized by the caller). Throws a
/// "damaged .pomar file" error for a normal with only one of its two codes the zero code.
void from_codes(const StoredAttribute &stored, const int64_t *codes, VertexAttribute &out,
                size_t v);
/// Range of each code (inclusive), for the decoder's checks.
void code_range(const StoredAttribute &stored, uint32_t component, int64_t &lo, int64_t &hi);

// ---- the building blocks (tested on their own) ----
/// YCoCg-R: rgb -> (Y, Co, Cg), Y in 0..255, Co and Cg in -255..255; exactly invertible.
void rgb_to_ycocg(const uint8_t rgb[3], int32_t out[3]);
void ycocg_to_rgb(const int32_t ycocg[3], uint8_t rgb[3]);
/// Octahedral code of a non-zero normal at `bits` per coordinate, and back (unit length).
void octahedral_encode(const float n[3], int bits, uint32_t &u, uint32_t &v);
void octahedral_decode(uint32_t u, uint32_t v, int bits, float n[3]);
/// The code, one past the octahedral grid, that both coordinates of a zero-length normal
/// take (StoredAttribute::zero_normals).
constexpr uint32_t octahedral_zero_code(int bits) { return (1u << bits) - 1; }
/// Whether a normal's codes (u, v) are those of a zero-length normal.
inline bool is_zero_normal(int64_t u, int64_t v, int bits) {
  const int64_t zero = octahedral_zero_code(bits);
  return u == zero && v == zero;
}
/// A float's bits as an integer ordered like the floats (-0 just below +0; NaNs at the ends).
int64_t float_code(float x);
float code_float(int64_t code);

} // namespace pomar
