// The _dynid extension module: dynid's engine and readers for Python (the package dynid wraps it; docs/python.md).
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "dynid/mesh/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif
#include <dlfcn.h>

namespace py = pybind11;

PYBIND11_MODULE(_dynid, m) {
  m.doc() = "dynid engine bindings (use the dynid package)";
  m.attr("__version__") = DYNID_VERSION;
  // dynid's errors keep their messages: bad input -> dynid.InputError (a ValueError), numerical failure ->
  // dynid.NumericalError (an ArithmeticError), a broken invariant -> dynid.InternalError (a RuntimeError).
  static py::exception<dynid::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<dynid::NumericalError> numerical_error(m, "NumericalError", PyExc_ArithmeticError);
  static py::exception<dynid::InternalError> internal_error(m, "InternalError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const dynid::InputError& e) {
      input_error(e.what());
    } catch (const dynid::NumericalError& e) {
      numerical_error(e.what());
    } catch (const dynid::InternalError& e) {
      internal_error(e.what());
    }
  });
  m.def("set_threads", [](int n) {
    if (n <= 0) return;
#ifdef _OPENMP
    omp_set_num_threads(n);
#endif
    using SetThreads = void (*)(int);
    if (auto f = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) f(n);
  }, py::arg("n"), "Threads for assembly, factorization and residual forces (results do not depend on it).");
  dynid::python::bind_model(m);
  dynid::python::bind_analysis(m);
  dynid::python::bind_data(m);
}
