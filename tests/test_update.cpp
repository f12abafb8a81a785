// Model updating with Ceres: the paper's Table 1 beam (f1, f2, combined), ties, fixed parameters, bounds,
// ill-posed set-ups, and the SMU real shear frames.
#include <cmath>
#include <functional>

#include "dynid/engine/model_fit.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/results_json.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

struct FitRun {
  Case c;
  ModalData measured;
  FitSummary fit;
};

FitRun Update(const std::string& file, const std::function<void(UpdateSpec*)>& edit = {}) {
  FitRun r{load_case(file), {}, {}};
  UpdateSpec u = *r.c.update;
  if (edit) edit(&u);
  r.measured = update_measured_data(r.c);
  ParametricModel pm(r.c.model);
  for (const Parameter& p : u.parameters) pm.add(p);
  u.options.ties = u.ties;
  r.fit = fit_parameters(pm, r.measured, u.initial, u.free, u.options);
  return r;
}

bool HasWarning(const FitSummary& f, const std::string& part) {
  for (const std::string& w : f.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

TEST(PaperBeamUpdate, TargetReproducesTable1) {
  // The target (element 4's density +20 %) against the paper's 'Target' row: 0.02 % (issue), met to 0.015 %.
  const FitRun r = Update(test::CasesDir() + "/paper-beam-update/case.yaml");
  const double target[] = {45.18, 123.67, 245.59, 402.2, 603.2};
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(test::RelClose(r.measured.frequencies_hz[k], target[k], 2e-4)) << k;
}

TEST(PaperBeamUpdate, F2RecoversElement4) {
  const FitRun r = Update(test::CasesDir() + "/paper-beam-update/case.yaml");
  ASSERT_TRUE(r.fit.converged) << r.fit.termination;
  for (int e = 0; e < 10; ++e) EXPECT_NEAR(r.fit.theta[e], e == 3 ? 1.20 : 1.00, 0.01) << "rho:" << e + 1;
  EXPECT_EQ(r.fit.covariance_rank, 10);
}

TEST(PaperBeamUpdate, CombinedRecoversElement4) {
  const FitRun r = Update(test::CasesDir() + "/paper-beam-update/combined.yaml");
  ASSERT_TRUE(r.fit.converged) << r.fit.termination;
  for (int e = 0; e < 10; ++e) EXPECT_NEAR(r.fit.theta[e], e == 3 ? 1.20 : 1.00, 0.01) << "rho:" << e + 1;
}

TEST(PaperBeamUpdate, F1MatchesFrequenciesButCannotLocate) {
  // Five frequencies for ten mass factors: the frequencies are matched (0.05 %), and the report says the data
  // determine only part of the parameters (rank-deficient J^T J, no standard deviation for the others).
  const FitRun r = Update(test::CasesDir() + "/paper-beam-update/f1.yaml");
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(test::RelClose(r.fit.final_hz[k], r.measured.frequencies_hz[k], 5e-4)) << k;
  EXPECT_LT(r.fit.covariance_rank, 10);
  EXPECT_TRUE(HasWarning(r.fit, "determine only"));
  EXPECT_TRUE(HasWarning(r.fit, "free parameters but only 5 data values"));
  int undetermined = 0;
  for (int e = 0; e < 10; ++e) undetermined += std::isnan(r.fit.stddev[e]);
  EXPECT_GT(undetermined, 0);
  // And the mass is not put on element 4 alone: the spread shows the non-uniqueness.
  EXPECT_GT(std::abs(r.fit.theta[3] - 1.2), 0.05);
}

TEST(Update, TiesFixedAndBounds) {
  // rho:7 tied to rho:4 (ratio 1), rho:1 fixed at 1.1, rho:10 bounded to [0.9, 0.95] (the data want 1.0).
  const FitRun r = Update(test::CasesDir() + "/paper-beam-update/combined.yaml", [](UpdateSpec* u) {
    u->ties = {{6, {3, 1.0}}};
    u->initial[0] = 1.1;
    u->free[0] = 0;
    u->parameters[9].lower = 0.9;
    u->parameters[9].upper = 0.95;
    u->parameters[9].nominal = 0.92;
    u->initial[9] = 0.92;
  });
  EXPECT_DOUBLE_EQ(r.fit.theta[0], 1.1);
  EXPECT_DOUBLE_EQ(r.fit.theta[6], r.fit.theta[3]);
  EXPECT_NEAR(r.fit.theta[9], 0.95, 1e-6);
  EXPECT_TRUE(HasWarning(r.fit, "'rho:10' ended on its bound"));
  EXPECT_TRUE(std::isnan(r.fit.stddev[0]));  // fixed: no standard deviation
}

TEST(Update, UnpairedModeIsReported) {
  const FitRun r0 = Update(test::CasesDir() + "/paper-beam-update/combined.yaml");
  Case c = load_case(test::CasesDir() + "/paper-beam-update/combined.yaml");
  ModalData m = update_measured_data(c);
  m.shapes.col(2).setOnes();  // a shape like no model mode
  ParametricModel pm(c.model);
  for (const Parameter& p : c.update->parameters) pm.add(p);
  const FitSummary f = fit_parameters(pm, m, c.update->initial, c.update->free, c.update->options);
  EXPECT_TRUE(HasWarning(f, "measured mode 3")) << (f.warnings.empty() ? "" : f.warnings[0]);
  (void)r0;
}

TEST(Update, PartnerThreeTimesAwayIsLeftUnpaired) {
  // Issue 16: a sixth "mode" with mode 2's shape at three times its frequency (a spurious identification). Its
  // only partner by MAC is 3x away, beyond kMaxPairingRatio: update_case sets it aside with a warning instead of
  // forcing it onto the remaining model mode, and the five good modes recover the target as in
  // CombinedRecoversElement4 (exact data: the same 0.01 tolerance).
  const Case c = load_case(test::CasesDir() + "/paper-beam-update/combined.yaml");
  const ModalData good = update_measured_data(c);
  ModalData m = good;
  m.frequencies_hz.conservativeResize(6);
  m.shapes.conservativeResize(Eigen::NoChange, 6);
  m.frequencies_hz[5] = 3 * good.frequencies_hz[1];
  m.shapes.col(5) = good.shapes.col(1);
  const UpdateRun r = update_case(c, &m);
  EXPECT_EQ(r.measured.num_modes(), 5);
  EXPECT_TRUE(HasWarning(r.fit, "measured mode 6 (")) << (r.fit.warnings.empty() ? "" : r.fit.warnings[0]);
  EXPECT_TRUE(HasWarning(r.fit, "set aside, not fitted"));
  ASSERT_TRUE(r.fit.converged) << r.fit.termination;
  for (int e = 0; e < 10; ++e) EXPECT_NEAR(r.fit.theta[e], e == 3 ? 1.20 : 1.00, 0.01) << "rho:" << e + 1;
  // The same pairing decides: plausible_modes at the initial values names mode 6 (index 5) alone.
  ParametricModel pm(c.model);
  for (const Parameter& p : c.update->parameters) pm.add(p);
  const PlausibleModes pl = plausible_modes(pm, m, c.update->initial, c.update->options);
  EXPECT_EQ(pl.unpaired, std::vector<int>{5});
}

TEST(Update, RobustLossResistsAnOutlierMode) {
  // Mode 3's frequency corrupted by 3 % (a misidentified peak), and a model that cannot absorb it (element 4's
  // density and one global stiffness factor). Measured: plain 1.385 / 1.027, Huber 1.291 / 1.014, Cauchy
  // 1.227 / 1.004 against the truth 1.2 / 1.0. Asserted: Cauchy within 0.05, at most half the plain error.
  Case c = load_case(test::CasesDir() + "/paper-beam-update/combined.yaml");
  ModalData m = update_measured_data(c);
  m.frequencies_hz[2] *= 1.03;
  ParametricModel pm(c.model);
  Parameter rho;
  rho.name = "rho:4";
  rho.kind = ParameterKind::kMass;
  rho.elements = {c.model.element_index(4)};
  rho.lower = 0.5;
  rho.upper = 2;
  pm.add(rho);
  Parameter E = rho;
  E.name = "E";
  E.kind = ParameterKind::kStiffness;
  E.elements.clear();
  for (int e = 0; e < c.model.num_elements(); ++e) E.elements.push_back(e);
  pm.add(E);
  FitOptions o = c.update->options;
  const FitSummary plain = fit_parameters(pm, m, pm.nominal(), {}, o);
  o.loss = FitOptions::Loss::kCauchy;
  const FitSummary robust = fit_parameters(pm, m, pm.nominal(), {}, o);
  const Eigen::Vector2d truth(1.2, 1.0);
  const double e_plain = (plain.theta - truth).cwiseAbs().maxCoeff(), e_robust = (robust.theta - truth).cwiseAbs().maxCoeff();
  EXPECT_LT(e_robust, 0.05);
  EXPECT_LT(e_robust, 0.5 * e_plain);
}

TEST(SmuRealData, FourStoryShearFrame) {
  // Real identified modes. Before: frequency errors up to 12 %, MAC down to 0.70; after: < 0.2 % and > 0.99.
  const FitRun r = Update(test::CasesDir() + "/smu-four-story");
  ASSERT_TRUE(r.fit.converged);
  double before = 0, after = 0;
  for (int k = 0; k < 4; ++k) {
    before = std::max(before, std::abs(r.fit.initial_hz[k] / r.fit.measured_hz[k] - 1));
    after = std::max(after, std::abs(r.fit.final_hz[k] / r.fit.measured_hz[k] - 1));
    EXPECT_GT(r.fit.final_mac[k], 0.99);
  }
  EXPECT_GT(before, 0.1);
  EXPECT_LT(after, 0.002);
  for (int p = 0; p < 4; ++p) EXPECT_FALSE(std::isnan(r.fit.stddev[p]));
}

TEST(SmuRealData, EighteenStoryShearFrame) {
  // Frequencies improve (16 % -> < 2 %); the a-posteriori residual scale > 1 says the shear model cannot fit the
  // shapes within the stated noise (see cases/smu-eighteen-story/README.md).
  const FitRun r = Update(test::CasesDir() + "/smu-eighteen-story");
  ASSERT_TRUE(r.fit.converged);
  for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(r.fit.final_hz[k] / r.fit.measured_hz[k] - 1), 0.02) << k;
  EXPECT_GT(r.fit.residual_scale, 1.5);
}

}  // namespace
}  // namespace dynid
