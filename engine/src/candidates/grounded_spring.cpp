// grounded_spring / rotational_spring: an unmodelled elastic restraint on a free DOF of a node (a support or
// bracing the model leaves out), translational or rotational.
#include "candidates/common.hpp"

namespace dynid::internal {
namespace {

class GroundedSpring : public Candidate {
 public:
  GroundedSpring(const Model& m, int node, Dof d, double kref) : id_(m.nodes()[node].id), dof_(d), kref_(kref) {
    eq_ = m.dof_map().eq(node, d);
  }
  std::string kind() const override { return is_rotation(dof_) ? "rotational_spring" : "grounded_spring"; }
  // A rotational spring sits at a support (place(), below): a pin or a roller partly fixed. That is the physics of
  // flexible_support, the support's true stiffness against the model's idealisation, seen from the other side (a
  // clamp less than rigid there, a pin more than free here): one physics, its sites pooled.
  std::string physics() const override { return is_rotation(dof_) ? "flexible_support" : kind(); }
  Nature nature() const override { return Nature::kStiffness; }
  std::string description() const override {
    return std::string(is_rotation(dof_) ? "rotational" : "translational") + " spring to ground on " +
           std::string(dof_name(dof_)) + " at node " + std::to_string(id_);
  }
  Site site() const override { return {{id_}, {}}; }
  // Unit: the stiffness the band's modes see on that DOF (CandidateContext::band_stiffness), not K_ii, which grows
  // as the mesh is refined. Heavy-tailed prior of median 1: the spring's share k / (k + k_band) is uniform.
  std::vector<CandidateParameter> parameters() const override { return {{"stiffness", 0.0, 0.0, 100.0, 1.0, CandidateParameter::Prior::kHeavyTailed}}; }
  std::vector<CustomTerm> terms(const Model&, int first) const override {
    return {linear_term({eq_}, Eigen::MatrixXd::Constant(1, 1, kref_), {}, first)};
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"stiffness", is_rotation(dof_) ? "N m/rad" : "N/m", kref_ * th[0], kref_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "node " + std::to_string(id_) + " is restrained elastically in " + std::string(dof_name(dof_)) +
           " (an unmodelled support or bracing): spring " + with_std(v[0]);
  }

 private:
  int id_;
  Dof dof_;
  double kref_;
  int eq_ = -1;
};

// Translations: free DOFs of nodes with elements (in free-free models suspension_stiffness covers those).
// Rotations: free rotations of supported nodes only, a pin's or a roller's partial fixity. Elsewhere a restraint
// on rotation alone has no counterpart in a structure: what grips a member there restrains it in translation too
// (grounded_spring), connects through a joint (semi_rigid_joint), or stiffens the member (element_stiffness).
std::vector<std::unique_ptr<Candidate>> place(const CandidateContext& c, bool rotations) {
  std::vector<std::unique_ptr<Candidate>> out;
  const Model& m = *c.model;
  for (int n = 0; n < static_cast<int>(m.nodes().size()); ++n) {
    const bool supported = c.support[static_cast<std::size_t>(n)] != 0;
    if (!c.node_used[n] || (rotations && !supported)) continue;
    for (int t = 0; t < kNumDofTypes; ++t) {
      const Dof d = static_cast<Dof>(t);
      const int eq = m.dof_map().eq(n, d);
      if (eq < 0 || is_rotation(d) != rotations) continue;
      if (!rotations && m.free_free()) continue;
      out.push_back(std::make_unique<GroundedSpring>(m, n, d, c.band_stiffness[eq]));
    }
  }
  return out;
}

}  // namespace

CandidateKind grounded_spring_kind() {
  return {"grounded_spring", Nature::kStiffness, "a translational spring to ground on a free DOF of a node",
          [](const CandidateContext& c) { return place(c, false); }};
}

CandidateKind rotational_spring_kind() {
  return {"rotational_spring", Nature::kStiffness, "a rotational spring to ground on a free rotation of a node",
          [](const CandidateContext& c) { return place(c, true); }};
}

}  // namespace dynid::internal
