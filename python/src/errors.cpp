#include "errors.h"

namespace pomar_python {

namespace py = pybind11;

namespace {
PyObject *error_type = nullptr; // pomar.Error, alive as long as the module

void raise(const std::string &kind, const std::string &message) {
  py::object type = py::reinterpret_borrow<py::object>(error_type);
  py::object error = type(message);
  error.attr("kind") = kind;
  PyErr_SetObject(error_type, error.ptr());
}
} // namespace

std::string kind_of(const pomar::Error &e, const char *operation_kind) {
  // The memory checks of pomar/limits.h all say "not enough memory to ...".
  if (std::string(e.what()).rfind("not enough memory", 0) == 0)
    return "memory_limit";
  return operation_kind;
}

void register_errors(py::module_ &m) {
  error_type = PyErr_NewExceptionWithDoc(
      "pomar.Error",
      "A failure reported by the pomar library: str(e) is its one-line message, e.kind one "
      "of 'invalid_mesh', 'damaged_file', 'io', 'memory_limit', 'usage'.",
      PyExc_Exception, nullptr);
  if (!error_type)
    throw py::error_already_set();
  m.add_object("Error", py::handle(error_type)); // the module keeps a reference
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p)
        std::rethrow_exception(p);
    } catch (const KindedError &e) {
      raise(e.kind, e.message);
    } catch (const pomar::Error &e) {
      raise(kind_of(e, "error"), e.what());
    }
  });
}

} // namespace pomar_python
