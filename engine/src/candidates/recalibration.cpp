// global_recalibration: the classic alternative to a missing effect, E and rho of the whole model recalibrated.
// Always scored beside the candidates (not a kind of missing physics).
#include "candidates/common.hpp"
#include "candidates/registry.hpp"

namespace dynid::internal {
namespace {

class Recalibration : public Candidate {
 public:
  explicit Recalibration(const Model& m) {
    for (int e = 0; e < m.num_elements(); ++e) {
      els_.push_back(e);
      site_.elements.push_back(m.elements()[e].id);
    }
  }
  std::string kind() const override { return "global_recalibration"; }
  Nature nature() const override { return Nature::kBoth; }
  std::string description() const override { return "recalibrate the stiffness (E) and mass (rho) of the whole model"; }
  Site site() const override { return site_; }
  bool global() const override { return true; }
  std::vector<CandidateParameter> parameters() const override {
    return {{"E change", 0.0, -0.9, 3.0, 0.3}, {"rho change", 0.0, -0.9, 3.0, 0.3}};
  }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      const Member mb = member(m, e);
      out.push_back(linear_term(mb.dofs, mb.Ks, {}, first));
      out.push_back(linear_term(mb.dofs, {}, mb.M, first + 1));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"E factor", "", 1.0 + th[0], sd[0]}, {"rho factor", "", 1.0 + th[1], sd[1]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "the members' E and rho are off: E x " + fmt_value(v[0].value, 4) + ", rho x " + fmt_value(v[1].value, 4);
  }

 private:
  std::vector<int> els_;
  Site site_;
};

}  // namespace

std::unique_ptr<Candidate> make_recalibration(const Model& model) { return std::make_unique<Recalibration>(model); }

}  // namespace dynid::internal
