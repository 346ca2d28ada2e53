#include "errors.h"

namespace pomar_python {

namespace py = pybind11;

namespace {
PyObject *error_type = nullptr; // pomar.Error, alive as long as the module

void raise(const std::string &kind, const pomar::Error &e) {
  py::object type = py::reinterpret_borrow<py::object>(error_type);
  py::object error = type(pomar::printable(e.what())); // (the message may quote a file)
  error.attr("kind") = kind;
  error.attr("path") = e.path().empty() ? py::object(py::none()) : py::str(e.path());
  error.attr("level") =
      e.level() == pomar::Error::kNoBlock ? py::object(py::none()) : py::int_(e.level());
  error.attr("cluster") =
      e.cluster() == pomar::Error::kNoBlock ? py::object(py::none()) : py::int_(e.cluster());
  PyErr_SetObject(error_type, error.ptr());
}
} // namespace

std::string kind_of(const pomar::Error &e, const char *operation_kind) {
  using Kind = pomar::Error::Kind;
  switch (e.kind()) {
  case Kind::InvalidMesh:
    return "invalid_mesh";
  case Kind::DamagedFile:
    return "damaged_file";
  case Kind::TruncatedFile:
    return "truncated_file";
  case Kind::Unsupported:
    return "unsupported";
  case Kind::Io:
    return "io";
  case Kind::MemoryLimit:
    return "memory_limit";
  case Kind::Usage:
    return "usage";
  case Kind::Internal:
    return "internal";
  case Kind::Other:
    break;
  }
  return operation_kind; // an error thrown without a kind
}

void register_errors(py::module_ &m) {
  error_type = PyErr_NewExceptionWithDoc(
      "pomar.Error",
      "A failure reported by the pomar library: str(e) is its one-line message, e.kind one "
      "of 'invalid_mesh', 'damaged_file', 'truncated_file', 'unsupported', 'io', "
      "'memory_limit', 'usage', 'internal'; e.path, e.level, e.cluster: the file and the "
      "block it names (None if none).",
      PyExc_Exception, nullptr);
  if (!error_type)
    throw py::error_already_set();
  m.add_object("Error", py::handle(error_type)); // the module keeps a reference
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p)
        std::rethrow_exception(p);
    } catch (const KindedError &e) {
      raise(e.kind, e.error);
    } catch (const pomar::Error &e) {
      raise(kind_of(e, "error"), e);
    }
  });
}

} // namespace pomar_python
