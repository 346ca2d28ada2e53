// pomar.Error: the library's errors as one Python exception class whose `kind` is
// pomar::Error::kind() as snake_case text ("invalid_mesh", "damaged_file", ...), with the
// error's `path`, `level` and `cluster` (None when it names none); an error
// thrown without a kind (Kind::Other) gets the usual failure of the operation that raised
// it. Bad arguments the binding checks itself (dtype, shape, bits, level, cluster) raise
// TypeError / ValueError before the library runs.
#pragma once

#include <pomar/pomar.h>

#include <pybind11/pybind11.h>

#include <string>
#include <utility>

namespace pomar_python {

/// A library error on its way to Python as pomar.Error(message) with .kind.
struct KindedError {
  std::string kind;
  pomar::Error error; // message, path, level and cluster
};

/// The Python kind of `e`, raised by an operation whose usual failure is `operation_kind`.
std::string kind_of(const pomar::Error &e, const char *operation_kind);

/// Runs f(); a pomar::Error leaving it becomes a KindedError.
template <class F> auto call_library(const char *operation_kind, F &&f) -> decltype(f()) {
  try {
    return f();
  } catch (const pomar::Error &e) {
    throw KindedError{kind_of(e, operation_kind), e};
  }
}

/// Adds pomar.Error to the module and translates KindedError (and any stray
/// pomar::Error) into it.
void register_errors(pybind11::module_ &m);

} // namespace pomar_python
