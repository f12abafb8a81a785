#include "convert.hpp"

#include <cmath>

#include "dynid/io/modal_data_io.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid::python {

namespace {

template <class J>
py::object json_to_python(const J& j) {
  switch (j.type()) {
    case J::value_t::null: return py::none();
    case J::value_t::boolean: return py::bool_(j.template get<bool>());
    case J::value_t::number_integer: return py::int_(j.template get<long long>());
    case J::value_t::number_unsigned: return py::int_(j.template get<unsigned long long>());
    case J::value_t::number_float: return py::float_(j.template get<double>());
    case J::value_t::string: return py::str(j.template get_ref<const std::string&>());
    case J::value_t::array: {
      py::list l(j.size());
      std::size_t k = 0;
      for (const auto& v : j) l[k++] = json_to_python(v);
      return std::move(l);
    }
    case J::value_t::object: {
      py::dict d;
      for (auto it = j.begin(); it != j.end(); ++it) d[py::str(it.key())] = json_to_python(it.value());
      return std::move(d);
    }
    default: return py::none();
  }
}

std::string type_name(py::handle h) { return py::str(py::type::handle_of(h).attr("__name__")); }

// A float64 vector from any sequence or array (copies).
Eigen::VectorXd vector_of(py::handle h, const std::string& what) {
  try {
    return h.cast<Eigen::VectorXd>();
  } catch (const py::cast_error&) {
    throw InputError(what + ": expected a 1-D array of numbers, got " + type_name(h));
  }
}

Eigen::MatrixXd matrix_of(py::handle h, const std::string& what) {
  py::array a = py::array::ensure(h);
  if (!a || a.ndim() > 2) throw InputError(what + ": expected a 2-D array of numbers, got " + type_name(h));
  if (a.ndim() == 1) {  // one column
    Eigen::VectorXd v = vector_of(h, what);
    return Eigen::MatrixXd(v);
  }
  try {
    return h.cast<Eigen::MatrixXd>();
  } catch (const py::cast_error&) {
    throw InputError(what + ": expected a 2-D array of real numbers (float64), got dtype " + std::string(py::str(a.dtype())));
  }
}

Quantity quantity_of(const std::string& s, const std::string& what) {
  for (Quantity q : {Quantity::kDisplacement, Quantity::kVelocity, Quantity::kAcceleration, Quantity::kForce, Quantity::kOther})
    if (s == to_string(q)) return q;
  throw InputError(what + ": quantity '" + s + "' is not one of displacement, velocity, acceleration, force, other");
}

Channel channel_of(py::handle h, const std::string& what) {
  Channel c;
  if (py::isinstance<py::str>(h)) {
    c.dof = to_dof(h, what);
    c.name = to_string(c.dof);
    return c;
  }
  if (!py::isinstance<py::dict>(h)) throw InputError(what + ": expected a DOF label or a dict {dof, quantity, input, name, unit}");
  Options o(py::reinterpret_borrow<py::dict>(h), what);
  if (o.has("dof")) c.dof = to_dof(o.take("dof"), what + " dof");
  std::string q;
  if (o.get("quantity", &q)) c.quantity = quantity_of(q, what);
  o.get("input", &c.input);
  if (!o.has("input") && c.quantity == Quantity::kForce) c.input = true;
  if (!o.get("name", &c.name)) c.name = to_string(c.dof);
  o.get("unit", &c.unit);
  o.finish();
  return c;
}

py::dict channel_dict(const Channel& c) {
  py::dict d;
  d["name"] = c.name;
  d["dof"] = to_string(c.dof);
  d["quantity"] = to_string(c.quantity);
  d["unit"] = c.unit;
  d["input"] = c.input;
  return d;
}

}  // namespace

py::object to_python(const nlohmann::json& j) { return json_to_python(j); }
py::object to_python(const nlohmann::ordered_json& j) { return json_to_python(j); }

Options::Options(py::dict kw, std::string what) : kw_(std::move(kw)), what_(std::move(what)) {}

bool Options::has(const char* key) const { return kw_.contains(key) && !kw_[key].is_none(); }

py::object Options::take(const char* key) {
  taken_.insert(key);
  return kw_.contains(key) ? py::reinterpret_borrow<py::object>(kw_[key]) : py::none();
}

void Options::fail_type(const char* key, const py::object& v) const {
  throw InputError(what_ + ": option '" + key + "' has the wrong type (" + type_name(v) + ")");
}

void Options::finish() {
  std::string unknown;
  for (auto item : kw_) {
    const std::string k = py::str(item.first);
    if (!taken_.count(k)) unknown += (unknown.empty() ? "'" : ", '") + k + "'";
  }
  if (unknown.empty()) return;
  std::string known;
  for (const std::string& k : taken_) known += (known.empty() ? "" : ", ") + k;
  throw InputError(what_ + ": unknown option " + unknown + " (accepted: " + known + ")");
}

MeasuredDof to_dof(py::handle h, const std::string& what) {
  MeasuredDof d;
  if (py::isinstance<py::str>(h)) {
    const std::string s = h.cast<std::string>();
    double sign = 1;
    if (!parse_dof_label(s, &d, &sign)) throw InputError(what + ": '" + s + "' is not a DOF label (e.g. 13ux, 13:uy, 13+X)");
    return d;
  }
  if (py::isinstance<py::tuple>(h) || py::isinstance<py::list>(h)) {
    py::sequence s = py::reinterpret_borrow<py::sequence>(h);
    if (s.size() == 2 && py::isinstance<py::str>(s[1])) {
      d.node = s[0].cast<int>();
      const std::string n = s[1].cast<std::string>();
      if (!parse_dof(n, &d.dof)) throw InputError(what + ": '" + n + "' is not a DOF type (ux, uy, uz, rx, ry, rz)");
      return d;
    }
  }
  throw InputError(what + ": expected a DOF label such as '13ux' or a pair (13, 'ux'), got " + type_name(h));
}

std::vector<MeasuredDof> to_dofs(py::handle h, const std::string& what, const Model* model) {
  if (py::isinstance<py::str>(h)) {
    const std::string s = h.cast<std::string>();
    if (model && s == "all") return all_dofs(*model);
    if (model && s == "translations") return dofs_of_types(*model, kTranslations);
    return {to_dof(h, what)};
  }
  if (!py::isinstance<py::sequence>(h)) throw InputError(what + ": expected a list of DOF labels (e.g. ['13ux', '14ux'])");
  std::vector<MeasuredDof> out;
  for (py::handle x : py::reinterpret_borrow<py::sequence>(h)) out.push_back(to_dof(x, what));
  return out;
}

py::list dof_labels(const std::vector<MeasuredDof>& dofs) {
  py::list l(dofs.size());
  for (std::size_t k = 0; k < dofs.size(); ++k) l[k] = to_string(dofs[k]);
  return l;
}

ModalData to_modal_data(py::handle h, const std::string& what) {
  if (!py::isinstance<py::dict>(h))
    throw InputError(what + ": modal data is a dict {'dofs', 'frequency_hz', 'shapes'} (or the modal-data JSON structure), got " + type_name(h));
  py::dict d = py::reinterpret_borrow<py::dict>(h);
  if (d.contains("modal_data") && !d.contains("shapes")) return to_modal_data(d["modal_data"], what);  // identify's result
  if (d.contains("modes") && !d.contains("shapes")) {  // the JSON structure (identify's result, a modal-data file)
    py::object json = py::module_::import("json");
    const std::string text = py::str(json.attr("dumps")(d["modes"].is_none() ? py::list() : d["modes"]));
    return parse_modal_data_json("{\"modes\": " + text + "}", what);
  }
  ModalData m;
  Options o(d, what);
  for (const char* k : {"dofs", "frequency_hz", "shapes"})
    if (!o.has(k)) throw InputError(what + ": '" + k + "' is missing (modal data: dofs, frequency_hz, shapes)");
  m.dofs = to_dofs(o.take("dofs"), what + " dofs");
  m.frequencies_hz = vector_of(o.take("frequency_hz"), what + " frequency_hz");
  m.shapes = matrix_of(o.take("shapes"), what + " shapes");
  if (o.has("damping_ratio")) m.damping_ratios = vector_of(o.take("damping_ratio"), what + " damping_ratio");
  if (o.has("mpc")) m.mpc = vector_of(o.take("mpc"), what + " mpc");
  if (o.has("frequency_std_hz")) m.frequency_std_hz = vector_of(o.take("frequency_std_hz"), what + " frequency_std_hz");
  if (o.has("damping_std")) m.damping_std = vector_of(o.take("damping_std"), what + " damping_std");
  if (o.has("shape_std")) m.shape_std = vector_of(o.take("shape_std"), what + " shape_std");
  if (!o.get("source", &m.source)) m.source = what;
  o.take("modes");  // a result that carries both structures
  o.finish();
  m.validate(what);
  return m;
}

py::dict from_modal_data(ModalData m) {
  py::dict d;
  d["dofs"] = dof_labels(m.dofs);
  d["frequency_hz"] = move_array(std::move(m.frequencies_hz));
  d["shapes"] = move_array(std::move(m.shapes));
  if (m.damping_ratios.size()) d["damping_ratio"] = move_array(std::move(m.damping_ratios));
  if (m.mpc.size()) d["mpc"] = move_array(std::move(m.mpc));
  if (m.frequency_std_hz.size()) d["frequency_std_hz"] = move_array(std::move(m.frequency_std_hz));
  if (m.damping_std.size()) d["damping_std"] = move_array(std::move(m.damping_std));
  if (m.shape_std.size()) d["shape_std"] = move_array(std::move(m.shape_std));
  d["source"] = m.source;
  return d;
}

Recording to_recording(py::handle h, const std::string& what) {
  if (!py::isinstance<py::dict>(h))
    throw InputError(what + ": a recording is a dict {'sample_rate_hz', 'channels', 'records'}, got " + type_name(h));
  Options o(py::reinterpret_borrow<py::dict>(h), what);
  Recording r;
  if (!o.get("sample_rate_hz", &r.sample_rate_hz)) throw InputError(what + ": 'sample_rate_hz' is missing");
  if (!o.has("channels")) throw InputError(what + ": 'channels' is missing (one DOF label or dict per column)");
  int k = 0;
  for (py::handle c : py::reinterpret_borrow<py::sequence>(o.take("channels")))
    r.channels.push_back(channel_of(c, what + " channel " + std::to_string(++k)));
  if (!o.has("records")) throw InputError(what + ": 'records' is missing (a list of samples x channels arrays)");
  py::object recs = o.take("records");
  if (py::isinstance<py::array>(recs)) {
    r.records.push_back(matrix_of(recs, what + " records"));
  } else {
    k = 0;
    for (py::handle a : py::reinterpret_borrow<py::sequence>(recs))
      r.records.push_back(matrix_of(a, what + " record " + std::to_string(++k)));
  }
  o.get("source", &r.source);
  o.finish();
  if (r.source.empty()) r.source = what;
  r.validate(what);
  return r;
}

py::dict from_recording(Recording r) {
  py::dict d;
  d["sample_rate_hz"] = r.sample_rate_hz;
  py::list ch;
  for (const Channel& c : r.channels) ch.append(channel_dict(c));
  d["channels"] = ch;
  py::list recs;
  for (Eigen::MatrixXd& m : r.records) recs.append(move_array(std::move(m)));
  d["records"] = recs;
  d["source"] = r.source;
  return d;
}

FrfData to_frf(py::handle h, const std::string& what) {
  if (!py::isinstance<py::dict>(h)) throw InputError(what + ": FRFs are a dict {'frequency_hz', 'H', 'outputs', 'inputs'}");
  Options o(py::reinterpret_borrow<py::dict>(h), what);
  FrfData f;
  for (const char* k : {"frequency_hz", "H", "outputs", "inputs"})
    if (!o.has(k)) throw InputError(what + ": '" + k + "' is missing");
  f.frequency_hz = vector_of(o.take("frequency_hz"), what + " frequency_hz");
  try {
    f.H = o.take("H").cast<Eigen::MatrixXcd>();
  } catch (const py::cast_error&) {
    throw InputError(what + ": H must be a frequencies x (outputs * inputs) complex array");
  }
  int k = 0;
  for (py::handle c : py::reinterpret_borrow<py::sequence>(o.take("outputs")))
    f.outputs.push_back(channel_of(c, what + " output " + std::to_string(++k)));
  k = 0;
  for (py::handle c : py::reinterpret_borrow<py::sequence>(o.take("inputs"))) {
    Channel ch = channel_of(c, what + " input " + std::to_string(++k));
    ch.quantity = Quantity::kForce;
    ch.input = true;
    f.inputs.push_back(ch);
  }
  if (o.has("coherence")) f.coherence = matrix_of(o.take("coherence"), what + " coherence");
  o.get("window_decay", &f.window_decay);
  o.get("source", &f.source);
  o.finish();
  if (f.source.empty()) f.source = what;
  f.validate(what);
  return f;
}

py::dict from_frf(FrfData f) {
  py::dict d;
  d["frequency_hz"] = move_array(std::move(f.frequency_hz));
  d["H"] = py::cast(std::move(f.H), py::return_value_policy::move);
  py::list o, i;
  for (const Channel& c : f.outputs) o.append(channel_dict(c));
  for (const Channel& c : f.inputs) i.append(channel_dict(c));
  d["outputs"] = o;
  d["inputs"] = i;
  if (f.coherence.size()) d["coherence"] = move_array(std::move(f.coherence));
  d["window_decay"] = f.window_decay;
  d["source"] = f.source;
  return d;
}

SparseMatrix to_sparse(py::handle h, const std::string& what) {
  SparseMatrix A;
  if (py::hasattr(h, "tocsc") && !py::isinstance<py::array>(h)) {
    py::object c = h.attr("tocsc")();
    try {
      A = c.cast<SparseMatrix>();
    } catch (const py::cast_error&) {
      throw InputError(what + ": a scipy.sparse matrix of real numbers is expected");
    }
  } else {
    Eigen::MatrixXd D = matrix_of(h, what);
    A = D.sparseView();
  }
  if (A.rows() != A.cols())
    throw InputError(what + ": a " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) + " matrix; a square one is needed");
  A.makeCompressed();
  for (int j = 0; j < A.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(A, j); it; ++it)
      if (!std::isfinite(it.value()))
        throw InputError(what + ": entry (" + std::to_string(it.row()) + ", " + std::to_string(j) + ") is not finite");
  return A;
}

py::object from_sparse(const SparseMatrix& A) {
  return py::cast(A);  // pybind11/eigen.h: scipy.sparse.csc_matrix
}

}  // namespace dynid::python
