// Numerical edge cases handled on purpose (issue 8): each gives the right answer or a specific error, never a
// crash or a silently wrong number. Mechanisms and singular mass matrices: test_eigen; modes that do not pair:
// test_detect (DetectErrors) and test_update (UnpairedModeIsReported); bounds: test_update (TiesFixedAndBounds);
// non-finite matrices: test_assembly, test_eigen. The rest is here.
#include <Eigen/Dense>
#include <cmath>
#include <limits>

#include "dynid/engine/correlation.hpp"
#include "dynid/engine/detect.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/serep.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/test_data.hpp"
#include "dynid/mesh/generators.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.14159265358979323846;

// A square one-bay tower with square columns and equal beams both ways: a 90-degree rotation maps it onto
// itself, so its x and y bending modes share one eigenvalue.
Model SymmetricTower() {
  Frame3DSpec s;
  s.stories = 3;
  s.divisions = 2;
  s.span_x = s.span_y = 4;
  s.height = 3;
  s.material = {"steel", 2.1e11, 0, 0.3, 7800};
  s.column = {"col", 4e-3, 1e-5, 1e-5, 0};
  s.beam = {"beam", 3e-3, 9e-6, 9e-6, 0};
  return make_frame3d(s);
}

TEST(EdgeCases, ShiftAboveTheLowestEigenvalueIsNamed) {
  // Shift-invert Lanczos factors K - sigma M by Cholesky: with sigma above the lowest eigenvalue the matrix is
  // indefinite. The answer is a status and a message that says so, with the DOF where the factorization broke.
  const Model m = load_case(test::CasesDir() + "/paper-beam").model;
  EigenOptions o;
  o.num_modes = 3;
  o.method = EigenOptions::Method::kSparse;
  const ModalResult ok = modal_analysis(m, o);
  ASSERT_TRUE(ok.ok());
  o.shift = 0.5 * (ok.eigenvalues[1] + ok.eigenvalues[2]);
  const ModalResult r = modal_analysis(m, o);
  EXPECT_EQ(r.summary.status, EigenStatus::kFactorizationFailed);
  EXPECT_NE(r.summary.message.find("shift lies above the lowest eigenvalue"), std::string::npos) << r.summary.message;
  EXPECT_NE(r.summary.message.find("node "), std::string::npos) << r.summary.message;
  EXPECT_EQ(r.eigenvalues.size(), 0);
}

TEST(EdgeCases, RepeatedEigenvaluesOfASymmetricTower) {
  const Model m = SymmetricTower();
  const AssembledSystem sys = assemble_system(m);
  EigenOptions o;
  o.num_modes = 8;
  o.method = EigenOptions::Method::kSparse;
  const ModalResult sp = modal_analysis(m, sys, o);
  o.method = EigenOptions::Method::kDense;
  const ModalResult de = modal_analysis(m, sys, o);
  ASSERT_TRUE(sp.ok() && de.ok());
  // The solver finds both members of the pair (Lanczos sees a repeated eigenvalue once in exact arithmetic),
  // and the same subspace as the dense solver (its basis is arbitrary): 1e-9 is the solver's tolerance.
  EXPECT_TRUE(test::RelClose(sp.eigenvalues[0], sp.eigenvalues[1], 1e-9));
  EXPECT_TRUE(test::RelClose(sp.eigenvalues[0], de.eigenvalues[0], 1e-9));
  EXPECT_TRUE(test::RelClose(sp.eigenvalues[1], de.eigenvalues[1], 1e-9));
  EXPECT_LT(test::SubspaceGap(sp.modes.leftCols(2), de.modes.leftCols(2)), 1e-8);
  const auto groups = repeated_groups(sp.frequencies_hz, 1e-6);
  ASSERT_GE(groups.size(), 2u);
  EXPECT_EQ(groups[0], (std::vector<int>{0, 1}));

  // A "measurement" of the same tower whose pair came out rotated by 30 degrees (any basis is as valid: a real
  // tower's imperfections choose one). Sensors: x and y at every node above the base.
  std::vector<int> nodes;
  for (const Node& n : m.nodes())
    if (n.x.z() > 0) nodes.push_back(n.id);
  const std::vector<MeasuredDof> dofs = dofs_of_types(m, dof_bit(Dof::UX) | dof_bit(Dof::UY), nodes);
  ModalData data = sample_modes(m, sp, dofs, 0, 4, "rotated");
  const double c = std::cos(kPi / 6), s = std::sin(kPi / 6);
  const Eigen::MatrixXd pair = data.shapes.leftCols(2);
  data.shapes.col(0) = c * pair.col(0) + s * pair.col(1);
  data.shapes.col(1) = -s * pair.col(0) + c * pair.col(1);

  const Eigen::MatrixXd model_shapes = sample_modes(m, sp, dofs, 0, 4, "model").shapes;
  const Eigen::MatrixXd plain = mac_matrix(data.shapes, model_shapes);
  EXPECT_LT(plain(0, 0), 0.8);  // per-vector MAC depends on the basis: cos^2(30 deg) = 0.75
  const Eigen::MatrixXd sub = subspace_mac_matrix(data.shapes, model_shapes, repeated_groups(sp.frequencies_hz.head(4), 1e-6));
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) EXPECT_GT(sub(i, j), 1 - 1e-10) << i << "," << j;
  const Pairing p = pair_modes(sub, data.frequencies_hz, sp.frequencies_hz.head(4), 0.9);
  ASSERT_EQ(p.pairs.size(), 4u);
  EXPECT_NE(p.pairs[0].b, p.pairs[1].b);
  EXPECT_LE(std::max(p.pairs[0].b, p.pairs[1].b), 1);
  // The member of the subspace the data show: the rotation is recovered (cos 30, sin 30 up to sign).
  const Eigen::VectorXd coef = subspace_coefficients(data.shapes.col(0), model_shapes, {0, 1});
  EXPECT_NEAR(std::abs(coef[0]), c, 1e-10);
  EXPECT_NEAR(std::abs(coef[1]), s, 1e-10);

  // detect() pairs on the subspace: every mode used, MAC 1, and the unchanged tower has no residual force
  // beyond rounding (its rotated modes are exact modes).
  DetectOptions d;
  d.localize_only = true;
  d.serep_modes = 8;         // a well-conditioned SEREP basis: the residuals below are rounding only
  d.candidates = {1, 2, 3};  // the pairing is the point here, not the ranking
  const DetectSummary S = detect(m, data, d);
  ASSERT_EQ(S.used_modes.size(), 4u);
  for (int k = 0; k < 4; ++k) EXPECT_GT(S.mac[k], 1 - 1e-8) << k;
  for (const std::string& w : S.warnings) EXPECT_EQ(w.find("pairs with no model mode"), std::string::npos) << w;
  const double force_scale = (sys.K * sp.modes.col(0)).norm();
  EXPECT_LT(S.residuals.cwiseAbs().maxCoeff(), 1e-8 * force_scale);
}

TEST(EdgeCases, RigidBodyModesBesideNearZeroElasticModes) {
  // A free-free 2D frame bar of two stiff 1 m halves joined by a 10 mm element 10^9 times softer: three rigid-body
  // modes, then a hinge mode (the halves fold about the joint) and an axial mode below 1 Hz, 1000 times below
  // the first bending mode of a half. Rigid-body modes come from the geometry, not from a threshold on
  // the eigenvalue, so the near-zero elastic modes are neither taken for rigid ones nor lost among them.
  const double a = 1.0, gap = 0.01, A = 1e-3, I = 1e-6, rho = 7800, E_soft = 320;
  Model m;
  m.add_material({"steel", 2.1e11, 0, 0.3, rho});
  m.add_material({"soft", E_soft, 0, 0.3, rho});
  m.add_section({"s", A, 0, I, 0});
  int id = 0;
  for (int i = 0; i <= 10; ++i) m.add_node(++id, Eigen::Vector3d(0.1 * a * i, 0, 0));
  for (int i = 0; i <= 10; ++i) m.add_node(++id, Eigen::Vector3d(a + gap + 0.1 * a * i, 0, 0));
  for (int i = 1; i <= 21; ++i) {
    Element e;
    e.id = i;
    e.type = ElementType::Frame2D;
    e.node_ids = {{i, i + 1}};
    e.material = (i == 11) ? 1 : 0;
    e.section = 0;
    m.add_element(e);
  }
  m.set_free_free(true);
  m.finalize();
  EigenOptions o;
  o.num_modes = 7;
  o.method = EigenOptions::Method::kSparse;
  const ModalResult r = modal_analysis(m, o);
  ASSERT_TRUE(r.ok()) << r.summary.message;
  ASSERT_EQ(r.eigenvalues.size(), 7);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(r.rigid_body[k]) << k;
  for (int k = 3; k < 7; ++k) EXPECT_FALSE(r.rigid_body[k]) << k;
  // Analytic, rigid halves of mass m_h = rho A a: hinge omega^2 = 24 k_r / (m_h a^2) with k_r = E I / gap (the
  // joint carries a pure moment in this symmetric mode); axial omega^2 = 2 k_a / m_h with k_a = E A / gap.
  // 3 %: the joint's own length and mass (1 % of a half) and the halves' flexibility (1e-6) are neglected.
  const double mh = rho * A * a;
  const double hinge = 24 * (E_soft * I / gap) / (mh * a * a), axial = 2 * (E_soft * A / gap) / mh;
  EXPECT_TRUE(test::RelClose(r.eigenvalues[3], hinge, 0.03)) << std::sqrt(hinge) / (2 * kPi) << " Hz";
  EXPECT_TRUE(test::RelClose(r.eigenvalues[4], axial, 0.03)) << std::sqrt(axial) / (2 * kPi) << " Hz";
  // Mode 6 is the joint's third soft motion (the halves slide across it, about 10 Hz); mode 7 the first bending
  // mode of the stiff halves (about 580 Hz).
  EXPECT_LT(r.frequencies_hz[5], 30.0);
  EXPECT_GT(r.frequencies_hz[6], 300.0);
  // The elastic modes are exact (residual) and mass-orthogonal to the rigid motions (1e-10).
  EXPECT_LT(r.summary.max_residual, 1e-10);
  const AssembledSystem sys = assemble_system(m);
  const Eigen::MatrixXd G = r.modes.leftCols(3).transpose() * (sys.M * r.modes.rightCols(4));
  EXPECT_LT(G.cwiseAbs().maxCoeff(), 1e-10);
}

// A model with fewer free DOFs than rigid-body motions (found by fuzz_case: the support check read past the
// singular values, an out-of-bounds read): one inclined member, clamped at one end, only ux free at the other.
// The check must pass (ux is held by the member) and the single eigenvalue is K/M of that DOF (1e-12: a 1x1
// problem, rounding only).
TEST(EdgeCases, FewerFreeDofsThanRigidMotions) {
  Model m;
  m.add_node(1, {0, 0, 0});
  m.add_node(2, {1, 1, 0});
  m.add_material({"steel", 2.1e11, 0, 0.3, 7800});
  m.add_section({"s", 1e-4, 0, 1e-8, 0, 0});
  Element e;
  e.id = 1;
  e.type = ElementType::Frame2D;
  e.node_ids = {{1, 2}};
  e.material = e.section = 0;
  m.add_element(e);
  m.restrain(1, kAllDofs);
  m.restrain(2, dof_bit(Dof::UY) | dof_bit(Dof::RZ));
  ASSERT_NO_THROW(m.finalize());
  ASSERT_EQ(m.num_dofs(), 1);
  EXPECT_EQ(m.rigid_body_motions().cols(), 2);  // translation x and rotation about z touch the free ux
  EXPECT_EQ(m.free_rigid_body_modes().cols(), 0);
  SparseMatrix K, M;
  Assembler(m).assemble(&K, &M);
  EigenOptions o;
  o.num_modes = 1;
  const ModalResult r = modal_analysis(m, o);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(test::RelClose(r.eigenvalues[0], K.coeff(0, 0) / M.coeff(0, 0), 1e-12));
}

TEST(EdgeCases, SerepWithMoreModesThanMastersAndDependentShapes) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  EigenOptions o;
  o.num_modes = 8;
  const ModalResult r = modal_analysis(c.model, o);
  // 4 masters, 6 modes: the master rows of the modes have rank 4, so the reduced 4 x 4 model keeps 4 modes.
  // Reported (rank, infinite condition), finite matrices, and the kept modes' eigenvalues are no longer exact.
  const std::vector<int> uy = measured_equations(c.model, dofs_of_types(c.model, dof_bit(Dof::UY)));
  const std::vector<int> masters(uy.begin(), uy.begin() + 4);
  const SerepReduction s = serep_reduce(r.modes.leftCols(6), r.eigenvalues.head(6), masters);
  EXPECT_EQ(s.rank, 4);
  EXPECT_EQ(s.modes, 6);
  EXPECT_TRUE(std::isinf(s.condition));
  EXPECT_TRUE(s.K.allFinite() && s.M.allFinite());
  // Dependent shapes (a mode given twice, and one given as a combination of two others): rank 4 of 6.
  Eigen::MatrixXd dep = r.modes.leftCols(6);
  dep.col(4) = dep.col(1);
  dep.col(5) = dep.col(0) + 2 * dep.col(2);
  const SerepReduction d = serep_reduce(dep, r.eigenvalues.head(6), uy);
  EXPECT_EQ(d.rank, 4);
  EXPECT_TRUE(d.K.allFinite() && d.M.allFinite());

  // detect() on 3 measured DOFs with a 5-mode SEREP basis says that the reduction keeps only 3 modes.
  const Case dc = load_case(test::CasesDir() + "/paper-beam-damage/translations.yaml");
  const ModalData data = detect_changed_data(dc, nullptr);
  std::vector<MeasuredDof> three(data.dofs.begin(), data.dofs.begin() + 3);
  ModalData few;
  few.dofs = three;
  few.frequencies_hz = data.frequencies_hz.head(2);
  few.shapes = data.shapes.topRows(3).leftCols(2);
  DetectOptions opt;
  opt.serep_modes = 5;
  opt.localize_only = true;
  const DetectSummary S = detect(dc.model, few, opt);
  bool said = false;
  for (const std::string& w : S.warnings) said |= w.find("the reduced model keeps 3") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_EQ(S.serep_rank, 3);
}

TEST(EdgeCases, NonFiniteMeasuredData) {
  // NaN or Inf in measured data is an error naming the mode and the DOF, wherever it enters.
  const Case c = load_case(test::CasesDir() + "/paper-beam-damage/translations.yaml");
  const ModalData measured = detect_changed_data(c, nullptr);
  ModalData d = measured;
  d.frequencies_hz[1] = kNaN;
  EXPECT_NE(test::ErrorOf([&] { d.validate("measured"); }).find("mode 2"), std::string::npos);
  EXPECT_NE(test::ErrorOf([&] { detect(c.model, d, DetectOptions{}); }), "(no error)");
  d = measured;
  d.shapes(2, 0) = std::numeric_limits<double>::infinity();
  const std::string e = test::ErrorOf([&] { d.validate("measured"); });
  EXPECT_NE(e.find("mode 1"), std::string::npos) << e;
  EXPECT_NE(e.find(to_string(d.dofs[2])), std::string::npos) << e;
  // In files: a modal data JSON cannot hold NaN, but a text table can.
  EXPECT_NE(test::ErrorOf([] { parse_text_table("# t x\n0 1\n1 nan\n2 3\n", "nan.csv", true); }).find("nan.csv:3"),
            std::string::npos);
  EXPECT_NE(test::ErrorOf([] { parse_text_table("0,1\n1,inf\n", "inf.csv", true); }).find("inf.csv:2"),
            std::string::npos);
}

TEST(EdgeCases, NonFiniteModelData) {
  // A case file with .nan or .inf (YAML's spellings) for a coordinate or a material constant: an error naming
  // the file, the line and the value.
  auto model = [](const std::string& E, const std::string& x2) {
    return "model:\n  element: frame2d\n  materials:\n    steel: {E: " + E +
           ", rho: 7800}\n  sections:\n    s: {A: 1.0e-3, I: 1.0e-6}\n  defaults: {material: steel, section: s}\n"
           "  nodes:\n    - [1, 0, 0]\n    - [2, " + x2 + ", 0]\n  elements:\n    - [1, 1, 2]\n"
           "  supports:\n    - {nodes: [1], fix: all}\n";
  };
  EXPECT_EQ(test::ErrorOf([&] { parse_case(model("2.1e11", "1"), "ok.yaml"); }), "(no error)");
  const std::string e1 = test::ErrorOf([&] { parse_case(model("2.1e11", ".nan"), "nan.yaml"); });
  EXPECT_NE(e1.find("nan.yaml:10"), std::string::npos) << e1;
  EXPECT_NE(e1.find("must be finite"), std::string::npos) << e1;
  const std::string e2 = test::ErrorOf([&] { parse_case(model(".inf", "1"), "inf.yaml"); });
  EXPECT_NE(e2.find("inf.yaml:4"), std::string::npos) << e2;
  EXPECT_NE(e2.find("must be finite"), std::string::npos) << e2;
}

TEST(EdgeCases, UpdatingThatStallsSaysSo) {
  // One iteration cannot reach the minimum: the fit reports NO_CONVERGENCE and warns that the parameters are the
  // last iterate, not a minimum (bounds: test_update TiesFixedAndBounds).
  Case c = load_case(test::CasesDir() + "/paper-beam-update/combined.yaml");
  const ModalData m = update_measured_data(c);
  ParametricModel pm(c.model);
  for (const Parameter& p : c.update->parameters) pm.add(p);
  FitOptions fo = c.update->options;
  fo.max_iterations = 1;
  const FitSummary f = fit_parameters(pm, m, c.update->initial, c.update->free, fo);
  EXPECT_FALSE(f.converged);
  EXPECT_EQ(f.termination, "NO_CONVERGENCE");
  bool said = false;
  for (const std::string& w : f.warnings) said |= w.find("stopped without converging") != std::string::npos;
  EXPECT_TRUE(said);
}

}  // namespace
}  // namespace dynid
