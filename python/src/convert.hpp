// Conversions between dynid's C++ types and Python objects for the `dynid` module (docs/python.md).
//
// Copies and views: NumPy arrays returned by the module own the C++ result they were moved from (no copy of the
// matrix). Arrays passed in are read through Eigen::Ref where the binding allows it (float64 in Fortran order:
// no copy); any other array (C order, another dtype) is converted, which copies. Sparse matrices are always
// copied into dynid's CSC storage (both triangles). docs/python.md lists the calls that copy.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "dynid/engine/modal.hpp"
#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/recording.hpp"
#include "dynid/mesh/model.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid::python {

namespace py = pybind11;

/// JSON (as io's builders make it) to plain Python objects: dict, list, str, int, float, bool, None.
py::object to_python(const nlohmann::json& j);
py::object to_python(const nlohmann::ordered_json& j);

/// Keyword options read one by one; what is left at the end is an error naming the unknown keys and the
/// accepted ones (as a case file's unknown keys are). Throws dynid::InputError with `what` in the message.
class Options {
 public:
  Options(py::dict kw, std::string what);
  bool has(const char* key) const;
  py::object take(const char* key);  ///< the value (None if absent), marked as used
  template <class T>
  bool get(const char* key, T* out) {
    py::object v = take(key);
    if (v.is_none()) return false;
    try {
      *out = v.cast<T>();
    } catch (const py::cast_error&) {
      fail_type(key, v);
    }
    return true;
  }
  /// Raises for keys not taken.
  void finish();
  const std::string& what() const { return what_; }

 private:
  [[noreturn]] void fail_type(const char* key, const py::object& v) const;
  py::dict kw_;
  std::string what_;
  std::set<std::string> taken_;
};

/// A DOF label ("13ux", "13:uy", "13+X"), or a (node, "ux") pair.
MeasuredDof to_dof(py::handle h, const std::string& what);
/// A list of DOF labels; with a model also "all" and "translations".
std::vector<MeasuredDof> to_dofs(py::handle h, const std::string& what, const Model* model = nullptr);
py::list dof_labels(const std::vector<MeasuredDof>& dofs);

/// Modal data: a dict {"dofs": [labels], "frequency_hz": array, "shapes": dofs x modes array, optional
/// "damping_ratio", "mpc", "frequency_std_hz", "damping_std", "shape_std" arrays, "source"}; also accepts the
/// modal-data JSON structure {"modes": [{"frequency_hz", "shape": {label: value}}]} (what identify returns).
ModalData to_modal_data(py::handle h, const std::string& what);
py::dict from_modal_data(ModalData d);

/// Recording: {"sample_rate_hz", "channels": [{"name", "dof", "quantity", "unit", "input"}], "records":
/// [samples x channels arrays]}. A channel may be given as a DOF label alone (an acceleration output).
Recording to_recording(py::handle h, const std::string& what);
py::dict from_recording(Recording r);
/// FRFs: {"frequency_hz", "H": frequencies x (outputs * inputs) complex array, "outputs": [...], "inputs": [...],
/// optional "coherence", "window_decay"}.
FrfData to_frf(py::handle h, const std::string& what);
py::dict from_frf(FrfData h);

/// A square matrix given as scipy.sparse (any format) or a dense NumPy array, in dynid's storage (CSC, both
/// triangles). Copies.
SparseMatrix to_sparse(py::handle h, const std::string& what);
/// scipy.sparse.csc_matrix of A (copies the three arrays once).
py::object from_sparse(const SparseMatrix& A);

/// numpy float64 array moved from an Eigen object (no copy).
template <class M>
py::array move_array(M&& m) {
  return py::cast(std::move(m), py::return_value_policy::move);
}

}  // namespace dynid::python
