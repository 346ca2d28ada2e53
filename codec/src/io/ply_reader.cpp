// PLY: loading. The header, then the fast path (ply_simple_read.cpp) or the walk
// (ply_walker.cpp), then, unless the walk captured the mesh, vcglib's importer with count
// checks; per-vertex attributes and face texture data come from the walk.
#include "io/ply_internal.h"

#include <pomar/vcg_adapter.h>

#include <wrap/io_trimesh/import_ply.h>

#include <algorithm>
#include <cmath>

namespace pomar::io {
namespace {

using PlyImporter = vcg::tri::io::ImporterPLY<IoMesh>;

/// The mesh of a walk that captured the positions and triangles (PlyCapture), as the
/// general path would build it without vcglib's second read of the file: the attributes
/// go through a vcglib mesh of the same vertices (put_attributes, then from_vcg's
/// take_attributes), so that they come out exactly as there (quality, texture coordinates
/// and named scalars in its order; the caller restores an alpha of 255, keep_alpha). False if the
/// capture stopped or met a non-finite coordinate: the general path reads the file, and
/// names the problem.
bool mesh_from_capture(PlyCapture &capture, const PlyLayout &layout, const PlyVertexPlan &plan,
                       const std::vector<std::string> &texture_files, const std::string &path,
                       Mesh &out, size_t &unreferenced) {
  const size_t nv = layout.vertices;
  if (!capture.ok || capture.positions.size() != 3 * nv ||
      capture.triangles.size() != 3 * layout.triangles || nv >= UINT32_MAX)
    return false;
  for (const float x : capture.positions)
    if (!std::isfinite(x))
      return false;
  for (const VertexAttribute &a : plan.attributes)
    if (a.vertex_count() != nv)
      fail(path, "PLY vertex attribute '" + a.name + "' was not read for every vertex");
  Mesh mesh;
  if (!plan.attributes.empty()) {
    IoMesh m;
    vcg::tri::Allocator<IoMesh>::AddVertices(m, nv);
    const int mask = put_attributes(plan.attributes, texture_files, m);
    std::vector<uint32_t> identity(nv);
    for (size_t v = 0; v < nv; ++v)
      identity[v] = static_cast<uint32_t>(v);
    vcg_detail::take_attributes(m, identity, mask, mesh);
  }
  mesh.positions = std::move(capture.positions);
  mesh.triangles = std::move(capture.triangles);
  std::vector<uint8_t> used(nv, 0);
  for (const uint32_t v : mesh.triangles)
    used[v] = 1;
  unreferenced = static_cast<size_t>(std::count(used.begin(), used.end(), uint8_t(0)));
  mesh.texture_files = texture_files;
  out = std::move(mesh);
  return true;
}

/// The face texture data the walk read: corner_texcoords; face_materials from texnumber,
/// with one material "texture_<i>" per texture file (texture i) and, for a texnumber that
/// names no texture file, one with an empty name and no texture.
void take_face_data(PlyFaceData &d, const PlyLayout &layout, Mesh &mesh) {
  if (d.corner_texcoords.size() == 6 * layout.triangles && layout.triangles > 0)
    mesh.corner_texcoords = std::move(d.corner_texcoords);
  if (!d.numbers.empty() && d.numbers.size() == layout.triangles) {
    const size_t textures = mesh.texture_files.size();
    for (size_t i = 0; i < textures; ++i)
      mesh.materials.push_back(Material{"texture_" + num(i), int32_t(i), {}});
    mesh.face_materials.resize(d.numbers.size());
    for (size_t f = 0; f < d.numbers.size(); ++f) {
      const int64_t t = d.numbers[f];
      if (t >= 0 && uint64_t(t) < textures) {
        mesh.face_materials[f] = uint32_t(t);
        continue;
      }
      if (mesh.materials.size() == textures)
        mesh.materials.push_back(Material{"", -1, {}});
      mesh.face_materials[f] = uint32_t(textures);
    }
  }
}

/// The RGBA colour of the file, in `mesh` (made through a vcglib mesh, whose colours are
/// always RGBA: take_attributes keeps an alpha only where one differs from 255): a file with
/// an alpha property gives 4 channels, whatever their values.
void keep_alpha(PlyVertexPlan &plan, Mesh &mesh) {
  for (VertexAttribute &a : plan.attributes)
    if (a.kind == AttributeKind::Colour && a.components == 4)
      if (VertexAttribute *c = mesh.find(AttributeKind::Colour, a.name))
        if (c->components == 3 && a.vertex_count() == c->vertex_count()) {
          c->components = 4;
          c->colour = std::move(a.colour);
        }
}

/// Names, in `ignored`, each property of the face (or tristrips) elements that is neither
/// an index list, nor read by the walk (`kept`: texcoord, texnumber), nor one vcglib's mask
/// `file_mask` already names (add_ignored_from_mask: face colour, normal, quality, flags,
/// wedge texture coordinates and colours).
void name_unkept_face_properties(const PlyHeader &h, int file_mask, const PlyFaceData &kept,
                                 std::vector<std::string> &ignored) {
  using M = vcg::tri::io::Mask;
  static const struct {
    const char *name;
    int mask;
  } kNamed[] = {{"flags", M::IOM_FACEFLAGS},       {"quality", M::IOM_FACEQUALITY},
                {"nx", M::IOM_FACENORMAL},         {"ny", M::IOM_FACENORMAL},
                {"nz", M::IOM_FACENORMAL},         {"red", M::IOM_FACECOLOR},
                {"green", M::IOM_FACECOLOR},       {"blue", M::IOM_FACECOLOR},
                {"alpha", M::IOM_FACECOLOR},       {"color", M::IOM_WEDGCOLOR},
                {"texcoord", M::IOM_WEDGTEXCOORD}, {"texnumber", M::IOM_WEDGTEXMULTI}};
  for (const PlyElement &e : h.elements) {
    if (e.name != "face" && e.name != "tristrips")
      continue;
    for (const PlyProperty &p : e.props) {
      if ((p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) ||
          &p == kept.texcoord || &p == kept.texnumber)
        continue;
      bool named = false;
      for (const auto &k : kNamed)
        named |= p.name == k.name && (file_mask & k.mask);
      if (!named)
        add_unique(ignored,
                   (e.name + (p.is_list ? " list" : "") + " property '" + p.name + "'").c_str());
    }
  }
}

} // namespace

Mesh load_ply(const std::string &path, LoadReport &report, const SizeCheck &check) {
  PlyLayout layout;
  PlyVertexPlan plan;
  PlyCapture capture;
  PlyFaceData face_data;
  std::vector<std::string> texture_files;
  PlyHeader header;
  {
    FileReader in(path);
    header = read_ply_header(in, path);
    const uint64_t faces = element_count(header, "face");
    report.text = header.encoding == PlyHeader::Ascii;
    run_size_check(check, path, element_count(header, "vertex"), faces);
    const PlyElement *vertex = nullptr;
    for (const PlyElement &e : header.elements)
      if (e.name == "vertex")
        vertex = &e;
    plan = plan_vertex_attributes(vertex, report.ignored_attributes);
    texture_files = header.texture_files;
    face_data = plan_face_data(header);
    const uint64_t data_start = in.pos();
    Mesh fast;
    size_t unreferenced = 0;
    if (texture_files.empty() && read_simple_ply(in, header, fast, unreferenced)) {
      report.file_vertices = header.elements[0].count;
      report.file_faces = faces;
      report.unreferenced_vertices = unreferenced;
      return fast;
    }
    // The walk also takes the positions and triangles (PlyCapture): vcglib need not read
    // the file again.
    capture.ok = true;
    if (in.pos() == data_start) {
      layout = walk_ply(in, header, path, &plan, &capture, &face_data);
    } else { // the general path reads the data from its start
      FileReader again(path);
      read_ply_header(again, path);
      layout = walk_ply(again, header, path, &plan, &capture, &face_data);
    }
    if (layout.triangles > faces) // polygons or triangle strips
      run_size_check(check, path, layout.vertices, layout.triangles);
  }
  int file_mask = 0; // what the file has, whatever our mesh type can store
  PlyImporter::LoadMask(path.c_str(), file_mask);
  {
    using M = vcg::tri::io::Mask; // per-vertex data is read by the walk (plan)
    file_mask &= ~(M::IOM_VERTCOLOR | M::IOM_VERTNORMAL | M::IOM_VERTQUALITY | M::IOM_VERTTEXCOORD |
                   M::IOM_VERTRADIUS | M::IOM_VERTFLAGS);
    if (face_data.texcoord) // face texture data: read by the walk (and named if unusable)
      file_mask &= ~M::IOM_WEDGTEXCOORD;
    if (face_data.texnumber)
      file_mask &= ~M::IOM_WEDGTEXMULTI;
  }
  if (face_data.bad_texcoord)
    add_unique(report.ignored_attributes,
               "texture coordinates (face texcoord lists not of two values per corner)");
  add_ignored_from_mask(file_mask, report.ignored_attributes);
  name_unkept_face_properties(header, file_mask, face_data, report.ignored_attributes);
  if (layout.edges)
    add_unique(report.ignored_attributes, "edges");
  if (layout.camera)
    add_unique(report.ignored_attributes, "camera");
  report.file_vertices = layout.vertices;
  report.file_faces = layout.faces;
  report.polygons_triangulated = layout.polygons;
  Mesh captured;
  if (mesh_from_capture(capture, layout, plan, texture_files, path, captured,
                        report.unreferenced_vertices)) {
    take_face_data(face_data, layout, captured);
    keep_alpha(plan, captured);
    return captured;
  }

  IoMesh m;
  int mask = 0;
  const int err = guarded(path, [&] { return PlyImporter::Open(m, path.c_str(), mask); });
  if (PlyImporter::ErrorCritical(err))
    fail(path, "PLY import failed: " +
                   vcg_message<PlyImporter>(err, vcg::tri::io::PlyInfo::E_MAXPLYINFOERRORS));
  check_counts(m, layout.vertices, layout.triangles, path, "vcglib's PLY importer");
  clear_flags(m);
  check_finite(m, path, false);

  for (const VertexAttribute &a : plan.attributes)
    if (a.vertex_count() != m.vert.size())
      fail(path, "PLY vertex attribute '" + a.name + "' was not read for every vertex");
  const int attribute_mask = put_attributes(plan.attributes, texture_files, m);
  // Unreferenced vertices kept (the file stores them).
  Mesh mesh = from_vcg(m, &report.unreferenced_vertices, attribute_mask, true);
  keep_alpha(plan, mesh);
  mesh.texture_files = texture_files; // also without per-vertex texture coordinates
  take_face_data(face_data, layout, mesh);
  return mesh;
}

} // namespace pomar::io
