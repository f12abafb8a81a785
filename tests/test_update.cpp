// Model updating with Ceres: the paper's Table 1 beam (f1, f2, combined), ties, fixed parameters, bounds,
// ill-posed set-ups, and the SMU real shear frames.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>

#include "dynid/engine/modal.hpp"
#include "dynid/engine/modal_data.hpp"
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

// A free-free beam (2 m steel, 100 elements) hung on two fitted vertical springs (nodes 2 and 100) that put its
// bounce and pitch modes near 3 Hz. The fit deflates the rigid-body motions only while K leaves them free; with
// the springs at their values they are tied down, in SI and in mm, t, s (E in MPa, rho in t/mm^3, k in N/mm): the
// same four frequencies. The test of "free" used to compare ||K R|| with 1e-9 ||K||_1 ||R||, which on this mesh
// let springs up to ~1e5 N/m (bounce ~6 Hz) pass for free, and bounce and pitch came out rigid at 0 Hz (this test
// failed so at 5 Hz, in SI already). Now it compares the motions' eigenvalues on K with 1e-12 max K_ii / M_ii
// (EigenOptions::rigid_eigenvalue_tolerance: here a bounce of ~1.2 Hz). The reference, the explicit-spring model
// solved densely, was itself refused at 3 Hz ("not supported against translation y") until Model::finalize's
// check weighed each row of K R against its own |K| |R|. Tolerance 1e-6 relative: the Lanczos tolerance.
TEST(Update, RigidBodyTestDoesNotDependOnTheUnits) {
  struct Units {
    double length, E, rho, k;  // factors from SI
  };
  for (const Units u : {Units{1, 1, 1, 1}, Units{1e3, 1e-6, 1e-12, 1e-3}}) {
    BeamSpec b;
    b.length = 2.0 * u.length;
    b.elements = 100;
    b.material = {"steel", 2.1e11 * u.E, 0, 0.3, 7850 * u.rho};
    b.section = {"s", 0.01 * u.length * u.length, 0, 1e-4 / 12 * std::pow(u.length, 4), 0};
    const Model free = make_beam(b);
    ASSERT_TRUE(free.free_free());
    const double k = 2.8e4 * u.k;  // N/m -> N/mm: bounce sqrt(2 k / 157 kg) / (2 pi) = 3.0 Hz
    Model held = test::UnsupportedCopy(free);
    held.add_element(test::GroundedSpring(9001, 2, Dof::UY, k));
    held.add_element(test::GroundedSpring(9002, 100, Dof::UY, k));
    held.finalize();
    EigenOptions eo;
    eo.num_modes = 4;
    eo.method = EigenOptions::Method::kDense;
    const ModalResult ref = modal_analysis(held, eo);
    ASSERT_TRUE(ref.ok());
    ASSERT_EQ(std::count(ref.rigid_body.begin(), ref.rigid_body.end(), 1), 0);
    ASSERT_NEAR(ref.frequencies_hz[0], 3.0, 0.1);
    const ModalData meas = sample_modes(held, ref, dofs_of_types(held, dof_bit(Dof::UY)), 0, 4, "exact");
    ParametricModel pm(free);
    for (int node : {2, 100}) {
      Parameter t;
      t.name = "k" + std::to_string(node);
      t.kind = ParameterKind::kSpring;
      t.node = free.node_index(node);
      t.dofs = dof_bit(Dof::UY);
      t.nominal = 0;
      pm.add(t);
    }
    const Correlation c = correlate(pm, meas, Eigen::Vector2d(k, k), FitOptions{});
    ASSERT_EQ(c.model_hz.size(), 4);
    for (int m = 0; m < 4; ++m) {
      EXPECT_EQ(c.model_mode[m], m) << "units x" << u.length << ", mode " << m + 1;
      EXPECT_TRUE(test::RelClose(c.model_hz[m], meas.frequencies_hz[m], 1e-6))
          << "units x" << u.length << ", mode " << m + 1;
    }
  }
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

// A shape covariance beyond the per-entry noise (FitOptions::shape_covariance_factors): each mode's shape residuals
// and their derivatives are whitened by (D^2 + F F^T)^(-1/2), D the per-entry std (1 % here). Checked against the
// dense inverse square root of that covariance (Eigen's SelfAdjointEigenSolver) applied to the plain residuals and
// Jacobian, to 1e-9 of their largest entry (two routes to one matrix, rounding apart); frequency rows untouched;
// a mode without factors unchanged; a factor count that does not match the modes is refused, naming both.
TEST(Update, ShapeCovarianceFactorsWhitenTheShapeResiduals) {
  Case c = load_case(test::CasesDir() + "/paper-beam-update/combined.yaml");
  const ModalData m = update_measured_data(c);
  ParametricModel pm(c.model);
  for (const Parameter& q : c.update->parameters) pm.add(q);
  FitOptions o = c.update->options;
  ASSERT_EQ(o.objective, FitObjective::kCombined);
  ASSERT_EQ(o.shape_noise_modes.size() + o.shape_noise_entries.size(), 0);  // D = shape_noise I
  const Linearization plain = linearize(pm, m, pm.nominal(), o);
  const Eigen::Index a = static_cast<Eigen::Index>(m.dofs.size());
  std::mt19937 rng(7);
  std::normal_distribution<double> z(0.0, 1.0);
  o.shape_covariance_factors.assign(static_cast<std::size_t>(m.num_modes()), Eigen::MatrixXd(a, 0));
  for (int k = 1; k < m.num_modes(); ++k) {
    Eigen::MatrixXd F(a, k == 1 ? 1 : 3);
    for (Eigen::Index i = 0; i < F.size(); ++i) F.data()[i] = 0.02 * z(rng);
    o.shape_covariance_factors[static_cast<std::size_t>(k)] = F;
  }
  const Linearization mixed = linearize(pm, m, pm.nominal(), o);
  ASSERT_EQ(mixed.r.size(), plain.r.size());
  const double rtop = plain.r.cwiseAbs().maxCoeff(), jtop = plain.J.cwiseAbs().maxCoeff();
  for (int k = 0; k < m.num_modes(); ++k) {
    const Eigen::Index b = plain.block_start[static_cast<std::size_t>(k)];
    EXPECT_EQ(mixed.r[b], plain.r[b]) << "mode " << k;
    EXPECT_TRUE(mixed.J.row(b).isApprox(plain.J.row(b))) << "mode " << k;
    const Eigen::MatrixXd G = o.shape_covariance_factors[static_cast<std::size_t>(k)] / o.shape_noise;
    const Eigen::MatrixXd C = Eigen::MatrixXd::Identity(a, a) + G * G.transpose();
    const Eigen::MatrixXd W = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(C).operatorInverseSqrt();
    EXPECT_LT((mixed.r.segment(b + 1, a) - W * plain.r.segment(b + 1, a)).cwiseAbs().maxCoeff(), 1e-9 * rtop)
        << "mode " << k;
    EXPECT_LT((mixed.J.middleRows(b + 1, a) - W * plain.J.middleRows(b + 1, a)).cwiseAbs().maxCoeff(), 1e-9 * jtop)
        << "mode " << k;
    if (k > 0) EXPECT_GT((mixed.r.segment(b + 1, a) - plain.r.segment(b + 1, a)).norm(), 1e-3 * rtop) << "mode " << k;
  }
  o.shape_covariance_factors.pop_back();
  const std::string e = test::ErrorOf([&] { linearize(pm, m, pm.nominal(), o); });
  EXPECT_NE(e.find(std::to_string(m.num_modes() - 1) + " shape covariance factors for " +
                   std::to_string(m.num_modes()) + " measured modes"),
            std::string::npos)
      << e;
}

// A 2x2-bay, 4-story space frame (720 DOF: the sparse path), 8 stiffness factors (story x half of the plan),
// target factors in [0.85, 1.15], 8 modes measured at the x and y translations of the four corner columns
// with 0.1 % frequency and 1 % shape noise, a weak prior (std 0.2).
struct FrameFit {
  Model model;
  std::unique_ptr<ParametricModel> pm;
  ModalData measured;
  FitOptions options;
};

FrameFit SpaceFrameFit() {
  FrameFit f;
  const Frame3DSpec spec = test::SteelFrame3D(2, 2, 4);
  f.model = make_frame3d(spec);
  f.pm = std::make_unique<ParametricModel>(f.model);
  const int P = 8;
  std::vector<std::vector<int>> members(P);
  for (int e = 0; e < f.model.num_elements(); ++e) {
    const auto& en = f.model.element_nodes(e);
    const Eigen::Vector3d c = 0.5 * (f.model.nodes()[en[0]].x + f.model.nodes()[en[1]].x);
    const int story = std::min(spec.stories - 1, static_cast<int>(std::floor((c.z() - 1e-6) / spec.height)));
    members[2 * story + (c.x() < spec.span_x ? 0 : 1)].push_back(e);
  }
  for (int p = 0; p < P; ++p) {
    Parameter q;
    q.name = "E:" + std::to_string(p);
    q.kind = ParameterKind::kStiffness;
    q.elements = members[p];
    q.lower = 0.3;
    q.upper = 3;
    q.scale = 0.2;
    f.pm->add(q);
  }
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd truth(P);
  for (int p = 0; p < P; ++p) truth[p] = 1 + 0.15 * U(rng);
  const int nx = spec.bays_x + 1;
  for (int k = 1; k <= spec.stories; ++k)
    for (int j : {0, spec.bays_y})
      for (int i : {0, spec.bays_x})
        for (Dof d : {Dof::UX, Dof::UY}) f.measured.dofs.push_back({1 + (k * (spec.bays_y + 1) + j) * nx + i, d});
  SparseMatrix K, M;
  f.pm->matrices(truth, &K, &M);
  EigenOptions eo;
  eo.num_modes = 8;
  const EigenSolution t = solve_eigen(K, M, eo);
  const std::vector<int> rows = measured_equations(f.model, f.measured.dofs);
  f.measured.frequencies_hz.resize(8);
  f.measured.shapes.resize(static_cast<Eigen::Index>(rows.size()), 8);
  for (int k = 0; k < 8; ++k) {
    f.measured.frequencies_hz[k] = eigenvalue_to_hz(t.eigenvalues[k]) * (1 + 1e-3 * std::sqrt(3.0) * U(rng));
    for (std::size_t r = 0; r < rows.size(); ++r)
      f.measured.shapes(static_cast<Eigen::Index>(r), k) = t.modes(rows[r], k);
    const double big = f.measured.shapes.col(k).cwiseAbs().maxCoeff();
    for (std::size_t r = 0; r < rows.size(); ++r)
      f.measured.shapes(static_cast<Eigen::Index>(r), k) += 1e-2 * std::sqrt(3.0) * big * U(rng);
  }
  f.options.objective = FitObjective::kCombined;
  f.options.regularization = 1;
  return f;
}

TEST(Update, ReducedBasisFitReachesTheDirectFitsMinimum) {
  // The reduced-basis fit (surrogates on the modes and one Krylov block, corrected to the full model's residuals
  // and Jacobian at each step) against Ceres on the full model at every step: the same minimum with fewer
  // eigen-solves. Tolerances: the two stop within the direct fit's own truncation of the shape derivatives
  // (a relative gradient error of ~1e-3), so the costs agree to 1e-4 (measured: 1e-7) and the parameters
  // to a tenth of their standard deviations (measured: 4e-4 of them).
  const FrameFit f = SpaceFrameFit();
  ASSERT_GT(f.model.num_dofs(), f.options.dense_max_dofs);
  FitOptions o = f.options;
  const FitSummary direct = fit_parameters(*f.pm, f.measured, f.pm->nominal(), {}, o);
  o.reduced_basis = FitOptions::ReducedBasis::kOn;
  const FitSummary reduced = fit_parameters(*f.pm, f.measured, f.pm->nominal(), {}, o);
  ASSERT_TRUE(direct.converged) << direct.termination;
  ASSERT_TRUE(reduced.converged) << reduced.termination << "\n" << reduced.report;
  EXPECT_FALSE(direct.reduced_basis);
  EXPECT_TRUE(reduced.reduced_basis);
  EXPECT_LT(reduced.final_cost, direct.final_cost * (1 + 1e-4)) << reduced.report;
  EXPECT_GT(reduced.final_cost, direct.final_cost * (1 - 1e-4)) << reduced.report;
  double worst = 0;  // the largest parameter difference in standard deviations
  for (int p = 0; p < f.pm->num_parameters(); ++p) {
    ASSERT_TRUE(std::isfinite(direct.stddev[p]));
    worst = std::max(worst, std::abs(reduced.theta[p] - direct.theta[p]) / direct.stddev[p]);
    EXPECT_LT(std::abs(reduced.theta[p] - direct.theta[p]), 0.1 * direct.stddev[p]) << "parameter " << p;
    EXPECT_NEAR(reduced.stddev[p], direct.stddev[p], 0.01 * direct.stddev[p]) << "parameter " << p;
  }
  EXPECT_LT(reduced.evaluations, direct.evaluations);
  std::printf(
      "direct: cost %.8g, %d iterations, %d eigen-solves; reduced: cost %.8g, %d steps (%d rejected), %d "
      "eigen-solves, %d surrogate iterations; parameters apart by at most %.3g std\n",
      direct.final_cost, direct.iterations, direct.evaluations, reduced.final_cost, reduced.iterations,
      reduced.rejected_steps, reduced.evaluations, reduced.surrogate_iterations, worst);
}

TEST(Update, ReducedBasisOnlyWhereItApplies) {
  // kAuto below its DOF threshold runs the direct fit; kOn with the f2 objective (SEREP, not a modal residual)
  // runs the direct fit and says so.
  const FrameFit f = SpaceFrameFit();
  FitOptions o = f.options;
  o.reduced_basis = FitOptions::ReducedBasis::kAuto;
  o.reduced_basis_min_dofs = f.model.num_dofs() + 1;
  EXPECT_FALSE(fit_parameters(*f.pm, f.measured, f.pm->nominal(), {}, o).reduced_basis);
  o.reduced_basis_min_dofs = f.model.num_dofs();
  EXPECT_TRUE(fit_parameters(*f.pm, f.measured, f.pm->nominal(), {}, o).reduced_basis);
  o.reduced_basis = FitOptions::ReducedBasis::kOn;
  o.objective = FitObjective::kSerep;
  const FitSummary s = fit_parameters(*f.pm, f.measured, f.pm->nominal(), {}, o);
  EXPECT_FALSE(s.reduced_basis);
  EXPECT_TRUE(HasWarning(s, "the reduced-basis fit does not apply here"));
}

TEST(Update, ReducedBasisFromTheCaseFile) {
  // reduced_basis: off | on | auto; anything else names the key and the choices. On the SMU frame (solved
  // densely) `on` runs the direct fit and says why.
  const test::ScratchDir dir{"rb"};
  const std::string frame = test::CasesDir() + "/smu-four-story/";
  auto text = [&](const std::string& v) {
    return "name: t\nmodel: {include: " + frame + "model.yaml}\nupdate:\n  measured: " + frame +
           "measured.json\n  objective: combined\n  reduced_basis: " + v +
           "\n  parameters:\n    - {name: k, factor: E, each: [1, 2, 3, 4], bounds: [0.2, 5.0]}\n";
  };
  EXPECT_HAS(test::ErrorOf([&] { load_case(dir.write("bad.yaml", text("fast"))); }),
             "reduced_basis must be off, on or auto (on from 20000 DOFs)");
  const Case c = load_case(dir.write("on.yaml", text("on")));
  EXPECT_EQ(c.update->options.reduced_basis, FitOptions::ReducedBasis::kOn);
  const UpdateRun run = update_case(c);
  EXPECT_FALSE(run.fit.reduced_basis);
  EXPECT_TRUE(HasWarning(run.fit, "the reduced-basis fit does not apply here"));
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
