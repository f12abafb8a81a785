// axial_preload and distributed_mass: effects spread over all members or one element group (a tension or
// compression the model leaves out; non-structural mass such as slabs, cladding, fittings).
#include <algorithm>
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

// A preload's axial forces per unit of the group's mean force: the self-stress of a lack of fit in the group
// (SelfStress::preload), so that a tensioned tie also compresses the members it pulls on; members that carry none
// are left out. Without a static state (beam2d lines, free-free models, mechanisms): the group alone, uniformly.
struct PreloadState {
  std::vector<int> els;
  std::vector<double> force;
};

// sum_e n_e int N'^T N' (the consistent geometric stiffness of the state n). Unit: the group's mean force that
// shifts the band's eigenvalues by 100 % in all, to first order (1 / sum_r |phi_r^T G phi_r| / omega_r^2, G the
// state's geometric stiffness per unit force): a tie rod the data's modes hardly feel needs a large force, a strip
// a small one, whatever the mesh. Without a band that feels the state: the Euler load pi^2 EI / Lg^2 of the
// group's extent Lg. Either sign stops at 0.9 of the band's first-order buckling load of the state (a tie's
// tension compresses its neighbours; compression of the group alone), and compression also at 0.9 of that Euler
// load.
class AxialPreload : public OnElements {
 public:
  AxialPreload(const CandidateContext& c, std::string group, std::vector<int> els, PreloadState state)
      : OnElements(*c.model, std::move(group), std::move(els)), state_(std::move(state)) {
    const Model& m = *c.model;
    double EI = 0;
    Eigen::Vector3d a = Eigen::Vector3d::Constant(1e300), b = -a;
    for (int e : els_) {
      const Member mb = member(m, e);
      EI += mb.EI / static_cast<double>(els_.size());
      if (mb.EA > 0) ea_ = std::min(ea_, mb.EA);
      for (int k = 0; k < 2; ++k) {
        a = a.cwiseMin(m.nodes()[m.element_nodes(e)[k]].x);
        b = b.cwiseMax(m.nodes()[m.element_nodes(e)[k]].x);
      }
    }
    Eigen::VectorXd sens = Eigen::VectorXd::Zero(c.band_modes.cols());
    std::vector<int> dofs;
    for (std::size_t k = 0; k < state_.els.size() && sens.size() > 0; ++k) {
      const int e = state_.els[k];
      m.element_dofs(e, &dofs);
      const Eigen::MatrixXd G = state_.force[k] * m.unit_geometric_stiffness(e);
      Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dofs.size()), sens.size());
      for (std::size_t i = 0; i < dofs.size(); ++i)
        if (dofs[i] >= 0) phi.row(static_cast<Eigen::Index>(i)) = c.band_modes.row(dofs[i]);
      sens += (phi.transpose() * G * phi).diagonal();
    }
    const double Lg = std::max((b - a).norm(), 1e-12);
    const double euler = M_PI * M_PI * EI / (Lg * Lg);
    pref_ = euler;
    double lower = -0.9 * euler, upper = 100 * euler;
    if (sens.size() > 0) {
      sens = sens.cwiseQuotient(c.band_eigenvalues);
      if (sens.cwiseAbs().sum() > 0) {
        pref_ = 1.0 / sens.cwiseAbs().sum();
        upper = 100 * pref_;
        if (sens.maxCoeff() > 0) lower = std::max(lower, -0.9 / sens.maxCoeff());
        if (sens.minCoeff() < 0) upper = std::min(upper, 0.9 / -sens.minCoeff());
      }
    }
    lower_ = lower / pref_;
    upper_ = upper / pref_;
  }
  std::string kind() const override { return "axial_preload"; }
  /// A tension that stretches the group's weakest member by more than kMaxPreloadStrain is no preload a
  /// structure carries (steel yields near 0.2 %, prestressing tendons near 0.9 %); compression stops at buckling.
  bool plausible(const Eigen::VectorXd& th) const override { return pref_ * th[0] <= kMaxPreloadStrain * ea_; }
  Nature nature() const override { return Nature::kStiffness; }
  std::string description() const override { return "axial preload (geometric stiffness) in " + group_words(group_); }
  std::vector<CandidateParameter> parameters() const override {
    return {{"force", 0.0, lower_, upper_, 1.0, CandidateParameter::Prior::kHeavyTailed}};
  }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (std::size_t k = 0; k < state_.els.size(); ++k) {
      const int e = state_.els[k];
      std::vector<int> dofs;
      m.element_dofs(e, &dofs);
      out.push_back(linear_term(dofs, pref_ * state_.force[k] * m.unit_geometric_stiffness(e), {}, first));
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
  PreloadState state_;
  double pref_ = 1, lower_ = -0.9, upper_ = 100;
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

// One candidate on all members and on each group: `make(group, elements)` gives it, or nullptr where the group
// cannot have one.
template <class Make>
std::vector<std::unique_ptr<Candidate>> per_group(const CandidateContext& c, const Make& make) {
  std::vector<std::unique_ptr<Candidate>> out;
  for (const std::string& g : member_groups(*c.model)) {
    std::vector<int> els = group_members(*c.model, g);
    if (els.empty()) continue;
    if (std::unique_ptr<Candidate> x = make(g, std::move(els))) out.push_back(std::move(x));
  }
  return out;
}

// Whether the structure can hold a preload in the members `els`, and the forces it would carry. A preload is a
// self-stress: a lack of fit in those members (fit-up, shrinkage, a tensioned tie) that meets a restraint. Static
// analysis K u = f of a unit axial strain imposed on them (f = sum K_axial,e u_e^0, u_e^0 the element's free
// elongation), then the axial force left in them, N_e = E A (elongation / L - 1), against E A (the force when fully
// restrained), and in every other member, N_e = E A elongation / L (the neighbours a tie pulls on). A cantilever,
// a mast or a beam on a roller expands freely: N = 0 to rounding, so no preload can act there (and a strut
// bracing it is not mistaken for one). Below 1e-4 of the restrained force the strain needed for any force
// becomes implausible; rounding stays far below that. Members without axial DOFs (beam2d) cannot say: a
// preload then needs at least two supported nodes to react against, and acts on the group alone.
class SelfStress {
 public:
  // support: the model's support restraints per node (CandidateContext::support).
  SelfStress(const Model& m, const std::vector<DofMask>& support)
      : m_(m),
        supported_(static_cast<int>(std::count_if(support.begin(), support.end(), [](DofMask s) { return s != 0; }))) {
    if (m.free_free() || m.num_dofs() == 0) return;
    const AssembledSystem sys = assemble_system(m);
    factor_.emplace();
    factor_->analyze(sys.K);
    if (!factor_->factorize(sys.K)) factor_.reset();  // a mechanism: no static state to speak of
  }
  /// The state per unit mean tension in `els` (length-weighted), or nothing when they cannot hold a preload.
  std::optional<PreloadState> preload(const std::vector<int>& els) const {
    const PreloadState alone{els, std::vector<double>(els.size(), 1.0)};
    Eigen::VectorXd f = Eigen::VectorXd::Zero(m_.num_dofs());
    std::vector<Eigen::VectorXd> free_elongation(static_cast<std::size_t>(m_.num_elements()));
    double restrained = 0;
    for (int e : els) {
      const auto types = m_.element_dof_types(e);
      const Eigen::Vector3d a = m_.nodes()[m_.element_nodes(e)[0]].x,
                            axis = (m_.nodes()[m_.element_nodes(e)[1]].x - a).normalized();
      Eigen::VectorXd u0 = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(types.size()));
      for (std::size_t i = 0; i < types.size(); ++i) {
        const int t = static_cast<int>(types[i].second);
        if (t < 3) u0[static_cast<Eigen::Index>(i)] = (m_.nodes()[types[i].first].x - a).dot(axis) * axis[t];
      }
      restrained = std::max(restrained, std::abs(m_.member_axial_force(e, u0)));
      const Eigen::VectorXd fe = m_.element_parts(e).K_axial * u0;
      std::vector<int> dofs;
      m_.element_dofs(e, &dofs);
      for (std::size_t i = 0; i < dofs.size(); ++i)
        if (dofs[i] >= 0) f[dofs[i]] += fe[static_cast<Eigen::Index>(i)];
      free_elongation[static_cast<std::size_t>(e)] = std::move(u0);
    }
    if (!(restrained > 0)) {  // no axial DOFs
      return supported_ >= 2 ? std::optional<PreloadState>(alone) : std::nullopt;
    }
    if (!factor_) return alone;  // free-free or a mechanism: cannot say, keep the candidate
    Eigen::VectorXd u(f.size());
    factor_->solve(f.data(), u.data());
    // Axial force of every member in the expansion's state; the group's (compression) from its restrained part.
    PreloadState state;
    double left = 0, mean = 0, length = 0, largest = 0;
    std::vector<int> dofs;
    for (int e = 0; e < m_.num_elements(); ++e) {
      if (!is_member(m_.elements()[e].type)) continue;
      m_.element_dofs(e, &dofs);
      const Eigen::VectorXd& u0 = free_elongation[static_cast<std::size_t>(e)];
      Eigen::VectorXd ue =
          u0.size() > 0 ? Eigen::VectorXd(-u0) : Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dofs.size()));
      for (std::size_t i = 0; i < dofs.size(); ++i)
        if (dofs[i] >= 0) ue[static_cast<Eigen::Index>(i)] += u[dofs[i]];
      const double N = m_.member_axial_force(e, ue);
      if (u0.size() > 0) {
        const double L = (m_.nodes()[m_.element_nodes(e)[1]].x - m_.nodes()[m_.element_nodes(e)[0]].x).norm();
        left = std::max(left, std::abs(N));
        mean += N * L;
        length += L;
      }
      largest = std::max(largest, std::abs(N));
      state.els.push_back(e);
      state.force.push_back(N);
    }
    if (!(left > 1e-4 * restrained)) return std::nullopt;
    mean /= length;
    // A group whose members' forces cancel on average (one pushed, one pulled) has no mean to scale by: alone.
    if (!(std::abs(mean) > 1e-4 * restrained)) return alone;
    // The lack of fit sits where its self-stress is largest: when a member outside the group carries more than
    // every member of it (a tie that closes a loop with one of the group's beams), the same forces are the
    // lack of fit of that member's group, not of this one, and the group gets no candidate.
    if (!(left >= (1 - 1e-6) * largest)) return std::nullopt;
    PreloadState out;
    for (std::size_t k = 0; k < state.els.size(); ++k)
      if (std::abs(state.force[k]) > 1e-9 * largest) {
        out.els.push_back(state.els[k]);
        out.force.push_back(state.force[k] / mean);  // a shortening: tension in the group, mean 1
      }
    return out;
  }

 private:
  const Model& m_;
  int supported_;  // nodes with a support restraint
  std::optional<CholmodFactor> factor_;
};

}  // namespace

CandidateKind axial_preload_kind() {
  return {"axial_preload", Nature::kStiffness, "an axial force (geometric stiffness) in all members or one group",
          [](const CandidateContext& c) {
            const SelfStress self_stress(*c.model, c.support);
            return per_group(c, [&](const std::string& g, std::vector<int> els) -> std::unique_ptr<Candidate> {
              std::optional<PreloadState> state = self_stress.preload(els);
              if (!state) return nullptr;
              return std::make_unique<AxialPreload>(c, g, std::move(els), std::move(*state));
            });
          }};
}

CandidateKind distributed_mass_kind() {
  return {"distributed_mass", Nature::kMass, "non-structural mass spread over all members or one group",
          [](const CandidateContext& c) {
            return per_group(c, [&](const std::string& g, std::vector<int> els) -> std::unique_ptr<Candidate> {
              return std::make_unique<NonStructuralMass>(c, g, std::move(els));
            });
          }};
}

}  // namespace dynid::internal
