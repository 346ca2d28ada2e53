// pomar::encode, the encoder's entry point, as a list of steps: validate the per-corner
// values, try the mesh as it is (most meshes are clean), else cut it and encode the cut with
// its lossless record (lossless/lossless_stage.h), then fill the report. The codec proper is
// encode_manifold (encode/encoder.cpp).
#include <algorithm>
#include <functional>
#include <string>

#include "lossless/lossless_stage.h"
#include "lossless/seam_cut.h"
#include "mesh/corner_table.h"
#include "repair/cut.h"

namespace pomar {
namespace {

/// Validates the per-corner values; true if the mesh has some to keep. They are coded as the
/// seam cut (lossless/seam_cut.h), whose copies the record welds back: such a mesh always
/// has a record.
bool check_corner_values(const Mesh &mesh, const EncodeOptions &options) {
  const bool corners = has_corner_values(mesh) && options.attributes.keep.texcoords;
  if (corners)
    validate_corner_values(mesh, options.attributes.exact);
  if (options.strict && corners)
    throw Error(Error::Kind::Usage,
                "per-corner texture coordinates and face materials are kept with a lossless "
                "record, which strict mode does not write: encode without strict (--strict), "
                "or drop the texture coordinates");
  return corners;
}

/// Most meshes are clean: code them as they are (the file is then byte for byte what strict
/// gives). The manifold encoder checks the topology early (its corner table), before it
/// releases the mesh: if the table refuses the mesh (TopologyError), the mesh is cut; if the
/// encoder refuses it for another reason, the topology is checked here, and only an invalid
/// one is cut. False (no file) when the mesh is to be cut.
bool encode_as_it_is(const Mesh &mesh, const EncodeOptions &options, EncodeReport *report,
                     const std::function<void()> &release, const bool &released,
                     std::vector<uint8_t> &file) {
  // The refusal is caught rather than checked first: the corner table is the encoder's own
  // first step, and building it twice would cost every clean mesh a second topology pass.
  try {
    file = encode_manifold(mesh, options, report, nullptr, release, false);
    return true;
  } catch (const TopologyError &) { // (its corner table refused the mesh)
    if (released)
      throw;
  } catch (const Error &) {
    if (released || mesh.triangles.size() % 3 || valid_topology(mesh))
      throw; // not a matter of topology: the error stands
  }
  return false;
}

/// The cut (cut_for_encoding) coded with its record. (Per-corner texture coordinates: the
/// encoder chooses their predictor level by level, encode/encoder_codec.h
/// choose_wedge_predictor.)
std::vector<uint8_t> encode_cut(const Mesh &mesh, const EncodeOptions &options,
                                EncodeReport *report, bool cut_needed, bool corners,
                                LosslessCut &c) {
  cut_for_encoding(mesh, cut_needed, corners, c);
  if (!cut_needed) // (the topology is not known to be valid: a refusal is not named)
    return encode_manifold(*c.coded, options, report, &c.hook, {}, false);
  try { // (the encoder's corner table checks the cut, see repair/cut.h)
    return encode_manifold(c.cut, options, report, &c.hook);
  } catch (const TopologyError &e) {
    throw still_invalid(e);
  }
}

/// The cut and the record's coding. On a mesh whose topology may be valid (`valid`:
/// unreferenced vertices, or the order kept) the cut is first taken to be the mesh itself:
/// make_manifold leaves such a mesh as it is, and the manifold encoder's corner table says
/// whether it is (a scan's stray points then cost no topology analysis); if the encoder
/// refuses it and the topology is the reason, the mesh is cut after all.
std::vector<uint8_t> cut_and_encode(const Mesh &mesh, const EncodeOptions &options,
                                    EncodeReport *report, bool corners, bool valid,
                                    LosslessCut &c) {
  if (valid) {
    try {
      return encode_cut(mesh, options, report, false, corners, c);
    } catch (const TopologyError &) {
    } catch (const Error &) {
      if (mesh.triangles.size() % 3 || valid_topology(mesh))
        throw; // not a matter of topology: the error stands
    }
  }
  return encode_cut(mesh, options, report, true, corners, c);
}

/// The report of a file with a lossless record: what the cut changed, in the input's terms.
void fill_lossless_report(const Mesh &mesh, const EncodeOptions &options, const LosslessCut &c,
                          EncodeReport &report) {
  const size_t nv = mesh.vertex_count();
  LosslessReport &l = report.lossless;
  l = LosslessReport();
  l.stored = true;
  l.vertex_copies = c.record.copies.size();
  l.vertices_split = c.repair.vertices_split;
  l.edges_cut = c.repair.edges_cut;
  l.faces_flipped = c.record.flipped.size();
  for (const auto &d : c.record.duplicates)
    l.duplicate_faces += d.second;
  l.degenerate_faces = c.record.degenerate.size();
  l.unreferenced_vertices = c.record.extra_q.size() / 3;
  l.keep_order = options.keep_order;
  l.seam_edges = c.seams.seam_edges;
  l.wedge_copies = c.seams.wedge_copies;
  l.bytes = report.info.lossless_bytes;
  report.info.input_vertices = nv;
  report.info.input_faces = mesh.triangle_count();
  report.input_vertices = nv;
  std::vector<uint8_t> used(nv, 0);
  for (uint32_t v : mesh.triangles)
    used[v] = 1;
  report.unreferenced_vertices =
      static_cast<size_t>(std::count(used.begin(), used.end(), uint8_t(0)));
  if (options.keep_order) {
    report.decoded_to_input.resize(nv);
    for (uint32_t v = 0; v < nv; ++v)
      report.decoded_to_input[v] = v;
  } else {
    report.decoded_to_input = c.output_to_input;
  }
}

/// encode(), given the mesh (`owned`, the same mesh) or not (nullptr): a clean mesh given is
/// freed once the manifold encoder has quantized it.
std::vector<uint8_t> encode_any(const Mesh &mesh, const EncodeOptions &options,
                                EncodeReport *report, Mesh *owned) {
  bool released = false;
  std::function<void()> release;
  if (owned)
    release = [&] {
      *owned = Mesh();
      released = true;
    };
  const bool corners = check_corner_values(mesh, options);
  if (options.strict)
    return encode_manifold(mesh, options, report, nullptr, release);

  // False once the topology is known to be one the manifold encoder does not take as it is.
  bool valid = true;
  if (!options.keep_order && !corners && all_vertices_used(mesh)) {
    std::vector<uint8_t> file;
    if (encode_as_it_is(mesh, options, report, release, released, file))
      return file;
    valid = false;
  }

  check_encode_input(mesh, options); // unreferenced vertices included
  LosslessCut c;
  start_lossless_cut(mesh, options, c);
  std::vector<uint8_t> file = cut_and_encode(mesh, options, report, corners, valid, c);
  if (report)
    fill_lossless_report(mesh, options, c, *report);
  return file;
}

} // namespace

std::vector<uint8_t> encode(const Mesh &mesh, const EncodeOptions &options, EncodeReport *report) {
  return encode_any(mesh, options, report, nullptr);
}

std::vector<uint8_t> encode(Mesh &&mesh, const EncodeOptions &options, EncodeReport *report) {
  struct LeaveEmpty { // whether encode returns or throws
    Mesh &mesh;
    ~LeaveEmpty() { mesh = Mesh(); }
  } leave_empty{mesh};
  return encode_any(mesh, options, report, &mesh);
}

} // namespace pomar
