// The binding keeps the library's threading rule (one thread at a time per decoder) for
// Python threads too: every call releases the GIL, then takes the decoder's own mutex, so
// update() on one thread and want_sphere() on another wait for each other instead of racing.
#include "selective.h"

#include "convert.h"
#include "errors.h"

#include <pomar/random_access.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace pomar_python {

namespace {

/// The bytes of a file given as a Python bytes-like object, copied once.
class OwnedBytes : public pomar::ByteSource {
public:
  explicit OwnedBytes(std::vector<uint8_t> bytes)
      : bytes_(std::move(bytes)), memory_(bytes_.data(), bytes_.size()) {}
  uint64_t size() const override { return memory_.size(); }
  void read(uint64_t offset, size_t n, uint8_t *out) override { memory_.read(offset, n, out); }

private:
  std::vector<uint8_t> bytes_;
  pomar::MemorySource memory_;
};

class Decoder {
public:
  Decoder(const py::handle &source, bool skip_damaged, const py::handle &max_memory,
          unsigned threads) {
    std::unique_ptr<pomar::ByteSource> bytes;
    std::string path;
    if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
      path = py::str(py::module_::import("os").attr("fspath")(source)).cast<std::string>();
    } else {
      const ReadBuffer buffer(source, "SelectiveDecoder()");
      bytes = std::make_unique<OwnedBytes>(
          std::vector<uint8_t>(buffer.data(), buffer.data() + buffer.size()));
    }
    pomar::SelectiveOptions options;
    options.skip_damaged = skip_damaged;
    options.memory_limit = memory_limit(max_memory);
    options.threads = threads;
    py::gil_scoped_release unlocked;
    decoder_ = call_library("damaged_file", [&] {
      if (!bytes)
        bytes = std::make_unique<pomar::FileSource>(path);
      return std::make_unique<pomar::SelectiveDecoder>(std::move(bytes), options);
    });
  }

  /// f(decoder) with the GIL released and the decoder's mutex held.
  template <class F> auto locked(F &&f) -> decltype(f(std::declval<pomar::SelectiveDecoder &>())) {
    py::gil_scoped_release unlocked;
    std::lock_guard<std::mutex> lock(mutex_);
    return call_library("damaged_file", [&] { return f(*decoder_); });
  }

  int level_or_finest(const py::handle &level) {
    const int finest = locked([](pomar::SelectiveDecoder &d) { return d.finest_level(); });
    return checked_level(level, finest, finest);
  }

  uint32_t checked_cluster(uint32_t cluster) {
    const uint32_t count = locked([](pomar::SelectiveDecoder &d) { return d.cluster_count(); });
    if (cluster >= count)
      throw py::value_error("cluster " + std::to_string(cluster) +
                            " does not exist: the file has " + std::to_string(count) + " clusters");
    return cluster;
  }

private:
  std::mutex mutex_;
  std::unique_ptr<pomar::SelectiveDecoder> decoder_;
};

std::vector<float> point(const py::handle &value, const char *name) {
  std::vector<float> p;
  try {
    p = value.cast<std::vector<float>>();
  } catch (const py::cast_error &) {
  }
  if (p.size() != 3)
    throw py::type_error(std::string(name) + " must be 3 numbers (x, y, z)");
  return p;
}

/// A camera as pomar::ViewCamera (and the web client's viewOf) describes it.
pomar::ViewCamera view_camera(const py::handle &eye, const std::vector<float> &view_proj,
                              float fov_y, float width, float height, float near_distance) {
  pomar::ViewCamera camera;
  const std::vector<float> e = point(eye, "eye");
  std::copy(e.begin(), e.end(), camera.eye);
  if (view_proj.size() != 16)
    throw py::type_error("view_proj must be 16 numbers (a 4x4 matrix, column-major)");
  std::copy(view_proj.begin(), view_proj.end(), camera.view_proj);
  camera.fov_y = fov_y;
  camera.width = width;
  camera.height = height;
  camera.near_distance = near_distance;
  return camera;
}

using D = pomar::SelectiveDecoder;
using DecoderClass = py::class_<Decoder>;

/// What to decode: clusters, regions, vertices, faces, a level per cluster.
void register_wanted(DecoderClass &cls) {
  cls.def(
         "want_cluster",
         [](Decoder &s, uint32_t cluster, const py::handle &level) {
           const uint32_t c = s.checked_cluster(cluster);
           const int l = s.level_or_finest(level);
           s.locked([&](D &d) { d.want_cluster(c, l); });
         },
         py::arg("cluster"), py::arg("level") = py::none())
      .def(
          "want_all",
          [](Decoder &s, const py::handle &level) {
            const int l = s.level_or_finest(level);
            s.locked([&](D &d) { d.want_all(l); });
          },
          py::arg("level") = py::none())
      .def(
          "want_sphere",
          [](Decoder &s, const py::handle &center, float radius, const py::handle &level) {
            const std::vector<float> c = point(center, "center");
            const int l = s.level_or_finest(level);
            s.locked([&](D &d) { d.want_sphere(c.data(), radius, l); });
          },
          py::arg("center"), py::arg("radius"), py::arg("level") = py::none())
      .def(
          "want_box",
          [](Decoder &s, const py::handle &lo, const py::handle &hi, const py::handle &level) {
            const std::vector<float> a = point(lo, "lo"), b = point(hi, "hi");
            const int l = s.level_or_finest(level);
            s.locked([&](D &d) { d.want_box(a.data(), b.data(), l); });
          },
          py::arg("lo"), py::arg("hi"), py::arg("level") = py::none())
      .def(
          "want_vertices",
          [](Decoder &s, const std::vector<uint32_t> &vertices, const py::handle &level) {
            const int l = s.level_or_finest(level);
            s.locked([&](D &d) { d.want_vertices(vertices, l); });
          },
          py::arg("vertices"), py::arg("level") = py::none())
      .def(
          "want_faces",
          [](Decoder &s, const std::vector<uint32_t> &faces, const py::handle &level) {
            const int l = s.level_or_finest(level);
            s.locked([&](D &d) { d.want_faces(faces, l); });
          },
          py::arg("faces"), py::arg("level") = py::none())
      .def("clear_wanted", [](Decoder &s) { s.locked([](D &d) { d.clear_wanted(); }); })
      .def(
          "set_wanted",
          [](Decoder &s, const std::vector<int> &levels) {
            const uint32_t count = s.locked([](D &d) { return d.cluster_count(); });
            if (levels.size() != count)
              throw py::value_error("set_wanted needs one level per cluster (" +
                                    std::to_string(count) + "), got " +
                                    std::to_string(levels.size()));
            s.locked([&](D &d) { d.set_wanted(levels); });
          },
          py::arg("levels"))
      .def_property_readonly("wanted", [](Decoder &s) {
        std::vector<int> w = s.locked([](D &d) { return d.wanted(); });
        return array_from_vector(std::move(w), 0);
      });
}

/// A camera's view: the levels its pixel error asks for, and the cluster errors behind them.
void register_view(DecoderClass &cls) {
  cls.def(
         "want_view",
         [](Decoder &s, const py::handle &eye, const std::vector<float> &view_proj, float fov_y,
            float width, float height, float near_distance, float pixel_error) {
           const pomar::ViewCamera camera =
               view_camera(eye, view_proj, fov_y, width, height, near_distance);
           s.locked([&](D &d) { d.want_view(camera, pixel_error); });
         },
         py::arg("eye"), py::arg("view_proj"), py::arg("fov_y"), py::arg("width"),
         py::arg("height"), py::arg("near"), py::arg("pixel_error"))
      .def(
          "view_levels",
          [](Decoder &s, const py::handle &eye, const std::vector<float> &view_proj, float fov_y,
             float width, float height, float near_distance, float pixel_error) {
            const pomar::ViewCamera camera =
                view_camera(eye, view_proj, fov_y, width, height, near_distance);
            return array_from_vector(
                s.locked([&](D &d) { return d.view_levels(camera, pixel_error); }), 0);
          },
          py::arg("eye"), py::arg("view_proj"), py::arg("fov_y"), py::arg("width"),
          py::arg("height"), py::arg("near"), py::arg("pixel_error"))
      .def_property_readonly(
          "has_cluster_errors",
          [](Decoder &s) { return s.locked([](D &d) { return d.has_cluster_errors(); }); })
      .def(
          "cluster_error",
          [](Decoder &s, uint32_t cluster, int level) {
            const uint32_t c = s.checked_cluster(cluster);
            return s.locked([&](D &d) { return d.cluster_error(c, level); });
          },
          py::arg("cluster"), py::arg("level"));
}

/// The decode and what it gives: the mesh, its clusters and levels, what was read.
void register_results(DecoderClass &cls) {
  cls.def("update", [](Decoder &s) { s.locked([](D &d) { d.update(); }); })
      .def_property_readonly("levels",
                             [](Decoder &s) {
                               std::vector<int> l = s.locked([](D &d) { return d.levels(); });
                               return array_from_vector(std::move(l), 0);
                             })
      .def("mesh_arrays",
           [](Decoder &s) { return arrays_from_mesh(s.locked([](D &d) { return d.mesh(); })); })
      .def("vertex_cluster",
           [](Decoder &s) {
             return array_from_vector(s.locked([](D &d) { return d.vertex_cluster(); }), 0);
           })
      .def("vertex_level",
           [](Decoder &s) {
             return array_from_vector(s.locked([](D &d) { return d.vertex_level(); }), 0);
           })
      .def_property_readonly(
          "damaged",
          [](Decoder &s) { return damaged_list(s.locked([](D &d) { return d.damaged(); })); })
      .def_property_readonly(
          "bytes_read", [](Decoder &s) { return s.locked([](D &d) { return d.bytes_read(); }); })
      .def_property_readonly(
          "blocks_read", [](Decoder &s) { return s.locked([](D &d) { return d.blocks_read(); }); })
      .def_property_readonly("clusters_decoded", [](Decoder &s) {
        return s.locked([](D &d) { return d.clusters_decoded(); });
      });
}

} // namespace

void register_selective_decoder(py::module_ &m) {
  py::class_<Decoder> cls(m, "SelectiveDecoder");
  cls.def(py::init<const py::handle &, bool, const py::handle &, unsigned>(), py::arg("source"),
          py::kw_only(), py::arg("skip_damaged") = false, py::arg("memory_limit") = py::none(),
          py::arg("threads") = 0u)
      .def_property_readonly("info",
                             [](Decoder &s) {
                               pomar::FileInfo i = s.locked([](D &d) { return d.info(); });
                               return info_dict(i);
                             })
      .def_property_readonly(
          "cluster_count",
          [](Decoder &s) { return s.locked([](D &d) { return d.cluster_count(); }); })
      .def_property_readonly(
          "base_clustered_level",
          [](Decoder &s) { return s.locked([](D &d) { return d.base_clustered_level(); }); })
      .def_property_readonly("finest_level", [](Decoder &s) {
        return s.locked([](D &d) { return d.finest_level(); });
      });
  register_wanted(cls);
  register_view(cls);
  register_results(cls);
}

} // namespace pomar_python
