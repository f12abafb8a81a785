// sensor_mass and suspension_stiffness: equal point masses at the sensor nodes (accelerometers loading a light
// structure) and equal springs at the suspension points of a free-free test (the test was not free).
#include <limits>

#include "candidates/common.hpp"

namespace dynid::internal {
namespace {

// The heaviest sensor the sensor-mass candidate finds plausible (in kg; CandidateContext::kilogram converts): a seismic
// accelerometer with its mounting block weighs up to about 1 kg, laboratory accelerometers 0.2-100 g. Tens of kilograms
// at every measured node are not the sensors' mass, whatever else they are (a mass spread over a structure whose
// sensors are evenly spaced). A limit on what is plausible, not a bound: the prior, normalised over the bounds, stays
// as it is.
constexpr double kMaxSensorKg = 2.0;

class NodeSet : public Candidate {
 public:
  NodeSet(const Model& m, const std::vector<int>& nodes, bool springs, double ref,
          double most = std::numeric_limits<double>::infinity())
      : springs_(springs), ref_(ref), most_(most) {
    for (int n : nodes) {
      std::vector<int> d;
      for (int t = 0; t < 3; ++t)
        if (m.dof_map().eq(n, static_cast<Dof>(t)) >= 0) d.push_back(m.dof_map().eq(n, static_cast<Dof>(t)));
      if (d.empty()) continue;
      ids_.push_back(m.nodes()[n].id);
      dofs_.push_back(std::move(d));
    }
  }
  bool ok() const { return !ids_.empty(); }
  std::string kind() const override { return springs_ ? "suspension_stiffness" : "sensor_mass"; }
  Nature nature() const override { return springs_ ? Nature::kStiffness : Nature::kMass; }
  std::string description() const override {
    return springs_ ? "suspension springs of the free-free test at " + std::to_string(ids_.size()) + " points"
                    : "mass of the sensors at the " + std::to_string(ids_.size()) + " measured nodes";
  }
  Site site() const override { return {ids_, {}}; }
  bool global() const override { return true; }
  // Sensors: unit 2 % of the structure's mass shared by the sensors. Suspension: unit the stiffness that puts the
  // rigid-body modes at 1 % of the lowest measured frequency (stiffness grows as frequency squared).
  std::vector<CandidateParameter> parameters() const override {
    if (springs_) return {{"stiffness", 0.0, 0.0, 1e4, 100.0, CandidateParameter::Prior::kHeavyTailed}};
    return {{"mass", 0.0, 0.0, 20.0, 2.0, CandidateParameter::Prior::kHeavyTailed}};
  }
  std::vector<CustomTerm> terms(const Model&, int first) const override {
    std::vector<CustomTerm> out;
    for (const auto& d : dofs_) {
      const Eigen::Index n = static_cast<Eigen::Index>(d.size());
      const Eigen::MatrixXd I = ref_ * Eigen::MatrixXd::Identity(n, n);
      out.push_back(springs_ ? linear_term(d, I, {}, first) : linear_term(d, {}, I, first));
    }
    return out;
  }
  bool plausible(const Eigen::VectorXd& th) const override { return ref_ * th[0] <= most_; }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{springs_ ? "stiffness per point" : "mass per sensor", springs_ ? "N/m" : "kg", ref_ * th[0], ref_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return springs_ ? "the free-free test was not free: suspension stiffness " + with_std(v[0]) + " at each support point"
                    : "the sensors load the structure: " + with_std(v[0]) + " at each of the " + std::to_string(ids_.size()) + " measured nodes";
  }

 private:
  bool springs_;
  double ref_, most_;
  std::vector<int> ids_;
  std::vector<std::vector<int>> dofs_;
};

}  // namespace

CandidateKind sensor_mass_kind() {
  return {"sensor_mass", Nature::kMass, "equal masses at the sensor nodes (the accelerometers' own mass)",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            const double n = std::max<double>(1.0, static_cast<double>(c.sensor_nodes.size()));
            auto s = std::make_unique<NodeSet>(
                *c.model, c.sensor_nodes, false, 0.02 * c.structure_mass / n,
                c.kilogram > 0 ? kMaxSensorKg * c.kilogram : std::numeric_limits<double>::infinity());
            if (s->ok()) out.push_back(std::move(s));
            return out;
          }};
}

CandidateKind suspension_stiffness_kind() {
  return {"suspension_stiffness", Nature::kStiffness, "free-free tests: equal springs at the suspension points",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            if (!c.model->free_free() || c.suspension_nodes.empty() || c.measured->num_modes() == 0) return out;
            const double w = 2 * M_PI * 0.01 * c.measured->frequencies_hz.minCoeff();
            const double n = static_cast<double>(c.suspension_nodes.size());
            auto s = std::make_unique<NodeSet>(*c.model, c.suspension_nodes, true, c.structure_mass * w * w / n);
            if (s->ok()) out.push_back(std::move(s));
            return out;
          }};
}

}  // namespace dynid::internal
