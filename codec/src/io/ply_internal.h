// Internal to pomar_io's PLY code: the header's model (elements, properties, types) and
// what the files of the PLY reader share. ply_header.cpp parses the header; ply_walker.cpp
// walks the body (checks it for vcglib, reads the vertex attributes and face texture data,
// captures positions and triangles); ply_plan.cpp decides what of the vertex and face
// elements is kept; ply_simple_read.cpp reads the common float xyz + triangles shape
// straight into the flat arrays; ply_reader.cpp puts these together with vcglib's
// importer (load_ply); ply_writer.cpp writes PLY files.
#pragma once

#include "io/io_common.h"

#include <cstdint>
#include <string>
#include <vector>

namespace pomar::io {

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
inline bool is_list_of(const PlyProperty *p, PlyType item, PlyType count) {
  return p && p->is_list && p->type == item && p->count_type == count;
}
inline bool is_scalar_of(const PlyProperty *p, PlyType type) {
  return p && !p->is_list && p->type == type;
}

struct PlyHeader {
  enum Encoding { Ascii, BinaryLittle, BinaryBig } encoding = Ascii;
  std::vector<PlyElement> elements;
  std::vector<std::string> texture_files; ///< "comment TextureFile <name>" lines
};

/// The size in bytes of one value of type t.
size_t type_size(PlyType t);

/// Parses the header, leaving `in` at the first data byte.
PlyHeader read_ply_header(FileReader &in, const std::string &path);

/// The count of the first element with that name (0 if none).
uint64_t element_count(const PlyHeader &h, const char *name);

/// What the walk found; the triangle count is what vcglib's importer will build.
struct PlyLayout {
  size_t vertices = 0;
  size_t faces = 0; // polygons of the face element, or triangles of the strips
  size_t triangles = 0;
  size_t polygons = 0; // faces with more than 3 corners
  bool edges = false, camera = false;
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
PlyVertexPlan plan_vertex_attributes(const PlyElement *vertex, std::vector<std::string> &ignored);

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
PlyFaceData plan_face_data(const PlyHeader &h);

/// Walks the rest of the PLY body from `in`, validating the connectivity element (and
/// reading the vertex attributes of `plan`, capturing positions and triangles in `capture`
/// and reading the face texture data of `faces`, if given).
PlyLayout walk_ply(FileReader &in, const PlyHeader &h, const std::string &path,
                   PlyVertexPlan *plan = nullptr, PlyCapture *capture = nullptr,
                   PlyFaceData *faces = nullptr);

/// The common case read straight into the flat arrays: a vertex element of exactly float
/// x, y, z and a face element of one uchar-counted int or uint "vertex_indices" list,
/// binary little-endian or ASCII, all triangles with valid indices, finite coordinates.
/// Returns false for anything else (attributes, polygons, damage, ...) having changed only
/// `in`'s position: the general path then reads the file (and names what is wrong).
bool read_simple_ply(FileReader &in, const PlyHeader &h, Mesh &out, size_t &unreferenced);

} // namespace pomar::io
