// pomar verify: the original mesh (snapped to the file's grid, repaired with --repair)
// against the file decoded in memory or a mesh decoded from it, through the library's mesh
// comparer (mesh/mesh_compare.h): the same triangles and vertices, every attribute within
// its stored bound, per-corner texture coordinates and face materials. Exit 3 on a mismatch.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "commands.h"
#include "console.h"
#include "exit_codes.h"
#include "mesh/mesh_compare.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"
#include "pomar/repair.h"
#include "specs.h"

namespace pomar::tool {

namespace {

/// Every attribute of `ref` the file should keep against `out`, vertices matched by
/// position (a vertex may share its position with others: the closest of them counts).
/// Prints one line per attribute; false if one is missing or outside its bound.
bool verify_attributes(const pomar::Mesh &ref, const pomar::Mesh &out, const pomar::FileInfo &info,
                       const pomar::AttributeMask &keep) {
  const pomar::VerticesByPosition at = pomar::vertices_by_position(ref);
  bool ok = true;
  for (const pomar::VertexAttribute &a : ref.attributes) {
    if (!keep.keeps(a.kind))
      continue;
    const pomar::VertexAttribute *b = out.find(a.kind, a.name);
    const pomar::AttributeInfo *stored = nullptr;
    for (const pomar::AttributeInfo &s : info.attributes)
      if (s.kind == a.kind && s.name == a.name)
        stored = &s;
    if (!b || !stored || b->components != a.components) {
      std::fprintf(stderr, "pomar: MISMATCH: %s attribute '%s' of the original is %s\n",
                   pomar::kind_name(a.kind), a.name.c_str(),
                   !stored ? "not in the file (verify --drop if it was dropped on purpose)"
                           : "missing from the decoded mesh");
      ok = false;
      continue;
    }
    const bool exact = stored->bits == 0;
    // (vertices at no position of the original: the geometry check reports them)
    const double worst = pomar::worst_attribute_error(at, a, out, *b, exact);
    const bool within = exact ? worst == 0 : worst <= stored->bound;
    ok &= within;
    std::fprintf(within ? stdout : stderr, "%s  %s '%s': %s, max error %.6g%s\n",
                 within ? "" : "pomar: MISMATCH:", pomar::kind_name(a.kind), a.name.c_str(),
                 describe_precision(a.kind, a.components, stored->bits, stored->bound).c_str(),
                 worst, a.kind == pomar::AttributeKind::Normal && !exact ? " deg" : "");
  }
  if (keep.texcoords && ref.texture_files != out.texture_files) {
    std::fprintf(stderr, "pomar: MISMATCH: texture file names differ\n");
    ok = false;
  }
  return ok;
}

/// The per-corner texture coordinates and face materials of `ref` against `out`
/// (pomar::compare_corners). UVs within `bound` (0 = exact: bit for bit); materials by
/// name, texture file and properties (`names`), else by texture file. Prints a line for
/// each; false if one is missing or differs.
bool verify_corners(const pomar::Mesh &ref, const pomar::Mesh &out, int bits, double bound,
                    bool names) {
  const bool uvs = !ref.corner_texcoords.empty(), materials = !ref.face_materials.empty();
  if (!uvs && !materials)
    return true;
  const std::vector<float> ou = pomar::corner_uvs(out);
  if (uvs && ou.empty()) {
    std::fprintf(stderr, "pomar: MISMATCH: the per-corner texture coordinates of the original "
                         "are missing from the decoded mesh\n");
    return false;
  }
  if (materials && out.face_materials.empty()) {
    std::fprintf(stderr, "pomar: MISMATCH: the face materials of the original are missing from "
                         "the decoded mesh\n");
    return false;
  }
  const bool exact = bound == 0;
  // (faces at no face of the original: the geometry check reports them)
  const pomar::CornerDifference d = pomar::compare_corners(
      ref, uvs ? pomar::corner_uvs(ref) : std::vector<float>(), out, ou, exact, names);
  bool ok = true;
  if (uvs) {
    const bool within = exact ? d.worst_uv_error == 0 : d.worst_uv_error <= bound;
    ok &= within;
    std::fprintf(within ? stdout : stderr,
                 "%s  per-corner texture coordinates: %s, max error %.6g\n",
                 within ? "" : "pomar: MISMATCH:",
                 exact ? std::string("exact").c_str()
                       : (std::to_string(bits) + " bits, within " + std::to_string(bound)).c_str(),
                 d.worst_uv_error);
  }
  if (materials) {
    const size_t mismatches = d.material_mismatches;
    ok &= mismatches == 0;
    std::fprintf(mismatches ? stderr : stdout, "%s  face materials: %zu materials, %s\n",
                 mismatches ? "pomar: MISMATCH:" : "", ref.materials.size(),
                 mismatches ? (std::to_string(mismatches) + " faces differ").c_str()
                 : names    ? "the same per face (names, textures, properties)"
                            : "the same texture per face");
  }
  return ok;
}

} // namespace

int run_verify(const VerifyArgs &a) {
  const std::string &original = a.original, &file = a.file, &decoded = a.decoded;
  const bool repair = a.repair;
  pomar::Mesh ref = pomar::load_mesh(original);
  // With --repair the reference is the repaired original: what `encode --repair` encoded.
  if (repair)
    repair_and_report(ref, true);
  const std::vector<uint8_t> data = pomar::read_file(file);
  const pomar::FileInfo info = pomar::inspect(data.data(), data.size());
  // A file without a lossless record (encode --strict, or older) has no unreferenced vertex.
  const size_t dropped = info.lossless_bytes == 0 ? pomar::drop_unreferenced_vertices(ref) : 0;
  const bool could_repair = !repair && info.lossless_bytes == 0 && pomar::repair_would_change(ref);
  const pomar::Mesh out =
      decoded.empty() ? pomar::decode(data.data(), data.size()) : pomar::load_mesh(decoded);
  // Snap the original onto the file's grid, as the encoder did.
  for (size_t i = 0; i < ref.positions.size(); ++i) {
    const int axis = static_cast<int>(i % 3);
    ref.positions[i] = info.grid.dequantize(axis, info.grid.quantize(axis, ref.positions[i]));
  }
  // STL stores triangles only (no vertex shared or unused): the triangles are compared.
  std::string ext = decoded.size() >= 4 ? decoded.substr(decoded.size() - 4) : "";
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  const bool triangles_only = ext == ".stl";
  const bool same = pomar::same_geometry(ref, out, triangles_only);
  const std::string what = decoded.empty() ? file : decoded;
  const pomar::AttributeMask keep = parse_drop(a.drop);
  bool attributes_ok = !same || verify_attributes(ref, out, info, keep);
  if (same && keep.texcoords && (!ref.corner_texcoords.empty() || !ref.face_materials.empty())) {
    // The precision of the stored corners: the decoded mesh's (a decoded mesh file has
    // none: the file is decoded for it).
    int corner_bits = out.corner_texcoord_bits;
    double corner_bound = out.corner_texcoord_bound;
    if (!decoded.empty()) {
      const pomar::Mesh full = pomar::decode(data.data(), data.size());
      corner_bits = full.corner_texcoord_bits;
      corner_bound = full.corner_texcoord_bound;
    }
    // PLY keeps each face's texture, not the material's name and properties.
    const bool names = ext != ".ply";
    attributes_ok &= verify_corners(ref, out, corner_bits, corner_bound, names);
  }
  if (!same) {
    std::fprintf(stderr,
                 "pomar: MISMATCH: %s differs from %s on the %d-bit grid (%zu vertices and %zu "
                 "faces against %zu and %zu)%s\n",
                 what.c_str(), original.c_str(), info.bits, out.vertex_count(),
                 out.triangle_count(), ref.vertex_count(), ref.triangle_count(),
                 could_repair
                     ? " (the original needs a repair to be encoded: if it was encoded with "
                       "--repair, verify with --repair)"
                     : "");
    return kExitMismatch;
  }
  if (!attributes_ok) {
    std::fprintf(stderr, "pomar: MISMATCH: %s has the geometry of %s but not its attributes\n",
                 what.c_str(), original.c_str());
    return kExitMismatch;
  }
  std::printf("OK: %s matches %s%s: the same %zu vertices and %zu oriented triangles, every vertex "
              "on its %d-bit grid position",
              what.c_str(), original.c_str(), repair ? " after repair" : "", out.vertex_count(),
              out.triangle_count(), info.bits);
  if (dropped)
    std::printf(" (%zu unreferenced vertices of the original are not in the file: encoded with "
                "--strict)",
                dropped);
  if (triangles_only)
    std::printf(" (STL keeps triangles only: vertices not compared)");
  if (!info.attributes.empty())
    std::printf(", attributes within their bounds");
  std::printf("\n");
  return 0;
}

} // namespace pomar::tool
