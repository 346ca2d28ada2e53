// OBJ: the common case (positions and faces only) read here in one pass; anything else a
// line scan with tinyobjloader's rules (it silently skips short faces and does not
// range-check indices), then tinyobjloader itself (vcglib's OBJ importer drops faces), with
// the material libraries (`mtllib`) beside the file for their texture names (`map_Kd`);
// writing formatted here (vcglib's exporter needs material code), with a `.mtl` beside
// the file when the mesh names texture files.
#include "io/io_common.h"

#include <cmath>

#include <tiny_obj_loader.h>

#include <algorithm>
#include <climits>
#include <fstream>
#include <istream>
#include <map>
#include <streambuf>

namespace pomar::io {
namespace {

/// What a line scan of an OBJ file finds, using tinyobjloader's line rules.
struct ObjScan {
  size_t vertices = 0, faces = 0, triangles = 0, polygons = 0;
  bool normals = false, texcoords = false, colors = false;
  bool mtllib = false, usemtl = false;
  size_t value_lines = 0; // 'vn' and 'vt' lines
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
      s.usemtl = true;
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

/// The OBJ file's vertex colours (8-bit: round(255 c)), normals and texture coordinates that
/// are per vertex; the others are named in `ignored`.
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

/// Reads the material libraries an OBJ file names (`mtllib`), relative to the OBJ file's
/// directory (or absolute), with tinyobjloader's MTL parser; records the ones it did not
/// read and why. Only regular files of 1 byte to 64 MiB are read: a FIFO, a device, a
/// directory or a /proc file (size 0; /proc/kmsg would block) is not, nor a huge file that
/// cannot be a material library.
class MaterialLibraries : public tinyobj::MaterialReader {
public:
  explicit MaterialLibraries(const std::string &obj_path) {
    const size_t slash = obj_path.find_last_of('/');
    dir_ = slash == std::string::npos ? "" : obj_path.substr(0, slash + 1);
  }
  bool operator()(const std::string &name, std::vector<tinyobj::material_t> *materials,
                  std::map<std::string, int> *names, std::string *warn, std::string *err) override {
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
    if (why) {
      missing.push_back("material library '" + name + "' " + why);
      return false;
    }
    tinyobj::LoadMtl(names, materials, &in, warn, err);
    return true;
  }
  std::vector<std::string> missing; ///< "material library 'NAME' not found", ...

private:
  std::string dir_;
};

/// Adds to `keys` the MTL keywords of what a material holds besides its name and diffuse
/// texture (map_Kd). A diffuse colour of 1 1 1 (white: the texture as it is, what save_mesh
/// writes) counts as nothing else.
void other_material_properties(const tinyobj::material_t &m, std::vector<std::string> &keys) {
  auto note = [&](bool differs, const char *key) {
    if (differs)
      add_unique(keys, key);
  };
  auto zero = [](const tinyobj::real_t *c) { return c[0] == 0 && c[1] == 0 && c[2] == 0; };
  auto white = [](const tinyobj::real_t *c) { return c[0] == 1 && c[1] == 1 && c[2] == 1; };
  note(!zero(m.ambient), "Ka");
  note(!zero(m.diffuse) && !white(m.diffuse), "Kd");
  note(!zero(m.specular), "Ks");
  note(!zero(m.transmittance), "Tf");
  note(!zero(m.emission), "Ke");
  note(m.shininess != 1, "Ns");
  note(m.ior != 1, "Ni");
  note(m.dissolve != 1, "d");
  note(m.illum != 0, "illum");
  note(!(m.ambient_texname + m.specular_texname + m.specular_highlight_texname + m.bump_texname +
         m.displacement_texname + m.alpha_texname + m.reflection_texname + m.roughness_texname +
         m.metallic_texname + m.sheen_texname + m.emissive_texname + m.normal_texname)
            .empty(),
       "other maps");
  note(!m.unknown_parameter.empty(), "other keywords");
}

/// The texture files of the materials (`map_Kd`, in material order, each once) go to the
/// mesh's texture list; what else the materials say is named in `ignored`: libraries that
/// could not be read, other material properties, which material each face uses.
void take_obj_materials(const std::vector<tinyobj::material_t> &materials,
                        const std::vector<tinyobj::shape_t> &shapes, const ObjScan &scan,
                        const MaterialLibraries &libraries, Mesh &mesh,
                        std::vector<std::string> &ignored) {
  for (const tinyobj::material_t &m : materials)
    if (!m.diffuse_texname.empty() &&
        std::find(mesh.texture_files.begin(), mesh.texture_files.end(), m.diffuse_texname) ==
            mesh.texture_files.end())
      mesh.texture_files.push_back(m.diffuse_texname);
  for (const std::string &why : libraries.missing)
    add_unique(ignored, ("materials (" + why + ")").c_str());
  std::vector<std::string> keys;
  for (const tinyobj::material_t &m : materials)
    other_material_properties(m, keys);
  if (!keys.empty()) {
    std::string list;
    for (const std::string &k : keys)
      list += (list.empty() ? "" : " ") + k;
    add_unique(ignored, ("material properties other than texture names (" + list + ")").c_str());
  }
  std::vector<int> used;
  for (const auto &shape : shapes)
    for (const int id : shape.mesh.material_ids)
      if (id >= 0 && std::find(used.begin(), used.end(), id) == used.end())
        used.push_back(id);
  if (used.size() > 1)
    add_unique(ignored, ("which material each face uses (" + num(used.size()) +
                         " materials; their texture names are kept)")
                            .c_str());
  if (scan.usemtl && !scan.mtllib)
    add_unique(ignored, "materials (usemtl without a material library)");
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
  // Material libraries beside the file (for texture names), no triangulation
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
  take_obj_materials(materials, shapes, scan, libraries, mesh, report.ignored_attributes);

  report.file_vertices = scan.vertices;
  report.file_faces = scan.faces;
  report.polygons_triangulated = scan.polygons;
  report.unreferenced_vertices = count_unreferenced(mesh);
  return mesh;
}

std::string mtl_text(const Mesh &mesh) {
  std::string s = "# pomar: the mesh's texture files\n";
  for (size_t i = 0; i < mesh.texture_files.size(); ++i)
    s += "newmtl texture_" + num(i) + "\nKd 1 1 1\nmap_Kd " + mesh.texture_files[i] + "\n";
  return s;
}

void write_obj(TextFileWriter &out, const Mesh &mesh, const std::string &mtllib) {
  const VertexAttribute *colour = mesh.find(AttributeKind::Colour);
  const VertexAttribute *normal = mesh.find(AttributeKind::Normal);
  const VertexAttribute *uv = mesh.find(AttributeKind::TexCoord);
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
  const bool vt = table(uv, "vt"), vn = table(normal, "vn");
  if (!mtllib.empty())
    s += "usemtl texture_0\n";
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    s += 'f';
    for (int k = 0; k < 3; ++k) { // "f a b c", "f a/a ...", "f a//a ..." or "f a/a/a ..."
      const uint64_t i = uint64_t(mesh.triangles[3 * t + k]) + 1;
      s += ' ';
      append_uint(s, i);
      if (vt || vn) {
        s += '/';
        if (vt)
          append_uint(s, i);
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
