// The lossless record: what the codec's first stage (the manifold cut, make_manifold)
// changed, in the decoder's numbering, so that a full decode gives back the input mesh
// exactly (docs/format.md, "LSLS section"; docs/architecture.md, "The lossless stage").
//
// The record is read against the fully decoded cut mesh D (its vertices in decoding order,
// its faces in canonical order: each rotated to start at its smallest vertex, then sorted):
//   copies      decoded vertices that are one input vertex with an earlier decoded vertex
//               (the cuts of non-manifold vertices and edges); a copy always has the exact
//               position of its original, so only vertices whose position repeats an
//               earlier one are candidates;
//   flipped     faces of D whose vertex order the cut reversed;
//   duplicates  faces of D that the input holds more than once (exact duplicates);
//   degenerate  input faces repeating a vertex index, in output numbering;
//   extra       vertices no kept face uses (unreferenced ones, and those only degenerate
//               faces use), on the grid; they come after D's vertices;
//   order       optionally (keep_order) the input vertex numbering.
// Output vertex numbering: D's vertices that are not copies, in decoding order, then the
// extra vertices in input order (unless `order` renumbers them).
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "format/file_format.h"
#include "pomar/pomar.h"

namespace pomar {

struct LosslessRecord {
  /// (decoded vertex, the first decoded vertex of the same input vertex), by first member.
  std::vector<std::pair<uint32_t, uint32_t>> copies;
  /// Increasing indices into D's canonical face order.
  std::vector<uint32_t> flipped;
  /// (canonical face index, extra copies >= 1), increasing face index.
  std::vector<std::pair<uint32_t, uint32_t>> duplicates;
  /// Faces repeating a vertex, output numbering, as (a, a, b): sorted; a == b for (a, a, a).
  std::vector<std::array<uint32_t, 2>> degenerate;
  /// Quantized positions (x, y, z per vertex) of the extra vertices, in output order.
  std::vector<int32_t> extra_q;
  /// Empty, or for each output vertex the input vertex it is (a permutation).
  std::vector<uint32_t> order;
  /// The attributes of the extra vertices (their values in extra order, kind, name and
  /// components as the input's), stored bit for bit: no face uses these vertices, so the
  /// levels never code them.
  std::vector<VertexAttribute> extra_attributes;

  bool empty() const {
    return copies.empty() && flipped.empty() && duplicates.empty() && degenerate.empty() &&
           extra_q.empty() && order.empty();
  }
};

/// The counts at the start of a record (readable without the decoded mesh).
struct LosslessCounts {
  uint64_t copies = 0, flipped = 0;
  uint64_t duplicated = 0, duplicate_faces = 0; ///< faces of D with duplicates; the duplicates
  uint64_t degenerate = 0, extra = 0;
  bool order = false;
  /// What a full decode gives, from D's counts.
  uint64_t vertices(uint64_t decoded) const { return decoded - copies + extra; }
  uint64_t faces(uint64_t decoded) const { return decoded + duplicate_faces + degenerate; }
};
LosslessCounts read_lossless_counts(const uint8_t *data, size_t size);

/// D's faces in canonical order: face indices sorted by (rotated) vertex triple.
std::vector<uint32_t> canonical_face_order(const std::vector<uint32_t> &triangles);

/// The section body. `decoded` is D (the full decode of the cut mesh), as far as the record
/// needs it (build_lossless_record); consumed (a kept order is coded on D with the record
/// undone, made in D's arrays).
std::vector<uint8_t> write_lossless_record(const LosslessRecord &record, Mesh &&decoded);

/// Reads a section body against D (`bits`: the grid's); every count and index is checked
/// (pomar::Error naming the part of the record that is damaged).
LosslessRecord read_lossless_record(const uint8_t *data, size_t size, const Mesh &decoded,
                                    int bits);

/// D with the record undone: the input mesh (positions on the grid), made in D's own arrays
/// (D is left empty; a damaged record throws before D is touched). `source` (optional)
/// receives for each vertex of the result the vertex of D it comes from (kNone: a vertex no
/// face of D uses).
Mesh apply_lossless_record(Mesh &&decoded, const LosslessRecord &record, const Quantizer &grid,
                           std::vector<uint32_t> *source = nullptr);

} // namespace pomar
