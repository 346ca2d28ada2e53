// The walk over a PLY body before vcglib's importer sees the file (see io_common.h for
// why): every element read or skipped value by value, the connectivity element checked as
// vcglib will take it; on the way the vertex attributes, face texture data and (for float
// x, y, z and triangles) the positions and triangles are read.
#include "io/ply_internal.h"

#include <algorithm>
#include <climits>
#include <cstring>

namespace pomar::io {
namespace {

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

} // namespace

PlyLayout walk_ply(FileReader &in, const PlyHeader &h, const std::string &path, PlyVertexPlan *plan,
                   PlyCapture *capture, PlyFaceData *faces) {
  return PlyWalker(in, h, path, plan, capture, faces).run();
}

} // namespace pomar::io
