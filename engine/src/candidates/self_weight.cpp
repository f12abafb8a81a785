// self_weight: the axial forces of the structure's own weight (the geometric stiffness of a static analysis
// under gravity), which soften slender columns and stiffen hangers. Unlike a uniform preload, the forces vary
// member by member as the static analysis distributes them (larger in the lower columns of a frame). Parameter:
// the load factor on the weight (1 = the model's own mass under gravity; more when dead loads without their mass
// in the model, or a heavier structure, act).
#include <cmath>

#include "candidates/common.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/solvers/cholmod.hpp"

namespace dynid::internal {
namespace {

class SelfWeight : public Candidate {
 public:
  SelfWeight(std::vector<int> els, std::vector<double> force, Site site)
      : els_(std::move(els)), force_(std::move(force)), site_(std::move(site)) {
    for (double f : force_) compression_ = std::max(compression_, -f);
  }
  std::string kind() const override { return "self_weight"; }
  Nature nature() const override { return Nature::kStiffness; }
  std::string description() const override { return "axial forces of the structure's own weight (geometric stiffness under gravity)"; }
  Site site() const override { return site_; }
  bool global() const override { return true; }
  std::vector<CandidateParameter> parameters() const override { return {{"load factor", 0.0, 0.0, 200.0, 5.0, CandidateParameter::Prior::kHeavyTailed}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (std::size_t k = 0; k < els_.size(); ++k) {
      std::vector<int> dofs;
      m.element_dofs(els_[k], &dofs);
      out.push_back(linear_term(dofs, force_[k] * m.unit_geometric_stiffness(els_[k]), {}, first));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"load factor", "", th[0], sd[0]}, {"largest compression", "N", compression_ * th[0], compression_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "the weight the structure carries softens it (geometric stiffness of its gravity load, left out of the model): "
           "load factor " + with_std(v[0]) + " on the model's own weight (largest compression " + fmt_value(v[1].value, 3) + " N)";
  }

 private:
  std::vector<int> els_;
  std::vector<double> force_;
  Site site_;
  double compression_ = 0;
};

}  // namespace

CandidateKind self_weight_kind() {
  return {"self_weight", Nature::kStiffness, "the axial forces of the structure's own weight under gravity",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            const Model& m = *c.model;
            if (m.free_free() || m.num_dofs() == 0) return out;
            // Static analysis K u = g M r, r the unit translation along gravity (consistent gravity loads).
            const AssembledSystem sys = assemble_system(m);
            Eigen::VectorXd r = Eigen::VectorXd::Zero(m.num_dofs());
            for (int n = 0; n < static_cast<int>(m.nodes().size()); ++n)
              for (int t = 0; t < 3; ++t) {
                const int eq = m.dof_map().eq(n, static_cast<Dof>(t));
                if (eq >= 0) r[eq] = c.gravity[t];
              }
            const Eigen::VectorXd f = c.gravity_acceleration * (sys.M * r);
            CholmodFactor F;
            F.analyze(sys.K);
            if (!F.factorize(sys.K)) return out;  // a mechanism: no static state to speak of
            Eigen::VectorXd u(m.num_dofs());
            F.solve(f.data(), u.data());
            std::vector<int> els;
            std::vector<double> force;
            Site site;
            double largest = 0;
            for (int e = 0; e < m.num_elements(); ++e) {
              if (!is_member(m.elements()[e].type)) continue;
              std::vector<int> dofs;
              m.element_dofs(e, &dofs);
              Eigen::VectorXd ue(static_cast<Eigen::Index>(dofs.size()));
              for (std::size_t k = 0; k < dofs.size(); ++k) ue[static_cast<Eigen::Index>(k)] = dofs[k] >= 0 ? u[dofs[k]] : 0.0;
              const double N = m.member_axial_force(e, ue);
              largest = std::max(largest, std::abs(N));
              els.push_back(e);
              force.push_back(N);
              site.elements.push_back(m.elements()[e].id);
            }
            // Members that carry the weight transversely only (a beam along x under gravity -y) get no axial
            // force: the candidate would do nothing.
            if (largest > 1e-9 * c.gravity_acceleration * c.structure_mass)
              out.push_back(std::make_unique<SelfWeight>(std::move(els), std::move(force), std::move(site)));
            return out;
          }};
}

}  // namespace dynid::internal
