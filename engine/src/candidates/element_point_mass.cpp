// element_point_mass: a mass attached between the nodes of a member, at a fitted position along it. The mass m at
// xi moves with the member's own interpolation N(xi) (linear axially, cubic Hermite transversely), so it adds
// m N(xi)^T N(xi) to the element's mass matrix: the consistent mass of a point load, exact for the element's
// shape functions. Parameters: the mass, then the position xi in [0, 1] from the element's first node.
#include "candidates/common.hpp"

namespace dynid::internal {
namespace {

class ElementPointMass : public Candidate {
 public:
  ElementPointMass(const Model& m, int e, double mref) : e_(e), eid_(m.elements()[e].id), mref_(mref) {
    const auto& n = m.element_nodes(e);
    a_ = m.nodes()[n[0]].id;
    b_ = m.nodes()[n[1]].id;
  }
  std::string kind() const override { return "element_point_mass"; }
  std::string physics() const override { return "attached_mass"; }
  Nature nature() const override { return Nature::kMass; }
  std::string description() const override {
    return "mass attached on element " + std::to_string(eid_) + " between nodes " + std::to_string(a_) + " and " + std::to_string(b_);
  }
  Site site() const override { return {{}, {eid_}}; }
  // Mass in units of 1 % of the structure's mass (as lumped_mass); position uniform along the element.
  std::vector<CandidateParameter> parameters() const override {
    return {{"mass", 0.0, 0.0, 100.0, 5.0, CandidateParameter::Prior::kHeavyTailed}, {"position", 0.5, 0.0, 1.0, 0.0}};
  }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    CustomTerm t;
    m.element_dofs(e_, &t.dofs);
    t.params = {first, first + 1};
    const double mref = mref_;
    const int e = e_;
    const Model* model = &m;
    t.eval = [mref, e, model](const Eigen::VectorXd& th, Eigen::MatrixXd* dK, Eigen::MatrixXd* dM,
                              std::vector<Eigen::MatrixXd>* dKd, std::vector<Eigen::MatrixXd>* dMd) {
      Eigen::MatrixXd dN;
      const Eigen::MatrixXd N = model->member_point_interpolation(e, th[1], &dN);
      const Eigen::MatrixXd NN = N.transpose() * N;
      (void)dK;
      if (dM) *dM = mref * th[0] * NN;
      if (dKd) *dKd = {Eigen::MatrixXd(), Eigen::MatrixXd()};
      if (dMd) *dMd = {mref * NN, mref * th[0] * (dN.transpose() * N + N.transpose() * dN)};
    };
    return {t};
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"mass", "kg", mref_ * th[0], mref_ * sd[0]}, {"position", "", th[1], sd[1]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "an unmodelled mass is attached on element " + std::to_string(eid_) + " at " + fmt_value(v[1].value, 2) +
           " of its length from node " + std::to_string(a_) + " towards node " + std::to_string(b_) + ": " + with_std(v[0]);
  }

 private:
  int e_, eid_, a_ = 0, b_ = 0;
  double mref_;
};

}  // namespace

CandidateKind element_point_mass_kind() {
  return {"element_point_mass", Nature::kMass, "a mass attached between the nodes of a member, at a fitted position",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            for (int e = 0; e < c.model->num_elements(); ++e)
              if (is_member(c.model->elements()[e].type))
                out.push_back(std::make_unique<ElementPointMass>(*c.model, e, 0.01 * c.structure_mass));
            return out;
          }};
}

}  // namespace dynid::internal
