// Per-vertex attributes of a pomar::Mesh: colour, normals, scalars, texture coordinates.
// Included by pomar/pomar.h; see docs/format.md ("ATTR section") for how they are stored.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pomar {

enum class AttributeKind : uint8_t {
  Colour = 1,   ///< 8 bits a channel, RGB or RGBA: always exact
  Normal = 2,   ///< float3, octahedral grid (or exact)
  Scalar = 3,   ///< one float (MeshLab's quality, PLY `confidence`, `intensity`, ...)
  TexCoord = 4, ///< float2 (u, v)
};

/// "colour", "normal", "scalar", "texcoord".
const char *kind_name(AttributeKind kind);

/// One attribute of every vertex, as a flat array of `components` values per vertex.
struct VertexAttribute {
  AttributeKind kind = AttributeKind::Scalar;
  /// Unique in a mesh. Colour/normal/texcoord: usually "colour", "normal", "texcoord";
  /// scalars: the property name ("quality", "confidence", "intensity", ...). 1..255 bytes.
  std::string name;
  uint32_t components = 1;     ///< colour 3 (RGB) or 4 (RGBA), normal 3, texcoord 2, scalar 1
  std::vector<uint8_t> colour; ///< kind Colour: components bytes per vertex
  std::vector<float> values;   ///< other kinds: components floats per vertex
  /// Set on decoded attributes: 0 = exact (colour always; floats stored bit for bit), else
  /// the quantization bits; `bound` = the largest error of a value against the input
  /// (normals: angle in degrees; scalars and texture coordinates: absolute, per component).
  int bits = 0;
  double bound = 0;
  size_t vertex_count() const {
    return components ? (kind == AttributeKind::Colour ? colour.size() : values.size()) / components
                      : 0;
  }
};

/// Which attribute kinds to leave out (encode: not stored; decode: not decoded).
struct AttributeMask {
  bool colour = true, normals = true, scalars = true, texcoords = true;
  bool keeps(AttributeKind kind) const;
  static AttributeMask none() { return {false, false, false, false}; }
};

/// Precision of the stored float attributes (EncodeOptions::attributes).
struct AttributeOptions {
  /// Bits per octahedral coordinate of a normal, 4..16. The default 9 keeps every normal
  /// within 0.33 degrees (measured, tests/test_attributes.cpp; 8 bits: 0.67, 10: 0.166,
  /// 12: 0.042, 16: 0.0026; each bit halves the error).
  int normal_bits = 9;
  int scalar_bits = 16;   ///< bits over each scalar's range, 1..24
  int texcoord_bits = 12; ///< bits over the range of u and of v, 1..24
  /// Store every float bit for bit (NaN, infinities, denormals and the sign of -0
  /// included). Otherwise a NaN or infinite value is an error naming the vertex, and a
  /// zero-length normal comes back as exactly (0, 0, 0).
  bool exact = false;
  AttributeMask keep; ///< kinds to store (the others are dropped)
};

/// The largest angle (degrees) between a unit normal and its octahedral code at `bits`
/// (4..16), measured (see tests/test_attributes.cpp); decoded normals carry it as `bound`.
double normal_error_bound(int bits);

} // namespace pomar
