// pomar verify: the original mesh (snapped to the file's grid, repaired with
// --repair) against the file decoded in memory or a mesh decoded from it: the
// same triangles and vertices, every attribute within its stored bound,
// per-corner texture coordinates and face materials. Exit 3 on a mismatch.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>

#include "commands.h"
#include "console.h"
#include "exit_codes.h"
#include "pomar/mesh_io.h"
#include "pomar/pomar.h"
#include "pomar/repair.h"
#include "specs.h"

namespace pomar::tool {

namespace {

using Point = std::array<float, 3>;
using Triangle = std::array<Point, 3>;

/// The mesh as a sorted multiset of triangles of positions, each in its
/// smallest rotation: equal for two meshes with the same oriented triangles and
/// positions, whatever the vertex and face order.
std::vector<Triangle> triangle_multiset(const pomar::Mesh &m) {
  std::vector<Triangle> out(m.triangle_count());
  auto p = [&](uint32_t v) {
    return Point{m.positions[3 * v], m.positions[3 * v + 1],
                 m.positions[3 * v + 2]};
  };
  for (size_t f = 0; f < out.size(); ++f) {
    const Triangle t = {p(m.triangles[3 * f]), p(m.triangles[3 * f + 1]),
                        p(m.triangles[3 * f + 2])};
    // The smallest of the three rotations (corners may share a position).
    const Triangle r1 = {t[1], t[2], t[0]}, r2 = {t[2], t[0], t[1]};
    out[f] = std::min({t, r1, r2});
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Largest difference between attribute values a (of vertex i) and b (of vertex
/// j): degrees for normals, absolute otherwise; exact attributes: 0 when
/// bit-identical.
double attribute_error(const pomar::VertexAttribute &a, size_t i,
                       const pomar::VertexAttribute &b, size_t j, bool exact) {
  const uint32_t n = a.components;
  if (a.kind == pomar::AttributeKind::Colour) {
    double e = 0;
    for (uint32_t k = 0; k < n; ++k)
      e = std::max(e, std::fabs(double(a.colour[i * n + k]) -
                                double(b.colour[j * n + k])));
    return e;
  }
  const float *x = &a.values[i * n], *y = &b.values[j * n];
  if (exact && std::memcmp(x, y, 4 * n) == 0)
    return 0;
  if (a.kind == pomar::AttributeKind::Normal && !exact) {
    const bool zero_x = x[0] == 0 && x[1] == 0 && x[2] == 0;
    const bool zero_y = y[0] == 0 && y[1] == 0 && y[2] == 0;
    if (zero_x || zero_y) // a zero-length normal comes back as exactly zero
      return zero_x && zero_y ? 0 : HUGE_VAL;
    const double cx = double(x[1]) * y[2] - double(x[2]) * y[1];
    const double cy = double(x[2]) * y[0] - double(x[0]) * y[2];
    const double cz = double(x[0]) * y[1] - double(x[1]) * y[0];
    const double dot =
        double(x[0]) * y[0] + double(x[1]) * y[1] + double(x[2]) * y[2];
    return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * 180.0 /
           M_PI;
  }
  double e = 0;
  for (uint32_t k = 0; k < n; ++k) {
    const double d = std::fabs(double(x[k]) - double(y[k]));
    e = std::max(e, std::isnan(d) ? HUGE_VAL : d);
  }
  return exact && e == 0 ? HUGE_VAL
                         : e; // bit patterns differ (-0 and 0, NaN payloads)
}

/// verify: every attribute of `ref` the file should keep against `out`,
/// vertices matched by position (a vertex may share its position with others:
/// the closest of them counts). Prints one line per attribute; false if one is
/// missing or outside its bound.
bool verify_attributes(const pomar::Mesh &ref, const pomar::Mesh &out,
                       const pomar::FileInfo &info,
                       const pomar::AttributeMask &keep) {
  std::map<Point, std::vector<uint32_t>> at;
  for (uint32_t v = 0; v < ref.vertex_count(); ++v)
    at[Point{ref.positions[3 * v], ref.positions[3 * v + 1],
             ref.positions[3 * v + 2]}]
        .push_back(v);
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
      std::fprintf(
          stderr, "pomar: MISMATCH: %s attribute '%s' of the original is %s\n",
          pomar::kind_name(a.kind), a.name.c_str(),
          !stored
              ? "not in the file (verify --drop if it was dropped on purpose)"
              : "missing from the decoded mesh");
      ok = false;
      continue;
    }
    const bool exact = stored->bits == 0;
    double worst = 0;
    for (uint32_t v = 0; v < out.vertex_count(); ++v) {
      const auto it =
          at.find(Point{out.positions[3 * v], out.positions[3 * v + 1],
                        out.positions[3 * v + 2]});
      if (it == at.end())
        continue; // the geometry check reports it
      double best = HUGE_VAL;
      for (uint32_t r : it->second)
        best = std::min(best, attribute_error(a, r, *b, v, exact));
      worst = std::max(worst, best);
    }
    const bool within = exact ? worst == 0 : worst <= stored->bound;
    ok &= within;
    std::fprintf(
        within ? stdout : stderr, "%s  %s '%s': %s, max error %.6g%s\n",
        within ? "" : "pomar: MISMATCH:", pomar::kind_name(a.kind),
        a.name.c_str(),
        describe_precision(a.kind, a.components, stored->bits, stored->bound)
            .c_str(),
        worst, a.kind == pomar::AttributeKind::Normal && !exact ? " deg" : "");
  }
  if (keep.texcoords && ref.texture_files != out.texture_files) {
    std::fprintf(stderr, "pomar: MISMATCH: texture file names differ\n");
    ok = false;
  }
  return ok;
}

/// The texture coordinates of every corner of `m`: corner_texcoords, or the
/// per-vertex ones at each corner (what the OBJ reader gives when no vertex has
/// two); empty if none.
std::vector<float> corner_uvs(const pomar::Mesh &m) {
  if (!m.corner_texcoords.empty())
    return m.corner_texcoords;
  const pomar::VertexAttribute *uv = m.find(pomar::AttributeKind::TexCoord);
  std::vector<float> out;
  if (uv && uv->vertex_count() == m.vertex_count())
    for (const uint32_t v : m.triangles)
      out.insert(out.end(), {uv->values[2 * v], uv->values[2 * v + 1]});
  return out;
}

/// Triangle f's material as "name|texture file|properties" (`names`: else the
/// texture file only), "" without materials.
std::string face_material_text(const pomar::Mesh &m, size_t f, bool names) {
  if (m.face_materials.empty())
    return "";
  const pomar::Material &mat = m.materials[m.face_materials[f]];
  const std::string file =
      mat.texture >= 0 ? m.texture_files[size_t(mat.texture)] : "";
  return names ? mat.name + "|" + file + "|" + mat.properties : file;
}

/// verify: the per-corner texture coordinates and face materials of `ref`
/// against `out`, faces matched by their corner positions (in their smallest
/// rotation, the corners taken in that order; of several faces with the same
/// corners, the closest). UVs within `bound` (0 = exact: bit for bit);
/// materials by name, texture file and properties (`names`), else by texture
/// file. Prints a line for each; false if one is missing or differs.
bool verify_corners(const pomar::Mesh &ref, const pomar::Mesh &out, int bits,
                    double bound, bool names) {
  const std::vector<float> ru = corner_uvs(ref), ou = corner_uvs(out);
  const bool uvs = !ref.corner_texcoords.empty(),
             materials = !ref.face_materials.empty();
  if (!uvs && !materials)
    return true;
  if (uvs && ou.empty()) {
    std::fprintf(
        stderr,
        "pomar: MISMATCH: the per-corner texture coordinates of the original "
        "are missing from the decoded mesh\n");
    return false;
  }
  if (materials && out.face_materials.empty()) {
    std::fprintf(
        stderr,
        "pomar: MISMATCH: the face materials of the original are missing from "
        "the decoded mesh\n");
    return false;
  }
  // The smallest rotation of each face's corners, and that rotation.
  auto key = [](const pomar::Mesh &m, size_t f, int &rotation) {
    Triangle t;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.triangles[3 * f + size_t(k)];
      t[size_t(k)] = Point{m.positions[3 * v], m.positions[3 * v + 1],
                           m.positions[3 * v + 2]};
    }
    const Triangle r[3] = {t, {t[1], t[2], t[0]}, {t[2], t[0], t[1]}};
    rotation = int(std::min_element(r, r + 3) - r);
    return r[rotation];
  };
  std::map<Triangle, std::vector<std::pair<size_t, int>>>
      faces; // of ref: (face, rotation)
  for (size_t f = 0; f < ref.triangle_count(); ++f) {
    int rotation = 0;
    const Triangle t = key(ref, f, rotation);
    faces[t].push_back({f, rotation});
  }
  const bool exact = bound == 0;
  double worst = 0;
  size_t material_mismatches = 0;
  for (size_t g = 0; g < out.triangle_count(); ++g) {
    int rotation = 0;
    const auto it = faces.find(key(out, g, rotation));
    if (it == faces.end())
      continue; // the geometry check reports it
    double best = HUGE_VAL;
    bool material_ok = !materials;
    for (const auto &[f, r] : it->second) {
      double e = 0;
      for (int k = 0; uvs && k < 3; ++k) {
        const float *a = &ru[6 * f + 2 * size_t((k + r) % 3)];
        const float *b = &ou[6 * g + 2 * size_t((k + rotation) % 3)];
        for (int c = 0; c < 2; ++c) {
          const double d = std::fabs(double(a[c]) - double(b[c]));
          e = std::max(
              e, exact ? (std::memcmp(a + c, b + c, 4) == 0 ? 0 : HUGE_VAL)
                 : std::isnan(d) ? HUGE_VAL
                                 : d);
        }
      }
      best = std::min(best, e);
      material_ok |= face_material_text(ref, f, names) ==
                     face_material_text(out, g, names);
    }
    worst = std::max(worst, best);
    material_mismatches += !material_ok;
  }
  bool ok = true;
  if (uvs) {
    const bool within = exact ? worst == 0 : worst <= bound;
    ok &= within;
    std::fprintf(within ? stdout : stderr,
                 "%s  per-corner texture coordinates: %s, max error %.6g\n",
                 within ? "" : "pomar: MISMATCH:",
                 exact ? std::string("exact").c_str()
                       : (std::to_string(bits) + " bits, within " +
                          std::to_string(bound))
                             .c_str(),
                 worst);
  }
  if (materials) {
    ok &= material_mismatches == 0;
    std::fprintf(
        material_mismatches ? stderr : stdout,
        "%s  face materials: %zu materials, %s\n",
        material_mismatches ? "pomar: MISMATCH:" : "", ref.materials.size(),
        material_mismatches
            ? (std::to_string(material_mismatches) + " faces differ").c_str()
        : names ? "the same per face (names, textures, properties)"
                : "the same texture per face");
  }
  return ok;
}

/// The vertex positions of `m`, sorted: equal for meshes with the same
/// vertices.
std::vector<Point> point_multiset(const pomar::Mesh &m) {
  std::vector<Point> out(m.vertex_count());
  for (size_t v = 0; v < out.size(); ++v)
    out[v] = {m.positions[3 * v], m.positions[3 * v + 1],
              m.positions[3 * v + 2]};
  std::sort(out.begin(), out.end());
  return out;
}

} // namespace

int run_verify(const VerifyArgs &a) {
  const std::string &original = a.original, &file = a.file,
                    &decoded = a.decoded;
  const bool repair = a.repair;
  pomar::Mesh ref = pomar::load_mesh(original);
  // With --repair the reference is the repaired original: what `encode
  // --repair` encoded.
  if (repair)
    repair_and_report(ref, true);
  const std::vector<uint8_t> data = pomar::read_file(file);
  const pomar::FileInfo info = pomar::inspect(data.data(), data.size());
  // A file without a lossless record (encode --strict, or older) has no
  // unreferenced vertex.
  const size_t dropped =
      info.lossless_bytes == 0 ? pomar::drop_unreferenced_vertices(ref) : 0;
  const bool could_repair =
      !repair && info.lossless_bytes == 0 && pomar::repair_would_change(ref);
  const pomar::Mesh out = decoded.empty()
                              ? pomar::decode(data.data(), data.size())
                              : pomar::load_mesh(decoded);
  // Snap the original onto the file's grid, as the encoder did.
  for (size_t i = 0; i < ref.positions.size(); ++i) {
    const int axis = static_cast<int>(i % 3);
    ref.positions[i] =
        info.grid.dequantize(axis, info.grid.quantize(axis, ref.positions[i]));
  }
  // STL stores triangles only (no vertex shared or unused): the triangles are
  // compared.
  std::string ext =
      decoded.size() >= 4 ? decoded.substr(decoded.size() - 4) : "";
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  const bool triangles_only = ext == ".stl";
  const bool same =
      triangle_multiset(ref) == triangle_multiset(out) &&
      (triangles_only || (ref.vertex_count() == out.vertex_count() &&
                          point_multiset(ref) == point_multiset(out)));
  const std::string what = decoded.empty() ? file : decoded;
  const pomar::AttributeMask keep = parse_drop(a.drop);
  bool attributes_ok = !same || verify_attributes(ref, out, info, keep);
  if (same && keep.texcoords &&
      (!ref.corner_texcoords.empty() || !ref.face_materials.empty())) {
    // The precision of the stored corners: the decoded mesh's (a decoded mesh
    // file has none: the file is decoded for it).
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
                 "pomar: MISMATCH: %s differs from %s on the %d-bit grid (%zu "
                 "vertices and %zu "
                 "faces against %zu and %zu)%s\n",
                 what.c_str(), original.c_str(), info.bits, out.vertex_count(),
                 out.triangle_count(), ref.vertex_count(), ref.triangle_count(),
                 could_repair ? " (the original needs a repair to be encoded: "
                                "if it was encoded with "
                                "--repair, verify with --repair)"
                              : "");
    return kExitMismatch;
  }
  if (!attributes_ok) {
    std::fprintf(
        stderr,
        "pomar: MISMATCH: %s has the geometry of %s but not its attributes\n",
        what.c_str(), original.c_str());
    return kExitMismatch;
  }
  std::printf("OK: %s matches %s%s: the same %zu vertices and %zu oriented "
              "triangles, every vertex "
              "on its %d-bit grid position",
              what.c_str(), original.c_str(), repair ? " after repair" : "",
              out.vertex_count(), out.triangle_count(), info.bits);
  if (dropped)
    std::printf(" (%zu unreferenced vertices of the original are not in the "
                "file: encoded with "
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
