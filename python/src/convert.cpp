#include "convert.h"

#include "errors.h"

#include <pomar/limits.h>

#include <cstring>

namespace pomar_python {

namespace {

std::string shape_text(const py::array &array) {
  std::string shape = "(";
  for (py::ssize_t d = 0; d < array.ndim(); ++d)
    shape += (d ? ", " : "") + std::to_string(array.shape(d));
  return shape + (array.ndim() == 1 ? ",)" : ")");
}

/// The C-contiguous array of T behind `object` with shape `shape` ("(n, 3)", "(n,)"):
/// `columns` values a row (0: one dimension; `alt_columns`, if not 0, is also accepted),
/// `rows` rows unless rows < 0. Otherwise a TypeError/ValueError naming `name`.
template <class T>
py::array_t<T> checked_array(const py::handle &object, const std::string &name, const char *dtype,
                             const char *shape, py::ssize_t columns, py::ssize_t alt_columns = 0,
                             py::ssize_t rows = -1) {
  if (!py::isinstance<py::array>(object))
    throw py::type_error(name + " must be a numpy array of " + dtype + ", shape " + shape +
                         "; got " + std::string(py::str(py::type::of(object))));
  auto array = py::reinterpret_borrow<py::array>(object);
  if (!array.dtype().is(py::dtype::of<T>()))
    throw py::type_error(name + " must have dtype " + dtype + ", not " +
                         std::string(py::str(array.dtype())) + " (convert with " + name +
                         ".astype(numpy." + dtype + "))");
  const bool shape_ok = columns == 0
                            ? array.ndim() == 1
                            : array.ndim() == 2 && (array.shape(1) == columns ||
                                                    (alt_columns && array.shape(1) == alt_columns));
  if (!shape_ok)
    throw py::value_error(name + " must have shape " + shape + ", not " + shape_text(array));
  if (rows >= 0 && array.shape(0) != rows)
    throw py::value_error(name + " has " + std::to_string(array.shape(0)) + " rows but there are " +
                          std::to_string(rows) + " vertices: one row per vertex");
  if (!(array.flags() & py::array::c_style))
    throw py::value_error(name +
                          " is not C-contiguous (a slice, a transpose or Fortran order?): "
                          "pass numpy.ascontiguousarray(" +
                          name + ")");
  return py::reinterpret_borrow<py::array_t<T>>(array);
}

/// An attribute's description and precision (VertexAttribute or AttributeInfo): the
/// entries of Mesh.attribute_info and of info()["attributes"].
template <class A> py::dict attribute_entry(const A &a) {
  py::dict entry;
  entry["kind"] = pomar::kind_name(a.kind);
  entry["name"] = a.name;
  entry["components"] = a.components;
  entry["bits"] = a.bits;
  entry["exact"] = a.bits == 0;
  entry["bound"] = a.bound;
  return entry;
}

template <class T> std::vector<T> copy_values(const py::array_t<T> &array) {
  const T *first = array.data();
  return std::vector<T>(first, first + array.size());
}

} // namespace

pomar::Mesh mesh_from_arrays(const py::handle &vertices, const py::handle &faces) {
  pomar::Mesh mesh;
  mesh.positions = copy_values(checked_array<float>(vertices, "vertices", "float32", "(n, 3)", 3));
  mesh.triangles = copy_values(checked_array<uint32_t>(faces, "faces", "uint32", "(m, 3)", 3));
  return mesh;
}

void add_attributes(pomar::Mesh &mesh, const py::handle &colors, const py::handle &normals,
                    const py::handle &scalars, const py::handle &texcoords,
                    const py::handle &texture_files) {
  const auto n = static_cast<py::ssize_t>(mesh.positions.size() / 3);
  auto add = [&](pomar::AttributeKind kind, std::string name, uint32_t components) {
    pomar::VertexAttribute &a = mesh.attributes.emplace_back();
    a.kind = kind;
    a.name = std::move(name);
    a.components = components;
    return &a;
  };
  if (!colors.is_none()) {
    const auto array =
        checked_array<uint8_t>(colors, "colors", "uint8", "(n, 3) or (n, 4)", 3, 4, n);
    add(pomar::AttributeKind::Colour, "colour", static_cast<uint32_t>(array.shape(1)))->colour =
        copy_values(array);
  }
  if (!normals.is_none())
    add(pomar::AttributeKind::Normal, "normal", 3)->values =
        copy_values(checked_array<float>(normals, "normals", "float32", "(n, 3)", 3, 0, n));
  if (!scalars.is_none()) {
    if (!py::isinstance<py::dict>(scalars))
      throw py::type_error("scalars must be a dict name -> float32 array (n,), not " +
                           std::string(py::str(py::type::of(scalars))));
    for (const auto &[key, value] : py::reinterpret_borrow<py::dict>(scalars)) {
      if (!py::isinstance<py::str>(key))
        throw py::type_error("scalars' names must be str, not " +
                             std::string(py::str(py::type::of(key))));
      const std::string name = key.cast<std::string>();
      if (name.empty() || name.size() > 255)
        throw py::value_error("a scalar's name must have 1..255 bytes: '" + name + "'");
      for (const pomar::VertexAttribute &a : mesh.attributes)
        if (a.name == name)
          throw py::value_error("scalar name '" + name +
                                "' is taken by another attribute: choose another name");
      add(pomar::AttributeKind::Scalar, name, 1)->values = copy_values(
          checked_array<float>(value, "scalars['" + name + "']", "float32", "(n,)", 0, 0, n));
    }
  }
  if (!texcoords.is_none())
    add(pomar::AttributeKind::TexCoord, "texcoord", 2)->values =
        copy_values(checked_array<float>(texcoords, "texcoords", "float32", "(n, 2)", 2, 0, n));
  if (!texture_files.is_none()) {
    if (py::isinstance<py::str>(texture_files) || !py::isinstance<py::sequence>(texture_files))
      throw py::type_error("texture_files must be a list of str");
    for (const py::handle &file : py::reinterpret_borrow<py::sequence>(texture_files)) {
      if (!py::isinstance<py::str>(file))
        throw py::type_error("texture_files must be a list of str, it holds a " +
                             std::string(py::str(py::type::of(file))));
      mesh.texture_files.push_back(file.cast<std::string>());
    }
  }
}

void add_texture_images(pomar::Mesh &mesh, const py::handle &images) {
  if (images.is_none())
    return;
  if (py::isinstance<py::str>(images) || !py::isinstance<py::sequence>(images))
    throw py::type_error("texture_images must be a list of bytes (or None), one per texture file");
  const auto list = py::reinterpret_borrow<py::sequence>(images);
  if (list.size() > mesh.texture_files.size())
    throw py::value_error("texture_images has " + std::to_string(list.size()) +
                          " entries but there are " + std::to_string(mesh.texture_files.size()) +
                          " texture files");
  for (const py::handle &item : list) {
    if (item.is_none()) {
      mesh.texture_images.emplace_back();
      continue;
    }
    if (!py::isinstance<py::bytes>(item))
      throw py::type_error("texture_images must hold bytes or None, not " +
                           std::string(py::str(py::type::of(item))));
    const std::string b = item.cast<std::string>();
    mesh.texture_images.emplace_back(b.begin(), b.end());
  }
}

void add_corner_data(pomar::Mesh &mesh, const py::handle &corner_texcoords,
                     const py::handle &face_materials, const py::handle &materials) {
  const auto m = static_cast<py::ssize_t>(mesh.triangles.size() / 3);
  if (!corner_texcoords.is_none()) {
    if (!py::isinstance<py::array>(corner_texcoords))
      throw py::type_error("corner_texcoords must be a numpy array of float32, shape (m, 3, 2); "
                           "got " +
                           std::string(py::str(py::type::of(corner_texcoords))));
    auto array = py::reinterpret_borrow<py::array>(corner_texcoords);
    if (!array.dtype().is(py::dtype::of<float>()))
      throw py::type_error("corner_texcoords must have dtype float32, not " +
                           std::string(py::str(array.dtype())) +
                           " (convert with corner_texcoords.astype(numpy.float32))");
    if (array.ndim() != 3 || array.shape(1) != 3 || array.shape(2) != 2)
      throw py::value_error("corner_texcoords must have shape (m, 3, 2), not " + shape_text(array));
    if (array.shape(0) != m)
      throw py::value_error("corner_texcoords has " + std::to_string(array.shape(0)) +
                            " rows but there are " + std::to_string(m) +
                            " faces: one row per face");
    if (!(array.flags() & py::array::c_style))
      throw py::value_error("corner_texcoords is not C-contiguous: pass "
                            "numpy.ascontiguousarray(corner_texcoords)");
    mesh.corner_texcoords = copy_values(py::reinterpret_borrow<py::array_t<float>>(array));
  }
  if (!face_materials.is_none()) {
    const auto array =
        checked_array<uint32_t>(face_materials, "face_materials", "uint32", "(m,)", 0);
    if (array.shape(0) != m)
      throw py::value_error("face_materials has " + std::to_string(array.shape(0)) +
                            " entries but there are " + std::to_string(m) + " faces: one per face");
    mesh.face_materials = copy_values(array);
  }
  if (!materials.is_none()) {
    if (py::isinstance<py::str>(materials) || !py::isinstance<py::sequence>(materials))
      throw py::type_error("materials must be a list of dicts {name, texture, properties}");
    for (const py::handle &item : py::reinterpret_borrow<py::sequence>(materials)) {
      if (!py::isinstance<py::dict>(item))
        throw py::type_error("materials must be a list of dicts {name, texture, properties}, "
                             "it holds a " +
                             std::string(py::str(py::type::of(item))));
      const auto d = py::reinterpret_borrow<py::dict>(item);
      pomar::Material material;
      for (const auto &[key, value] : d) {
        const std::string k = py::isinstance<py::str>(key) ? key.cast<std::string>() : "";
        if (k == "name" && py::isinstance<py::str>(value))
          material.name = value.cast<std::string>();
        else if (k == "properties" && py::isinstance<py::str>(value))
          material.properties = value.cast<std::string>();
        else if (k == "texture" && py::isinstance<py::int_>(value) &&
                 !py::isinstance<py::bool_>(value))
          material.texture = value.cast<int32_t>();
        else
          throw py::type_error("a material is a dict {name: str, texture: int, properties: "
                               "str}; bad entry " +
                               std::string(py::repr(key)));
      }
      mesh.materials.push_back(std::move(material));
    }
  }
  const size_t textures = mesh.texture_files.size();
  for (const pomar::Material &material : mesh.materials)
    if (material.texture < -1 || (material.texture >= 0 && size_t(material.texture) >= textures))
      throw py::value_error("material '" + material.name + "' has texture " +
                            std::to_string(material.texture) + " but there are " +
                            std::to_string(textures) + " texture_files (-1: none)");
  for (const uint32_t f : mesh.face_materials)
    if (f >= mesh.materials.size())
      throw py::value_error("face_materials holds " + std::to_string(f) + " but there are " +
                            std::to_string(mesh.materials.size()) + " materials");
}

py::tuple arrays_from_mesh(pomar::Mesh &&mesh) {
  py::dict attributes;
  py::dict scalars;
  py::list info;
  for (pomar::VertexAttribute &a : mesh.attributes) {
    const char *key = nullptr;
    switch (a.kind) {
    case pomar::AttributeKind::Colour:
      key = "colors";
      break;
    case pomar::AttributeKind::Normal:
      key = "normals";
      break;
    case pomar::AttributeKind::TexCoord:
      key = "texcoords";
      break;
    case pomar::AttributeKind::Scalar:
      break;
    }
    // A second colour/normal/texcoord attribute (not made by the readers) has no field.
    if (key && attributes.contains(key))
      continue;
    info.append(attribute_entry(a));
    if (a.kind == pomar::AttributeKind::Colour)
      attributes[key] = array_from_vector(std::move(a.colour), a.components);
    else if (key)
      attributes[key] = array_from_vector(std::move(a.values), a.components);
    else
      scalars[py::str(a.name)] = array_from_vector(std::move(a.values), 0);
  }
  attributes["scalars"] = scalars;
  attributes["texture_files"] = py::cast(mesh.texture_files);
  py::list images; // per texture file: its embedded image (bytes) or None
  for (size_t t = 0; t < mesh.texture_files.size(); ++t) {
    if (t < mesh.texture_images.size() && !mesh.texture_images[t].empty())
      images.append(py::bytes(reinterpret_cast<const char *>(mesh.texture_images[t].data()),
                              mesh.texture_images[t].size()));
    else
      images.append(py::none());
  }
  attributes["texture_images"] = images;
  if (!mesh.corner_texcoords.empty()) {
    py::dict entry;
    entry["kind"] = "corner texcoord";
    entry["name"] = "corner_texcoords";
    entry["components"] = 2;
    entry["bits"] = mesh.corner_texcoord_bits;
    entry["exact"] = mesh.corner_texcoord_bits == 0;
    entry["bound"] = mesh.corner_texcoord_bound;
    info.append(entry);
    auto *owned = new std::vector<float>(std::move(mesh.corner_texcoords));
    py::capsule owner(owned, [](void *p) { delete static_cast<std::vector<float> *>(p); });
    const size_t faces = owned->size() / 6, f = sizeof(float);
    attributes["corner_texcoords"] =
        py::array_t<float>({faces, size_t(3), size_t(2)}, {6 * f, 2 * f, f}, owned->data(), owner);
  } else {
    attributes["corner_texcoords"] = py::none();
  }
  if (!mesh.face_materials.empty())
    attributes["face_materials"] = array_from_vector(std::move(mesh.face_materials), 0);
  else
    attributes["face_materials"] = py::none();
  py::list materials;
  for (const pomar::Material &material : mesh.materials) {
    py::dict d;
    d["name"] = material.name;
    d["texture"] = material.texture;
    d["properties"] = material.properties;
    materials.append(d);
  }
  attributes["materials"] = materials;
  attributes["attribute_info"] = info;
  return py::make_tuple(array_from_vector(std::move(mesh.positions), 3),
                        array_from_vector(std::move(mesh.triangles), 3), attributes);
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
  if (i.clustered()) { // (as pomar info --json)
    const auto has = [&](const char *name) {
      for (const pomar::FileInfo::Section &section : i.sections)
        if (section.name == name)
          return true;
      return false;
    };
    d["stored_errors"] = has("CERR");
    d["block_order"] = has("BLKO") ? "spatial" : "id";
  }
  d["lossless_bytes"] = i.lossless_bytes;
  d["lossless_bits_per_vertex"] = bpv(i.lossless_bytes);
  d["input_vertices"] = i.input_vertices;
  d["input_faces"] = i.input_faces;
  d["header_bytes"] = i.header_bytes;
  d["base_bytes"] = i.base_bytes;
  d["total_bytes"] = i.total_bytes;
  d["bpv"] = bpv(i.total_bytes);
  d["connectivity_bpv"] = bpv(i.connectivity_bytes);
  d["geometry_bpv"] = bpv(i.geometry_bytes);
  py::list attributes;
  for (const pomar::AttributeInfo &a : i.attributes) {
    py::dict entry = attribute_entry(a);
    entry["bytes"] = a.bytes;
    entry["bpv"] = bpv(a.bytes);
    attributes.append(entry);
  }
  d["attributes"] = attributes;
  d["attribute_bytes"] = i.attribute_bytes;
  d["texture_files"] = py::list(py::cast(i.texture_files));
  d["embedded_texture_bytes"] = py::list(py::cast(i.embedded_texture_bytes));
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
