// pomar.Error: the library's errors as one Python exception class with a `kind`.
//
// pomar::Error does not carry a kind yet (issue 11 gives it one), so the kind is the
// usual failure of the operation that raised it: "invalid_mesh" (encode), "damaged_file"
// (decode, info, SelectiveDecoder), "io" (read, write), "usage" (a memory limit text that
// does not parse), and "memory_limit" whenever a memory check refused the work. Bad
// arguments the binding can check itself (dtype, shape, bits, level, cluster) raise
// TypeError / ValueError before the library is called.
#pragma once

#include <pomar/pomar.h>

#include <pybind11/pybind11.h>

#include <string>
#include <utility>

namespace pomar_python {

/// A library error on its way to Python as pomar.Error(message) with .kind.
struct KindedError {
  std::string kind;
  std::string message;
};

/// The kind of `e`, raised by an operation whose usual failure is `operation_kind`.
std::string kind_of(const pomar::Error &e, const char *operation_kind);

/// Runs f(); a pomar::Error leaving it becomes a KindedError.
template <class F> auto call_library(const char *operation_kind, F &&f) -> decltype(f()) {
  try {
    return f();
  } catch (const pomar::Error &e) {
    throw KindedError{kind_of(e, operation_kind), e.what()};
  }
}

/// Adds pomar.Error to the module and translates KindedError (and any stray
/// pomar::Error) into it.
void register_errors(pybind11::module_ &m);

} // namespace pomar_python
