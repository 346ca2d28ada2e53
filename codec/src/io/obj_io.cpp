// OBJ: the common case (positions and faces only) read here in one pass; anything else a
// line scan with tinyobjloader's rules (it silently skips short faces and does not
// range-check indices; the scan also records which material each face uses), then
// tinyobjloader itself (vcglib's OBJ importer drops faces) for positions, faces, normals,
// texture coordinates and colours, with the material libraries (`mtllib`) beside the file,
// which are parsed here (tinyobjloader's parser does not keep their lines as written);
// writing formatted here (vcglib's exporter needs material code), with a `.mtl` beside the
// file when the mesh has materials or names texture files.
//
// Texture coordinates: per vertex (a VertexAttribute "texcoord") when every corner has one
// and the corners of each vertex agree, per corner (Mesh::corner_texcoords, fan-triangulated
// like the faces) when some vertex has two different ones; dropped and named when some
// corner has none. Materials: every `newmtl` block of the libraries in the order read, then
// the `usemtl` names no library defines (no texture, no properties); faces before the first
// `usemtl` of a file that has one use a material with an empty name (written back as faces
// before any `usemtl`, or after a bare `usemtl` line).
#include "io/io_common.h"

#include <cmath>

#include <tiny_obj_loader.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <fstream>
#include <istream>
#include <map>
#include <streambuf>
#include <unordered_map>

namespace pomar::io {
namespace {

/// What a line scan of an OBJ file finds, using tinyobjloader's line rules.
struct ObjScan {
  size_t vertices = 0, faces = 0, triangles = 0, polygons = 0;
  bool normals = false, texcoords = false, colors = false;
  bool mtllib = false, usemtl = false;
  size_t value_lines = 0; // 'vn' and 'vt' lines
  /// The `usemtl` names in order of first use; per 'f' line (once a `usemtl` was seen),
  /// the index of the name in force, kNoMaterial before the first.
  std::vector<std::string> usemtl_names;
  std::vector<uint32_t> face_material;
  uint32_t current_material = kNoMaterial;
  static constexpr uint32_t kNoMaterial = UINT32_MAX;
};

/// Splits at spaces and tabs (tinyobjloader's separators within a line).
std::vector<std::string> split_blanks(const char *p, const char *end) {
  std::vector<std::string> out;
  while (p < end) {
    while (p < end && (*p == ' ' || *p == '\t'))
      ++p;
    const char *q = p;
    while (q < end && *q != ' ' && *q != '\t')
      ++q;
    if (q > p)
      out.emplace_back(p, q);
    p = q;
  }
  return out;
}

/// Checks one "v" line: three finite decimal coordinates.
void scan_obj_vertex(const std::vector<std::string> &tok, ObjScan &s, size_t line,
                     const std::string &path) {
  const std::string where = "line " + num(line) + ": vertex " + num(s.vertices);
  if (tok.size() < 4)
    fail(path, where + " has fewer than 3 coordinates");
  float p[3];
  for (int i = 0; i < 3; ++i)
    if (!parse_float(tok[i + 1], p[i]))
      fail(path, where + " has a bad coordinate '" + tok[i + 1] + "'");
  if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
    fail(path, where + " has a non-finite coordinate " + point_text(p[0], p[1], p[2]));
  s.colors |= tok.size() >= 7;
  ++s.vertices;
}

/// Checks one "f" line: 3..255 corners (tinyobjloader drops shorter faces silently and
/// stores the corner count in a byte).
void scan_obj_face(const std::vector<std::string> &tok, ObjScan &s, size_t line,
                   const std::string &path) {
  const size_t n = tok.size() - 1;
  if (n < 3 || n > 255)
    fail(path, "line " + num(line) + ": face with " + num(n) + " vertices (3 to 255 supported)");
  ++s.faces;
  s.triangles += n - 2;
  s.polygons += n > 3;
  if (s.usemtl)
    s.face_material.push_back(s.current_material);
}

/// A `usemtl` line (as tinyobjloader reads it: the first word is the name; none: an empty
/// name, which no library defines). The faces before the first one use no material.
void scan_obj_usemtl(const std::vector<std::string> &tok, ObjScan &s) {
  if (!s.usemtl)
    s.face_material.assign(s.faces, ObjScan::kNoMaterial);
  s.usemtl = true;
  const std::string name = tok.size() > 1 ? tok[1] : std::string();
  const auto at = std::find(s.usemtl_names.begin(), s.usemtl_names.end(), name);
  s.current_material = static_cast<uint32_t>(at - s.usemtl_names.begin());
  if (at == s.usemtl_names.end())
    s.usemtl_names.push_back(name);
}

/// Scans the lines as tinyobjloader splits them (LF, CRLF or CR; text after a NUL byte is
/// ignored), recording vertices, faces and the attributes that will be dropped.
ObjScan scan_obj(const std::vector<uint8_t> &bytes, const std::string &path) {
  ObjScan s;
  const char *p = reinterpret_cast<const char *>(bytes.data());
  const char *const end = p + bytes.size();
  for (size_t line = 1; p < end; ++line) {
    const char *eol = p;
    while (eol < end && *eol != '\n' && *eol != '\r')
      ++eol;
    const char *stop = std::find(p, eol, '\0');
    const std::vector<std::string> tok = split_blanks(p, stop);
    p = eol + (eol < end && *eol == '\r' && eol + 1 < end && eol[1] == '\n' ? 2 : 1);
    if (tok.empty())
      continue;
    const std::string &key = tok[0];
    if (key == "v")
      scan_obj_vertex(tok, s, line, path);
    else if (key == "f")
      scan_obj_face(tok, s, line, path);
    else if (key == "vn") {
      s.normals = true;
      ++s.value_lines;
    } else if (key == "vt") {
      s.texcoords = true;
      ++s.value_lines;
    } else if (key == "mtllib")
      s.mtllib = true;
    else if (key == "usemtl")
      scan_obj_usemtl(tok, s);
  }
  return s;
}

/// A read-only std::streambuf over memory, to feed tinyobjloader without a copy.
class MemoryBuffer : public std::streambuf {
public:
  MemoryBuffer(const uint8_t *data, size_t size) {
    char *p = const_cast<char *>(reinterpret_cast<const char *>(data));
    setg(p, p, p + size);
  }
};

std::string first_line(const std::string &s) {
  const std::string line = s.substr(0, s.find('\n'));
  return line.empty() ? "unknown error" : line;
}

/// Fan-triangulates tinyobjloader's faces (corner 0 with each following edge), checking
/// that every index is a vertex. Returns the triangles as flat indices.
std::vector<uint32_t> fan_triangles(const std::vector<tinyobj::shape_t> &shapes, size_t vertices,
                                    const std::string &path) {
  std::vector<uint32_t> tris;
  size_t face = 0;
  for (const auto &shape : shapes) {
    const auto &idx = shape.mesh.indices;
    size_t at = 0;
    for (const unsigned char n : shape.mesh.num_face_vertices) {
      if (n < 3 || at + n > idx.size())
        fail(path, "tinyobjloader returned an inconsistent face " + num(face));
      for (size_t c = 0; c < n; ++c) {
        const int v = idx[at + c].vertex_index;
        if (v < 0 || static_cast<size_t>(v) >= vertices)
          fail(path, "face " + num(face) + " references vertex " + std::to_string(v + 1) +
                         " but there are " + num(vertices) + " vertices");
      }
      for (size_t c = 1; c + 1 < n; ++c)
        tris.insert(tris.end(), {uint32_t(idx[at].vertex_index), uint32_t(idx[at + c].vertex_index),
                                 uint32_t(idx[at + c + 1].vertex_index)});
      at += n;
      ++face;
    }
  }
  return tris;
}

/// Per-vertex normals or texture coordinates from OBJ's per-corner indices (`which`: the
/// corner's normal_index or texcoord_index): kept when every corner of each vertex uses the
/// same values; otherwise empty and `why` says where they differ.
std::vector<float> per_vertex(const std::vector<tinyobj::shape_t> &shapes,
                              const std::vector<float> &table, size_t width, size_t vertices,
                              int tinyobj::index_t::*which, std::string &why) {
  std::vector<float> out(vertices * width, 0.0f);
  std::vector<int> index(vertices, -1);
  for (const auto &shape : shapes)
    for (const tinyobj::index_t &c : shape.mesh.indices) {
      const int i = c.*which;
      if (i < 0 || size_t(i) * width + width > table.size()) {
        why = "not given for every corner";
        return {};
      }
      const size_t v = size_t(c.vertex_index);
      if (index[v] >= 0 && index[v] != i &&
          !std::equal(&table[size_t(i) * width], &table[size_t(i) * width] + width,
                      &table[size_t(index[v]) * width])) {
        why = "per corner, differing at vertex " + std::to_string(v + 1);
        return {};
      }
      index[v] = i;
      std::copy(&table[size_t(i) * width], &table[size_t(i) * width] + width, &out[v * width]);
    }
  return out;
}

/// Per-corner texture coordinates of the fan-triangulated faces (as fan_triangles splits
/// them), u, v per corner; empty if a corner has none (`why` then says so).
std::vector<float> per_corner_texcoords(const std::vector<tinyobj::shape_t> &shapes,
                                        const std::vector<float> &table, size_t triangles,
                                        std::string &why) {
  std::vector<float> out;
  out.reserve(6 * triangles);
  for (const auto &shape : shapes) {
    const auto &idx = shape.mesh.indices;
    size_t at = 0;
    for (const unsigned char n : shape.mesh.num_face_vertices) {
      for (size_t c = 1; c + 1 < n; ++c)
        for (const size_t k : {at, at + c, at + c + 1}) {
          const int i = idx[k].texcoord_index;
          if (i < 0 || 2 * size_t(i) + 2 > table.size()) {
            why = "not given for every corner";
            return {};
          }
          out.push_back(table[2 * size_t(i)]);
          out.push_back(table[2 * size_t(i) + 1]);
        }
      at += n;
    }
  }
  return out;
}

/// The OBJ file's vertex colours (8-bit: round(255 c)), the normals that are per vertex and
/// the texture coordinates, per vertex when they are so, else per corner; what cannot be
/// kept is named in `ignored`.
void take_obj_attributes(const tinyobj::attrib_t &attrib,
                         const std::vector<tinyobj::shape_t> &shapes, const ObjScan &scan,
                         size_t vertices, Mesh &mesh, std::vector<std::string> &ignored) {
  if (scan.colors && attrib.colors.size() == 3 * vertices) {
    VertexAttribute c;
    c.kind = AttributeKind::Colour;
    c.name = "colour";
    c.components = 3;
    for (float x : attrib.colors)
      c.colour.push_back(
          static_cast<uint8_t>(std::lround(std::min(1.0f, std::max(0.0f, x)) * 255)));
    mesh.attributes.push_back(std::move(c));
  } else if (scan.colors) {
    add_unique(ignored, "colors");
  }
  const struct {
    bool present;
    const std::vector<float> &table;
    size_t width;
    int tinyobj::index_t::*which;
    AttributeKind kind;
    const char *name, *label;
  } kinds[] = {{scan.normals, attrib.normals, 3, &tinyobj::index_t::normal_index,
                AttributeKind::Normal, "normal", "normals"},
               {scan.texcoords, attrib.texcoords, 2, &tinyobj::index_t::texcoord_index,
                AttributeKind::TexCoord, "texcoord", "texture coordinates"}};
  for (const auto &k : kinds) {
    if (!k.present)
      continue;
    std::string why;
    std::vector<float> values = per_vertex(shapes, k.table, k.width, vertices, k.which, why);
    if (values.empty() && k.kind == AttributeKind::TexCoord &&
        why != "not given for every corner") { // a seam: one value per corner
      why.clear();
      mesh.corner_texcoords = per_corner_texcoords(shapes, k.table, scan.triangles, why);
      if (!mesh.corner_texcoords.empty())
        continue;
    }
    if (values.empty()) {
      add_unique(ignored, (std::string(k.label) + " (" + why + ")").c_str());
      continue;
    }
    VertexAttribute a;
    a.kind = k.kind;
    a.name = k.name;
    a.components = static_cast<uint32_t>(k.width);
    a.values = std::move(values);
    mesh.attributes.push_back(std::move(a));
  }
}

/// The material blocks of an MTL text: per `newmtl`, its name (the rest of the line), its
/// diffuse texture (`map_Kd`: the rest of the line; with options, "-s 1 1 1 name", the
/// line is kept as a property and the name is its last word) and every other non-empty
/// line as written. Text before the first `newmtl` (comments) is not kept.
struct MtlBlock {
  Material material;
  std::string texture; ///< map_Kd's file name, or empty
};

std::string trim_blanks(const std::string &s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos)
    return {};
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e + 1 - b);
}

void parse_mtl(const std::string &text, std::vector<MtlBlock> &blocks) {
  size_t at = 0;
  bool in_block = false;
  while (at < text.size()) {
    size_t eol = text.find_first_of("\n\r", at);
    if (eol == std::string::npos)
      eol = text.size();
    const std::string line = text.substr(at, eol - at);
    at = eol + 1;
    const std::string trimmed = trim_blanks(line);
    if (trimmed.empty())
      continue;
    const size_t key_end = std::min(trimmed.find_first_of(" \t"), trimmed.size());
    const std::string key = trimmed.substr(0, key_end), rest = trim_blanks(trimmed.substr(key_end));
    if (key == "newmtl") {
      blocks.emplace_back();
      blocks.back().material.name = rest;
      in_block = true;
    } else if (!in_block) {
      continue;
    } else if (key == "map_Kd" && !rest.empty() && rest[0] != '-') {
      blocks.back().texture = rest;
    } else {
      if (key == "map_Kd" && !rest.empty()) // options: the name is the last word
        blocks.back().texture = rest.substr(rest.find_last_of(" \t") + 1);
      blocks.back().material.properties += trimmed + "\n";
    }
  }
}

/// Reads the material libraries an OBJ file names (`mtllib`, in tinyobjloader's order and
/// with its rules: the first readable name of each line), relative to the OBJ file's
/// directory (or absolute), into MTL blocks; records the ones it did not read and why. Only
/// regular files of 1 byte to 64 MiB are read: a FIFO, a device, a directory or a /proc
/// file (size 0; /proc/kmsg would block) is not, nor a huge file that cannot be a material
/// library.
class MaterialLibraries : public tinyobj::MaterialReader {
public:
  explicit MaterialLibraries(const std::string &obj_path) {
    const size_t slash = obj_path.find_last_of('/');
    dir_ = slash == std::string::npos ? "" : obj_path.substr(0, slash + 1);
  }
  bool operator()(const std::string &name, std::vector<tinyobj::material_t> *,
                  std::map<std::string, int> *, std::string *, std::string *) override {
    const std::string path = !name.empty() && name[0] == '/' ? name : dir_ + name;
    struct stat st;
    const char *why = nullptr;
    std::ifstream in;
    if (::stat(path.c_str(), &st) != 0)
      why = "not found";
    else if (!S_ISREG(st.st_mode) || st.st_size == 0 || st.st_size > (64 << 20))
      why = "not a regular file of 1 byte to 64 MiB";
    else if (in.open(path, std::ios::binary), !in.is_open())
      why = "cannot be read";
    std::string text;
    if (!why) {
      text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      if (in.bad())
        why = "cannot be read";
    }
    if (why) {
      missing.push_back("material library '" + name + "' " + why);
      return false;
    }
    parse_mtl(text.substr(0, text.find('\0')), blocks);
    return true;
  }
  std::vector<std::string> missing; ///< "material library 'NAME' not found", ...
  std::vector<MtlBlock> blocks;     ///< every library's blocks, in the order read

private:
  std::string dir_;
};

/// The materials: the libraries' blocks, then the `usemtl` names they do not define, then
/// (if faces come before the first `usemtl`) one with an empty name; their textures
/// (`map_Kd`, in material order, each once) go to the mesh's texture list, the material of
/// each face (fan-triangulated) to face_materials. Libraries that could not be read are
/// named in `ignored`.
void take_obj_materials(const std::vector<tinyobj::shape_t> &shapes, const ObjScan &scan,
                        const MaterialLibraries &libraries, Mesh &mesh,
                        std::vector<std::string> &ignored) {
  for (const MtlBlock &b : libraries.blocks) {
    Material m = b.material;
    if (!b.texture.empty()) {
      auto at = std::find(mesh.texture_files.begin(), mesh.texture_files.end(), b.texture);
      if (at == mesh.texture_files.end())
        at = mesh.texture_files.insert(at, b.texture);
      m.texture = static_cast<int32_t>(at - mesh.texture_files.begin());
    }
    mesh.materials.push_back(std::move(m));
  }
  for (const std::string &why : libraries.missing)
    add_unique(ignored, ("materials (" + why + ")").c_str());
  if (!scan.usemtl)
    return;
  auto material_index = [&](const std::string &name) {
    for (size_t i = 0; i < mesh.materials.size(); ++i)
      if (mesh.materials[i].name == name)
        return static_cast<uint32_t>(i);
    mesh.materials.push_back(Material{name, -1, {}});
    return static_cast<uint32_t>(mesh.materials.size() - 1);
  };
  std::vector<uint32_t> used(scan.usemtl_names.size());
  for (size_t i = 0; i < used.size(); ++i)
    used[i] = material_index(scan.usemtl_names[i]);
  const bool before_first = std::find(scan.face_material.begin(), scan.face_material.end(),
                                      ObjScan::kNoMaterial) != scan.face_material.end();
  const uint32_t none = before_first ? material_index("") : 0;
  mesh.face_materials.reserve(scan.triangles);
  size_t face = 0;
  for (const auto &shape : shapes)
    for (const unsigned char n : shape.mesh.num_face_vertices) {
      const uint32_t f = scan.face_material[face++];
      mesh.face_materials.insert(mesh.face_materials.end(), n - 2u,
                                 f == ObjScan::kNoMaterial ? none : used[f]);
    }
}

/// A coordinate as tinyobjloader reads it (so that both paths give the same floats):
/// not a correctly rounded conversion but its own sum in doubles, reproduced here
/// operation by operation: the integer digits accumulated as m = m * 10 + d, each fraction
/// digit d at place k added as d * 10^-k (a table of 0.1 ... 1e-7, std::pow beyond), an
/// exponent applied as ldexp(m * 5^x, x), the sign last; then rounded to float. Only plain
/// decimals (io_common's plain_decimal) with at most 4 exponent digits come here.
bool obj_coordinate(const char *b, const char *e, float &out) {
  static const double kTenths[] = {1.0, 0.1, 0.01, 0.001, 0.0001, 0.00001, 0.000001, 0.0000001};
  if (!plain_decimal(b, e))
    return false;
  const bool negative = *b == '-';
  b += negative;
  double m = 0.0;
  for (; b != e && *b >= '0' && *b <= '9'; ++b) {
    m *= 10;
    m += static_cast<int>(*b - '0');
  }
  if (b != e && *b == '.')
    for (int place = 1; ++b != e && *b >= '0' && *b <= '9'; ++place)
      m += static_cast<int>(*b - '0') * (place < 8 ? kTenths[place] : std::pow(10.0, -place));
  int exponent = 0;
  if (b != e) { // (e|E)[+-]digits: plain_decimal checked the form
    ++b;
    const bool down = *b == '-';
    b += *b == '-' || *b == '+';
    if (e - b > 4)
      return false;
    for (; b != e; ++b)
      exponent = exponent * 10 + (*b - '0');
    exponent = down ? -exponent : exponent;
  }
  const double value =
      (negative ? -1 : 1) * (exponent ? std::ldexp(m * std::pow(5.0, exponent), exponent) : m);
  out = static_cast<float>(value);
  return std::isfinite(out);
}

/// The common OBJ read straight into the flat arrays, without tinyobjloader: lines "v x y
/// z" (three plain decimal coordinates, finite), "f a b c ..." (3 to 255 positive indices,
/// no '/', fan-triangulated as fan_triangles does), comments, empty lines and the "o", "g"
/// and "s" lines (which change nothing here: faces stay in file order). Anything else
/// (normals, texture coordinates, colours, materials, relative or slashed indices, an index
/// past the last vertex, a NUL byte, ...) returns false, and the scan and tinyobjloader
/// read the file with every check and message of theirs. The mesh is the one they give.
bool read_simple_obj(const std::vector<uint8_t> &bytes, const std::string &path,
                     const SizeCheck &check, Mesh &out, LoadReport &report) {
  const char *p = reinterpret_cast<const char *>(bytes.data());
  const char *const end = p + bytes.size();
  if (std::find(p, end, '\0') != end)
    return false;
  Mesh mesh;
  size_t faces = 0, polygons = 0;
  uint32_t corner[256];
  while (p < end) {
    const char *eol = p;
    while (eol < end && *eol != '\n' && *eol != '\r')
      ++eol;
    const char *q = p;
    p = eol + (eol < end && *eol == '\r' && eol + 1 < end && eol[1] == '\n' ? 2 : 1);
    const auto blank = [](char c) { return c == ' ' || c == '\t'; };
    const auto token = [&](const char *&b, const char *&e) { // the next token of the line
      while (q < eol && blank(*q))
        ++q;
      b = q;
      while (q < eol && !blank(*q))
        ++q;
      e = q;
      return b != e;
    };
    const char *b, *e;
    if (!token(b, e) || *b == '#')
      continue;
    const size_t key = size_t(e - b);
    if (key == 1 && (*b == 'o' || *b == 'g' || *b == 's'))
      continue;
    if (key == 1 && *b == 'v') {
      for (int k = 0; k < 3; ++k) {
        float x;
        if (!token(b, e) || !obj_coordinate(b, e, x))
          return false;
        mesh.positions.push_back(x);
      }
      if (token(b, e)) // a w or a colour: tinyobjloader's path
        return false;
      continue;
    }
    if (key != 1 || *b != 'f')
      return false;
    uint32_t n = 0;
    for (uint64_t index; token(b, e); corner[n++] = uint32_t(index - 1))
      if (n == 255 || !parse_digits(b, e, INT_MAX, index) || index == 0)
        return false;
    if (n < 3)
      return false;
    for (uint32_t c = 1; c + 1 < n; ++c)
      mesh.triangles.insert(mesh.triangles.end(), {corner[0], corner[c], corner[c + 1]});
    ++faces;
    polygons += n > 3;
  }
  const size_t vertices = mesh.positions.size() / 3;
  for (const uint32_t v : mesh.triangles)
    if (v >= vertices)
      return false;
  report.plain_obj = true; // the check's memory estimate is this reader's
  run_size_check(check, path, vertices, mesh.triangles.size() / 3);
  report.file_vertices = vertices;
  report.file_faces = faces;
  report.polygons_triangulated = polygons;
  report.unreferenced_vertices = count_unreferenced(mesh);
  out = std::move(mesh);
  return true;
}

} // namespace

Mesh load_obj(const std::string &path, LoadReport &report, const SizeCheck &check) {
  const std::vector<uint8_t> bytes = read_file(path);
  Mesh fast;
  if (read_simple_obj(bytes, path, check, fast, report))
    return fast;
  const ObjScan scan = scan_obj(bytes, path);
  report.obj_attributes = scan.normals || scan.texcoords || scan.colors; // for the check
  report.obj_value_lines = scan.value_lines;
  run_size_check(check, path, scan.vertices, scan.triangles);

  MemoryBuffer buffer(bytes.data(), bytes.size());
  std::istream stream(&buffer);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  // Material libraries beside the file (parsed by `libraries`), no triangulation
  // (tinyobjloader's own picks a quad diagonal by geometry), no default vertex colors.
  MaterialLibraries libraries(path);
  const bool ok = guarded(path, [&] {
    return tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream, &libraries, false,
                            false);
  });
  if (!ok)
    fail(path, "OBJ parse error: " + first_line(err));
  if (attrib.vertices.size() != 3 * scan.vertices)
    fail(path, "tinyobjloader read " + num(attrib.vertices.size() / 3) +
                   " vertices but the file has " + num(scan.vertices) + " 'v' lines");
  size_t faces = 0;
  for (const auto &shape : shapes)
    faces += shape.mesh.num_face_vertices.size();
  if (faces != scan.faces)
    fail(path, "tinyobjloader read " + num(faces) + " faces but the file has " + num(scan.faces) +
                   " 'f' lines");

  Mesh mesh;
  mesh.triangles = fan_triangles(shapes, scan.vertices, path);
  if (mesh.triangles.size() != 3 * scan.triangles)
    fail(path, "triangulation produced " + num(mesh.triangles.size() / 3) +
                   " triangles, expected " + num(scan.triangles));
  mesh.positions.assign(attrib.vertices.begin(), attrib.vertices.end());
  take_obj_attributes(attrib, shapes, scan, scan.vertices, mesh, report.ignored_attributes);
  take_obj_materials(shapes, scan, libraries, mesh, report.ignored_attributes);

  report.file_vertices = scan.vertices;
  report.file_faces = scan.faces;
  report.polygons_triangulated = scan.polygons;
  report.unreferenced_vertices = count_unreferenced(mesh);
  return mesh;
}

std::string mtl_text(const Mesh &mesh) {
  std::string s;
  if (mesh.materials.empty()) {
    s = "# pomar: the mesh's texture files\n";
    for (size_t i = 0; i < mesh.texture_files.size(); ++i)
      s += "newmtl texture_" + num(i) + "\nKd 1 1 1\nmap_Kd " + mesh.texture_files[i] + "\n";
    return s;
  }
  s = "# pomar\n";
  for (const Material &m : mesh.materials) {
    if (m.name.empty()) // "no material": faces outside any usemtl group
      continue;
    s += "newmtl " + m.name + "\n" + m.properties;
    if (!m.properties.empty() && m.properties.back() != '\n')
      s += '\n';
    const bool map_kd = m.properties.compare(0, 7, "map_Kd ") == 0 ||
                        m.properties.find("\nmap_Kd ") != std::string::npos;
    if (m.texture >= 0 && !map_kd)
      s += "map_Kd " + mesh.texture_files[size_t(m.texture)] + "\n";
  }
  return s;
}

void write_obj(TextFileWriter &out, const Mesh &mesh, const std::string &mtllib) {
  const VertexAttribute *colour = mesh.find(AttributeKind::Colour);
  const VertexAttribute *normal = mesh.find(AttributeKind::Normal);
  const bool corners = !mesh.corner_texcoords.empty();
  const VertexAttribute *uv = corners ? nullptr : mesh.find(AttributeKind::TexCoord);
  std::string &s = out.text();
  s += "# pomar\n";
  if (!mtllib.empty()) { // tinyobjloader splits the names at spaces unless escaped
    s += "mtllib ";
    for (const char c : mtllib)
      s += c == ' ' ? std::string("\\ ") : std::string(1, c);
    s += '\n';
  }
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    s += "v ";
    append_point(s, &mesh.positions[3 * v]);
    if (colour && colour->vertex_count() == mesh.vertex_count())
      for (int k = 0; k < 3; ++k) { // r g b in [0, 1]; RGBA loses its alpha
        s += ' ';
        append_float(s, float(colour->colour[v * colour->components + k]) / 255.0f);
      }
    s += '\n';
    out.done();
  }
  auto table = [&](const VertexAttribute *a, const char *prefix) {
    if (!a || a->vertex_count() != mesh.vertex_count())
      return false;
    for (size_t v = 0; v < mesh.vertex_count(); ++v) {
      s += prefix;
      for (uint32_t k = 0; k < a->components; ++k) {
        s += ' ';
        append_float(s, a->values[v * a->components + k]);
      }
      s += '\n';
      out.done();
    }
    return true;
  };
  // Per-corner texture coordinates: one "vt" line per distinct (u, v) bit pattern, in order
  // of first use; corner_vt[c] is the vt number of corner c.
  std::vector<uint32_t> corner_vt;
  if (corners) {
    std::unordered_map<uint64_t, uint32_t> seen;
    corner_vt.resize(mesh.corner_texcoords.size() / 2);
    for (size_t c = 0; c < corner_vt.size(); ++c) {
      uint32_t bits[2];
      std::memcpy(bits, &mesh.corner_texcoords[2 * c], 8);
      const auto ins = seen.emplace(uint64_t(bits[0]) << 32 | bits[1], uint32_t(seen.size() + 1));
      corner_vt[c] = ins.first->second;
      if (!ins.second)
        continue;
      s += "vt ";
      append_float(s, mesh.corner_texcoords[2 * c]);
      s += ' ';
      append_float(s, mesh.corner_texcoords[2 * c + 1]);
      s += '\n';
      out.done();
    }
  }
  const bool vt = corners || table(uv, "vt"), vn = table(normal, "vn");
  const bool groups = !mesh.materials.empty() && !mesh.face_materials.empty();
  if (!mtllib.empty() && mesh.materials.empty())
    s += "usemtl texture_0\n";
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (groups && (t == 0 || mesh.face_materials[t] != mesh.face_materials[t - 1])) {
      const std::string &name = mesh.materials[mesh.face_materials[t]].name;
      if (!name.empty() || t > 0) // a bare usemtl: no material (read back as the empty name)
        s += name.empty() ? "usemtl\n" : "usemtl " + name + "\n";
    }
    s += 'f';
    for (int k = 0; k < 3; ++k) { // "f a b c", "f a/t ...", "f a//a ..." or "f a/t/a ..."
      const uint64_t i = uint64_t(mesh.triangles[3 * t + k]) + 1;
      s += ' ';
      append_uint(s, i);
      if (vt || vn) {
        s += '/';
        if (vt)
          append_uint(s, corners ? corner_vt[3 * t + k] : i);
        if (vn) {
          s += '/';
          append_uint(s, i);
        }
      }
    }
    s += '\n';
    out.done();
  }
}

} // namespace pomar::io
