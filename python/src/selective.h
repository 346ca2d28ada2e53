// pomar.SelectiveDecoder: random access to a .pomar file from Python.
#pragma once

#include <pybind11/pybind11.h>

namespace pomar_python {

void register_selective_decoder(pybind11::module_ &m);

} // namespace pomar_python
