// PLY: writing as ASCII (formatted here: vcglib prints only 7 significant digits), with
// attributes (ASCII or binary, through TextFileWriter) or binary from the flat arrays
// (vcglib's exporter as the reference and on big-endian hosts).
#include "io/io_common.h"

#include <pomar/vcg_adapter.h>

#include <wrap/io_trimesh/export_ply.h>

#include <cerrno>
#include <cstring>
#include <fstream>

namespace pomar::io {
namespace {

/// Size of the header of a PLY file written by vcglib ("...end_header\n").
uint64_t ply_header_size(const std::string &file, const std::string &target) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  uint64_t size = 0;
  while (size < 65536 && std::getline(in, line)) {
    size += line.size() + 1;
    if (line == "end_header")
      return size;
  }
  fail(target, "vcglib wrote a PLY file without end_header");
}

} // namespace

void write_ply_ascii(TextFileWriter &out, const Mesh &mesh) {
  out.text() += "ply\nformat ascii 1.0\ncomment pomar\nelement vertex " + num(mesh.vertex_count()) +
                "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
                num(mesh.triangle_count()) +
                "\nproperty list uchar int vertex_indices\nend_header\n";
  append_vertices(out, mesh, "");
  append_triangles(out, mesh, "3 ", 0);
}

namespace {
/// The texture index PLY stores for triangle f (its material's texture, -1 for none).
int32_t face_texture_number(const Mesh &mesh, size_t f) {
  return mesh.materials[mesh.face_materials[f]].texture;
}

/// The binary little-endian body of write_ply_with_attributes: every vertex record (x y z,
/// then each attribute's components in the header's order) and every face (indices, then
/// texcoord and texnumber when the mesh has them), written in runs of records into room
/// made once per run (a byte at a time through std::string::operator+= is 10x slower).
void write_binary_body(TextFileWriter &out, const Mesh &mesh) {
  const size_t nv = mesh.vertex_count(), nt = mesh.triangle_count();
  size_t record = 12;
  for (const VertexAttribute &a : mesh.attributes)
    record += a.kind == AttributeKind::Colour ? a.components : 4 * size_t(a.components);
  std::string &s = out.text();
  char *p = nullptr;
  // Room for the next `count` records of `size` bytes at the end of the text (p points to it).
  auto room = [&](size_t count, size_t size) {
    const size_t start = s.size();
    s.resize(start + count * size);
    p = &s[start];
  };
  auto put32 = [&p](uint32_t v) {
    for (int i = 0; i < 4; ++i)
      *p++ = static_cast<char>((v >> (8 * i)) & 0xFF);
  };
  auto put_float32 = [&put32](float f) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    put32(v);
  };
  const size_t vertex_run = std::max<size_t>(1, TextFileWriter::kChunk / record);
  for (size_t first = 0; first < nv; first += vertex_run) {
    const size_t last = std::min(nv, first + vertex_run);
    room(last - first, record);
    for (size_t v = first; v < last; ++v) {
      for (int k = 0; k < 3; ++k)
        put_float32(mesh.positions[3 * v + k]);
      for (const VertexAttribute &a : mesh.attributes)
        for (uint32_t k = 0; k < a.components; ++k) {
          if (a.kind == AttributeKind::Colour)
            *p++ = static_cast<char>(a.colour[v * a.components + k]);
          else
            put_float32(a.values[v * a.components + k]);
        }
    }
    out.done();
  }
  const bool uv = !mesh.corner_texcoords.empty(), number = !mesh.face_materials.empty();
  const size_t face_record = 13 + (uv ? 25 : 0) + (number ? 4 : 0);
  const size_t face_run = TextFileWriter::kChunk / face_record;
  for (size_t first = 0; first < nt; first += face_run) {
    const size_t last = std::min(nt, first + face_run);
    room(last - first, face_record);
    for (size_t t = first; t < last; ++t) {
      *p++ = static_cast<char>(3);
      for (int k = 0; k < 3; ++k)
        put32(mesh.triangles[3 * t + k]);
      if (uv) {
        *p++ = static_cast<char>(6);
        for (int k = 0; k < 6; ++k)
          put_float32(mesh.corner_texcoords[6 * t + k]);
      }
      if (number)
        put32(static_cast<uint32_t>(face_texture_number(mesh, t)));
    }
    out.done();
  }
}
} // namespace

void write_ply_with_attributes(TextFileWriter &out, const Mesh &mesh, bool binary,
                               const std::string &path) {
  validate_attributes(mesh, false);
  const size_t nv = mesh.vertex_count();
  std::string &s = out.text();
  s += std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") +
       " 1.0\ncomment pomar\n";
  for (const std::string &t : mesh.texture_files) {
    if (t.find_first_of("\r\n") != std::string::npos || t.size() > 200)
      fail(path, "texture file name cannot be stored in a PLY comment: " + t.substr(0, 64));
    s += "comment TextureFile " + t + "\n";
  }
  s += "element vertex " + num(nv) + "\nproperty float x\nproperty float y\nproperty float z\n";
  std::vector<std::string> used = {"x", "y", "z"};
  auto declare = [&](const char *type, const std::string &name) {
    if (std::find(used.begin(), used.end(), name) != used.end())
      fail(path, "two PLY vertex properties would be named '" + name + "'");
    if (name.find_first_of(" \t\r\n") != std::string::npos)
      fail(path, "attribute name '" + name + "' cannot be a PLY property name (white space)");
    used.push_back(name);
    s += std::string("property ") + type + " " + name + "\n";
  };
  for (const VertexAttribute &a : mesh.attributes) {
    switch (a.kind) {
    case AttributeKind::Colour:
      for (const char *c : {"red", "green", "blue", "alpha"})
        if (c[0] != 'a' || a.components == 4)
          declare("uchar", c);
      break;
    case AttributeKind::Normal:
      for (const char *c : {"nx", "ny", "nz"})
        declare("float", c);
      break;
    case AttributeKind::TexCoord:
      declare("float", "texture_u");
      declare("float", "texture_v");
      break;
    case AttributeKind::Scalar:
      declare("float", a.name);
      break;
    }
  }
  const bool uv = !mesh.corner_texcoords.empty(), number = !mesh.face_materials.empty();
  s += "element face " + num(mesh.triangle_count()) + "\nproperty list uchar int vertex_indices\n";
  if (uv)
    s += "property list uchar float texcoord\n";
  if (number)
    s += "property int texnumber\n";
  s += "end_header\n";
  if (binary)
    return write_binary_body(out, mesh);
  for (size_t v = 0; v < nv; ++v) { // ASCII
    for (int k = 0; k < 3; ++k) {
      if (k)
        s += ' ';
      append_float(s, mesh.positions[3 * v + k]);
    }
    for (const VertexAttribute &a : mesh.attributes)
      for (uint32_t k = 0; k < a.components; ++k) {
        s += ' ';
        if (a.kind == AttributeKind::Colour)
          append_uint(s, a.colour[v * a.components + k]);
        else
          append_float(s, a.values[v * a.components + k]);
      }
    s += '\n';
    out.done();
  }
  if (!uv && !number)
    return append_triangles(out, mesh, "3 ", 0);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    s += '3';
    for (int k = 0; k < 3; ++k) {
      s += ' ';
      append_uint(s, mesh.triangles[3 * t + k]);
    }
    if (uv) {
      s += " 6";
      for (int k = 0; k < 6; ++k) {
        s += ' ';
        append_float(s, mesh.corner_texcoords[6 * t + k]);
      }
    }
    if (number) {
      s += ' ';
      s += std::to_string(face_texture_number(mesh, t));
    }
    s += '\n';
    out.done();
  }
}

std::string binary_ply_header(uint64_t vertices, uint64_t faces) {
  return "ply\nformat binary_little_endian 1.0\ncomment VCGLIB generated\nelement vertex " +
         num(vertices) + "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         num(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

void save_ply_binary(const std::string &path, const Mesh &mesh) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  // The bytes vcglib's exporter writes for our mesh type (same header, float xyz, a uchar
  // count and three ints per face), written from the flat arrays in large chunks instead
  // of through a vcglib copy and one fwrite per value.
  const uint64_t nv = mesh.vertex_count(), nf = mesh.triangle_count();
  const std::string header = binary_ply_header(nv, nf);
  ChunkedFileWriter out(path, header.size() + 12 * nv + 13 * nf);
  out.put(header.data(), header.size());
  out.put(mesh.positions.data(), 12 * nv);
  for (uint64_t f = 0; f < nf; ++f) {
    char *p = out.reserve(13);
    p[0] = 3;
    std::memcpy(p + 1, &mesh.triangles[3 * f], 12);
  }
  out.commit();
#else
  save_ply_binary_vcg(path, mesh);
#endif
}

void save_ply_binary_vcg(const std::string &path, const Mesh &mesh) {
  IoMesh m;
  to_vcg(mesh, m);
  TempFile tmp(path);
  const uint64_t nv = mesh.vertex_count(), nf = mesh.triangle_count();
  using Exporter = vcg::tri::io::ExporterPLY<IoMesh>;
  errno = 0;
  const int err = Exporter::Save(m, tmp.path().c_str(), true);
  if (err != 0)
    fail_io(path, "cannot write: " +
                      vcg_message<Exporter>(err, vcg::tri::io::PlyInfo::E_MAXPLYINFOERRORS) +
                      errno_suffix());
  check_written_size(tmp.path(), ply_header_size(tmp.path(), path) + 12 * nv + 13 * nf, path);
  tmp.commit(true);
}

} // namespace pomar::io
