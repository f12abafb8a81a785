// element_stiffness / element_mass: one element stiffer or softer (damage, a cover plate) or heavier (added
// material) than modelled, as a fraction of its own stiffness (without geometric stiffness) or mass.
#include "candidates/common.hpp"

namespace dynid::internal {
namespace {

class ElementChange : public Candidate {
 public:
  ElementChange(const Model& m, int e, bool mass) : e_(e), eid_(m.elements()[e].id), mass_(mass) {}
  // Springs only change stiffness, point masses only mass.
  static bool applies(const Model& m, int e, bool mass) {
    const ElementKind& k = element_kind(m.elements()[e].type);
    return mass ? k.has_mass() : k.has_stiffness();
  }
  std::string kind() const override { return mass_ ? "element_mass" : "element_stiffness"; }
  std::string physics() const override { return mass_ ? "attached_mass" : "local_stiffness"; }
  Nature nature() const override { return mass_ ? Nature::kMass : Nature::kStiffness; }
  std::string description() const override {
    return std::string(mass_ ? "mass" : "stiffness") + " change of element " + std::to_string(eid_);
  }
  Site site() const override { return {{}, {eid_}}; }
  // Stiffness: lost (damage) or gained (a cover plate). Mass: only gained. An element's own mass (rho A l) is what
  // the model knows best, and material that is missing takes its stiffness with it (damage, which the stiffness
  // kinds model); a mass loss alone has no mechanism, so, like the other mass kinds (lumped, distributed, sensor
  // masses), element_mass adds mass.
  std::vector<CandidateParameter> parameters() const override {
    return {{"fraction", 0.0, mass_ ? 0.0 : -0.95, 3.0, 0.5}};
  }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    const Member mb = member(m, e_);
    return {mass_ ? linear_term(mb.dofs, {}, mb.M, first) : linear_term(mb.dofs, mb.Ks, {}, first)};
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{mass_ ? "mass change" : "stiffness change", "%", 100.0 * th[0], 100.0 * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    const bool loss = v[0].value < 0;
    return "element " + std::to_string(eid_) +
           (mass_ ? " carries added mass: "
                  : (loss ? " has lost stiffness (damage): " : " is stiffer than modelled: ")) +
           with_std(v[0]);
  }

 private:
  int e_, eid_;
  bool mass_;
};

std::vector<std::unique_ptr<Candidate>> place(const CandidateContext& c, bool mass) {
  std::vector<std::unique_ptr<Candidate>> out;
  for (int e = 0; e < c.model->num_elements(); ++e)
    if (ElementChange::applies(*c.model, e, mass)) out.push_back(std::make_unique<ElementChange>(*c.model, e, mass));
  return out;
}

}  // namespace

CandidateKind element_stiffness_kind() {
  return {"element_stiffness", Nature::kStiffness, "one element stiffer or softer than modelled (damage)",
          [](const CandidateContext& c) { return place(c, false); }};
}

CandidateKind element_mass_kind() {
  return {"element_mass", Nature::kMass, "one element heavier or lighter than modelled",
          [](const CandidateContext& c) { return place(c, true); }};
}

}  // namespace dynid::internal
