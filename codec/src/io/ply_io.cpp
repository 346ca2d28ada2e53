// PLY: a walk over the header and every element before vcglib's importer sees the file
// (see io_common.h for why), then the import with count checks; writing as ASCII
// (formatted here: vcglib prints only 7 significant digits) or binary (from the flat
// arrays; vcglib's exporter as the reference and on big-endian hosts).
#include "io/io_common.h"
#include "memory/prefault.h"

#include <pomar/vcg_adapter.h>

#include <wrap/io_trimesh/export_ply.h>
#include <wrap/io_trimesh/import_ply.h>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <fstream>

namespace pomar::io {
namespace {

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::F32; // list items for a list
  bool is_list = false;
  PlyType count_type = PlyType::U8; // lists only
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> props;
  /// The first property with that name, as plylib's FindProp picks it.
  const PlyProperty *find(const char *prop) const {
    for (const auto &p : props)
      if (p.name == prop)
        return &p;
    return nullptr;
  }
};

/// Whether plylib would accept property p for a descriptor with these types: it demands
/// exactly the declared types (no conversion).
bool is_list_of(const PlyProperty *p, PlyType item, PlyType count) {
  return p && p->is_list && p->type == item && p->count_type == count;
}
bool is_scalar_of(const PlyProperty *p, PlyType type) {
  return p && !p->is_list && p->type == type;
}

struct PlyHeader {
  enum Encoding { Ascii, BinaryLittle, BinaryBig } encoding = Ascii;
  std::vector<PlyElement> elements;
  std::vector<std::string> texture_files; ///< "comment TextureFile <name>" lines
};

size_t type_size(PlyType t) {
  switch (t) {
  case PlyType::I8:
  case PlyType::U8:
    return 1;
  case PlyType::I16:
  case PlyType::U16:
    return 2;
  case PlyType::I32:
  case PlyType::U32:
  case PlyType::F32:
    return 4;
  case PlyType::F64:
    return 8;
  }
  return 0;
}

/// The type names plylib accepts (classic and sized spellings).
bool parse_ply_type(const std::string &s, PlyType &t) {
  static const struct {
    const char *a, *b;
    PlyType t;
  } names[] = {{"char", "int8", PlyType::I8},      {"uchar", "uint8", PlyType::U8},
               {"short", "int16", PlyType::I16},   {"ushort", "uint16", PlyType::U16},
               {"int", "int32", PlyType::I32},     {"uint", "uint32", PlyType::U32},
               {"float", "float32", PlyType::F32}, {"double", "float64", PlyType::F64}};
  for (const auto &n : names)
    if (s == n.a || s == n.b) {
      t = n.t;
      return true;
    }
  return false;
}

std::string base_name(const std::string &path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

/// vcglib expands "comment TextureFile <name>" into a 255-byte stack buffer, substituting
/// the file's base name for each "<this>"; refuse comments that could overflow it.
void check_texture_comment(const std::string &line, const std::string &path) {
  if (line.find("TextureFile") == std::string::npos)
    return;
  const size_t expansions = static_cast<size_t>(std::count(line.begin(), line.end(), '<'));
  const size_t base = base_name(path).size();
  if (base >= 250 || line.size() + expansions * base >= 250)
    fail(path, "PLY TextureFile comment too long for vcglib");
}

/// Handles one "element" or "property" header line.
void add_ply_declaration(PlyHeader &h, const std::vector<std::string> &tok,
                         const std::string &path) {
  auto bad = [&](const std::string &why) { fail(path, "invalid PLY header: " + why); };
  if (tok[0] == "element") {
    uint64_t count = 0;
    if (tok.size() < 3 || !parse_count(tok[2], INT_MAX, count))
      bad("bad element line '" + tok[0] + " " + (tok.size() > 1 ? tok[1] : "") + " ...'");
    h.elements.push_back({tok[1], count, {}});
    return;
  }
  if (h.elements.empty())
    bad("property before the first element");
  PlyProperty p;
  const bool list = tok.size() > 1 && tok[1] == "list";
  if (list ? tok.size() < 5 : tok.size() < 3)
    bad("incomplete property line");
  p.is_list = list;
  if (list && !parse_ply_type(tok[2], p.count_type))
    bad("unknown type '" + tok[2] + "'");
  if (!parse_ply_type(tok[list ? 3 : 1], p.type))
    bad("unknown type '" + tok[list ? 3 : 1] + "'");
  p.name = tok[list ? 4 : 2];
  h.elements.back().props.push_back(p);
}

/// Parses the header, leaving `in` at the first data byte.
PlyHeader read_ply_header(FileReader &in, const std::string &path) {
  auto bad = [&](const std::string &why) { fail(path, "invalid PLY header: " + why); };
  std::string line;
  if (!in.line(line) || line.compare(0, 3, "ply") != 0)
    fail(path, "not a PLY file (no 'ply' magic)");
  PlyHeader h;
  bool have_format = false;
  for (;;) {
    if (!in.line(line))
      bad("no end_header");
    if (line.size() > 500) // plylib reads header lines in 511-byte pieces
      bad("line longer than 500 characters");
    if (line.find('\0') != std::string::npos) // plylib's strtok would stop there
      bad("NUL byte");
    const std::vector<std::string> tok = split_ws(line);
    if (tok.empty())
      bad("empty line");
    if (tok[0] == "comment" || tok[0] == "obj_info") {
      check_texture_comment(line, path);
      const size_t at = line.find("TextureFile");
      if (tok[0] == "comment" && tok.size() >= 3 && tok[1] == "TextureFile") {
        std::string name = line.substr(line.find_first_not_of(" \t", at + 11));
        while (!name.empty() && (name.back() == '\r' || name.back() == ' '))
          name.pop_back();
        h.texture_files.push_back(name);
      }
    } else if (tok[0] == "end_header") {
      break;
    } else if (tok[0] == "format") {
      if (have_format || !h.elements.empty() || tok.size() < 3)
        bad("misplaced or incomplete format line");
      if (tok[1] == "ascii")
        h.encoding = PlyHeader::Ascii;
      else if (tok[1] == "binary_little_endian")
        h.encoding = PlyHeader::BinaryLittle;
      else if (tok[1] == "binary_big_endian")
        h.encoding = PlyHeader::BinaryBig;
      else
        bad("unknown format '" + tok[1] + "'");
      have_format = true;
    } else if (tok[0] == "element" || tok[0] == "property") {
      if (!have_format)
        bad("format line missing before '" + tok[0] + "'");
      add_ply_declaration(h, tok, path);
    } else {
      bad("unexpected keyword '" + tok[0] + "'");
    }
  }
  if (!have_format)
    bad("no format line");
  return h;
}

/// What the walk found; the triangle count is what vcglib's importer will build.
struct PlyLayout {
  size_t vertices = 0;
  size_t faces = 0; // polygons of the face element, or triangles of the strips
  size_t triangles = 0;
  size_t polygons = 0; // faces with more than 3 corners
  bool edges = false, camera = false;
};

/// Reads PLY values of any type during the walk (binary in either byte order, or ASCII).
class PlyValues {
public:
  PlyValues(FileReader &in, PlyHeader::Encoding enc, const std::string &path)
      : in_(in), enc_(enc), path_(path) {}

  /// One integer value; false at the end of the file.
  bool integer(PlyType t, int64_t &v) {
    if (t == PlyType::F32 || t == PlyType::F64)
      fail(path_, "PLY list count or vertex index of floating-point type");
    if (enc_ == PlyHeader::Ascii) {
      if (!in_.token(tok_))
        return false;
      if (!parse_int(tok_, v))
        fail(path_, "bad integer '" + tok_ + "' in PLY data");
      return true;
    }
    unsigned char b[4] = {0, 0, 0, 0};
    const size_t n = type_size(t);
    if (!in_.read(b, n))
      return false;
    if (enc_ == PlyHeader::BinaryBig)
      std::reverse(b, b + n);
    v = decode(t, b);
    return true;
  }

  /// One value of any type as a float (doubles rounded); false at the end of the file.
  bool real(PlyType t, float &v) {
    if (enc_ == PlyHeader::Ascii) {
      if (!in_.token(tok_))
        return false;
      int64_t i = 0;
      if (t == PlyType::F32 || t == PlyType::F64) {
        if (tok_.find('(') != std::string::npos || !parse_float(tok_, v))
          fail(path_, "bad number '" + tok_ + "' in PLY data");
      } else {
        if (!parse_int(tok_, i))
          fail(path_, "bad integer '" + tok_ + "' in PLY data");
        v = static_cast<float>(i);
      }
      return true;
    }
    unsigned char b[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    const size_t n = type_size(t);
    if (!in_.read(b, n))
      return false;
    if (enc_ == PlyHeader::BinaryBig)
      std::reverse(b, b + n);
    if (t == PlyType::F32) {
      std::memcpy(&v, b, 4);
    } else if (t == PlyType::F64) {
      double d;
      std::memcpy(&d, b, 8);
      v = static_cast<float>(d);
    } else {
      v = static_cast<float>(decode(t, b));
    }
    return true;
  }

  /// Skips `count` values of type t; false at the end of the file.
  bool skip(PlyType t, uint64_t count) {
    if (enc_ != PlyHeader::Ascii)
      return count <= UINT64_MAX / 8 && in_.skip(count * type_size(t));
    for (uint64_t i = 0; i < count; ++i) {
      if (!in_.token(tok_))
        return false;
      check_ascii_number(t);
    }
    return true;
  }

  /// Whether `count` values of type t can still be in the file (a bound, to refuse absurd
  /// list lengths before allocating: binary values take their size, ASCII ones >= 1 byte).
  bool fits(PlyType t, uint64_t count) const {
    const uint64_t bytes = enc_ == PlyHeader::Ascii ? 1 : type_size(t);
    return count <= in_.remaining() / bytes;
  }

  /// Skips one property (scalar or list); false at the end of the file.
  bool skip(const PlyProperty &p) {
    if (!p.is_list)
      return skip(p.type, 1);
    int64_t n = 0;
    if (!integer(p.count_type, n))
      return false;
    if (n < 0)
      fail(path_, "negative PLY list length");
    return skip(p.type, static_cast<uint64_t>(n));
  }

private:
  /// plylib reads ASCII values with fscanf("%d"/"%f"), which stops inside a malformed
  /// token and then reads the rest as the next value. Requiring every token to be a whole
  /// number of the property's kind keeps vcglib's reading aligned with this walk.
  void check_ascii_number(PlyType t) {
    int64_t i = 0;
    float f = 0;
    const bool ok = t == PlyType::F32 || t == PlyType::F64
                        ? tok_.find('(') == std::string::npos && parse_float(tok_, f)
                        : parse_int(tok_, i);
    if (!ok)
      fail(path_, "bad number '" + tok_ + "' in PLY data");
  }

  /// Little-endian bytes (zero-padded to 4) to an integer of type t.
  static int64_t decode(PlyType t, const unsigned char *b) {
    const uint32_t u = b[0] | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
    switch (t) {
    case PlyType::I8:
      return static_cast<int8_t>(u);
    case PlyType::I16:
      return static_cast<int16_t>(u);
    case PlyType::I32:
      return static_cast<int32_t>(u);
    default:
      return u; // U8, U16, U32
    }
  }

  FileReader &in_;
  PlyHeader::Encoding enc_;
  std::string path_, tok_;
};

/// The per-vertex attributes of a PLY file and which vertex property feeds which of them.
struct PlyVertexPlan {
  struct Slot {
    int attribute = -1; // index into attributes, -1: not kept
    uint32_t component = 0;
  };
  std::vector<Slot> slots; // per property of the vertex element
  std::vector<VertexAttribute> attributes;
};

/// Decides what of the vertex element is kept: colour (8-bit red, green, blue [alpha], or
/// diffuse_*), normal (nx, ny, nz), texture coordinates (texture_u/texture_v, u/v or s/t)
/// and every other scalar property as a scalar of its name (values converted to float).
/// Colours with wider channels are not kept (named in `ignored`).
PlyVertexPlan plan_vertex_attributes(const PlyElement *vertex, std::vector<std::string> &ignored) {
  PlyVertexPlan plan;
  if (!vertex)
    return plan;
  plan.slots.resize(vertex->props.size());
  std::vector<bool> taken(vertex->props.size(), false);
  auto index = [&](const char *name) -> int {
    for (size_t i = 0; i < vertex->props.size(); ++i)
      if (vertex->props[i].name == name && !vertex->props[i].is_list)
        return static_cast<int>(i);
    return -1;
  };
  auto is_float = [&](int i) {
    return vertex->props[i].type == PlyType::F32 || vertex->props[i].type == PlyType::F64;
  };
  auto add = [&](AttributeKind kind, const std::string &name, const std::vector<int> &props) {
    VertexAttribute a;
    a.kind = kind;
    a.name = name;
    a.components = static_cast<uint32_t>(props.size());
    for (size_t k = 0; k < props.size(); ++k) {
      plan.slots[props[k]] = {static_cast<int>(plan.attributes.size()), static_cast<uint32_t>(k)};
      taken[props[k]] = true;
    }
    plan.attributes.push_back(a);
  };
  for (const char *prefix : {"", "diffuse_"}) {
    const std::string p = prefix;
    const int r = index((p + "red").c_str()), g = index((p + "green").c_str()),
              b = index((p + "blue").c_str()), a = index((p + "alpha").c_str());
    if (r < 0 || g < 0 || b < 0 || taken[r] || taken[g] || taken[b])
      continue;
    std::vector<int> props = {r, g, b};
    if (a >= 0)
      props.push_back(a);
    bool bytes = true;
    for (int i : props)
      bytes &= vertex->props[i].type == PlyType::U8;
    if (bytes) {
      add(AttributeKind::Colour, "colour", props);
    } else {
      add_unique(ignored, vertex->props[r].type == PlyType::U16
                              ? "colors (16-bit channels: pomar keeps 8-bit colour)"
                              : "colors (channels not 8-bit: pomar keeps 8-bit colour)");
      for (int i : props)
        taken[i] = true;
    }
  }
  const int nx = index("nx"), ny = index("ny"), nz = index("nz");
  if (nx >= 0 && ny >= 0 && nz >= 0 && is_float(nx) && is_float(ny) && is_float(nz))
    add(AttributeKind::Normal, "normal", {nx, ny, nz});
  for (const auto &uv :
       {std::pair<const char *, const char *>{"texture_u", "texture_v"}, {"u", "v"}, {"s", "t"}}) {
    const int u = index(uv.first), v = index(uv.second);
    if (u >= 0 && v >= 0 && !taken[u] && !taken[v] && is_float(u) && is_float(v)) {
      add(AttributeKind::TexCoord, "texcoord", {u, v});
      break;
    }
  }
  for (size_t i = 0; i < vertex->props.size(); ++i) {
    const PlyProperty &prop = vertex->props[i];
    if (taken[i] || prop.name == "x" || prop.name == "y" || prop.name == "z")
      continue;
    if (prop.name == "flags")
      add_unique(ignored, "flags");
    else if (prop.is_list)
      add_unique(ignored, ("vertex list property '" + prop.name + "'").c_str());
    else if (prop.name.empty() || prop.name.size() > 255)
      add_unique(ignored, "vertex property with an unusable name");
    else
      add(AttributeKind::Scalar, prop.name, {static_cast<int>(i)});
  }
  return plan;
}

/// Positions and triangles a walk can take on the way (PlyWalker's `capture`), so that a
/// file of float x, y, z and triangles needs no second read by vcglib:
/// `ok` turns false as soon as the file is anything else (polygons, triangle strips, no
/// float x, y, z) and the general path reads it.
struct PlyCapture {
  bool ok = true;
  std::vector<float> positions;
  std::vector<uint32_t> triangles;
};

/// The face element's texture data (MeshLab's layout): a float list "texcoord" of u, v per
/// corner and an integer "texnumber", the face's texture. Read by the walk into per-triangle
/// arrays (polygons fan-triangulated as vcglib does: corner 0 with each following edge).
struct PlyFaceData {
  const PlyProperty *texcoord = nullptr, *texnumber = nullptr;
  std::vector<float> corner_texcoords; ///< 6 per triangle
  std::vector<int64_t> numbers;        ///< texnumber, 1 per triangle
  bool bad_texcoord = false;           ///< a list not of two values per corner
};

/// The face element's texcoord and texnumber properties, if it has them in a usable type.
PlyFaceData plan_face_data(const PlyHeader &h) {
  PlyFaceData d;
  for (const PlyElement &e : h.elements)
    if (e.name == "face") {
      const PlyProperty *tc = e.find("texcoord"), *tn = e.find("texnumber");
      if (tc && tc->is_list && (tc->type == PlyType::F32 || tc->type == PlyType::F64))
        d.texcoord = tc;
      if (tn && !tn->is_list)
        d.texnumber = tn;
      break;
    }
  return d;
}

/// Walks the rest of the PLY body, validating the connectivity element (and reading the
/// vertex attributes of `plan` and the face texture data of `faces`, if given).
class PlyWalker {
public:
  PlyWalker(FileReader &in, const PlyHeader &h, const std::string &path,
            PlyVertexPlan *plan = nullptr, PlyCapture *capture = nullptr,
            PlyFaceData *faces = nullptr)
      : in_(in), h_(h), path_(path), values_(in, h.encoding, path), plan_(plan), capture_(capture),
        faces_(faces) {}

  PlyLayout run() {
    choose_elements();
    for (const PlyElement &e : h_.elements) {
      if (&e == conn_)
        walk(e, e.name == "tristrips");
      else if (e.name == "vertex" && plan_)
        vertex_element(e);
      else
        skip_element(e);
      layout_.edges |= e.name == "edge" && e.count > 0;
      layout_.camera |= e.name == "camera" && e.count > 0;
    }
    return layout_;
  }

private:
  /// Finds the vertex element and the list vcglib will take faces from, trying the
  /// property types in the order of ImporterPLY::Open. vcglib reads a "face", "tristrips",
  /// "range_grid" or "edge" element even when it registered none of its properties, into
  /// uninitialized memory; such files are refused.
  void choose_elements() {
    const PlyElement *vertex = single("vertex"), *face = single("face"),
                     *strips = single("tristrips"), *edge = single("edge");
    single("camera");
    if (single("range_grid"))
      fail(path_, "PLY range grids (range_grid element) are not supported");
    layout_.vertices = vertex ? static_cast<size_t>(vertex->count) : 0;
    conn_ = face, conn_prop_ = face ? face_index_list(*face) : nullptr;
    if (!conn_prop_ && strips)
      conn_ = strips, conn_prop_ = strips->find("vertex_indices");
    if (conn_ == strips && !is_list_of(conn_prop_, PlyType::I32, PlyType::I32))
      conn_prop_ = nullptr;
    if (!conn_prop_)
      conn_ = nullptr;
    if (capture_ && (conn_ != face || !conn_ || !vertex))
      capture_->ok = false; // (triangle strips, or nothing to capture)
    for (const PlyElement *e : {face, strips})
      if (e && e->count > 0 && e != conn_)
        fail(path_,
             "PLY " + e->name + " element without a vertex index list of a type vcglib reads");
    // plylib cannot byte-swap doubles (SwapDouble() is an assert(0)); these it would store.
    for (const char *name : {"x", "y", "z", "nx", "ny", "nz"})
      if (h_.encoding == PlyHeader::BinaryBig && vertex &&
          is_scalar_of(vertex->find(name), PlyType::F64))
        fail(path_, "big-endian PLY with double vertex data, which vcglib cannot read");
    // plylib reads binary index lists with a one-byte count unless the items are int.
    if (conn_prop_ && h_.encoding != PlyHeader::Ascii && conn_prop_->type != PlyType::I32 &&
        type_size(conn_prop_->count_type) != 1)
      fail(path_, "PLY " + conn_->name +
                      " list with a count wider than a byte and non-int indices, "
                      "which vcglib misreads in binary files");
    if (conn_ && conn_->count > 0 && (!vertex || conn_ < vertex))
      fail(path_, "PLY " + conn_->name + " element comes before the vertex element");
    if (edge && edge->count > 0 &&
        !(is_scalar_of(edge->find("vertex1"), PlyType::I32) &&
          is_scalar_of(edge->find("vertex2"), PlyType::I32)))
      fail(path_, "PLY edge element without int vertex1/vertex2 properties");
  }

  /// The element with that name, or null; refuses a second one (vcglib reads it without
  /// its properties registered).
  const PlyElement *single(const char *name) {
    const PlyElement *found = nullptr;
    for (const PlyElement &e : h_.elements)
      if (e.name == name) {
        if (found)
          fail(path_, std::string("PLY file has two '") + name + "' elements");
        found = &e;
      }
    return found;
  }

  /// The face's index list if its types are among those vcglib reads (FaceDesc 0, 13-24).
  static const PlyProperty *face_index_list(const PlyElement &face) {
    using T = PlyType;
    static const struct {
      const char *name;
      T item, count;
    } kinds[] = {{"vertex_indices", T::I32, T::U8},  {"vertex_index", T::I32, T::U8},
                 {"vertex_index", T::I32, T::I8},    {"vertex_index", T::I32, T::I32},
                 {"vertex_indices", T::I32, T::I8},  {"vertex_indices", T::I32, T::I32},
                 {"vertex_indices", T::U32, T::U8},  {"vertex_indices", T::U32, T::I8},
                 {"vertex_indices", T::U32, T::I32}, {"vertex_indices", T::U32, T::U16},
                 {"vertex_indices", T::I16, T::I8},  {"vertex_indices", T::I16, T::U8},
                 {"vertex_indices", T::I16, T::I32}};
    for (const auto &k : kinds)
      if (is_list_of(face.find(k.name), k.item, k.count))
        return face.find(k.name);
    return nullptr;
  }

  [[noreturn]] void truncated(const PlyElement &e, uint64_t item) {
    fail(path_, "truncated PLY file (" + e.name + " " + num(item) + " of " + num(e.count) + ")");
  }

  /// Skips an element; fixed-size binary elements in one seek.
  void skip_element(const PlyElement &e) {
    bool fixed = h_.encoding != PlyHeader::Ascii;
    uint64_t stride = 0;
    for (const auto &p : e.props)
      fixed &= !p.is_list, stride += type_size(p.type);
    if (fixed) {
      if (stride > 0 && (e.count > UINT64_MAX / stride || !in_.skip(e.count * stride)))
        truncated(e, 0);
      return;
    }
    for (uint64_t i = 0; i < e.count; ++i)
      for (const auto &p : e.props)
        if (!skip_unstored(p))
          truncated(e, i);
  }

  /// Skips a property vcglib does not store (for our mesh type: every list except the
  /// face/strip indices). plylib skips a binary list by reading a one-byte count, whatever
  /// the declared count type, into a 512-byte stack buffer, and takes an empty list for the
  /// end of the file (fread of 0 items); refuse lists it would misread. With `values`, the
  /// list's items are read into it instead of skipped (the same checks).
  bool skip_unstored(const PlyProperty &p, std::vector<float> *values = nullptr) {
    if (values) {
      values->clear();
      int64_t n = 0;
      if (h_.encoding != PlyHeader::Ascii && type_size(p.count_type) != 1)
        fail(path_, "PLY list '" + p.name +
                        "' has a count wider than a byte, which vcglib misreads in binary files");
      if (!values_.integer(p.count_type, n))
        return false;
      if (n < 0 ||
          (h_.encoding != PlyHeader::Ascii && static_cast<uint64_t>(n) * type_size(p.type) > 512))
        fail(path_,
             "PLY list '" + p.name + "' of " + std::to_string(n) + " items is too long for vcglib");
      if (n == 0 && h_.encoding != PlyHeader::Ascii)
        fail(path_, "PLY list '" + p.name + "' is empty, which vcglib cannot skip in binary files");
      if (!values_.fits(p.type, static_cast<uint64_t>(n)))
        return false;
      values->resize(static_cast<size_t>(n));
      for (float &x : *values)
        if (!values_.real(p.type, x))
          return false;
      return true;
    }
    if (!p.is_list || h_.encoding == PlyHeader::Ascii)
      return values_.skip(p);
    if (type_size(p.count_type) != 1)
      fail(path_, "PLY list '" + p.name +
                      "' has a count wider than a byte, which vcglib misreads in binary files");
    int64_t n = 0;
    if (!values_.integer(p.count_type, n))
      return false;
    if (n < 0 || static_cast<uint64_t>(n) * type_size(p.type) > 512)
      fail(path_,
           "PLY list '" + p.name + "' of " + std::to_string(n) + " items is too long for vcglib");
    if (n == 0)
      fail(path_, "PLY list '" + p.name + "' is empty, which vcglib cannot skip in binary files");
    return values_.skip(p.type, static_cast<uint64_t>(n));
  }

  /// The vertex element: read when it has attributes or its positions are captured,
  /// else skipped.
  void vertex_element(const PlyElement &e) {
    const bool capturing = capture_vertices(e);
    if (capturing || !plan_->attributes.empty()) {
      // Room for the values the file can hold (binary: the element's stride per vertex,
      // ASCII: two bytes or more per value): appending would otherwise copy each array
      // several times as it grows.
      uint64_t bytes = 0;
      for (const PlyProperty &p : e.props)
        bytes += p.is_list ? 1 : h_.encoding == PlyHeader::Ascii ? 2 : type_size(p.type);
      const size_t vertices =
          size_t(std::min<uint64_t>(e.count, in_.remaining() / std::max<uint64_t>(bytes, 1)));
      for (VertexAttribute &a : plan_->attributes)
        if (a.kind == AttributeKind::Colour)
          a.colour.reserve(a.components * vertices);
        else
          a.values.reserve(a.components * vertices);
      read_vertices(e, capturing);
    } else {
      skip_element(e);
    }
  }

  /// Whether the positions of vertex element `e` are captured: float x, y, z, scalar
  /// properties only and, in a binary file, the whole element there (else the capture
  /// stops, and the element is read or skipped as without it). Fills axis_: per property,
  /// the coordinate it holds (0, 1, 2) or -1.
  bool capture_vertices(const PlyElement &e) {
    if (!capture_ || !capture_->ok)
      return false;
    uint64_t stride = 0;
    for (const PlyProperty &p : e.props)
      capture_->ok &= !p.is_list, stride += type_size(p.type);
    // (Binary: the whole element in the file, else the skip reports the truncation as
    // before. ASCII elements are read item by item either way.)
    capture_->ok &=
        stride > 0 && (h_.encoding == PlyHeader::Ascii || e.count <= in_.remaining() / stride);
    axis_.assign(e.props.size(), -1);
    for (int k = 0; k < 3 && capture_->ok; ++k) {
      const PlyProperty *p = e.find(std::string(1, char('x' + k)).c_str());
      capture_->ok = is_scalar_of(p, PlyType::F32);
      if (capture_->ok)
        axis_[size_t(p - e.props.data())] = static_cast<int8_t>(k);
    }
    if (capture_->ok)
      capture_->positions.reserve(3 * size_t(std::min<uint64_t>(e.count, in_.remaining() / 12)));
    return capture_->ok;
  }

  /// Reads the vertex element's attribute values (the plan's) and, with `capturing`, its
  /// float x, y, z (axis_); skips the rest.
  void read_vertices(const PlyElement &e, bool capturing) {
    for (VertexAttribute &a : plan_->attributes) {
      const size_t n = size_t(std::min<uint64_t>(e.count, in_.remaining())) * a.components;
      if (a.kind == AttributeKind::Colour)
        a.colour.reserve(n);
      else
        a.values.reserve(n);
    }
    float position[3] = {0, 0, 0};
    for (uint64_t i = 0; i < e.count; ++i) {
      for (size_t j = 0; j < e.props.size(); ++j) {
        const PlyVertexPlan::Slot &slot = plan_->slots[j];
        if (capturing && axis_[j] >= 0) {
          if (!values_.real(PlyType::F32, position[axis_[j]]))
            truncated(e, i);
          continue;
        }
        if (slot.attribute < 0) {
          if (!skip_unstored(e.props[j]))
            truncated(e, i);
          continue;
        }
        float x = 0;
        if (!values_.real(e.props[j].type, x))
          truncated(e, i);
        VertexAttribute &a = plan_->attributes[size_t(slot.attribute)];
        if (a.kind == AttributeKind::Colour)
          a.colour.push_back(static_cast<uint8_t>(x));
        else
          a.values.push_back(x);
      }
      if (capturing)
        capture_->positions.insert(capture_->positions.end(), position, position + 3);
    }
  }

  /// Reads every item of the connectivity element and checks its index list.
  void walk(const PlyElement &e, bool strips) {
    if (capture_ && capture_->ok && conn_prop_ && !strips) {     // room for the file's triangles
      const uint64_t bytes = h_.encoding == PlyHeader::Ascii ? 8 // "3 a b c" and a line end
                                                             : type_size(conn_prop_->count_type) +
                                                                   3 * type_size(conn_prop_->type);
      capture_->triangles.reserve(3 * size_t(std::min<uint64_t>(e.count, in_.remaining() / bytes)));
    }
    const bool texture = faces_ && !strips;
    for (uint64_t i = 0; i < e.count; ++i) {
      bool have_uv = false, have_number = false;
      float number = 0;
      for (const auto &p : e.props) {
        if (texture && &p == faces_->texcoord) {
          if (!skip_unstored(p, &uv_))
            truncated(e, i);
          have_uv = true;
          continue;
        }
        if (texture && &p == faces_->texnumber) {
          if (!values_.real(p.type, number))
            truncated(e, i);
          have_number = true;
          continue;
        }
        if (&p != conn_prop_) {
          if (!skip_unstored(p))
            truncated(e, i);
          continue;
        }
        int64_t n = 0;
        if (!values_.integer(p.count_type, n))
          truncated(e, i);
        check_length(n, strips, i);
        if (!values_.fits(p.type, static_cast<uint64_t>(n))) // before allocating the list
          truncated(e, i);
        list_.resize(static_cast<size_t>(n));
        for (auto &v : list_)
          if (!values_.integer(p.type, v))
            truncated(e, i);
        if (strips)
          strip(i);
        else
          face(i);
      }
      if (texture && conn_prop_)
        face_texture(have_uv, have_number, number);
    }
  }

  /// The texture data of the face just read (list_), per triangle of its fan.
  void face_texture(bool have_uv, bool have_number, float number) {
    const size_t n = list_.size();
    if (have_uv && !faces_->bad_texcoord) {
      if (uv_.size() != 2 * n) {
        faces_->bad_texcoord = true;
        faces_->corner_texcoords = std::vector<float>();
      } else {
        for (size_t c = 1; c + 1 < n; ++c)
          for (const size_t k : {size_t(0), c, c + 1})
            faces_->corner_texcoords.insert(faces_->corner_texcoords.end(),
                                            {uv_[2 * k], uv_[2 * k + 1]});
      }
    }
    if (have_number)
      faces_->numbers.insert(
          faces_->numbers.end(), n - 2,
          std::isfinite(number) && std::fabs(number) < 2e9f ? static_cast<int64_t>(number) : -1);
  }

  /// Faces need 3..255 corners (vcglib keeps the count in a byte, the corners in int[512]).
  void check_length(int64_t n, bool strips, uint64_t item) {
    if (strips && (n < 0 || n > INT_MAX))
      fail(path_, "PLY tristrip " + num(item) + " has invalid length " + std::to_string(n));
    if (!strips && (n < 3 || n > 255))
      fail(path_, "PLY face " + num(item) + " has " + std::to_string(n) +
                      " vertices (3 to 255 supported)");
  }

  /// A polygon: all corners must be vertices.
  void face(uint64_t item) {
    for (int64_t v : list_)
      check_index(v, "face", item);
    if (capture_ && capture_->ok) {
      if (list_.size() == 3) // (polygons: vcglib's triangulation, the general path)
        capture_->triangles.insert(capture_->triangles.end(),
                                   {uint32_t(list_[0]), uint32_t(list_[1]), uint32_t(list_[2])});
      else
        capture_->ok = false;
    }
    ++layout_.faces;
    layout_.triangles += list_.size() - 2;
    layout_.polygons += list_.size() > 3;
  }

  /// A triangle strip, -1 restarting it; replays vcglib's loop to count its triangles.
  void strip(uint64_t item) {
    const size_t n = list_.size();
    for (size_t k = 0; k + 2 < n; ++k) {
      check_index(list_[k], "tristrip", item);
      if (list_[k + 2] == -1) {
        k += 2;
        continue;
      }
      check_index(list_[k + 1], "tristrip", item);
      check_index(list_[k + 2], "tristrip", item);
      ++layout_.triangles;
      ++layout_.faces;
    }
  }

  void check_index(int64_t v, const char *what, uint64_t item) {
    if (v < 0 || static_cast<uint64_t>(v) >= layout_.vertices)
      fail(path_, std::string("PLY ") + what + " " + num(item) + " references vertex " +
                      std::to_string(v) + " but there are " + num(layout_.vertices) + " vertices");
  }

  FileReader &in_;
  const PlyHeader &h_;
  std::string path_;
  PlyValues values_;
  const PlyElement *conn_ = nullptr;
  const PlyProperty *conn_prop_ = nullptr;
  std::vector<int64_t> list_;
  PlyLayout layout_;
  PlyVertexPlan *plan_ = nullptr;
  PlyCapture *capture_ = nullptr;
  PlyFaceData *faces_ = nullptr;
  std::vector<float> uv_;    // the current face's texcoord list
  std::vector<int8_t> axis_; // per vertex property: the captured coordinate, or -1
};

// ======================================================================================
// PLY: loading
// ======================================================================================

using PlyImporter = vcg::tri::io::ImporterPLY<IoMesh>;

/// The count of the first element with that name (0 if none).
uint64_t element_count(const PlyHeader &h, const char *name) {
  for (const PlyElement &e : h.elements)
    if (e.name == name)
      return e.count;
  return 0;
}

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

/// The common shape read straight into the flat arrays: a vertex element of exactly float
/// x, y, z, then a face element of exactly one uchar-counted int or uint "vertex_indices"
/// list.
bool simple_shape(const PlyHeader &h) {
  if (h.elements.size() != 2)
    return false;
  const PlyElement &ve = h.elements[0], &fe = h.elements[1];
  if (ve.name != "vertex" || ve.props.size() != 3 || fe.name != "face" || fe.props.size() != 1)
    return false;
  for (int k = 0; k < 3; ++k)
    if (ve.props[size_t(k)].is_list || ve.props[size_t(k)].type != PlyType::F32 ||
        ve.props[size_t(k)].name != std::string(1, char('x' + k)))
      return false;
  const PlyProperty &list = fe.props[0];
  return list.name == "vertex_indices" && is_list_of(&list, list.type, PlyType::U8) &&
         (list.type == PlyType::I32 || list.type == PlyType::U32);
}

/// Binary little-endian data of the simple shape (all triangles, finite coordinates):
/// positions in one read, faces in chunks; `used` marks the vertices the faces use.
bool read_simple_binary(FileReader &in, uint64_t nv, uint64_t nf, Mesh &out,
                        std::vector<uint8_t> &used) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  if (in.remaining() / 13 < nf || in.remaining() - 13 * nf < 12 * nv)
    return false;
  resize_prefaulted(out.positions, 3 * nv); // (written whole: memory/prefault.h)
  if (!in.read(out.positions.data(), 12 * nv))
    return false;
  for (uint64_t i = 0; i < 3 * nv; ++i)
    if (!std::isfinite(out.positions[i]))
      return false;
  resize_prefaulted(out.triangles, 3 * nf);
  constexpr uint64_t kChunk = 65536;
  std::vector<unsigned char> buf(13 * kChunk);
  for (uint64_t f0 = 0; f0 < nf; f0 += kChunk) {
    const uint64_t n = std::min(kChunk, nf - f0);
    if (!in.read(buf.data(), 13 * n))
      return false;
    for (uint64_t f = 0; f < n; ++f) {
      const unsigned char *p = &buf[13 * f];
      if (p[0] != 3)
        return false;
      uint32_t *t = &out.triangles[3 * (f0 + f)];
      std::memcpy(t, p + 1, 12);
      for (int k = 0; k < 3; ++k) { // (int indices: negative ones are >= nv as uint32)
        if (t[k] >= nv)
          return false;
        used[t[k]] = 1;
      }
    }
  }
  return true;
#else
  (void)in, (void)nv, (void)nf, (void)out, (void)used;
  return false;
#endif
}

/// The whitespace-separated tokens of the rest of a file (whitespace as fscanf has it),
/// read in chunks of 1 MiB.
class AsciiTokens {
public:
  explicit AsciiTokens(FileReader &in) : in_(in), buf_(kChunk + kMaxToken) {}

  /// The next token in [b, e); false at the end of the file or on a token too long for a
  /// number.
  bool next(const char *&b, const char *&e) {
    for (;;) { // skip whitespace
      while (pos_ < end_ && space(buf_[pos_]))
        ++pos_;
      if (pos_ < end_)
        break;
      if (!refill())
        return false;
    }
    size_t i = pos_;
    for (;;) {
      while (i < end_ && !space(buf_[i]))
        ++i;
      if (i < end_ || in_.remaining() == 0)
        break;
      if (i - pos_ >= kMaxToken) // a token this long is not a number of ours
        return false;
      const size_t scanned = i - pos_;
      if (!refill())
        return false;
      i = pos_ + scanned;
    }
    if (i - pos_ >= kMaxToken)
      return false;
    b = &buf_[pos_];
    e = &buf_[i];
    pos_ = i;
    return true;
  }

private:
  static constexpr size_t kChunk = size_t(1) << 20, kMaxToken = 64;
  static bool space(char c) {
    return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\v' || c == '\f';
  }
  /// Keeps the unread bytes (at most a token), appends the next chunk; false if none.
  bool refill() {
    const size_t n = std::min<uint64_t>(kChunk, in_.remaining());
    if (n == 0 || end_ - pos_ > kMaxToken)
      return false;
    std::memmove(buf_.data(), buf_.data() + pos_, end_ - pos_);
    end_ -= pos_;
    pos_ = 0;
    if (!in_.read(buf_.data() + end_, n))
      return false;
    end_ += n;
    return true;
  }

  FileReader &in_;
  std::vector<char> buf_;
  size_t pos_ = 0, end_ = 0;
};

/// ASCII data of the simple shape, as vcglib reads it: plain decimal coordinates (finite),
/// faces "3 a b c" with indices in range, nothing after the last face.
bool read_simple_ascii(FileReader &in, uint64_t nv, uint64_t nf, Mesh &out,
                       std::vector<uint8_t> &used) {
  if (nv > in.remaining() / 6 || nf > (in.remaining() + 1 - 6 * nv) / 8)
    return false; // an ASCII vertex takes 6 bytes or more, a face 8
  AsciiTokens tokens(in);
  const char *b = nullptr, *e = nullptr;
  resize_prefaulted(out.positions, 3 * nv); // (written whole: memory/prefault.h)
  for (float &x : out.positions) {
    if (!tokens.next(b, e) || !plain_decimal(b, e))
      return false;
    const auto r = std::from_chars(b, e, x);
    if (r.ec != std::errc() || r.ptr != e || !std::isfinite(x))
      return false;
  }
  resize_prefaulted(out.triangles, 3 * nf);
  for (uint64_t f = 0; f < nf; ++f) {
    if (!tokens.next(b, e) || e - b != 1 || *b != '3')
      return false;
    for (int k = 0; k < 3; ++k) {
      uint64_t v = 0;
      if (!tokens.next(b, e) || !parse_digits(b, e, nv - 1, v))
        return false;
      out.triangles[3 * f + k] = static_cast<uint32_t>(v);
      used[v] = 1;
    }
  }
  return !tokens.next(b, e);
}

/// The common case read straight into the flat arrays: the simple shape, binary little-
/// endian or ASCII, all triangles with valid indices, finite coordinates. Returns false
/// for anything else (attributes, polygons, damage, ...) having changed only `in`'s
/// position: the general path then reads the file (and names what is wrong).
bool read_simple_ply(FileReader &in, const PlyHeader &h, Mesh &out, size_t &unreferenced) {
  if (!simple_shape(h))
    return false;
  const uint64_t nv = h.elements[0].count, nf = h.elements[1].count;
  if (nv == 0 || nf == 0 || nv >= UINT32_MAX || nf > UINT32_MAX / 3)
    return false;
  std::vector<uint8_t> used = filled_vector<uint8_t>(nv);
  Mesh mesh;
  if (h.encoding == PlyHeader::BinaryLittle) {
    if (!read_simple_binary(in, nv, nf, mesh, used))
      return false;
  } else if (h.encoding == PlyHeader::Ascii) {
    if (!read_simple_ascii(in, nv, nf, mesh, used))
      return false;
  } else {
    return false;
  }
  // As from_vcg(..., keep_unreferenced): vertices no face uses are counted and kept (the
  // codec stores them).
  unreferenced = static_cast<size_t>(std::count(used.begin(), used.end(), uint8_t(0)));
  out = std::move(mesh);
  return true;
}

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
      layout = PlyWalker(in, header, path, &plan, &capture, &face_data).run();
    } else { // the general path reads the data from its start
      FileReader again(path);
      read_ply_header(again, path);
      layout = PlyWalker(again, header, path, &plan, &capture, &face_data).run();
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
/// made once per run (a byte at a time through std::string::operator+= was 10x slower).
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

void save_ply_binary(const std::string &path, const Mesh &mesh) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  // The bytes vcglib's exporter writes for our mesh type (same header, float xyz, a uchar
  // count and three ints per face), written from the flat arrays in large chunks instead
  // of through a vcglib copy and one fwrite per value.
  const uint64_t nv = mesh.vertex_count(), nf = mesh.triangle_count();
  const std::string header = "ply\nformat binary_little_endian 1.0\ncomment VCGLIB generated\n"
                             "element vertex " +
                             num(nv) +
                             "\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face " +
                             num(nf) + "\nproperty list uchar int vertex_indices\nend_header\n";
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
