// The lossless stage: the codec's first stage on encode (cut the mesh into a manifold,
// oriented one, remember what changed; pomar::encode in encode/encode.cpp runs it) and its
// last on a full decode (undo the cut).
// docs/architecture.md, "The lossless stage".
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "lossless/lossless_record.h"
#include "lossless/seam_cut.h"
#include "pomar/pomar.h"
#include "pomar/repair.h"

namespace pomar {

struct FileLayout;

/// What the lossless stage asks of the manifold encoder (encode_manifold).
struct LosslessHook {
  /// The grid to use instead of the bounding box of the coded vertices (it also covers the
  /// vertices no coded face uses).
  Quantizer grid;
  /// Called once the decoder's numbering is known (decoded vertex i is vertex
  /// decoded_to_cut[i] of the mesh given to encode_manifold); returns the LSLS body.
  std::function<std::vector<uint8_t>(const std::vector<uint32_t> &decoded_to_cut)> record;
  /// Per vertex of the mesh given to encode_manifold, optional: 1 = decimation keeps it (a
  /// texture seam's vertex, lossless/seam_cut.h).
  std::vector<uint8_t> locked;
  /// Per vertex, optional (with `origin`): twins on a simple texture seam, which decimation
  /// collapses together (DecimationOptions::twin, lossless/seam_cut.h).
  std::vector<uint32_t> twin, origin;
  /// The body of the required MATL section (materials of per-corner values), or empty.
  std::vector<uint8_t> materials;
};

/// The codec proper (codec/src/encode/encoder.cpp): a manifold, oriented mesh; unreferenced
/// vertices are dropped. With a hook, the file is version 4 and carries the record.
/// `release_input` (optional) is called once `mesh` is no longer read (quantized, its
/// attributes coded): the caller may free it then. A topology the corner table refuses
/// throws TopologyError, its message naming the mesh's own indices (`name_refusal`; false:
/// the message of the renumbered mesh, for a caller that cuts such a mesh anyway).
std::vector<uint8_t> encode_manifold(const Mesh &mesh, const EncodeOptions &options,
                                     EncodeReport *report, const LosslessHook *hook,
                                     const std::function<void()> &release_input = {},
                                     bool name_refusal = true);

/// The manifold encoder's checks of the input that do not depend on its topology (bits,
/// array sizes, no triangle, NaN/Inf); throws pomar::Error.
void check_encode_input(const Mesh &mesh, const EncodeOptions &options);

/// The record for `input` cut into `cut` by make_manifold (with `map`), when a full decode
/// numbers cut vertex decoded_to_cut[i] as i. `decoded` receives of that full decode (D)
/// what write_lossless_record reads (positions if there are vertex copies or the order is
/// kept, triangles if faces were flipped or removed or the order is kept) and
/// `output_to_input` what input vertex each vertex of the decoded output is.
LosslessRecord build_lossless_record(const Mesh &input, const Mesh &cut, const RepairMap &map,
                                     const std::vector<uint32_t> &decoded_to_cut,
                                     const Quantizer &grid, bool keep_order, Mesh &decoded,
                                     std::vector<uint32_t> &output_to_input);

/// The lossless path of pomar::encode: the mesh the manifold encoder codes (the cut, or the
/// input itself when nothing is cut nor neutralised), the cut's map and report, the hook,
/// and the record once the hook has built it. Not copyable: the hook refers to it.
struct LosslessCut {
  LosslessCut() = default;
  LosslessCut(const LosslessCut &) = delete;
  LosslessCut &operator=(const LosslessCut &) = delete;
  Mesh cut;
  const Mesh *coded = &cut;
  RepairMap map;
  RepairReport repair;
  SeamCut seams;
  LosslessHook hook;
  LosslessRecord record;
  Mesh decoded;
  std::vector<uint32_t> output_to_input; // of the decoded output (build_lossless_record)
};

/// The hook's grid (every vertex of `mesh`, used or not) and its record callback, which
/// builds `c.record` for `mesh` (held by the caller until the file is written).
void start_lossless_cut(const Mesh &mesh, const EncodeOptions &options, LosslessCut &c);

/// The mesh to code: make_manifold's cut (`cut_needed`, which checks the indices) or the
/// mesh taken as its own cut; with per-corner values (`corners`) the cut is then cut at its
/// texture seams (lossless/seam_cut.h). Throws InvalidMesh if no triangle is left.
void cut_for_encoding(const Mesh &mesh, bool cut_needed, bool corners, LosslessCut &c);

/// True if every vertex is used by a face (indices out of range are left to the encoder,
/// which names them).
bool all_vertices_used(const Mesh &mesh);

/// True when the manifold encoder takes `mesh` as it is: a valid corner table (manifold,
/// oriented, no face repeating a vertex, no duplicate).
bool valid_topology(const Mesh &mesh);

/// inspect(): the input's counts from a lossless record's counts, if the file has one (its
/// checksum is checked).
void lossless_info(const uint8_t *data, const FileLayout &layout, FileInfo &info);

/// A full decode's last stage: if the file carries a lossless record, undo the cut on the
/// decoded mesh (`data` holds the whole file).
/// `source` (optional): see apply_lossless_record (the identity when there is no record).
void undo_cut(const uint8_t *data, const FileLayout &layout, Mesh &decoded,
              std::vector<uint32_t> *source = nullptr);

} // namespace pomar
