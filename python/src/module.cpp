// pomar._pomar: the library's functions on numpy arrays and bytes. The user-facing API
// (pomar.Mesh, keyword arguments, files by extension) is python/pomar/__init__.py.
#include "convert.h"
#include "errors.h"
#include "selective.h"

#include <pomar/mesh_io.h>
#include <pomar/pomar.h>

#include <string>

namespace py = pybind11;
using namespace pomar_python;

namespace {

void check_bits(const char *name, int bits, int low, int high) {
  if (bits < low || bits > high)
    throw py::value_error(std::string(name) + " must be between " + std::to_string(low) + " and " +
                          std::to_string(high) + ", not " + std::to_string(bits));
}

/// The mesh of write()/encode(): arrays plus attributes (a dict with the keys of
/// add_attributes' and add_corner_data's arguments).
pomar::Mesh mesh_with_attributes(const py::handle &vertices, const py::handle &faces,
                                 const py::dict &attributes) {
  pomar::Mesh mesh = mesh_from_arrays(vertices, faces);
  auto field = [&](const char *key) -> py::object {
    if (!attributes.contains(key))
      return py::none();
    return attributes[key];
  };
  add_attributes(mesh, field("colors"), field("normals"), field("scalars"), field("texcoords"),
                 field("texture_files"));
  add_corner_data(mesh, field("corner_texcoords"), field("face_materials"), field("materials"));
  add_texture_images(mesh, field("texture_images"));
  return mesh;
}

py::bytes encode(const py::handle &vertices, const py::handle &faces, int bits, uint32_t clusters,
                 double cluster_ratio, bool progressive, const py::handle &max_memory,
                 const py::handle &progress, const py::dict &attributes, int normal_bits,
                 int scalar_bits, int texcoord_bits, bool exact_attributes, bool strict,
                 bool keep_order, unsigned threads, bool stored_errors, bool spatial_blocks) {
  check_bits("bits", bits, 4, 24);
  check_bits("normal_bits", normal_bits, 4, 16);
  check_bits("scalar_bits", scalar_bits, 1, 24);
  check_bits("texcoord_bits", texcoord_bits, 1, 24);
  pomar::Mesh mesh = mesh_with_attributes(vertices, faces, attributes);
  pomar::EncodeOptions options;
  options.attributes.normal_bits = normal_bits;
  options.attributes.scalar_bits = scalar_bits;
  options.attributes.texcoord_bits = texcoord_bits;
  options.attributes.exact = exact_attributes;
  options.bits = bits;
  options.clusters = clusters;
  options.cluster_ratio = cluster_ratio;
  options.progressive = progressive;
  options.strict = strict;
  options.keep_order = keep_order;
  options.threads = threads;
  options.cluster_errors = stored_errors;
  options.spatial_layout = spatial_blocks;
  options.memory_limit = memory_limit(max_memory);
  options.progress = python_progress(progress);
  std::vector<uint8_t> file;
  {
    py::gil_scoped_release unlocked;
    file = call_library("invalid_mesh", [&] { return pomar::encode(mesh, options); });
  }
  return py::bytes(reinterpret_cast<const char *>(file.data()), file.size());
}

py::tuple decode(const py::handle &data, const py::handle &level, bool skip_damaged,
                 const py::handle &max_memory, const py::handle &progress, bool attributes,
                 unsigned threads) {
  const ReadBuffer buffer(data, "decode()");
  pomar::DecodeOptions options;
  options.threads = threads;
  if (!attributes)
    options.attributes = pomar::AttributeMask::none();
  options.skip_damaged = skip_damaged;
  options.memory_limit = memory_limit(max_memory);
  options.progress = python_progress(progress);
  if (!level.is_none()) {
    const pomar::FileInfo i =
        call_library("damaged_file", [&] { return pomar::inspect(buffer.data(), buffer.size()); });
    options.level = checked_level(level, static_cast<int>(i.levels.size()), -1);
  }
  pomar::Mesh mesh;
  pomar::DecodeReport report;
  {
    py::gil_scoped_release unlocked;
    mesh = call_library("damaged_file", [&] {
      return pomar::decode(buffer.data(), buffer.size(), options, &report);
    });
  }
  py::tuple arrays = arrays_from_mesh(std::move(mesh));
  return py::make_tuple(arrays[0], arrays[1], damaged_list(report.damaged), arrays[2]);
}

py::dict info(const py::handle &data) {
  const ReadBuffer buffer(data, "info()");
  pomar::FileInfo i;
  {
    py::gil_scoped_release unlocked;
    i = call_library("damaged_file", [&] { return pomar::inspect(buffer.data(), buffer.size()); });
  }
  return info_dict(i);
}

py::tuple read_mesh(const std::string &path) {
  pomar::LoadReport report;
  pomar::Mesh mesh;
  {
    py::gil_scoped_release unlocked;
    mesh = call_library("io", [&] { return pomar::load_mesh(path, &report); });
  }
  py::dict r;
  r["format"] = report.format;
  r["file_vertices"] = report.file_vertices;
  r["file_faces"] = report.file_faces;
  r["unreferenced_vertices"] = report.unreferenced_vertices;
  r["welded_vertices"] = report.welded_vertices;
  r["polygons_triangulated"] = report.polygons_triangulated;
  r["ignored_attributes"] = py::cast(report.ignored_attributes);
  py::tuple arrays = arrays_from_mesh(std::move(mesh));
  return py::make_tuple(arrays[0], arrays[1], r, arrays[2]);
}

/// Writes the mesh; returns what the format cannot hold of its attributes (for a warning).
std::vector<std::string> write_mesh(const std::string &path, const py::handle &vertices,
                                    const py::handle &faces, bool binary,
                                    const py::dict &attributes) {
  const pomar::Mesh mesh = mesh_with_attributes(vertices, faces, attributes);
  py::gil_scoped_release unlocked;
  call_library("io", [&] { pomar::save_mesh(path, mesh, binary); });
  return pomar::attributes_not_saved(path, mesh);
}

void write_bytes(const std::string &path, const py::handle &data) {
  const ReadBuffer buffer(data, "write_bytes()");
  py::gil_scoped_release unlocked;
  call_library("io", [&] { pomar::write_file_atomic(path, buffer.data(), buffer.size()); });
}

} // namespace

PYBIND11_MODULE(_pomar, m) {
  m.doc() = "pomar's library on numpy arrays (use the pomar package, not this module)";
  register_errors(m);
  m.attr("__version__") = pomar::version();
  m.def("encode", &encode, py::arg("vertices"), py::arg("faces"), py::arg("bits"),
        py::arg("clusters"), py::arg("cluster_ratio"), py::arg("progressive"),
        py::arg("memory_limit"), py::arg("progress"), py::arg("attributes"), py::arg("normal_bits"),
        py::arg("scalar_bits"), py::arg("texcoord_bits"), py::arg("exact_attributes"),
        py::arg("strict"), py::arg("keep_order"), py::arg("threads"), py::arg("stored_errors"),
        py::arg("spatial_blocks"));
  m.def("decode", &decode, py::arg("data"), py::arg("level"), py::arg("skip_damaged"),
        py::arg("memory_limit"), py::arg("progress"), py::arg("attributes"), py::arg("threads"));
  m.def("info", &info, py::arg("data"));
  m.def("read_mesh", &read_mesh, py::arg("path"));
  m.def("write_mesh", &write_mesh, py::arg("path"), py::arg("vertices"), py::arg("faces"),
        py::arg("binary"), py::arg("attributes"));
  m.def("write_bytes", &write_bytes, py::arg("path"), py::arg("data"));
  register_selective_decoder(m);
}
