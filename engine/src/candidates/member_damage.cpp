// member_damage: part of a member (a run of two or more of its consecutive elements) softer than modelled by one
// common fraction: damage or a reduced section spread along a member, which an element-by-element change would
// describe with several loosely determined parameters.
#include "candidates/common.hpp"

namespace dynid::internal {
namespace {

class MemberDamage : public Candidate {
 public:
  MemberDamage(const Model& m, std::vector<int> els) : els_(std::move(els)) {
    for (int e : els_) ids_.push_back(m.elements()[e].id);
  }
  std::string kind() const override { return "member_damage"; }
  std::string physics() const override { return "local_stiffness"; }
  Nature nature() const override { return Nature::kStiffness; }
  std::string description() const override {
    return "stiffness change along elements " + std::to_string(ids_.front()) + " to " + std::to_string(ids_.back()) + " (" +
           std::to_string(ids_.size()) + " elements of one member)";
  }
  Site site() const override { return {{}, ids_}; }
  std::vector<CandidateParameter> parameters() const override { return {{"fraction", 0.0, -0.95, 3.0, 0.5}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      const Member mb = member(m, e);
      out.push_back(linear_term(mb.dofs, mb.Ks, {}, first));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"stiffness change", "%", 100.0 * th[0], 100.0 * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "elements " + std::to_string(ids_.front()) + " to " + std::to_string(ids_.back()) + " of one member have " +
           (v[0].value < 0 ? "lost stiffness (damage along the member): " : "gained stiffness: ") + with_std(v[0]);
  }

 private:
  std::vector<int> els_, ids_;
};

}  // namespace

CandidateKind member_damage_kind() {
  return {"member_damage", Nature::kStiffness,
          "a run of two or more consecutive elements of one member softer or stiffer by one common fraction",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            for (const std::vector<int>& mem : c.members) {
              const int n = static_cast<int>(mem.size());
              for (int len = 2; len <= n; ++len)
                for (int a = 0; a + len <= n; ++a)
                  out.push_back(std::make_unique<MemberDamage>(*c.model, std::vector<int>(mem.begin() + a, mem.begin() + a + len)));
            }
            return out;
          }};
}

}  // namespace dynid::internal
