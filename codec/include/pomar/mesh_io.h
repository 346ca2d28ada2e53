// Reading and writing triangle meshes as PLY, OBJ, OFF and STL files.
//
// The format is chosen by the file extension (case-insensitive): .ply, .obj, .off, .stl.
// Positions, triangles and per-vertex attributes (Mesh::attributes) are kept: PLY vertex
// colour (8-bit), normals, texture coordinates, every other scalar property by its name and
// "comment TextureFile" names; OBJ vertex colours (rounded to 8 bits) and the normals that
// are per vertex; OFF vertex colours and normals.
// Textured meshes are kept too (Mesh::corner_texcoords, face_materials, materials):
//  - OBJ: texture coordinates are a per-vertex attribute when every corner has one and no
//    vertex has two different ones, else per corner (`f v/vt`, polygons fan-triangulated);
//    when some corner has none they are dropped. The materials are the `newmtl` blocks of the
//    libraries (`mtllib`, beside the file) in the order read: name, `map_Kd` as the texture
//    (an index into texture_files, each file once) and every other line as written in
//    `properties`; then the `usemtl` names no library defines (no texture, no properties).
//    face_materials (when the file has a `usemtl`) gives each face the material in force;
//    faces before the first `usemtl` get a material with an empty name.
//  - PLY: a face list `texcoord` (u, v per corner) gives corner_texcoords, a face
//    `texnumber` face_materials, with one material "texture_<i>" per TextureFile comment
//    (texture i) and, for a number naming no file, one with an empty name and no texture.
// Everything else a file may carry (other face data, per-corner normals, ...) is dropped and
// named in LoadReport::ignored_attributes. save_mesh writes what each format holds of the
// attributes (attributes_not_saved names the rest).
// PLY, OFF and ASCII STL are read through vcglib's importers (so a file loads as it does
// in MeshLab), binary STL directly, OBJ through tinyobjloader. Every failure throws
// pomar::Error with a one-line message that starts with the file's path.
//
// Numbers are printed and parsed in the "C" convention (decimal point). Writing is
// locale-independent; the vcglib readers use the C library and therefore expect the
// process's LC_NUMERIC to be "C" (the default unless the program calls setlocale).
#pragma once

#include <pomar/pomar.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace pomar {

/// What load_mesh found in a file besides the mesh it returns.
struct LoadReport {
  std::string format; ///< "ply", "obj", "off" or "stl"
  /// Whether the file is text (ASCII PLY or STL; OBJ and OFF always): set before the size
  /// check is called, for a per-format memory estimate (pomar::encode_input).
  bool text = false;
  /// OBJ, set before the size check like `text`: the file has only "v x y z" and plain-index
  /// "f" lines (and comments, "o", "g", "s") and pomar's own reader reads it; false:
  /// tinyobjloader reads it (normals, texture coordinates, colours, materials, slashed or
  /// relative indices, ...), whose arrays need more memory.
  bool plain_obj = false;
  /// OBJ read by tinyobjloader, set before the size check: the file has normals, texture
  /// coordinates or vertex colours, whose lines and per-corner indices it holds too.
  bool obj_attributes = false;
  /// OBJ read by tinyobjloader, set before the size check: its 'vn' and 'vt' lines (one
  /// normal and one texture coordinate per corner: 3 of each per face).
  size_t obj_value_lines = 0;
  size_t file_vertices = 0;         ///< vertices stored in the file (STL: 3 per facet)
  size_t file_faces = 0;            ///< faces/polygons in the file (PLY tristrips: triangles)
  size_t unreferenced_vertices = 0; ///< vertices no face uses (kept: pomar::encode stores them)
  size_t welded_vertices = 0;       ///< STL only: corners merged with an identical position
  size_t polygons_triangulated = 0; ///< faces with more than 3 vertices, split into triangles
  /// Data present in the file that is not kept, e.g. "normals", "colors",
  /// "texture coordinates", "quality", "materials", "flags", "radius", "edges", "camera".
  std::vector<std::string> ignored_attributes;
};

/// Called by load_mesh as soon as the file tells how large the mesh is, before the large
/// allocations: PLY and OFF header counts (PLY again after its structure walk if polygons
/// or strips make more triangles), binary STL facet count, OBJ 'v' lines and triangles
/// (after a line scan, before tinyobjloader; a plain OBJ once pomar's reader has read it,
/// its flat arrays being smaller than the text already held), ASCII STL facets (counted in
/// the text before it is parsed). STL passes half a vertex per facet (what a closed mesh
/// keeps once identical corners are welded). LoadReport::format, text, plain_obj,
/// obj_attributes and obj_value_lines are set when it is called, so that the check can
/// allow for the reader that takes the file. It may throw pomar::Error to refuse the file
/// (load_mesh prefixes the path), e.g. for a memory limit:
///   [&](uint64_t v, uint64_t f) {
///     pomar::check_encode_memory(v, f, limit, 0, 0, 1, pomar::encode_input(report),
///                                pomar::encode_input_extra(report, v));
///   }
using SizeCheck = std::function<void(uint64_t vertices, uint64_t faces)>;

/// Read a triangle mesh. Polygons are split into triangles (PLY/OBJ: fan from the first
/// vertex; OFF: vcglib's rule, which picks the better diagonal of a quad), STL corners with
/// exactly equal positions are welded, vertices no face uses are kept. Vertex and face
/// order of the file is kept. `*report` is reset first. Throws pomar::Error if
/// the file is missing, unreadable, malformed, has a NaN/Inf coordinate or contains no
/// triangles, and for files vcglib would misread (see codec/src/io/io_common.h), and when
/// `size_check` throws.
Mesh load_mesh(const std::string &path, LoadReport *report = nullptr,
               const SizeCheck &size_check = {});

/// Write a triangle mesh, replacing `path` atomically (see write_file_atomic). `binary`
/// selects binary little-endian PLY / binary STL (default) or ASCII PLY / ASCII STL; OBJ and
/// OFF are always text. Coordinates are written so that load_mesh reads back bit-identical
/// floats and the same triangles; STL has no shared vertices, so a mesh read back from
/// STL has its vertices in order of first use and loses unreferenced ones. Throws
/// pomar::Error on an unknown extension, an invalid mesh (index out of range, NaN/Inf
/// coordinate) or an I/O failure; the destination is then left untouched.
///
/// Attributes: PLY holds them all (vertex properties, "comment TextureFile", face
/// "texcoord" and "texnumber" as MeshLab writes them; of the materials only each face's
/// texture); OBJ vertex colour (RGB), normals and texture coordinates ("vt": per corner,
/// each distinct pair once, or per vertex) and, when the mesh has materials or names texture
/// files, a material library beside the file ("<name>.mtl", replaced atomically like the
/// file: each material's "newmtl", properties and "map_Kd", or without materials one
/// material with map_Kd per texture file; the images are not copied), the faces in runs of
/// one material after "usemtl" lines; OFF vertex colour (RGB or RGBA) and normals; STL none.
/// Per-corner texture coordinates must be finite, 6 per triangle; face materials one per
/// triangle, each a material; a material's texture -1 or a texture file; material names
/// without white space.
void save_mesh(const std::string &path, const Mesh &mesh, bool binary = true);

/// decode_to_ply_bounded's settings.
struct BoundedDecodeOptions {
  /// The bytes the decode may use at its peak (0: what is available, pomar/limits.h).
  uint64_t memory_limit = 0;
  unsigned threads = 0;                  ///< as SelectiveOptions::threads
  uint32_t min_parallel_vertices = 4096; ///< as SelectiveOptions::min_parallel_vertices
  Progress progress;                     ///< stages "count" and "write", per region
};

struct BoundedDecodeReport {
  uint64_t vertices = 0, faces = 0;
  uint32_t regions = 0;        ///< regions decoded (each twice: counted, then written)
  uint64_t largest_region = 0; ///< estimated peak of the largest region, tables included
};

/// A full decode of the .pomar file `in` written to the binary PLY `out` without holding
/// the whole mesh: the clusters are decoded in regions (runs of the Morton order of their
/// roots) whose level maps fit `memory_limit`, each region twice (once to count what each
/// cluster adds in each level, once to write its vertices and faces at the numbers a full
/// decode gives them). The file is byte for byte save_mesh(out, decode(in)). Random-access
/// files without attributes or a lossless record only (pomar::Error Kind::Unsupported
/// otherwise, saying why); Kind::MemoryLimit when one cluster with its neighbours at full
/// resolution does not fit (naming the memory it needs); Kind::Io when the disk cannot hold
/// the output (checked first). Written atomically like save_mesh.
BoundedDecodeReport decode_to_ply_bounded(const std::string &in, const std::string &out,
                                          const BoundedDecodeOptions &options = {});

/// What save_mesh(path, mesh) cannot write of the mesh's attributes in `path`'s format, one
/// entry per kind ("scalars 'quality', 'confidence'", "texture coordinates", "alpha of the
/// colours", ...); empty when it writes them all. For a warning naming what is not written.
std::vector<std::string> attributes_not_saved(const std::string &path, const Mesh &mesh);

/// Write `size` bytes to `path` atomically: they go to a temporary file in the same
/// directory (".<name>.tmp.<pid>.<n>"), which is fsync'ed and renamed over `path`. On
/// failure the temporary file is removed and pomar::Error is thrown naming the path and
/// the system error.
void write_file_atomic(const std::string &path, const void *data, size_t size);

/// Install handlers for SIGINT, SIGTERM and SIGHUP that remove the temporary files of
/// writes in progress (write_file_atomic, save_mesh) and then let the signal end the
/// process as it would have: an interrupted program leaves the previous output untouched
/// and no temporary file behind. For programs, like the pomar tool, that own their
/// signal handling; a library user with its own handlers can leave this alone.
void remove_temporary_files_on_signals();

/// Read a whole file. Throws pomar::Error naming the path and the system error text.
std::vector<uint8_t> read_file(const std::string &path);

} // namespace pomar
