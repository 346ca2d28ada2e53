#include "convert.h"

#include "errors.h"

#include <pomar/limits.h>

#include <cstring>

namespace pomar_python {

namespace {

/// The C-contiguous (n, 3) array of T behind `object`, or a TypeError/ValueError.
template <class T>
py::array_t<T> checked_rows(const py::handle &object, const char *name, const char *dtype) {
  if (!py::isinstance<py::array>(object))
    throw py::type_error(std::string(name) + " must be a numpy array of " + dtype +
                         ", shape (n, 3); got " + std::string(py::str(py::type::of(object))));
  auto array = py::reinterpret_borrow<py::array>(object);
  if (!array.dtype().is(py::dtype::of<T>()))
    throw py::type_error(std::string(name) + " must have dtype " + dtype + ", not " +
                         std::string(py::str(array.dtype())) + " (convert with " + name +
                         ".astype(numpy." + dtype + "))");
  if (array.ndim() != 2 || array.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < array.ndim(); ++d)
      shape += (d ? ", " : "") + std::to_string(array.shape(d));
    throw py::value_error(std::string(name) + " must have shape (n, 3), not " + shape +
                          (array.ndim() == 1 ? ",)" : ")"));
  }
  if (!(array.flags() & py::array::c_style))
    throw py::value_error(std::string(name) +
                          " is not C-contiguous (a slice, a transpose or Fortran order?): "
                          "pass numpy.ascontiguousarray(" +
                          name + ")");
  return py::reinterpret_borrow<py::array_t<T>>(array);
}

template <class T> std::vector<T> copy_values(const py::array_t<T> &array) {
  const T *first = array.data();
  return std::vector<T>(first, first + array.size());
}

} // namespace

pomar::Mesh mesh_from_arrays(const py::handle &vertices, const py::handle &faces) {
  pomar::Mesh mesh;
  mesh.positions = copy_values(checked_rows<float>(vertices, "vertices", "float32"));
  mesh.triangles = copy_values(checked_rows<uint32_t>(faces, "faces", "uint32"));
  return mesh;
}

py::tuple arrays_from_mesh(pomar::Mesh &&mesh) {
  return py::make_tuple(array_from_vector(std::move(mesh.positions), 3),
                        array_from_vector(std::move(mesh.triangles), 3));
}

ReadBuffer::ReadBuffer(const py::handle &object, const char *what) {
  if (py::isinstance<py::str>(object) || py::hasattr(object, "__fspath__"))
    throw py::type_error(std::string(what) + " takes the bytes of a .pomar file, not a path: " +
                         "use pomar.read(path) or open(path, 'rb').read()");
  if (PyObject_GetBuffer(object.ptr(), &view_, PyBUF_SIMPLE) != 0) {
    PyErr_Clear();
    throw py::type_error(std::string(what) + " takes a contiguous bytes-like object (bytes, " +
                         "bytearray, memoryview), not " +
                         std::string(py::str(py::type::of(object))));
  }
}

ReadBuffer::~ReadBuffer() { PyBuffer_Release(&view_); }

pomar::Progress python_progress(const py::handle &callback) {
  if (!callback.is_none() && !PyCallable_Check(callback.ptr()))
    throw py::type_error("progress must be a callable(fraction, stage) or None");
  return [callback](double fraction, const char *stage) {
    py::gil_scoped_acquire locked;
    if (PyErr_CheckSignals() != 0)
      throw py::error_already_set();
    if (!callback.is_none())
      callback(fraction, stage);
  };
}

py::list damaged_list(const std::vector<pomar::DamagedBlock> &blocks) {
  py::list out;
  for (const pomar::DamagedBlock &b : blocks) {
    py::dict d;
    d["block"] = b.block;
    d["problem"] = b.problem;
    d["level_kept"] = b.level_kept;
    out.append(d);
  }
  return out;
}

py::dict info_dict(const pomar::FileInfo &i) {
  auto bpv = [&](uint64_t bytes) {
    return i.vertices ? 8.0 * double(bytes) / double(i.vertices) : 0.0;
  };
  auto triple = [](const float v[3]) { return py::make_tuple(v[0], v[1], v[2]); };
  py::list levels;
  py::dict base;
  base["level"] = 0;
  base["vertices"] = i.base_vertices;
  base["faces"] = i.base_faces;
  base["bytes"] = i.base_bytes;
  levels.append(base);
  for (size_t l = 0; l < i.levels.size(); ++l) {
    py::dict level;
    level["level"] = l + 1;
    level["vertices"] = i.levels[l].vertices;
    level["faces"] = i.levels[l].faces;
    level["connectivity_bytes"] = i.levels[l].connectivity_bytes;
    level["geometry_bytes"] = i.levels[l].geometry_bytes;
    levels.append(level);
  }
  py::dict d;
  d["version"] = i.version;
  d["vertices"] = i.vertices;
  d["faces"] = i.faces;
  d["bits"] = i.bits;
  d["bbox_min"] = py::list(triple(i.bbox_min));
  d["grid_max"] = py::list(triple(i.bbox_max));
  d["base_vertices"] = i.base_vertices;
  d["base_faces"] = i.base_faces;
  d["levels"] = levels;
  d["level_count"] = i.levels.size();
  d["connectivity_bits"] = 8 * i.connectivity_bytes;
  d["geometry_bits"] = 8 * i.geometry_bytes;
  d["clusters"] = i.clusters;
  d["global_levels"] = i.global_levels;
  d["global_bytes"] = i.global_bytes;
  d["tables_bytes"] = i.tables_bytes;
  d["index_bytes"] = i.index_bytes;
  d["cluster_bytes"] = i.cluster_bytes;
  d["cluster_block_bytes"] = py::list(py::cast(i.cluster_block_bytes));
  py::list sections;
  for (const pomar::FileInfo::Section &section : i.sections) {
    py::dict entry;
    entry["name"] = section.name;
    entry["bytes"] = section.bytes;
    entry["bpv"] = bpv(section.bytes);
    entry["required"] = section.required;
    sections.append(entry);
  }
  d["sections"] = sections;
  d["header_bytes"] = i.header_bytes;
  d["base_bytes"] = i.base_bytes;
  d["total_bytes"] = i.total_bytes;
  d["bpv"] = bpv(i.total_bytes);
  d["connectivity_bpv"] = bpv(i.connectivity_bytes);
  d["geometry_bpv"] = bpv(i.geometry_bytes);
  py::list attributes;
  for (const pomar::AttributeInfo &a : i.attributes) {
    py::dict entry;
    entry["kind"] = pomar::kind_name(a.kind);
    entry["name"] = a.name;
    entry["components"] = a.components;
    entry["bits"] = a.bits;
    entry["exact"] = a.bits == 0;
    entry["bound"] = a.bound;
    entry["bytes"] = a.bytes;
    entry["bpv"] = bpv(a.bytes);
    attributes.append(entry);
  }
  d["attributes"] = attributes;
  d["attribute_bytes"] = i.attribute_bytes;
  d["texture_files"] = py::list(py::cast(i.texture_files));
  return d;
}

uint64_t memory_limit(const py::handle &value) {
  if (value.is_none())
    return 0;
  if (py::isinstance<py::str>(value))
    return call_library("usage",
                        [&] { return pomar::parse_memory_size(value.cast<std::string>()); });
  if (!py::isinstance<py::int_>(value) || value.cast<py::int_>() < py::int_(0))
    throw py::type_error("memory_limit must be a byte count >= 0 (0 = automatic) or a size "
                         "such as '512M', 'auto' or 'none'");
  return value.cast<uint64_t>();
}

int checked_level(const py::handle &level, int finest, int none_means) {
  if (level.is_none())
    return none_means;
  if (!py::isinstance<py::int_>(level))
    throw py::type_error("level must be an int (0 = base mesh) or None");
  const long l = level.cast<long>();
  if (l < 0 || l > finest)
    throw py::value_error("level " + std::to_string(l) +
                          " does not exist: the file has levels 0.." + std::to_string(finest));
  return static_cast<int>(l);
}

} // namespace pomar_python
