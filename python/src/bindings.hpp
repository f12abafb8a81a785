// The parts of the _dynid extension module, one function each (python/src/module.cpp calls them).
#pragma once

#include <pybind11/pybind11.h>

namespace dynid::python {
void bind_model(pybind11::module_& m);     // Model, Case, load_case
void bind_analysis(pybind11::module_& m);  // modal, correlation, SEREP, residual forces, detect, update, discover, tests
void bind_data(pybind11::module_& m);      // .mat, UFF and modal-data files, reports
}  // namespace dynid::python
