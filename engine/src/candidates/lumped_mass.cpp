// lumped_mass: an unmodelled mass attached at a node (equipment, a block, a person), on its translations.
#include "candidates/common.hpp"

namespace dynid::internal {
namespace {

class LumpedMass : public Candidate {
 public:
  LumpedMass(const Model& m, int node, double mref) : id_(m.nodes()[node].id), mref_(mref) {
    for (int t = 0; t < 3; ++t)
      if (m.dof_map().eq(node, static_cast<Dof>(t)) >= 0) dofs_.push_back(m.dof_map().eq(node, static_cast<Dof>(t)));
  }
  bool ok() const { return !dofs_.empty(); }
  std::string kind() const override { return "lumped_mass"; }
  std::string physics() const override { return "attached_mass"; }
  Nature nature() const override { return Nature::kMass; }
  std::string description() const override { return "lumped mass attached at node " + std::to_string(id_); }
  Site site() const override { return {{id_}, {}}; }
  // Unit: 1 % of the structure's mass; at most as heavy as the structure; a plausible attachment is a few per cent.
  std::vector<CandidateParameter> parameters() const override { return {{"mass", 0.0, 0.0, 100.0, 5.0, CandidateParameter::Prior::kHeavyTailed}}; }
  std::vector<CustomTerm> terms(const Model&, int first) const override {
    const Eigen::Index n = static_cast<Eigen::Index>(dofs_.size());
    return {linear_term(dofs_, {}, mref_ * Eigen::MatrixXd::Identity(n, n), first)};
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"mass", "kg", mref_ * th[0], mref_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "an unmodelled mass is attached at node " + std::to_string(id_) + ": " + with_std(v[0]);
  }

 private:
  int id_;
  double mref_;
  std::vector<int> dofs_;
};

}  // namespace

CandidateKind lumped_mass_kind() {
  return {"lumped_mass", Nature::kMass, "a mass attached at a node (on its translations)",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            for (int n = 0; n < static_cast<int>(c.model->nodes().size()); ++n) {
              if (!c.node_used[n]) continue;
              auto lm = std::make_unique<LumpedMass>(*c.model, n, 0.01 * c.structure_mass);
              if (lm->ok()) out.push_back(std::move(lm));
            }
            return out;
          }};
}

}  // namespace dynid::internal
