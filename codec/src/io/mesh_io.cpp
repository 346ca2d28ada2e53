// Mesh file I/O: picks the format from the extension and calls its reader or writer
// (ply_reader.cpp / ply_writer.cpp, obj_io.cpp, off_io.cpp, stl_io.cpp); reads whole
// files and writes them atomically (temporary file, fsync, rename).
//
// PLY, OFF and ASCII STL are read through vcglib, OBJ through tinyobjloader, binary STL
// directly; each reader first walks the file's structure and refuses what its importer
// would mishandle (io_common.h). Binary PLY and binary STL are written through vcglib's
// exporters into a temporary file whose size is checked (the exporters ignore write
// errors) before it is renamed over the destination. ASCII PLY, ASCII STL, OFF and OBJ are
// formatted by pomar, because vcglib prints only 7 significant digits (lossy for float)
// and its OBJ exporter needs material code; their text goes to the temporary file in 1 MiB
// chunks as it is formatted (TextFileWriter), never whole in memory.
#include "io/io_common.h"
#include "memory/prefault.h"

#include <climits>
#include <cmath>

namespace pomar {

using namespace io; // this file is the dispatch over pomar::io's readers and writers

namespace {

enum class Format { Ply, Obj, Off, Stl };

const char *const kSupported = "supported: .ply, .obj, .off, .stl";

/// Lower-case extension of the last path component, with its dot ("" if none).
std::string lower_extension(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
    return "";
  std::string ext = path.substr(dot);
  for (char &c : ext)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Format format_of(const std::string &path) {
  const std::string ext = lower_extension(path);
  if (ext == ".ply")
    return Format::Ply;
  if (ext == ".obj")
    return Format::Obj;
  if (ext == ".off")
    return Format::Off;
  if (ext == ".stl")
    return Format::Stl;
  if (ext.empty())
    fail(Error::Kind::Usage, path,
         std::string("no file extension to tell the mesh format (") + kSupported + ")");
  fail(Error::Kind::Usage, path, "unknown mesh file extension '" + ext + "' (" + kSupported + ")");
}

const char *format_name(Format f) {
  switch (f) {
  case Format::Ply:
    return "ply";
  case Format::Obj:
    return "obj";
  case Format::Off:
    return "off";
  case Format::Stl:
    return "stl";
  }
  return "?";
}

/// Refuses per-corner texture coordinates, face materials and materials that do not fit the
/// mesh: array sizes, indices out of range, non-finite coordinates, names and texture
/// indices that cannot be written.
void check_corner_data(const Mesh &mesh, const std::string &path) {
  const size_t nt = mesh.triangle_count();
  if (!mesh.corner_texcoords.empty() && mesh.corner_texcoords.size() != 6 * nt)
    fail(path, "cannot save: " + num(mesh.corner_texcoords.size()) +
                   " per-corner texture coordinate values for " + num(nt) +
                   " triangles (6 per triangle)");
  for (size_t i = 0; i < mesh.corner_texcoords.size(); ++i)
    if (!std::isfinite(mesh.corner_texcoords[i]))
      fail(path, "cannot save: corner " + num(i / 2 % 3) + " of triangle " + num(i / 6) +
                     " has a non-finite texture coordinate");
  if (!mesh.face_materials.empty() && mesh.face_materials.size() != nt)
    fail(path, "cannot save: " + num(mesh.face_materials.size()) + " face materials for " +
                   num(nt) + " triangles");
  for (size_t f = 0; f < mesh.face_materials.size(); ++f)
    if (mesh.face_materials[f] >= mesh.materials.size())
      fail(path, "cannot save: triangle " + num(f) + " uses material " +
                     num(mesh.face_materials[f]) + " but there are " + num(mesh.materials.size()) +
                     " materials");
  for (const Material &m : mesh.materials) {
    if (m.texture < -1 || (m.texture >= 0 && size_t(m.texture) >= mesh.texture_files.size()))
      fail(path, "cannot save: material '" + m.name + "' uses texture " +
                     std::to_string(m.texture) + " but there are " +
                     num(mesh.texture_files.size()) + " texture files");
    if (m.name.find_first_of(" \t\r\n") != std::string::npos)
      fail(path, "cannot save: material name '" + m.name + "' has white space");
  }
}

/// Refuses meshes that cannot be written (or read back): bad sizes, indices out of range,
/// NaN/Inf, more elements than vcglib's int counters.
void check_mesh_for_save(const Mesh &mesh, const std::string &path) {
  if (mesh.positions.size() % 3 != 0 || mesh.triangles.size() % 3 != 0)
    fail(path, "cannot save: positions and triangles must hold a multiple of 3 values");
  const size_t nv = mesh.vertex_count();
  if (nv > size_t(INT_MAX) || mesh.triangle_count() > size_t(INT_MAX))
    fail(path, "cannot save: more than INT_MAX vertices or triangles");
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    if (mesh.triangles[i] >= nv)
      fail(path, "cannot save: triangle " + num(i / 3) + " references vertex " +
                     num(mesh.triangles[i]) + " but there are " + num(nv) + " vertices");
  for (size_t v = 0; v < nv; ++v) {
    const float *p = &mesh.positions[3 * v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      fail(path, "cannot save: vertex " + num(v) + " has a non-finite coordinate " +
                     point_text(p[0], p[1], p[2]));
  }
  for (const std::string &name : mesh.texture_files) // one line of a header or .mtl file
    if (name.empty() || name.find_first_of("\r\n") != std::string::npos)
      fail(path, "cannot save: texture file name '" + name + "' is empty or has a line break");
  check_corner_data(mesh, path);
}

/// The material library written beside an OBJ file: its name with the extension .mtl.
std::string material_library_path(const std::string &obj_path) {
  return obj_path.substr(0, obj_path.find_last_of('.')) + ".mtl";
}

std::string file_name(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

} // namespace

std::vector<uint8_t> read_file(const std::string &path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0)
    fail_io(path, "cannot open: " + errno_text(errno));
  FdGuard guard(fd);
  struct stat st;
  const bool have_stat = ::fstat(fd, &st) == 0;
  if (have_stat && S_ISDIR(st.st_mode))
    fail_io(path, "is a directory");
  // A regular file is read into a buffer of its size (+1 to see the end): growing by
  // doubling would briefly hold 1.5 times a large file.
  std::vector<uint8_t> data;
  if (have_stat && S_ISREG(st.st_mode)) // (mapped first: memory/prefault.h)
    resize_prefaulted(data, static_cast<size_t>(st.st_size) + 1);
  size_t used = 0;
  for (;;) {
    if (used == data.size())
      data.resize(std::max<size_t>(data.size() * 2, used + 65536));
    const ssize_t r = ::read(fd, data.data() + used, data.size() - used);
    if (r < 0 && errno == EINTR)
      continue;
    if (r < 0)
      fail_io(path, "cannot read: " + errno_text(errno));
    if (r == 0)
      break;
    used += static_cast<size_t>(r);
  }
  data.resize(used);
  if (data.capacity() - used > used / 8) // grown by doubling (not a regular file)
    data.shrink_to_fit();
  return data;
}

void write_file_atomic(const std::string &path, const void *data, size_t size) {
  AtomicFile file(path);
  file.write(static_cast<const char *>(data), size);
  file.commit();
}

Mesh load_mesh(const std::string &path, LoadReport *report, const SizeCheck &size_check) {
  const Format format = format_of(path);
  LoadReport local;
  LoadReport &r = report ? *report : local;
  r = LoadReport();
  r.format = format_name(format);
  r.text = format == Format::Obj || format == Format::Off; // PLY and STL: set by their readers
  Mesh mesh;
  switch (format) {
  case Format::Ply:
    mesh = io::load_ply(path, r, size_check);
    break;
  case Format::Off:
    mesh = io::load_off(path, r, size_check);
    break;
  case Format::Stl:
    mesh = io::load_stl(path, r, size_check);
    break;
  case Format::Obj:
    mesh = io::load_obj(path, r, size_check);
    break;
  }
  if (mesh.triangles.empty())
    fail(path, "contains no triangles");
  return mesh;
}

void save_mesh(const std::string &path, const Mesh &mesh, bool binary) {
  const Format format = format_of(path);
  check_mesh_for_save(mesh, path);
  const bool attributes = !mesh.attributes.empty() || !mesh.texture_files.empty() ||
                          !mesh.corner_texcoords.empty() || !mesh.face_materials.empty();
  if (format == Format::Ply && binary && !attributes)
    return save_ply_binary(path, mesh);
  if (format == Format::Stl && binary)
    return save_stl_binary(path, mesh);
  std::string mtllib;
  if (format == Format::Obj && (!mesh.texture_files.empty() || !mesh.materials.empty())) {
    // the library first: the OBJ names it
    const std::string mtl = material_library_path(path), lib = mtl_text(mesh);
    write_file_atomic(mtl, lib.data(), lib.size());
    mtllib = file_name(mtl);
  }
  TextFileWriter out(path); // the text goes to the file in chunks as it is formatted
  switch (format) {
  case Format::Ply:
    if (attributes)
      write_ply_with_attributes(out, mesh, binary, path);
    else
      write_ply_ascii(out, mesh);
    break;
  case Format::Stl:
    write_stl_ascii(out, mesh);
    break;
  case Format::Off:
    write_off(out, mesh);
    break;
  case Format::Obj:
    write_obj(out, mesh, mtllib);
    break;
  }
  out.commit();
}

std::vector<std::string> attributes_not_saved(const std::string &path, const Mesh &mesh) {
  const Format format = format_of(path);
  std::vector<std::string> out;
  if (format == Format::Ply) {
    // PLY holds a texture index per face: one material per texture file, named by it.
    bool plain = true;
    for (size_t i = 0; i < mesh.materials.size(); ++i)
      plain &= mesh.materials[i].properties.empty() &&
               (mesh.materials[i].name == "texture_" + num(i) ||
                (mesh.materials[i].name.empty() && mesh.materials[i].texture < 0)) &&
               (mesh.materials[i].texture == int32_t(i) || mesh.materials[i].texture < 0);
    if (!plain)
      out.push_back("the material names and properties (each face's texture is written)");
    return out;
  }
  std::string scalars;
  bool alpha = false;
  for (const VertexAttribute &a : mesh.attributes) {
    if (a.kind == AttributeKind::Scalar)
      scalars += (scalars.empty() ? "scalars '" : ", '") + a.name + "'";
    alpha |= a.kind == AttributeKind::Colour && a.components == 4;
  }
  const bool stl = format == Format::Stl, off = format == Format::Off;
  const bool uv = mesh.find(AttributeKind::TexCoord) != nullptr;
  if (stl && mesh.find(AttributeKind::Colour))
    out.push_back("colours");
  if (alpha && format == Format::Obj)
    out.push_back("the alpha of the colours");
  if (stl && mesh.find(AttributeKind::Normal))
    out.push_back("normals");
  if (!scalars.empty())
    out.push_back(scalars);
  if ((stl || off) && uv)
    out.push_back("texture coordinates");
  if ((stl || off) && !mesh.texture_files.empty())
    out.push_back("texture file names");
  const bool corners = !mesh.corner_texcoords.empty();
  if ((stl || off) && corners)
    out.push_back("per-corner texture coordinates");
  if ((stl || off) && !mesh.materials.empty())
    out.push_back("materials");
  if (format == Format::Obj && corners && uv)
    out.push_back("the per-vertex texture coordinates (the per-corner ones are written)");
  if (format == Format::Obj && (uv || mesh.find(AttributeKind::Normal))) {
    // OBJ gives normals and texture coordinates to face corners: a vertex no face uses
    // has none when read back.
    if (const size_t unused = count_unreferenced(mesh))
      out.push_back("the normals and texture coordinates of " + num(unused) +
                    " vertices no face uses");
  }
  return out;
}

} // namespace pomar
