// dynid.Model and dynid.Case: models from case files, NumPy arrays and matrices.
#include <cmath>
#include <map>
#include <memory>

#include "bindings.hpp"
#include "convert.hpp"

#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include "dynid/engine/detect.hpp"
#include "dynid/engine/parametric.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/mat_file.hpp"
#include "dynid/io/matrix_model.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid::python {

namespace {

std::string key_text(py::handle k) { return py::str(k); }

Material material_from(const std::string& name, py::handle h) {
  Options o(py::reinterpret_borrow<py::dict>(h), "material '" + name + "'");
  Material m;
  m.name = name;
  if (!o.get("E", &m.E)) throw InputError("material '" + name + "': E is missing");
  o.get("rho", &m.rho);
  o.get("nu", &m.nu);
  o.get("G", &m.G);
  o.finish();
  if (!(m.E > 0)) throw InputError("material '" + name + "': E must be > 0");
  if (!(m.rho >= 0)) throw InputError("material '" + name + "': rho must be >= 0");
  return m;
}

Section section_from(const std::string& name, py::handle h) {
  Options o(py::reinterpret_borrow<py::dict>(h), "section '" + name + "'");
  Section s;
  s.name = name;
  if (!o.get("A", &s.A)) throw InputError("section '" + name + "': A is missing");
  double I = 0;
  if (o.get("I", &I)) s.Iz = I;
  o.get("Iz", &s.Iz);
  o.get("Iy", &s.Iy);
  o.get("J", &s.J);
  o.get("shear_factor", &s.shear_factor);
  o.finish();
  return s;
}

DofMask dof_mask_from(py::handle h, const std::string& what) {
  if (py::isinstance<py::str>(h)) {
    const std::string s = h.cast<std::string>();
    if (s == "all" || s == "fixed" || s == "clamped") return kAllDofs;
    if (s == "pinned") return kTranslations;
    Dof d;
    if (parse_dof(s, &d)) return dof_bit(d);
    throw InputError(what + ": must be all, fixed, pinned, or a list of DOFs such as ['ux', 'uy']; got '" + s + "'");
  }
  DofMask m = 0;
  for (py::handle x : py::reinterpret_borrow<py::sequence>(h)) {
    const std::string s = py::str(x);
    Dof d;
    if (!parse_dof(s, &d)) throw InputError(what + ": unknown DOF '" + s + "' (known: ux, uy, uz, rx, ry, rz)");
    m |= dof_bit(d);
  }
  return m;
}

// A name per element: one string for all, or a sequence of names / indices into `names`.
std::vector<int> per_element(py::handle h, std::size_t count, const std::vector<std::string>& names,
                             const std::map<std::string, int>& index, const char* what) {
  std::vector<int> out(count, -1);
  if (h.is_none()) {
    if (names.size() == 1) std::fill(out.begin(), out.end(), 0);
    else if (!names.empty())
      throw InputError(std::string("Model.from_arrays: ") + what + " is missing: with " + std::to_string(names.size()) +
                       " " + what + "s, give element_" + what + " (one name for all, or one per element)");
    return out;
  }
  auto lookup = [&](py::handle x, std::size_t e) {
    if (py::isinstance<py::str>(x)) {
      const std::string n = x.cast<std::string>();
      auto it = index.find(n);
      if (it == index.end()) throw InputError("Model.from_arrays: element " + std::to_string(e + 1) + ": " + what + " '" + n + "' is not defined");
      return it->second;
    }
    const int k = x.cast<int>();
    if (k < 0 || k >= static_cast<int>(names.size()))
      throw InputError("Model.from_arrays: element " + std::to_string(e + 1) + ": " + what + " index " + std::to_string(k) + " is out of range");
    return k;
  };
  if (py::isinstance<py::str>(h)) {
    const int k = lookup(h, 0);
    std::fill(out.begin(), out.end(), k);
    return out;
  }
  py::sequence s = py::reinterpret_borrow<py::sequence>(h);
  if (s.size() != count)
    throw InputError(std::string("Model.from_arrays: element_") + what + " has " + std::to_string(s.size()) + " entries for " +
                     std::to_string(count) + " elements");
  for (std::size_t e = 0; e < count; ++e) out[e] = lookup(s[e], e);
  return out;
}

ElementType element_type_from(const std::string& s, const std::string& what) {
  ElementType t;
  if (!parse_element_type(s, &t) || !is_member(t))
    throw InputError(what + ": unknown element type '" + s + "' (beam2d, frame2d, frame3d)");
  return t;
}

// Supports: "free", {node: fix}, or a list of {node|nodes, fix}.
void add_supports(Model* m, py::handle h) {
  if (h.is_none()) return;
  if (py::isinstance<py::str>(h)) {
    if (h.cast<std::string>() != "free") throw InputError("supports: expected 'free' (free-free), a dict {node: fix} or a list of {node, fix}");
    m->set_free_free(true);
    return;
  }
  if (py::isinstance<py::dict>(h)) {
    for (auto kv : py::reinterpret_borrow<py::dict>(h)) {
      const int node = kv.first.cast<int>();
      if (m->node_index(node) < 0) throw InputError("supports: node " + std::to_string(node) + " does not exist");
      m->restrain(node, dof_mask_from(kv.second, "support of node " + std::to_string(node)));
    }
    return;
  }
  for (py::handle s : py::reinterpret_borrow<py::sequence>(h)) {
    Options o(py::reinterpret_borrow<py::dict>(s), "support");
    std::vector<int> ids;
    int one = 0;
    if (o.get("node", &one)) ids.push_back(one);
    std::vector<int> more;
    if (o.get("nodes", &more)) ids.insert(ids.end(), more.begin(), more.end());
    if (ids.empty()) throw InputError("support: give node or nodes");
    if (!o.has("fix")) throw InputError("support: fix is missing (all, pinned, or a list such as ['ux', 'uy'])");
    const DofMask mask = dof_mask_from(o.take("fix"), "support");
    o.finish();
    for (int id : ids) {
      if (m->node_index(id) < 0) throw InputError("support: node " + std::to_string(id) + " does not exist");
      m->restrain(id, mask);
    }
  }
}

int next_free_id(const Model& m) {
  int id = 0;
  for (const Element& e : m.elements()) id = std::max(id, e.id);
  return id + 1;
}

void add_point_masses(Model* m, py::handle h) {
  if (h.is_none()) return;
  for (py::handle x : py::reinterpret_borrow<py::sequence>(h)) {
    Options o(py::reinterpret_borrow<py::dict>(x), "point mass");
    Element el;
    el.type = ElementType::PointMass;
    el.num_nodes = 1;
    if (!o.get("id", &el.id)) el.id = next_free_id(*m);
    int node = 0;
    if (!o.get("node", &node) || m->node_index(node) < 0)
      throw InputError("point mass " + std::to_string(el.id) + ": node is missing or does not exist");
    el.node_ids = {{node, 0}};
    o.get("mass", &el.mass);
    std::vector<double> J;
    if (o.get("inertia", &J)) {
      if (J.size() != 3) throw InputError("point mass " + std::to_string(el.id) + ": inertia must be [Jx, Jy, Jz]");
      el.rotary_inertia = Eigen::Vector3d(J[0], J[1], J[2]);
    }
    o.get("group", &el.group);
    o.finish();
    if (el.mass < 0 || el.rotary_inertia.minCoeff() < 0) throw InputError("point mass " + std::to_string(el.id) + ": mass and inertia must be >= 0");
    m->add_element(el);
  }
}

void add_springs(Model* m, py::handle h) {
  if (h.is_none()) return;
  for (py::handle x : py::reinterpret_borrow<py::sequence>(h)) {
    Options o(py::reinterpret_borrow<py::dict>(x), "spring");
    Element el;
    el.type = ElementType::Spring;
    if (!o.get("id", &el.id)) el.id = next_free_id(*m);
    const std::string w = "spring " + std::to_string(el.id);
    int node = 0;
    std::vector<int> nodes;
    if (o.get("node", &node)) {
      el.num_nodes = 1;
      el.node_ids = {{node, 0}};
    } else if (o.get("nodes", &nodes) && (nodes.size() == 1 || nodes.size() == 2)) {
      el.num_nodes = static_cast<int>(nodes.size());
      el.node_ids = {{nodes[0], nodes.size() == 2 ? nodes[1] : 0}};
    } else {
      throw InputError(w + ": give node (grounded) or nodes [a, b] (between two nodes)");
    }
    for (int k = 0; k < el.num_nodes; ++k)
      if (m->node_index(el.node_ids[k]) < 0) throw InputError(w + ": node " + std::to_string(el.node_ids[k]) + " does not exist");
    if (!o.has("dofs")) throw InputError(w + ": dofs is missing (e.g. ['rz'])");
    el.spring_dofs = dof_mask_from(o.take("dofs"), w + " dofs");
    if (!o.get("k", &el.stiffness) || !(el.stiffness > 0)) throw InputError(w + ": k is missing or not > 0");
    o.get("group", &el.group);
    o.finish();
    m->add_element(el);
  }
}

void set_mass_options(Model* m, const std::string& mass, bool rotary) {
  if (mass == "consistent") m->set_mass_type(MassType::Consistent);
  else if (mass == "lumped") m->set_mass_type(MassType::Lumped);
  else throw InputError("mass must be 'consistent' or 'lumped', got '" + mass + "'");
  m->set_rotary_inertia(rotary);
}

}  // namespace

std::shared_ptr<Model> model_from_arrays(py::array_t<double, py::array::c_style | py::array::forcecast> nodes,
                                         py::array_t<double, py::array::c_style | py::array::forcecast> elements,
                                         py::dict kw) {
  Options o(kw, "Model.from_arrays");
  auto m = std::make_shared<Model>();
  if (nodes.ndim() != 2 || (nodes.shape(1) != 2 && nodes.shape(1) != 3))
    throw InputError("Model.from_arrays: nodes must be an (n, 2) or (n, 3) array of coordinates");
  if (elements.ndim() != 2 || elements.shape(1) != 2)
    throw InputError("Model.from_arrays: elements must be an (e, 2) array of node ids (connectivity)");
  const auto nn = static_cast<std::size_t>(nodes.shape(0)), ne = static_cast<std::size_t>(elements.shape(0));
  std::vector<int> node_ids(nn), element_ids(ne);
  for (std::size_t k = 0; k < nn; ++k) node_ids[k] = static_cast<int>(k + 1);
  for (std::size_t k = 0; k < ne; ++k) element_ids[k] = static_cast<int>(k + 1);
  if (o.has("node_ids")) node_ids = o.take("node_ids").cast<std::vector<int>>();
  if (o.has("element_ids")) element_ids = o.take("element_ids").cast<std::vector<int>>();
  if (node_ids.size() != nn) throw InputError("Model.from_arrays: node_ids has " + std::to_string(node_ids.size()) + " ids for " + std::to_string(nn) + " nodes");
  if (element_ids.size() != ne)
    throw InputError("Model.from_arrays: element_ids has " + std::to_string(element_ids.size()) + " ids for " + std::to_string(ne) + " elements");
  auto X = nodes.unchecked<2>();
  for (std::size_t k = 0; k < nn; ++k) {
    const Eigen::Vector3d x(X(k, 0), X(k, 1), nodes.shape(1) == 3 ? X(k, 2) : 0.0);
    if (!x.allFinite()) throw InputError("Model.from_arrays: node " + std::to_string(node_ids[k]) + " has a non-finite coordinate");
    if (m->node_index(node_ids[k]) >= 0) throw InputError("Model.from_arrays: node " + std::to_string(node_ids[k]) + " is defined twice");
    m->add_node(node_ids[k], x);
  }
  std::vector<std::string> mat_names, sec_names;
  std::map<std::string, int> mat_index, sec_index;
  if (!o.has("materials")) throw InputError("Model.from_arrays: materials is missing (e.g. {'steel': {'E': 2.1e11, 'rho': 7850}})");
  for (auto kv : o.take("materials").cast<py::dict>()) {
    const std::string n = key_text(kv.first);
    mat_index[n] = m->add_material(material_from(n, kv.second));
    mat_names.push_back(n);
  }
  if (!o.has("sections")) throw InputError("Model.from_arrays: sections is missing (e.g. {'col': {'A': 5.3e-3, 'I': 8.1e-5}})");
  for (auto kv : o.take("sections").cast<py::dict>()) {
    const std::string n = key_text(kv.first);
    sec_index[n] = m->add_section(section_from(n, kv.second));
    sec_names.push_back(n);
  }
  const std::vector<int> emat = per_element(o.take("element_material"), ne, mat_names, mat_index, "material");
  const std::vector<int> esec = per_element(o.take("element_section"), ne, sec_names, sec_index, "section");
  std::string type_name = "frame2d";
  o.get("element", &type_name);
  const ElementType default_type = element_type_from(type_name, "Model.from_arrays element");
  std::vector<std::string> types, groups;
  if (o.has("element_types")) types = o.take("element_types").cast<std::vector<std::string>>();
  if (o.has("element_groups")) groups = o.take("element_groups").cast<std::vector<std::string>>();
  if (!types.empty() && types.size() != ne) throw InputError("Model.from_arrays: element_types needs one type per element");
  if (!groups.empty() && groups.size() != ne) throw InputError("Model.from_arrays: element_groups needs one group per element");
  Eigen::MatrixXd orient;
  if (o.has("element_orientation")) {
    orient = o.take("element_orientation").cast<Eigen::MatrixXd>();
    if (orient.rows() != static_cast<Eigen::Index>(ne) || orient.cols() != 3)
      throw InputError("Model.from_arrays: element_orientation must be (e, 3): a vector in each element's local x-z plane");
  }
  auto E = elements.unchecked<2>();
  for (std::size_t k = 0; k < ne; ++k) {
    Element el;
    el.id = element_ids[k];
    const std::string w = "element " + std::to_string(el.id);
    el.type = types.empty() ? default_type : element_type_from(types[k], w);
    for (int q = 0; q < 2; ++q) {
      const double v = E(k, q);
      if (v != std::floor(v) || m->node_index(static_cast<int>(v)) < 0)
        throw InputError("Model.from_arrays: " + w + ": node " + std::to_string(v) + " does not exist");
      el.node_ids[q] = static_cast<int>(v);
    }
    el.material = emat[k];
    el.section = esec[k];
    if (!groups.empty()) el.group = groups[k];
    if (orient.size()) el.orientation = orient.row(static_cast<Eigen::Index>(k)).transpose();
    if (m->element_index(el.id) >= 0) throw InputError("Model.from_arrays: " + w + " is defined twice");
    m->add_element(el);
  }
  add_point_masses(m.get(), o.take("point_masses"));
  add_springs(m.get(), o.take("springs"));
  add_supports(m.get(), o.take("supports"));
  std::string mass = "consistent";
  bool rotary = false;
  o.get("mass", &mass);
  o.get("rotary_inertia", &rotary);
  set_mass_options(m.get(), mass, rotary);
  o.finish();
  m->finalize();
  return m;
}

std::shared_ptr<Model> model_from_matrices(py::dict kw) {
  Options o(kw, "Model.from_matrices");
  MatrixModelData d;
  if (o.has("dofs")) {
    d.dofs_name = "dofs";
    for (py::handle x : o.take("dofs").cast<py::sequence>()) {
      const MeasuredDof md = to_dof(x, "Model.from_matrices dofs");
      d.dofs.push_back({md.node, md.dof});
    }
  }
  if (o.has("nodes")) {
    const Eigen::MatrixXd N = o.take("nodes").cast<Eigen::MatrixXd>();
    if (N.cols() != 3 && N.cols() != 4) throw InputError("Model.from_matrices: nodes must be (m, 3) or (m, 4): [id, x, y(, z)]");
    for (Eigen::Index i = 0; i < N.rows(); ++i)
      d.nodes.push_back(Node{static_cast<int>(N(i, 0)), Eigen::Vector3d(N(i, 1), N(i, 2), N.cols() == 4 ? N(i, 3) : 0.0)});
    d.nodes_name = "nodes";
  }
  if (o.has("K") != o.has("M")) throw InputError("Model.from_matrices: give both K and M (the assembled matrices), or neither");
  if (o.has("K")) {
    d.has_assembled = true;
    d.K = to_sparse(o.take("K"), "Model.from_matrices K");
    d.M = to_sparse(o.take("M"), "Model.from_matrices M");
  }
  if (o.has("groups")) {
    for (auto kv : o.take("groups").cast<py::dict>()) {
      MatrixModelData::Group g;
      g.name = key_text(kv.first);
      g.K_name = "group '" + g.name + "' K";
      g.M_name = "group '" + g.name + "' M";
      py::handle v = kv.second;
      if (py::isinstance<py::tuple>(v) || py::isinstance<py::list>(v)) {
        py::sequence s = py::reinterpret_borrow<py::sequence>(v);
        if (s.size() != 2) throw InputError("Model.from_matrices: group '" + g.name + "' must be (K, M) or a dict {K, M}");
        g.K = s[0].is_none() ? SparseMatrix() : to_sparse(s[0], g.K_name);
        g.M = s[1].is_none() ? SparseMatrix() : to_sparse(s[1], g.M_name);
      } else {
        Options go(py::reinterpret_borrow<py::dict>(v), "group '" + g.name + "'");
        if (go.has("K")) g.K = to_sparse(go.take("K"), g.K_name);
        if (go.has("M")) g.M = to_sparse(go.take("M"), g.M_name);
        go.finish();
      }
      d.groups.push_back(std::move(g));
    }
  }
  if (o.has("elements")) {
    int k = 0;
    for (py::handle x : o.take("elements").cast<py::sequence>()) {
      ++k;
      Options eo(py::reinterpret_borrow<py::dict>(x), "element " + std::to_string(k));
      ElementMatrices e;
      e.id = k;
      eo.get("id", &e.id);
      eo.get("group", &e.group);
      if (!eo.has("dofs")) throw InputError("element " + std::to_string(e.id) + ": dofs (0-based equations, or DOF labels) is missing");
      for (py::handle q : eo.take("dofs").cast<py::sequence>()) {
        if (py::isinstance<py::str>(q) || py::isinstance<py::tuple>(q)) {
          const MeasuredDof md = to_dof(q, "element " + std::to_string(e.id) + " dofs");
          int eq = -1;
          for (std::size_t i = 0; i < d.dofs.size(); ++i)
            if (d.dofs[i].node == md.node && d.dofs[i].dof == md.dof) eq = static_cast<int>(i);
          if (eq < 0) throw InputError("element " + std::to_string(e.id) + ": DOF " + to_string(md) + " is not in dofs");
          e.equations.push_back(eq);
        } else {
          e.equations.push_back(q.cast<int>());
        }
      }
      if (!eo.has("K") || !eo.has("M")) throw InputError("element " + std::to_string(e.id) + ": K and M are needed");
      e.K = eo.take("K").cast<Eigen::MatrixXd>();
      e.M = eo.take("M").cast<Eigen::MatrixXd>();
      if (eo.has("nodes")) e.nodes = eo.take("nodes").cast<std::vector<int>>();
      eo.finish();
      d.elements.push_back(std::move(e));
    }
  }
  // Defaults as for .mat files without tables: equation i is ux of node i, nodes at the origin.
  Eigen::Index size = d.has_assembled ? d.K.rows() : !d.groups.empty() ? std::max(d.groups[0].K.rows(), d.groups[0].M.rows()) : -1;
  if (d.dofs.empty()) {
    if (size < 0) throw InputError("Model.from_matrices: give dofs (one label per equation, e.g. '13uy') or K/M or groups");
    for (Eigen::Index i = 0; i < size; ++i) d.dofs.push_back({static_cast<int>(i + 1), Dof::UX});
  }
  if (d.nodes.empty()) {
    std::vector<int> ids;
    for (const DofRow& r : d.dofs) ids.push_back(r.node);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    for (int id : ids) d.nodes.push_back(Node{id, Eigen::Vector3d::Zero()});
  }
  auto m = std::make_shared<Model>();
  add_matrix_model(d, m.get(), nullptr);
  add_point_masses(m.get(), o.take("point_masses"));
  add_springs(m.get(), o.take("springs"));
  add_supports(m.get(), o.take("supports"));
  o.finish();
  m->finalize();
  return m;
}

void bind_model(py::module_& mod) {
  py::class_<Model, std::shared_ptr<Model>> model(mod, "Model", R"(A finalized structural model (nodes, elements, supports).

Build one with Model.from_arrays (NumPy node coordinates and connectivity), Model.from_matrices (assembled or
group/element matrices, SciPy sparse or NumPy) or dynid.load_case(path).model.)");
  model
      .def_static("_from_arrays", &model_from_arrays, py::arg("nodes"), py::arg("elements"), py::arg("options"))
      .def_static("_from_matrices", &model_from_matrices, py::arg("options"))
      .def_property_readonly("num_dofs", &Model::num_dofs, "Free DOFs (equations).")
      .def_property_readonly("num_elements", &Model::num_elements)
      .def_property_readonly("free_free", &Model::free_free)
      .def_property_readonly("warnings", &Model::warnings)
      .def_property_readonly("dofs", [](const Model& m) { return dof_labels(all_dofs(m)); },
                             "DOF labels of the equations, in equation order ('1ux', '1uy', ...).")
      .def_property_readonly("node_ids", [](const Model& m) {
        Eigen::VectorXi v(static_cast<Eigen::Index>(m.nodes().size()));
        for (std::size_t k = 0; k < m.nodes().size(); ++k) v[static_cast<Eigen::Index>(k)] = m.nodes()[k].id;
        return move_array(std::move(v));
      })
      .def_property_readonly("coordinates", [](const Model& m) {
        Eigen::MatrixXd X(static_cast<Eigen::Index>(m.nodes().size()), 3);
        for (std::size_t k = 0; k < m.nodes().size(); ++k) X.row(static_cast<Eigen::Index>(k)) = m.nodes()[k].x.transpose();
        return move_array(std::move(X));
      }, "Node coordinates, (n, 3).")
      .def_property_readonly("element_ids", [](const Model& m) {
        Eigen::VectorXi v(m.num_elements());
        for (int k = 0; k < m.num_elements(); ++k) v[k] = m.elements()[k].id;
        return move_array(std::move(v));
      })
      .def_property_readonly("element_nodes", [](const Model& m) {
        Eigen::MatrixXi v(m.num_elements(), 2);
        for (int k = 0; k < m.num_elements(); ++k) {
          const Element& e = m.elements()[k];
          v(k, 0) = e.node_ids[0];
          v(k, 1) = e.num_nodes > 1 ? e.node_ids[1] : -1;
        }
        return move_array(std::move(v));
      }, "Node ids of each element, (e, 2); -1 for one-node elements.")
      .def_property_readonly("element_types", [](const Model& m) {
        std::vector<std::string> t;
        for (const Element& e : m.elements()) t.emplace_back(element_type_name(e.type));
        return t;
      })
      .def_property_readonly("element_groups", [](const Model& m) {
        std::vector<std::string> t;
        for (const Element& e : m.elements()) t.push_back(e.group);
        return t;
      })
      .def("matrices", [](const Model& m) {
        AssembledSystem s;
        {
          py::gil_scoped_release nogil;
          s = assemble_system(m);
        }
        return py::make_tuple(from_sparse(s.K), from_sparse(s.M));
      }, "K and M on the free DOFs as scipy.sparse.csc_matrix (both triangles; copies).")
      .def("element_matrices", [](const Model& m, int id) {
        const int e = m.element_index(id);
        if (e < 0) throw InputError("element " + std::to_string(id) + " does not exist");
        Eigen::MatrixXd K, M;
        m.element_matrices(e, &K, &M);
        std::vector<int> eq;
        m.element_dofs(e, &eq);
        py::list labels;
        for (const auto& [node, dof] : m.element_dof_types(e)) labels.append(std::to_string(m.nodes()[node].id) + std::string(dof_name(dof)));
        py::dict d;
        d["K"] = move_array(std::move(K));
        d["M"] = move_array(std::move(M));
        d["equations"] = eq;
        d["dofs"] = labels;
        return d;
      }, py::arg("id"), "An element's K and M in global coordinates, its DOF labels and equations (-1 = restrained).")
      .def("equations", [](const Model& m, py::handle dofs) {
        return measured_equations(m, to_dofs(dofs, "equations", &m));
      }, py::arg("dofs"), "Equation numbers of DOF labels (0-based).")
      .def("changed", [](const Model& m, py::dict changes) {
        std::vector<std::pair<int, std::pair<double, double>>> ch;
        for (auto kv : changes) {
          auto v = kv.second.cast<std::pair<double, double>>();
          ch.push_back({kv.first.cast<int>(), v});
        }
        return std::make_shared<Model>(changed_model(m, ch));
      }, py::arg("changes"), "A copy with element changes {id: (dk, dm)} (fractions: -0.15 = 15 % loss).")
      .def("with_factors", [](const Model& m, py::dict factors) {
        std::vector<std::pair<int, PropertyFactors>> ch;
        for (auto kv : factors) {
          Options fo(py::reinterpret_borrow<py::dict>(kv.second), "factors of element " + key_text(kv.first));
          PropertyFactors f;
          fo.get("E", &f.E);
          fo.get("rho", &f.rho);
          fo.get("A", &f.A);
          fo.get("I", &f.I);
          fo.finish();
          ch.push_back({kv.first.cast<int>(), f});
        }
        return std::make_shared<Model>(apply_factors(m, ch));
      }, py::arg("factors"), "A copy with property factors {id: {'E': 0.9, 'rho': 1.1}} (1 = nominal).")
      .def("__repr__", [](const Model& m) {
        return "<dynid.Model: " + std::to_string(m.nodes().size()) + " nodes, " + std::to_string(m.num_elements()) +
               " elements, " + std::to_string(m.num_dofs()) + " DOFs>";
      });

  py::class_<Case, std::shared_ptr<Case>>(mod, "Case", "A case file: its model and the sections it has (docs/case-file.md).")
      .def_readonly("name", &Case::name)
      .def_readonly("path", &Case::path)
      .def_readonly("dir", &Case::dir)
      .def_readonly("description", &Case::description)
      .def_readonly("notes", &Case::notes)
      .def_property_readonly("model", [](std::shared_ptr<Case> c) { return std::shared_ptr<Model>(c, &c->model); },
                             "The case's model (shares the case; no copy).")
      .def_property_readonly("sections", [](const Case& c) {
        std::vector<std::string> s = {"model", "analysis"};
        if (c.detect) s.push_back("detect");
        if (c.update) s.push_back("update");
        if (c.test) s.push_back("test");
        if (c.discover) s.push_back("discover");
        return s;
      })
      .def("__repr__", [](const Case& c) { return "<dynid.Case '" + c.name + "' (" + c.path + ")>"; });

  mod.def("load_case", [](const std::filesystem::path& path) { return std::make_shared<Case>(load_case(path.string())); }, py::arg("path"),
          "Loads a case file, or a folder with case.yaml (docs/case-file.md).");
  mod.def("_model_from_case_text", [](const std::string& text, const std::string& name) {
    auto c = std::make_shared<Case>(parse_case(text, name, "."));
    return std::shared_ptr<Model>(c, &c->model);
  });
  mod.def("_case_with_model", [](std::shared_ptr<Model> m, const std::string& text, const std::string& name, const std::string& dir) {
    return std::make_shared<Case>(case_with_model(*m, text, name, dir));
  });
}

}  // namespace dynid::python
