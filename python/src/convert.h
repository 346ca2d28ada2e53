// Conversions between Python objects and the library's types, shared by the module's
// functions (module.cpp) and the SelectiveDecoder binding (selective.cpp).
#pragma once

#include <pomar/pomar.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h> // in every file of the module (one set of type casters)

#include <cstdint>
#include <string>
#include <vector>

namespace pomar_python {

namespace py = pybind11;

/// The vertices (float32, shape (n, 3)) and faces (uint32, shape (m, 3)) as a pomar::Mesh:
/// one copy each. Throws TypeError (wrong dtype) or ValueError (shape, not C-contiguous)
/// naming the argument and how to convert it.
pomar::Mesh mesh_from_arrays(const py::handle &vertices, const py::handle &faces);

/// A numpy array that owns `values` (moved, no copy): rows of `columns` values, or one
/// dimension if `columns` is 0.
template <class T> py::array_t<T> array_from_vector(std::vector<T> &&values, size_t columns) {
  auto *owned = new std::vector<T>(std::move(values));
  py::capsule owner(owned, [](void *p) { delete static_cast<std::vector<T> *>(p); });
  if (columns == 0)
    return py::array_t<T>({owned->size()}, {sizeof(T)}, owned->data(), owner);
  const size_t rows = owned->size() / columns;
  return py::array_t<T>({rows, columns}, {columns * sizeof(T), sizeof(T)}, owned->data(), owner);
}

/// The per-vertex attributes given to encode()/write() (each None when absent) added to
/// `mesh` (whose positions are set): colors uint8 (n, 3) or (n, 4), normals float32 (n, 3),
/// scalars a dict name -> float32 (n,), texcoords float32 (n, 2), texture_files a sequence
/// of str. TypeError/ValueError (naming the argument) for a wrong type, dtype or shape.
void add_attributes(pomar::Mesh &mesh, const py::handle &colors, const py::handle &normals,
                    const py::handle &scalars, const py::handle &texcoords,
                    const py::handle &texture_files);

/// The textured-mesh fields given to encode()/write() (each None when absent) added to
/// `mesh` (whose triangles are set): corner_texcoords float32 (m, 3, 2) (u, v of each
/// corner), face_materials uint32 (m,) (indices into materials), materials a sequence of
/// dicts {"name": str, "texture": int (index into texture_files, -1 for none),
/// "properties": str} ("texture" and "properties" optional). TypeError/ValueError (naming
/// the argument) for a wrong type, dtype or shape.
/// Embedded texture images (a list of bytes or None, one per texture file) into mesh.
void add_texture_images(pomar::Mesh &mesh, const py::handle &images);
void add_corner_data(pomar::Mesh &mesh, const py::handle &corner_texcoords,
                     const py::handle &face_materials, const py::handle &materials);

/// (vertices, faces, attributes) taking over the mesh's storage: numpy arrays and a dict
/// with the keyword arguments of pomar.Mesh for the attributes ("colors", "normals",
/// "scalars", "texcoords", "texture_files", "corner_texcoords", "face_materials",
/// "materials", "attribute_info"; per-corner texture coordinates have an entry of kind
/// "corner texcoord" there).
py::tuple arrays_from_mesh(pomar::Mesh &&mesh);

/// A contiguous bytes-like object (bytes, bytearray, memoryview, numpy uint8 array) held
/// for reading while the GIL is released: the exporter cannot resize it meanwhile.
class ReadBuffer {
public:
  ReadBuffer(const py::handle &object, const char *what);
  ~ReadBuffer();
  ReadBuffer(const ReadBuffer &) = delete;
  ReadBuffer &operator=(const ReadBuffer &) = delete;
  const uint8_t *data() const { return static_cast<const uint8_t *>(view_.buf); }
  size_t size() const { return static_cast<size_t>(view_.len); }

private:
  Py_buffer view_;
};

/// The Progress of an encode/decode running with the GIL released: at every report it
/// takes the GIL, runs Python's signal handlers (Ctrl-C interrupts a long call with
/// KeyboardInterrupt) and calls `callback(fraction, stage)` unless it is None. An exception
/// from either leaves the library call as it is. `callback` must outlive the call (it is
/// not reference-counted here: copies of the Progress happen without the GIL).
pomar::Progress python_progress(const py::handle &callback);

/// Skipped blocks as a list of dicts {"block", "problem", "level_kept"}.
py::list damaged_list(const std::vector<pomar::DamagedBlock> &blocks);

/// FileInfo as the dict `pomar info --json` prints (same keys and values).
py::dict info_dict(const pomar::FileInfo &info);

/// A memory limit: bytes (int; 0 = automatic) or text as `--max-memory` takes ("512M",
/// "2GiB", "auto", "none").
uint64_t memory_limit(const py::handle &value);

/// Level argument: None = `none_means`; otherwise an int in 0..finest (a ValueError
/// naming the file's levels if not). Arguments are checked here so that pomar.Error is
/// left to what the file and the mesh are.
int checked_level(const py::handle &level, int finest, int none_means);

} // namespace pomar_python
