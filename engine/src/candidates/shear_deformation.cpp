// shear_deformation: the members are Timoshenko beams (shear deformation and rotary inertia), not
// Euler-Bernoulli ones.
//
// Per member and bending plane (one for plane members, two for space frames, one kappa for both):
// K_b(alpha) = (K_b + alpha phi0 EI/L d d^T) / (1 + alpha phi0), phi0 = 12 EI/(G A L^2), d = e_t1 - e_t2 on the
// end rotations about the plane's normal; alpha = 1/kappa (0 = Euler-Bernoulli), the exact Timoshenko stiffness of
// the two-node element. Its mass is the one consistent with that stiffness (Model::member_bending_planes, Friedman &
// Kosmatka): the translational mass of its shape functions and the rotary inertia of the section's rotation (not
// of the slope w', which shear adds to: the Rayleigh term over-weights rotary inertia in thick members, and a
// kappa fitted with it came out high). The rotary inertia enters with the weight w(alpha) = 1 - exp(-(alpha /
// 0.45)^2): none at alpha = 0 (the model as given), over 99 % from alpha = 1 on (kappa <= 1, every real section),
// so that the candidate is the nominal model at its nominal parameter and Timoshenko's beam where it matters.
// Models that already include rotary inertia have it replaced by the section rotation's.
#include <array>
#include <cmath>

#include "candidates/common.hpp"

namespace dynid::internal {
namespace {

constexpr double kRotaryRamp = 0.45;  // alpha at which the rotary inertia weight reaches 1 - 1/e

class ShearDeformation : public Candidate {
 public:
  ShearDeformation(const Model& m, std::vector<int> els) : els_(std::move(els)) {
    for (int e : els_) site_.elements.push_back(m.elements()[e].id);
  }
  std::string kind() const override { return "shear_deformation"; }
  Nature nature() const override { return Nature::kBoth; }
  std::string description() const override { return "shear deformation and rotary inertia (Timoshenko beams) in all members"; }
  Site site() const override { return site_; }
  bool global() const override { return true; }
  // alpha = 1/kappa: kappa 0.85 (solid rectangle) to about 0.3 (thin-walled shapes in their web's plane).
  std::vector<CandidateParameter> parameters() const override { return {{"1/kappa", 0.0, 0.0, 20.0, 2.0}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      // Per bending plane: its stiffness, the shear term (E I / L) d d^T, phi0 = 12 E I / (G A L^2) and the mass
      // parts (Model::member_bending_planes).
      struct Plane {
        Eigen::MatrixXd Kb, D;
        double phi0;
        std::array<Eigen::MatrixXd, 6> P;
      };
      std::vector<Plane> planes;
      for (BendingPlane& b : m.member_bending_planes(e)) {
        if (!(b.EI > 0) || !(b.GA > 0)) continue;
        planes.push_back(
            {std::move(b.K), (b.EI / b.L) * b.d * b.d.transpose(), 12.0 * b.EI / (b.GA * b.L * b.L), b.mass});
      }
      if (planes.empty()) continue;
      CustomTerm t;
      m.element_dofs(e, &t.dofs);
      t.params = {first};
      t.eval = [planes, rotary = m.rotary_inertia()](const Eigen::VectorXd& th, Eigen::MatrixXd* dK,
                                                     Eigen::MatrixXd* dM, std::vector<Eigen::MatrixXd>* dKd,
                                                     std::vector<Eigen::MatrixXd>* dMd) {
        const double a = th[0], x = a / kRotaryRamp, g = std::exp(-x * x);
        // Rotary inertia: replaces the model's (rotary) or enters with the weight w = 1 - g.
        const double w = rotary ? 1.0 : 1.0 - g, dw = rotary ? 0.0 : 2.0 * x / kRotaryRamp * g;
        const Eigen::Index n = planes[0].Kb.rows();
        Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n), M = K, Kd = K, Md = K;
        for (const Plane& pl : planes) {
          const double phi0 = pl.phi0, phi = a * phi0, q = 1.0 + phi;
          const auto& P = pl.P;
          // The mass part at phi (shear_mass) and its derivative in alpha.
          auto part = [&](int o) -> Eigen::MatrixXd { return shear_mass(P[o], P[o + 1], P[o + 2], phi); };
          auto slope = [&](int o) -> Eigen::MatrixXd {
            return phi0 *
                   ((P[o + 1] + 2.0 * phi * P[o + 2]) * q - 2.0 * (P[o] + phi * P[o + 1] + phi * phi * P[o + 2])) /
                   (q * q * q);
          };
          K += (pl.Kb + phi * pl.D) / q - pl.Kb;
          M += part(0) - P[0] + w * part(3);
          if (rotary) M -= P[3];
          Kd += phi0 * (pl.D - pl.Kb) / (q * q);
          Md += slope(0) + w * slope(3) + dw * part(3);
        }
        if (dK) *dK = K;
        if (dM) *dM = M;
        if (dKd) *dKd = {Kd};
        if (dMd) *dMd = {Md};
      };
      out.push_back(std::move(t));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    const double a = std::max(th[0], 1e-300);
    return {{"shear coefficient kappa", "", 1.0 / a, sd[0] / (a * a)}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "the members deform in shear (Timoshenko, not Euler-Bernoulli beams): shear coefficient kappa = " + with_std(v[0]);
  }

 private:
  std::vector<int> els_;
  Site site_;
};

}  // namespace

CandidateKind shear_deformation_kind() {
  return {"shear_deformation", Nature::kBoth, "shear deformation and rotary inertia in every member (Timoshenko)",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            const std::vector<int> all = group_members(*c.model, "");
            if (!all.empty()) out.push_back(std::make_unique<ShearDeformation>(*c.model, all));
            return out;
          }};
}

}  // namespace dynid::internal
