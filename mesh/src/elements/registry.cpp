// The element registry (one line per element type, in ElementType order) and what the kinds share.
#include <sstream>

#include "dynid/mesh/error.hpp"
#include "dynid/mesh/model.hpp"
#include "internal/element_kinds.hpp"

namespace dynid {

const std::vector<const ElementKind*>& element_kinds() {
  static const std::vector<const ElementKind*> kinds = {
      &internal::beam2d_kind(),      // ElementType::Beam2D
      &internal::frame2d_kind(),     // ElementType::Frame2D
      &internal::frame3d_kind(),     // ElementType::Frame3D
      &internal::point_mass_kind(),  // ElementType::PointMass
      &internal::spring_kind(),      // ElementType::Spring
      &internal::matrix_kind(),      // ElementType::Matrix
  };
  return kinds;
}

const ElementKind& element_kind(ElementType t) {
  const auto& kinds = element_kinds();
  const auto i = static_cast<std::size_t>(t);
  if (i >= kinds.size() || kinds[i]->type() != t)
    throw InternalError("element_kind: element type " + std::to_string(i) + " is not registered in its place");
  return *kinds[i];
}

std::string_view element_type_name(ElementType t) { return element_kind(t).name(); }

bool parse_element_type(std::string_view name, ElementType* out) {
  for (const ElementKind* k : element_kinds())
    if (k->name() == name) {
      *out = k->type();
      return true;
    }
  return false;
}

void ElementKind::matrices(const Model& m, int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const {
  const ElementParts p = parts(m, e);
  if (K) *K = p.K();
  if (M) *M = p.M();
}

bool ElementKind::coupling(const Model&, int, const std::vector<std::pair<int, Dof>>&,
                           std::vector<std::pair<int, int>>* pairs) const {
  pairs->clear();
  return false;
}

Eigen::MatrixXd ElementKind::unit_geometric_stiffness(const Model& m, int e) const {
  throw InputError("element " + std::to_string(m.elements()[e].id) +
                   ": only beams and frames have a geometric stiffness");
}

std::vector<BendingPlane> ElementKind::bending_planes(const Model& m, int e) const {
  throw InputError("element " + std::to_string(m.elements()[e].id) + ": only beams and frames have bending planes");
}

Eigen::MatrixXd ElementKind::point_interpolation(const Model& m, int e, double, Eigen::MatrixXd*) const {
  throw InputError("element " + std::to_string(m.elements()[e].id) + ": only beams and frames have a member axis");
}

double ElementKind::axial_force(const Model&, int, const Eigen::VectorXd&) const { return 0.0; }

namespace internal {

std::string element_label(const Element& e) {
  return "element " + std::to_string(e.id) + " (" + std::string(element_type_name(e.type)) + ")";
}

bool finite_positive(double v) { return std::isfinite(v) && v > 0; }

std::string fmt_num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void setup_ends(const ElementSetup& s) {
  const Element& e = s.element;
  if (e.num_nodes < 1 || e.num_nodes > 2) throw InputError(s.who + ": must have 1 or 2 nodes");
  for (int a = 0; a < e.num_nodes; ++a) {
    const int n = s.model.node_index(e.node_ids[a]);
    if (n < 0) throw InputError(s.who + ": node " + std::to_string(e.node_ids[a]) + " does not exist");
    (*s.nodes)[a] = n;
  }
  for (double f : {e.factors.E, e.factors.rho, e.factors.A, e.factors.I})
    if (!finite_positive(f)) throw InputError(s.who + ": property factors must be finite and > 0");
}

std::vector<std::pair<int, Dof>> node_major_layout(const Model& m, int e, DofMask mask) {
  std::vector<std::pair<int, Dof>> out;
  for (int a = 0; a < m.elements()[e].num_nodes; ++a)
    for (int t = 0; t < kNumDofTypes; ++t)
      if (mask & (1u << t)) out.emplace_back(m.element_nodes(e)[a], static_cast<Dof>(t));
  return out;
}

void zero_parts(Eigen::Index n, ElementParts* p) {
  for (Eigen::MatrixXd* a : {&p->K_axial, &p->K_bending, &p->K_torsion, &p->K_discrete, &p->K_geometric,
                             &p->M_translational, &p->M_rotary, &p->M_discrete})
    a->setZero(n, n);
}

}  // namespace internal
}  // namespace dynid
