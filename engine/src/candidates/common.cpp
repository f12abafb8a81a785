#include "candidates/common.hpp"

#include <cmath>
#include <set>
#include <sstream>

namespace dynid {

const char* to_string(Nature n) {
  switch (n) {
    case Nature::kStiffness: return "stiffness";
    case Nature::kMass: return "mass";
    case Nature::kBoth: return "stiffness and mass";
  }
  return "?";
}

std::vector<int> install_candidates(ParametricModel* pm, const std::vector<const Candidate*>& set) {
  std::vector<int> first;
  for (const Candidate* c : set) {
    first.push_back(pm->num_parameters());
    for (const CandidateParameter& q : c->parameters()) {
      Parameter p;
      p.name = c->kind() + "." + q.name;
      p.kind = ParameterKind::kCustom;
      p.nominal = q.nominal;
      p.lower = q.lower;
      p.upper = q.upper;
      p.scale = q.prior_scale > 0 ? q.prior_scale : q.upper - q.lower;
      pm->add(p);
    }
  }
  for (std::size_t k = 0; k < set.size(); ++k)
    for (CustomTerm& t : set[k]->terms(pm->model(), first[k])) pm->add_term(std::move(t));
  return first;
}

}  // namespace dynid

namespace dynid::internal {

std::string fmt_value(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

std::string with_std(const PhysicalValue& v) {
  std::string s = fmt_value(v.value, 3) + (v.unit.empty() ? "" : " " + v.unit);
  if (std::isfinite(v.std) && v.value != 0) s += " ± " + fmt_value(100.0 * std::abs(v.std / v.value), 2) + " %";
  return s;
}

CustomTerm linear_term(std::vector<int> dofs, Eigen::MatrixXd AK, Eigen::MatrixXd AM, int param) {
  CustomTerm t;
  t.dofs = std::move(dofs);
  t.params = {param};
  t.eval = [AK = std::move(AK), AM = std::move(AM)](const Eigen::VectorXd& th, Eigen::MatrixXd* dK, Eigen::MatrixXd* dM,
                                                    std::vector<Eigen::MatrixXd>* dKd, std::vector<Eigen::MatrixXd>* dMd) {
    if (dK && AK.size()) *dK = th[0] * AK;
    if (dM && AM.size()) *dM = th[0] * AM;
    if (dKd) *dKd = {AK};
    if (dMd) *dMd = {AM};
  };
  return t;
}

Member member(const Model& model, int e) {
  Member m;
  m.e = e;
  model.element_dofs(e, &m.dofs);
  m.types = model.element_dof_types(e);
  const ElementParts p = model.element_parts(e);
  m.Ks = p.K_axial + p.K_bending + p.K_torsion + p.K_discrete;
  m.K = m.Ks + p.K_geometric;
  m.M = p.M_translational + p.M_rotary + p.M_discrete;
  m.Kb = p.K_bending;
  m.Mt = p.M_translational;
  const Element& el = model.elements()[e];
  if (!is_member(el.type)) return m;  // springs, point masses, matrix elements: matrices only
  const Material& mat = model.materials()[el.material];
  const Section& sec = model.sections()[el.section];
  const auto& n = model.element_nodes(e);
  m.L = (model.nodes()[n[1]].x - model.nodes()[n[0]].x).norm();
  m.EI = mat.E * el.factors.E * sec.Iz * el.factors.I;
  m.EA = mat.E * el.factors.E * sec.A * el.factors.A;
  m.GA = mat.shear_modulus() * el.factors.E * sec.A * el.factors.A;
  m.rhoA = mat.rho * el.factors.rho * sec.A * el.factors.A;
  m.rhoI = mat.rho * el.factors.rho * sec.Iz * el.factors.I;
  return m;
}

double translational_mass(const Model& model, int e) {
  const auto types = model.element_dof_types(e);
  Eigen::MatrixXd M;
  model.element_matrices(e, nullptr, &M);
  double best = 0;
  for (int d = 0; d < 3; ++d) {
    Eigen::VectorXd r = Eigen::VectorXd::Zero(M.rows());
    for (std::size_t i = 0; i < types.size(); ++i) r[static_cast<Eigen::Index>(i)] = static_cast<int>(types[i].second) == d ? 1.0 : 0.0;
    best = std::max(best, r.dot(M * r));
  }
  return best;
}

std::vector<int> group_members(const Model& m, const std::string& g) {
  std::vector<int> out;
  for (int e = 0; e < m.num_elements(); ++e)
    if (is_member(m.elements()[e].type) && (g.empty() || m.elements()[e].group == g)) out.push_back(e);
  return out;
}

std::vector<std::string> member_groups(const Model& m) {
  std::set<std::string> groups;
  for (int e : group_members(m, "")) groups.insert(m.elements()[e].group);
  std::vector<std::string> out = {""};
  if (groups.size() > 1)
    for (const std::string& g : groups)
      if (!g.empty()) out.push_back(g);
  return out;
}

std::string group_words(const std::string& g) { return g.empty() ? "all members" : "the members of group '" + g + "'"; }

std::vector<DofMask> support_restraints(const Model& m) {
  const int nn = static_cast<int>(m.nodes().size());
  DofMask everywhere = 0;
  for (int t = 0; t < kNumDofTypes; ++t) {
    const DofMask b = static_cast<DofMask>(1u << t);
    int active = 0, restrained = 0;
    for (int n = 0; n < nn; ++n) {
      if (!(m.dof_map().active(n) & b)) continue;
      ++active;
      restrained += (m.dof_map().restrained(n) & b) != 0;
    }
    if (active > 1 && restrained == active) everywhere |= b;
  }
  std::vector<DofMask> out(static_cast<std::size_t>(nn));
  for (int n = 0; n < nn; ++n)
    out[static_cast<std::size_t>(n)] =
        static_cast<DofMask>(m.dof_map().active(n) & m.dof_map().restrained(n) & ~everywhere);
  return out;
}

}  // namespace dynid::internal
