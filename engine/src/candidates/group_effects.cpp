// axial_preload and distributed_mass: effects spread over all members or one element group (a tension or
// compression the model leaves out; non-structural mass such as slabs, cladding, fittings).
#include <cmath>
#include <optional>

#include "candidates/common.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/solvers/cholmod.hpp"

namespace dynid::internal {
namespace {

// A global candidate acting on a set of elements (all members, or a group): its site is those elements.
class OnElements : public Candidate {
 public:
  OnElements(const Model& m, std::string group, std::vector<int> els) : group_(std::move(group)), els_(std::move(els)) {
    for (int e : els_) site_.elements.push_back(m.elements()[e].id);
  }
  Site site() const override { return site_; }
  bool global() const override { return true; }

 protected:
  std::string group_;
  std::vector<int> els_;

 private:
  Site site_;
};

// The largest axial strain a preload may stretch a member by (AxialPreload::plausible).
constexpr double kMaxPreloadStrain = 0.01;

// P int N'^T N' (the consistent geometric stiffness) on every element of the group. Unit: the force that shifts
// the band's eigenvalues by 100 % in all, to first order (1 / sum_r phi_r^T G phi_r / omega_r^2, G the group's
// geometric stiffness per unit force): a tie rod the data's modes hardly feel needs a large force, a strip a
// small one, whatever the mesh. Without a band that feels the group: the Euler load pi^2 EI / Lg^2 of the group's
// extent Lg. Compression stops at 0.9 of the lower of that Euler load and the band's first-order buckling load.
class AxialPreload : public OnElements {
 public:
  AxialPreload(const CandidateContext& c, std::string group, std::vector<int> els)
      : OnElements(*c.model, std::move(group), std::move(els)) {
    const Model& m = *c.model;
    double EI = 0;
    Eigen::Vector3d a = Eigen::Vector3d::Constant(1e300), b = -a;
    Eigen::VectorXd sens = Eigen::VectorXd::Zero(c.band_modes.cols());
    std::vector<int> dofs;
    for (int e : els_) {
      const Member mb = member(m, e);
      EI += mb.EI / static_cast<double>(els_.size());
      if (mb.EA > 0) ea_ = std::min(ea_, mb.EA);
      for (int k = 0; k < 2; ++k) {
        a = a.cwiseMin(m.nodes()[m.element_nodes(e)[k]].x);
        b = b.cwiseMax(m.nodes()[m.element_nodes(e)[k]].x);
      }
      if (sens.size() == 0) continue;
      m.element_dofs(e, &dofs);
      const Eigen::MatrixXd G = m.unit_geometric_stiffness(e);
      Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dofs.size()), sens.size());
      for (std::size_t i = 0; i < dofs.size(); ++i)
        if (dofs[i] >= 0) phi.row(static_cast<Eigen::Index>(i)) = c.band_modes.row(dofs[i]);
      sens += (phi.transpose() * G * phi).diagonal();
    }
    const double Lg = std::max((b - a).norm(), 1e-12);
    const double euler = M_PI * M_PI * EI / (Lg * Lg);
    pref_ = euler;
    double buckling = euler;
    if (sens.size() > 0) {
      sens = sens.cwiseQuotient(c.band_eigenvalues);
      if (sens.sum() > 0) {
        pref_ = 1.0 / sens.sum();
        buckling = std::min(euler, 1.0 / sens.maxCoeff());
      }
    }
    lower_ = -0.9 * buckling / pref_;
  }
  std::string kind() const override { return "axial_preload"; }
  /// A tension that stretches the group's weakest member by more than kMaxPreloadStrain is no preload a
  /// structure carries (steel yields near 0.2 %, prestressing tendons near 0.9 %); compression stops at buckling.
  bool plausible(const Eigen::VectorXd& th) const override { return pref_ * th[0] <= kMaxPreloadStrain * ea_; }
  Nature nature() const override { return Nature::kStiffness; }
  std::string description() const override { return "axial preload (geometric stiffness) in " + group_words(group_); }
  std::vector<CandidateParameter> parameters() const override {
    return {{"force", 0.0, lower_, 100.0, 1.0, CandidateParameter::Prior::kHeavyTailed}};
  }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      std::vector<int> dofs;
      m.element_dofs(e, &dofs);
      out.push_back(linear_term(dofs, pref_ * m.unit_geometric_stiffness(e), {}, first));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"axial force", "N", pref_ * th[0], pref_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return group_words(group_) + (v[0].value >= 0 ? " carry an axial tension" : " carry an axial compression") +
           " the model leaves out: " + with_std(PhysicalValue{v[0].name, v[0].unit, std::abs(v[0].value), v[0].std});
  }

 private:
  double pref_ = 1, lower_ = -0.9;
  double ea_ = INFINITY;  // the group's smallest E A
};

// Translational mass rho A int N^T N added in proportion to the members' own: a fraction of the group's mass.
class NonStructuralMass : public OnElements {
 public:
  NonStructuralMass(const CandidateContext& c, std::string group, std::vector<int> els)
      : OnElements(*c.model, std::move(group), std::move(els)) {
    const Model& m = *c.model;
    double len = 0;
    for (int e : els_) {
      const Member mb = member(m, e);
      mass_ += mb.rhoA * mb.L;
      len += mb.L;
    }
    per_length_ = mass_ / std::max(len, 1e-300);
  }
  std::string kind() const override { return "distributed_mass"; }
  Nature nature() const override { return Nature::kMass; }
  std::string description() const override { return "distributed non-structural mass on " + group_words(group_); }
  std::vector<CandidateParameter> parameters() const override { return {{"fraction", 0.0, 0.0, 5.0, 0.5, CandidateParameter::Prior::kHeavyTailed}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      const Member mb = member(m, e);
      out.push_back(linear_term(mb.dofs, {}, mb.Mt, first));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"mass per length", "kg/m", per_length_ * th[0], per_length_ * sd[0]}, {"total", "kg", mass_ * th[0], mass_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return group_words(group_) + " carry non-structural mass (cladding, fittings, payload): " + with_std(v[0]) + " (" +
           fmt_value(v[1].value, 3) + " kg in all)";
  }

 private:
  double mass_ = 0, per_length_ = 0;
};

// One candidate C on all members and on each group, for the groups `admits` (elements -> bool) lets through.
template <class C, class Admits>
std::vector<std::unique_ptr<Candidate>> per_group(const CandidateContext& c, const Admits& admits) {
  std::vector<std::unique_ptr<Candidate>> out;
  for (const std::string& g : member_groups(*c.model)) {
    std::vector<int> els = group_members(*c.model, g);
    if (!els.empty() && admits(els)) out.push_back(std::make_unique<C>(c, g, std::move(els)));
  }
  return out;
}

// Whether the structure can hold a preload in the members `els`. A preload is a self-stress: a lack of fit in
// those members (fit-up, shrinkage, a tensioned tie) that meets a restraint. Static analysis K u = f of a unit
// axial strain imposed on them (f = sum K_axial,e u_e^0, u_e^0 the element's free elongation), then the axial
// force left in them, N_e = E A (elongation / L - 1), against E A (the force when fully restrained). A cantilever,
// a mast or a beam on a roller expands freely: N = 0 to rounding, so no preload can act there (and a strut
// bracing it is not mistaken for one). Below 1e-4 of the restrained force the strain needed for any force
// becomes implausible; rounding stays far below that. Members without axial DOFs (beam2d) cannot say: a
// preload then needs at least two supported nodes to react against.
class SelfStress {
 public:
  explicit SelfStress(const Model& m) : m_(m) {
    if (m.free_free() || m.num_dofs() == 0) return;
    const AssembledSystem sys = assemble_system(m);
    factor_.emplace();
    factor_->analyze(sys.K);
    if (!factor_->factorize(sys.K)) factor_.reset();  // a mechanism: no static state to speak of
  }
  bool holds(const std::vector<int>& els) const {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(m_.num_dofs());
    std::vector<Eigen::VectorXd> free_elongation;
    std::vector<std::vector<int>> element_dofs(els.size());
    double restrained = 0;
    for (std::size_t k = 0; k < els.size(); ++k) {
      const int e = els[k];
      const auto types = m_.element_dof_types(e);
      const auto& n = m_.element_nodes(e);
      const Eigen::Vector3d a = m_.nodes()[n[0]].x, axis = (m_.nodes()[n[1]].x - a).normalized();
      Eigen::VectorXd u0 = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(types.size()));
      for (std::size_t i = 0; i < types.size(); ++i) {
        const int t = static_cast<int>(types[i].second);
        if (t < 3) u0[static_cast<Eigen::Index>(i)] = (m_.nodes()[types[i].first].x - a).dot(axis) * axis[t];
      }
      restrained = std::max(restrained, std::abs(m_.member_axial_force(e, u0)));
      const Eigen::VectorXd fe = m_.element_parts(e).K_axial * u0;
      std::vector<int>& dofs = element_dofs[k];
      m_.element_dofs(e, &dofs);
      for (std::size_t i = 0; i < dofs.size(); ++i)
        if (dofs[i] >= 0) f[dofs[i]] += fe[static_cast<Eigen::Index>(i)];
      free_elongation.push_back(std::move(u0));
    }
    if (!(restrained > 0)) {  // no axial DOFs
      int supported = 0;
      for (int k = 0; k < static_cast<int>(m_.nodes().size()); ++k) supported += m_.dof_map().restrained(k) != 0;
      return supported >= 2;
    }
    if (!factor_) return true;  // free-free or a mechanism: cannot say, keep the candidate
    Eigen::VectorXd u(f.size());
    factor_->solve(f.data(), u.data());
    double left = 0;
    for (std::size_t k = 0; k < els.size(); ++k) {
      const std::vector<int>& dofs = element_dofs[k];
      Eigen::VectorXd ue = -free_elongation[k];
      for (std::size_t i = 0; i < dofs.size(); ++i)
        if (dofs[i] >= 0) ue[static_cast<Eigen::Index>(i)] += u[dofs[i]];
      left = std::max(left, std::abs(m_.member_axial_force(els[k], ue)));
    }
    return left > 1e-4 * restrained;
  }

 private:
  const Model& m_;
  std::optional<CholmodFactor> factor_;
};

}  // namespace

CandidateKind axial_preload_kind() {
  return {"axial_preload", Nature::kStiffness, "an axial force (geometric stiffness) in all members or one group",
          [](const CandidateContext& c) {
            const SelfStress self_stress(*c.model);
            return per_group<AxialPreload>(c, [&](const std::vector<int>& els) { return self_stress.holds(els); });
          }};
}

CandidateKind distributed_mass_kind() {
  return {"distributed_mass", Nature::kMass, "non-structural mass spread over all members or one group",
          [](const CandidateContext& c) {
            return per_group<NonStructuralMass>(c, [](const std::vector<int>&) { return true; });
          }};
}

}  // namespace dynid::internal
