// Issue 19: measured uncertainty as data (per-entry shape standard deviations, exact normalising entries, the
// data's own std in updating) and the global search (fit_multistart). References: the per-mode noise path (the
// same weights given another way), central differences of the residuals (the analytic Jacobian), and the search
// run with another thread count (must give identical numbers).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/multistart.hpp"
#include "dynid/engine/regularization.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/results_json.hpp"
#include "dynid/solvers/cholmod.hpp"
#include "dynid/solvers/eigen.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

struct Problem {
  Case c;
  ModalData measured;
  std::unique_ptr<ParametricModel> pm;
  explicit Problem(const std::string& name) : c(load_case(test::CasesDir() + "/" + name)) {
    measured = update_measured_data(c);
    pm = std::make_unique<ParametricModel>(c.model);
    for (const Parameter& p : c.update->parameters) pm->add(p);
  }
};

// Per-entry std all equal to the per-mode level gives the per-mode fit (same weights, other code path): 1e-9 on
// the parameters (the same iterations to rounding). The data's own std (measured_noise) equal to the stated
// levels gives the stated fit; without them, one warning for frequencies and one for shapes.
TEST(MeasuredUncertainty, PerEntryAndDataStdMatchTheStatedLevels) {
  Problem s("smu-four-story");
  const UpdateSpec& u = *s.c.update;
  const FitSummary ref = fit_parameters(*s.pm, s.measured, u.initial, u.free, u.options);
  FitOptions o = u.options;
  o.shape_noise_entries = Eigen::MatrixXd::Constant(s.measured.shapes.rows(), s.measured.num_modes(), o.shape_noise);
  const FitSummary entries = fit_parameters(*s.pm, s.measured, u.initial, u.free, o);
  EXPECT_LT((entries.theta - ref.theta).cwiseAbs().maxCoeff(), 1e-9);

  const MeasuredNoise none = measured_noise(s.measured, u.options);
  EXPECT_EQ(none.warnings.size(), 2u);
  EXPECT_FALSE(none.frequency || none.shape);
  ModalData d = s.measured;
  d.frequency_std_hz = o.frequency_noise * d.frequencies_hz;
  d.shape_entry_std.resize(d.shapes.rows(), d.num_modes());
  for (int k = 0; k < d.num_modes(); ++k)
    d.shape_entry_std.col(k).setConstant(o.shape_noise * d.shapes.col(k).cwiseAbs().maxCoeff());
  const MeasuredNoise mine = measured_noise(d, u.options);
  EXPECT_TRUE(mine.frequency && mine.shape);
  EXPECT_TRUE(mine.warnings.empty());
  const FitSummary data = fit_parameters(*s.pm, d, u.initial, u.free, mine.options);
  EXPECT_LT((data.theta - ref.theta).cwiseAbs().maxCoeff(), 1e-9);
}

// Per-entry std with an exact normalising entry (std 0) per mode: the analytic Jacobian agrees with central
// differences of the residuals (step 1e-6, tolerance 1e-5 of the column's size: the residuals are smooth and the
// truncation error is O(h^2)); the exact entries carry no residual and no derivative, and are not counted as data.
TEST(MeasuredUncertainty, ExactEntriesAndTheJacobian) {
  Problem s("smu-four-story");
  ModalData d = s.measured;
  d.shape_entry_std.resize(d.shapes.rows(), d.num_modes());
  for (int k = 0; k < d.num_modes(); ++k) {
    Eigen::Index ref = 0;
    d.shapes.col(k).cwiseAbs().maxCoeff(&ref);
    d.shapes.col(k) /= d.shapes(ref, k);  // one entry normalised to 1, as identification packages do
    for (Eigen::Index r = 0; r < d.shapes.rows(); ++r) d.shape_entry_std(r, k) = 0.02 + 0.01 * static_cast<double>(r);
    d.shape_entry_std(ref, k) = 0;
  }
  const MeasuredNoise mn = measured_noise(d, s.c.update->options);
  const Eigen::VectorXd theta = Eigen::Vector4d(0.8, 0.9, 1.1, 1.3);
  const Linearization L = linearize(*s.pm, d, theta, mn.options);
  FitProblem fp(*s.pm, d, mn.options);
  const double h = 1e-6;
  for (int p = 0; p < 4; ++p) {
    Eigen::VectorXd a = theta, b = theta, ra, rb;
    a[p] += h, b[p] -= h;
    ASSERT_TRUE(fp.residuals(a, &ra) && fp.residuals(b, &rb));
    const Eigen::VectorXd fd = (ra - rb) / (2 * h);
    EXPECT_LT((fd - L.J.col(p)).norm(), 1e-5 * L.J.col(p).norm()) << "parameter " << p;
  }
  const int rows = 1 + static_cast<int>(d.shapes.rows());
  for (int k = 0; k < d.num_modes(); ++k) {
    Eigen::Index ref = 0;
    d.shape_entry_std.col(k).minCoeff(&ref);
    EXPECT_EQ(L.r[k * rows + 1 + ref], 0.0);
    EXPECT_EQ(L.J.row(k * rows + 1 + ref).norm(), 0.0);
  }
  const FitSummary f = fit_parameters(*s.pm, d, s.c.update->initial, s.c.update->free, mn.options);
  const int data = d.num_modes() * rows - d.num_modes();
  EXPECT_NEAR(f.residual_scale, std::sqrt(2 * f.final_cost / (data - 4)), 1e-12);
}

// JSON: "shape_std" as an object {dof: std} per mode reads into shape_entry_std and writes back alike.
TEST(MeasuredUncertainty, JsonPerEntryShapeStd) {
  const std::string text = R"({"modes": [
    {"frequency_hz": 2, "frequency_std_hz": 0.01, "shape": {"1ux": 1, "2ux": 0.5}, "shape_std": {"1ux": 0, "2ux": 0.03}},
    {"frequency_hz": 5, "frequency_std_hz": 0.02, "shape": {"1ux": -0.4, "2ux": 1}, "shape_std": {"1ux": 0.05, "2ux": 0}}]})";
  const ModalData d = parse_modal_data_json(text, "m.json");
  ASSERT_EQ(d.shape_entry_std.rows(), 2);
  EXPECT_EQ(d.shape_entry_std(1, 0), 0.03);
  EXPECT_EQ(d.shape_entry_std(0, 1), 0.05);
  const ModalData back = parse_modal_data_json(modal_data_json(d).dump(), "back.json");
  EXPECT_EQ(back.shape_entry_std, d.shape_entry_std);
  std::string bad = text;
  bad.replace(bad.find("\"2ux\": 0.03"), 11, "\"2ux\": -0.1");
  EXPECT_HAS(test::ErrorOf([&] { parse_modal_data_json(bad, "bad.json"); }), "bad.json: mode 1 has shape standard deviation");
}

// JSON: a mode may list mode 1's DOFs in another order (JSON objects have none; writers sort keys or not), each
// entry with its own UFF-style sign ("2-X" is -1 times "2+X"); shape_std alike. A DOF mode 1 lacks, a repeated
// one, and a label that is no DOF are errors naming the mode and the label. Exact: values are copied.
TEST(MeasuredUncertainty, JsonDofsInAnyOrderEachWithItsSign) {
  const std::string ordered = R"({"modes": [
    {"frequency_hz": 2, "shape": {"1ux": 1, "2ux": 0.5, "3uy": 0.2}, "shape_std": {"1ux": 0, "2ux": 0.03, "3uy": 0.01}},
    {"frequency_hz": 5, "shape": {"1ux": -0.4, "2ux": 1, "3uy": 0.7}, "shape_std": {"1ux": 0.05, "2ux": 0, "3uy": 0.02}}]})";
  const std::string shuffled = R"({"modes": [
    {"frequency_hz": 2, "shape": {"1ux": 1, "2ux": 0.5, "3uy": 0.2}, "shape_std": {"2ux": 0.03, "1ux": 0, "3uy": 0.01}},
    {"frequency_hz": 5, "shape": {"3+Y": 0.7, "2-X": -1, "1ux": -0.4}, "shape_std": {"3uy": 0.02, "1ux": 0.05, "2ux": 0}}]})";
  const ModalData a = parse_modal_data_json(ordered, "a.json"), b = parse_modal_data_json(shuffled, "b.json");
  ASSERT_EQ(b.dofs.size(), 3u);
  for (std::size_t r = 0; r < 3; ++r) EXPECT_TRUE(a.dofs[r] == b.dofs[r]) << r;
  EXPECT_EQ(a.shapes, b.shapes);
  EXPECT_EQ(a.shape_entry_std, b.shape_entry_std);
  auto error = [&](const std::string& from, const std::string& to) {
    std::string t = shuffled;
    t.replace(t.find(from), from.size(), to);
    return test::ErrorOf([&] { parse_modal_data_json(t, "b.json"); });
  };
  EXPECT_HAS(error("\"2-X\": -1", "\"4ux\": -1"), "b.json: mode 2: DOF \"4ux\" is not among mode 1's DOFs");
  EXPECT_HAS(error("\"2-X\": -1", "\"3uy\": -1"), "b.json: mode 2: DOF \"3uy\" is listed twice");
  EXPECT_HAS(error("\"2-X\": -1", "\"left\": -1"), "b.json: mode 2: \"left\" is not a DOF label");
  EXPECT_HAS(error("\"3uy\": 0.02", "\"3ux\": 0.02"),
             "b.json: mode 2 shape_std: DOF \"3ux\" is not among the shape's DOFs");
}

// The global search on the 18-story frame (6 stiffness groups): the same starts, costs and minima with 1 and 2
// threads (exactly: the starts are independent); every start accounted for in one minimum; the best no worse than
// start 0 (the single fit from the initial values); the rule's number of starts (2 per parameter, 8..32).
TEST(Multistart, SameResultForAnyThreadCountAndTheBestIsNoWorse) {
  Problem s("smu-eighteen-story");
  const UpdateSpec& u = *s.c.update;
  MultiStartOptions ms;
  const auto [one, two] =
      test::OnOneThreadAndTwo([&] { return fit_multistart(*s.pm, s.measured, u.initial, u.free, u.options, ms); });
  ASSERT_EQ(one.start_points.size(), static_cast<std::size_t>(starts_for(6)));
  EXPECT_EQ(starts_for(6), 12);
  EXPECT_EQ(one.start_cost, two.start_cost);
  ASSERT_EQ(one.minima.size(), two.minima.size());
  std::size_t counted = 0;
  for (std::size_t m = 0; m < one.minima.size(); ++m) {
    EXPECT_EQ(one.minima[m].theta, two.minima[m].theta);
    EXPECT_EQ(one.minima[m].starts, two.minima[m].starts);
    counted += one.minima[m].starts.size();
    if (m > 0) {
      EXPECT_GE(one.minima[m].cost, one.minima[m - 1].cost);
    }
  }
  EXPECT_EQ(counted + static_cast<std::size_t>(one.failed), one.start_points.size());
  const FitSummary single = fit_parameters(*s.pm, s.measured, u.initial, u.free, u.options);
  EXPECT_NEAR(one.start_cost[0], single.final_cost, 1e-9 * single.final_cost);
  EXPECT_LE(one.best.final_cost, single.final_cost);
  EXPECT_EQ(one.best.final_cost, one.minima[0].cost);
  Parameter unbounded;
  unbounded.name = "free";
  unbounded.kind = ParameterKind::kMass;
  unbounded.elements = {0};
  ParametricModel pm(s.c.model);
  pm.add(unbounded);
  EXPECT_HAS(test::ErrorOf([&] { fit_multistart(pm, s.measured, pm.nominal(), {}, u.options, ms); }),
             "parameter 'free' has no finite bounds");
}

// The bridge with both y support springs at 0 (their lower bound: the package's alpha = -1) is free to move in
// y. The LL^T of K passes on rounding-level pivots, so the mechanism must be recognised by its eigenvalues: the
// solve fails naming a DOF, as a breakdown of the factorization does. (Before, it returned 15 eigenvalues of
// ~1e-86 (rad/s)^2, and a fit's mode search grew to 373 modes on them: 20 s per evaluation, and wrong minima.)
TEST(Multistart, BridgeWithoutYSupportsIsAMechanism) {
  if (!std::filesystem::is_directory(test::CasesDir() + "/../../shared/data/real/gt-pedestrian-bridge"))
    GTEST_SKIP() << "../shared beside the source tree is missing";
  Problem s("gt-pedestrian-bridge");
  Eigen::VectorXd theta = s.c.update->initial;
  for (int p = 0; p < s.pm->num_parameters(); ++p)
    if (s.pm->parameter(p).name == "y1" || s.pm->parameter(p).name == "y2") theta[p] = 0;
  SparseMatrix K, M;
  s.pm->matrices(theta, &K, &M);
  CholmodFactor F;
  F.analyze(K);
  ASSERT_TRUE(F.factorize(K))
      << "the factorization itself broke down: this test no longer reaches the eigenvalue check";
  EigenOptions eo;
  eo.num_modes = 15;
  const EigenSolution e = solve_eigen(K, M, eo);
  EXPECT_EQ(e.summary.status, EigenStatus::kFactorizationFailed);
  EXPECT_HAS(e.summary.message, "K is singular to rounding");
  EXPECT_GE(e.summary.failed_dof, 0);
  const EigenSolution nominal = solve_eigen(s.pm->K0(), s.pm->M0(), eo);
  ASSERT_TRUE(nominal.summary.ok());
  EXPECT_NEAR(std::sqrt(nominal.eigenvalues[0]) / (2 * M_PI), 4.65964, 1e-5);
}

// A weak Tikhonov prior toward nominal (weight 1e-4: its cost is 1e-4 of the data's) on the bridge, where the data
// push 14 of 17 parameters onto their bounds: the fit converges where the unregularized one does, to the same
// parameters (within 1e-3; the prior's pull is of order its weight). The prior acts on the projected values, as
// the data do; on the raw variables it pulled them back across their bounds and the trust region zigzagged on the
// kink (100 iterations without converging, cost 11.6 instead of 0.63).
TEST(Multistart, BridgeWeakPriorConvergesToTheUnregularizedFit) {
  if (!std::filesystem::is_directory(test::CasesDir() + "/../../shared/data/real/gt-pedestrian-bridge"))
    GTEST_SKIP() << "../shared beside the source tree is missing";
  Problem s("gt-pedestrian-bridge");
  const UpdateSpec& u = *s.c.update;
  const FitOptions o = measured_noise(s.measured, u.options).options;
  const FitSummary plain = fit_parameters(*s.pm, s.measured, u.initial, u.free, o);
  FitOptions r = o;
  r.regularization = 1e-4;
  const FitSummary prior = fit_parameters(*s.pm, s.measured, u.initial, u.free, r);
  EXPECT_TRUE(plain.converged);
  EXPECT_TRUE(prior.converged) << prior.termination << " after " << prior.iterations << " iterations";
  EXPECT_LT((prior.theta - plain.theta).cwiseAbs().maxCoeff(), 1e-3);
}

// The L-curve corner (l_curve_corner: central differences on a grid of 4 weights per decade) against the exact
// curvature of a linear Tikhonov problem given by its singular values sigma_i = 10^(-i/4) (24, six decades) and
// data coefficients beta_i = sigma_i + 1e-4 (-1)^i (the discrete Picard condition down to a noise floor): with
// f_i = sigma_i^2 / (sigma_i^2 + w), ||r||^2 = sum ((1 - f_i) beta_i)^2 and ||x||^2 = sum (f_i beta_i / sigma_i)^2
// have closed-form first and second derivatives in t = ln w (checked here against central differences of the
// closed forms below them, step 1e-4: truncation ~1e-8, 1e-6 relative). The
// maximum of the exact curvature on a fine grid (1000 points per decade) and the discrete corner agree within one
// step of the coarse grid (a quarter decade), and the curvature there is positive.
TEST(Regularization, LCurveCornerMatchesTheExactCurvature) {
  const int m = 24;
  Eigen::ArrayXd sg(m), b(m);
  for (int i = 0; i < m; ++i) {
    sg[i] = std::pow(10.0, -i / 4.0);
    b[i] = sg[i] + 1e-4 * (i % 2 ? -1 : 1);
  }
  const Eigen::ArrayXd c = b.square() / sg.square();
  // R = ||r||^2, E = ||x||^2 and their derivatives in t = ln w (df/dt = -f (1 - f)).
  auto curve = [&](double t, double* R, double* E, double* dR, double* d2R, double* dE, double* d2E) {
    const Eigen::ArrayXd f = sg.square() / (sg.square() + std::exp(t)), g = 1 - f;
    *R = (g.square() * b.square()).sum();
    *E = (f.square() * c).sum();
    *dR = 2 * (f * g.square() * b.square()).sum();
    *d2R = -2 * (b.square() * f * g.square() * (1 - 3 * f)).sum();
    *dE = -2 * (f.square() * g * c).sum();
    *d2E = 2 * (c * f.square() * g * (2 - 3 * f)).sum();
  };
  auto kappa = [&](double t) {  // x = ln ||r|| = ln R / 2, y = ln ||x|| = ln E / 2
    double R, E, dR, d2R, dE, d2E;
    curve(t, &R, &E, &dR, &d2R, &dE, &d2E);
    const double x1 = dR / (2 * R), x2 = (d2R * R - dR * dR) / (2 * R * R);
    const double y1 = dE / (2 * E), y2 = (d2E * E - dE * dE) / (2 * E * E);
    return (x1 * y2 - x2 * y1) / std::pow(x1 * x1 + y1 * y1, 1.5);
  };
  for (double t : {-20.0, -10.0, -3.0}) {  // the closed forms against central differences
    const double h = 1e-4;
    double R, E, dR, d2R, dE, d2E, Rp, Ep, Rm, Em, dRp, dEp, dRm, dEm, u;
    curve(t, &R, &E, &dR, &d2R, &dE, &d2E);
    curve(t + h, &Rp, &Ep, &dRp, &u, &dEp, &u);
    curve(t - h, &Rm, &Em, &dRm, &u, &dEm, &u);
    EXPECT_TRUE(test::RelClose(dR, (Rp - Rm) / (2 * h), 1e-6)) << t;
    EXPECT_TRUE(test::RelClose(dE, (Ep - Em) / (2 * h), 1e-6)) << t;
    EXPECT_TRUE(test::RelClose(d2R, (dRp - dRm) / (2 * h), 1e-6)) << t;
    EXPECT_TRUE(test::RelClose(d2E, (dEp - dEm) / (2 * h), 1e-6)) << t;
  }
  const double lo = std::log(1e-12), hi = std::log(1e2);
  double t_star = lo, k_star = -1;
  for (int j = 0; j <= 14000; ++j) {
    const double t = lo + (hi - lo) * j / 14000.0;
    if (kappa(t) > k_star) k_star = kappa(t), t_star = t;
  }
  std::vector<double> misfit, size, curvature;
  for (int j = -48; j <= 8; ++j) {
    double R, E, u[4];
    curve(std::log(std::pow(10.0, j / 4.0)), &R, &E, u, u + 1, u + 2, u + 3);
    misfit.push_back(std::sqrt(R));
    size.push_back(std::sqrt(E));
  }
  const int corner = l_curve_corner(misfit, size, &curvature);
  ASSERT_GT(corner, 0);
  EXPECT_GT(curvature[corner], 0);
  EXPECT_LE(std::abs((corner - 48) / 4.0 - t_star / std::log(10.0)), 0.25 + 1e-9)
      << "discrete corner at w = 1e" << (corner - 48) / 4.0 << ", exact at 1e" << t_star / std::log(10.0);
}

// The L-curve path on the four-story frame (4 story stiffnesses, well determined by 4 modes at 4 floors): 17
// weights 2 per decade, smallest first; along the path the misfit never falls and the change from nominal never
// grows as the weight grows (as for Tikhonov's global minimisers; 1e-9 relative for the fits' rounding); the
// corner is an interior point of positive curvature and its weight is the one returned.
TEST(Regularization, LCurvePathOnTheFourStoryFrame) {
  Problem s("smu-four-story");
  const UpdateSpec& u = *s.c.update;
  const LCurveSummary l = l_curve(*s.pm, s.measured, u.initial, u.free, u.options);
  ASSERT_EQ(l.points.size(), 17u);
  for (std::size_t j = 1; j < l.points.size(); ++j) {
    EXPECT_NEAR(l.points[j].weight / l.points[j - 1].weight, std::sqrt(10.0), 1e-12);
    EXPECT_GE(l.points[j].misfit, l.points[j - 1].misfit * (1 - 1e-9)) << j;
    EXPECT_LE(l.points[j].size, l.points[j - 1].size * (1 + 1e-9)) << j;
  }
  ASSERT_GT(l.corner, 0);
  ASSERT_LT(l.corner, 16);
  EXPECT_GT(l.points[static_cast<std::size_t>(l.corner)].curvature, 0);
  EXPECT_EQ(l.weight, l.points[static_cast<std::size_t>(l.corner)].weight);
  LCurveOptions bad;
  bad.points_per_decade = 0;
  EXPECT_HAS(test::ErrorOf([&] { l_curve(*s.pm, s.measured, u.initial, u.free, u.options, bad); }),
             "l-curve options: points_per_decade must be >= 1");
  // The case file: regularization: l-curve runs this path, then the fit with the corner's weight.
  const test::ScratchDir dir{"lc"};
  const std::string frame = test::CasesDir() + "/smu-four-story/";
  auto text = [&](const std::string& rule) {
    return "name: t\nmodel: {include: " + frame + "model.yaml}\nupdate:\n  measured: " + frame +
           "measured.json\n  objective: combined\n  noise: {frequency: 0.005, shape: 0.05}\n  regularization: " + rule +
           "\n  parameters:\n    - {name: k, factor: E, each: [1, 2, 3, 4], bounds: [0.2, 5.0]}\n";
  };
  EXPECT_HAS(test::ErrorOf([&] { load_case(dir.write("bad.yaml", text("lcurve"))); }),
             "regularization must be a weight (a number >= 0) or l-curve, got 'lcurve'");
  const Case c = load_case(dir.write("lc.yaml", text("l-curve")));
  ASSERT_TRUE(c.update->lcurve);
  const UpdateRun run = update_case(c);
  ASSERT_TRUE(run.lcurve.has_value());
  EXPECT_EQ(run.lcurve->weight, l.weight);
  const nlohmann::json j = update_json(c.name, *run.pm, *c.update, run.fit, nullptr, &*run.lcurve);
  EXPECT_EQ(j["regularization"]["rule"], "l-curve");
  EXPECT_EQ(j["regularization"]["points"].size(), 17u);
}

}  // namespace
}  // namespace dynid
