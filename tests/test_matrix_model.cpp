// Models from matrices exported by another FE code (dynid/io/matrix_model.hpp, docs/matrix-input.md): the
// bundled paper-frame-matrices case against the frame it was exported from, group matrices, a remainder, and
// the reader's messages. References: the frame model (an independent path: beam element formulas, not matrices
// read from files) and analytic equalities (the sum of group matrices equals K).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dynid/engine/detect.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/matrix_market.hpp"
#include "dynid/io/matrix_model.hpp"
#include "dynid/io/point_map.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;
using test::ErrorOf;


DetectSummary DetectCase(const Case& c) {
  Model changed;
  const ModalData data = detect_changed_data(c, &changed);
  return detect(c.model, data, c.detect->options);
}

Eigen::VectorXd Frequencies(const Model& m, int modes = 8) {
  EigenOptions o;
  o.num_modes = modes;
  const ModalResult r = modal_analysis(m, o);
  EXPECT_TRUE(r.ok());
  return r.frequencies_hz;
}

// A scratch folder holding a copy of cases/paper-frame-matrices, removed at the end.
class MatrixFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    for (const auto& f : fs::directory_iterator(test::CasesDir() + "/paper-frame-matrices"))
      fs::copy_file(f.path(), scratch_.dir() / f.path().filename());
  }
  std::string Path(const std::string& f) const { return scratch_.path(f); }
  // The frame's group matrices on the file's equations: columns (elements 1-20) in Kc.mtx, Mc.mtx and beams
  // (21-31) in Kb.mtx, Mb.mtx. Returns the element-by-element model they are summed from.
  Case WriteGroups() const {
    Case all = Load("    dofs: dofs.csv\n    nodes: nodes.csv\n    elements: elements.txt\n");
    const int n = all.model.num_dofs();
    std::vector<Eigen::Triplet<double, int>> kc, mc, kb, mb;
    const std::vector<DofRow> rows = parse_dof_table(test::Slurp(Path("dofs.csv")), "dofs.csv");
    Eigen::MatrixXd Ke, Me;
    for (int e = 0; e < all.model.num_elements(); ++e) {
      const bool column = all.model.elements()[e].id <= 20;
      const auto types = all.model.element_dof_types(e);
      all.model.element_matrices(e, &Ke, &Me);
      std::vector<int> q;  // file equations of the element's DOFs
      for (const auto& [node, dof] : types)
        for (int r = 0; r < static_cast<int>(rows.size()); ++r)
          if (rows[r].node == all.model.nodes()[node].id && rows[r].dof == dof) q.push_back(r);
      for (int i = 0; i < Ke.rows(); ++i)
        for (int j = 0; j < Ke.rows(); ++j) {
          (column ? kc : kb).emplace_back(q[i], q[j], Ke(i, j));
          (column ? mc : mb).emplace_back(q[i], q[j], Me(i, j));
        }
    }
    auto save = [&](const std::string& f, const std::vector<Eigen::Triplet<double, int>>& t) {
      SparseMatrix A(n, n);
      A.setFromTriplets(t.begin(), t.end());
      write_matrix_market(Path(f), A, true, true);
    };
    save("Kc.mtx", kc), save("Mc.mtx", mc), save("Kb.mtx", kb), save("Mb.mtx", mb);
    return all;
  }
  // A matrix file (file equations) on a model's equations, dense.
  Eigen::MatrixXd OnModel(const std::string& f, const Model& m) const {
    const std::vector<DofRow> rows = parse_dof_table(test::Slurp(Path("dofs.csv")), "dofs.csv");
    const SparseMatrix A = read_matrix_market(Path(f));
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(m.num_dofs(), m.num_dofs());
    auto eq = [&](int r) { return m.dof_map().eq(m.node_index(rows[r].node), rows[r].dof); };
    for (int j = 0; j < A.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(A, j); it; ++it) D(eq(static_cast<int>(it.row())), eq(j)) += it.value();
    return D;
  }
  void Write(const std::string& f, const std::string& text) const { scratch_.write(f, text); }
  Case Load(const std::string& matrices_yaml) const {
    return load_case(scratch_.write("t.yaml", "name: t\nmodel:\n  matrices:\n" + matrices_yaml + "analysis: {modes: 8}\n"));
  }
  const test::ScratchDir scratch_{"mx"};
};

// Tolerance 1e-10: the files hold 17 significant digits, so the matrices are the frame's to rounding and the
// eigenvalues agree to the solver's accuracy (1e-12 relative residuals); 1e-10 is the bound.
TEST(MatrixModel, PaperFrameSameFrequenciesAsTheFrame) {
  const Case frame = load_case(test::CasesDir() + "/paper-frame");
  const Case mx = load_case(test::CasesDir() + "/paper-frame-matrices");
  ASSERT_EQ(mx.model.num_elements(), 31);
  EXPECT_EQ(mx.model.elements()[0].type, ElementType::Matrix);
  EXPECT_EQ(mx.model.num_dofs(), frame.model.num_dofs());
  EXPECT_TRUE(mx.model.warnings().empty()) << mx.model.warnings().front();  // supported ends are drawn, not loose
  const Eigen::VectorXd f0 = Frequencies(frame.model), f1 = Frequencies(mx.model);
  for (int k = 0; k < 8; ++k) EXPECT_TRUE(test::RelClose(f1[k], f0[k], 1e-10)) << "mode " << k + 1;
  // Element matrices equal the frame's (same element ids, same node ids, same DOF order).
  std::vector<int> d0, d1;
  Eigen::MatrixXd K0, M0, K1, M1;
  for (int e = 0; e < 31; ++e) {
    frame.model.element_matrices(e, &K0, &M0);
    mx.model.element_matrices(mx.model.element_index(frame.model.elements()[e].id), &K1, &M1);
    frame.model.element_dofs(e, &d0);
    EXPECT_EQ(mx.model.elements()[e].node_ids, frame.model.elements()[e].node_ids);
    std::vector<int> keep;
    for (int k = 0; k < static_cast<int>(d0.size()); ++k)
      if (d0[k] >= 0) keep.push_back(k);
    ASSERT_EQ(K1.rows(), static_cast<Eigen::Index>(keep.size()));
    for (std::size_t i = 0; i < keep.size(); ++i)
      for (std::size_t j = 0; j < keep.size(); ++j) {
        EXPECT_EQ(K1(i, j), K0(keep[i], keep[j]));
        EXPECT_EQ(M1(i, j), M0(keep[i], keep[j]));
      }
  }
}

// Detection and quantification on matrix elements are those of the frame (Table 3, element 28 case 3): the
// ranking is the same and dk, dm agree to 1e-8 (both are the same least-squares problem on matrices equal to
// rounding; the paper's values are -0.15, -0.15).
TEST(MatrixModel, DetectAndUpdateMatchTheFrame) {
  const Case mx = load_case(test::CasesDir() + "/paper-frame-matrices");
  const Case frame = load_case(test::CasesDir() + "/paper-frame-damage/element28-case3.yaml");
  const DetectSummary a = DetectCase(mx), b = DetectCase(frame);
  ASSERT_FALSE(a.elements.empty());
  EXPECT_EQ(a.elements.front().element, 28);
  EXPECT_EQ(a.elements.front().element, b.elements.front().element);
  ASSERT_EQ(a.amounts.size(), 1u);
  EXPECT_NEAR(a.amounts[0].dk, -0.15, 1e-8);
  EXPECT_NEAR(a.amounts[0].dm, -0.15, 1e-8);
  EXPECT_NEAR(a.amounts[0].dk, b.amounts[0].dk, 1e-8);

  // Updating: stiffness factors of elements 27, 28, 29 (Ceres) from the damaged frame's exact modes at the
  // translations: 0.85 for 28, 1 for the others, to 1e-6 (exact data; the solver's tolerances).
  const Model damaged = changed_model(frame.model, {{28, {-0.15, 0.0}}});
  EigenOptions eo;
  eo.num_modes = 6;
  const ModalResult truth = modal_analysis(damaged, eo);
  const ModalData data = sample_modes(damaged, truth, dofs_of_types(frame.model, kTranslations), 0, 6, "frame");
  ParametricModel pm(mx.model);
  for (int id : {27, 28, 29}) {
    Parameter p;
    p.name = "E:" + std::to_string(id);
    p.kind = ParameterKind::kStiffness;
    p.elements = {mx.model.element_index(id)};
    p.lower = 0.2;
    p.upper = 2.0;
    pm.add(p);
  }
  const FitSummary f = fit_parameters(pm, data, Eigen::Vector3d::Ones(), {}, FitOptions{});
  EXPECT_NEAR(f.theta[0], 1.0, 1e-6);
  EXPECT_NEAR(f.theta[1], 0.85, 1e-6);
  EXPECT_NEAR(f.theta[2], 1.0, 1e-6);
  // Section factors have no meaning for a matrix element: refused with the reason.
  Parameter a_factor;
  a_factor.name = "A:1";
  a_factor.kind = ParameterKind::kArea;
  a_factor.elements = {0};
  ParametricModel pm2(mx.model);
  EXPECT_HAS(ErrorOf([&] { pm2.add(a_factor); }), "is given by its matrices; only a stiffness (E) or mass (rho) factor");
}

// Group matrices (columns and beams as two Matrix Market files on the global equations) give the same
// frequencies; given K and M that hold more than the elements (the beams left out of elements.txt) give a
// remainder element with a note, and the same frequencies again. Tolerance 1e-10 as above.
TEST_F(MatrixFolder, GroupsAndRemainder) {
  const Case frame = load_case(test::CasesDir() + "/paper-frame");
  const Eigen::VectorXd f0 = Frequencies(frame.model);
  WriteGroups();
  const Case groups = Load("    dofs: dofs.csv\n    nodes: nodes.csv\n    groups:\n      columns: {K: Kc.mtx, M: Mc.mtx}\n"
                           "      beams: {K: Kb.mtx, M: Mb.mtx}\n");
  ASSERT_EQ(groups.model.num_elements(), 2);
  EXPECT_EQ(groups.model.elements()[1].group, "beams");
  Eigen::VectorXd f1 = Frequencies(groups.model);
  for (int k = 0; k < 8; ++k) EXPECT_TRUE(test::RelClose(f1[k], f0[k], 1e-10)) << "groups, mode " << k + 1;

  // Only the columns as elements, K and M in full: the beams' part (on all 60 DOFs: the beams join every
  // non-base node) becomes the remainder element 21.
  std::string text = test::Slurp(Path("elements.txt"));
  text = text.substr(0, text.find("element 21\n"));
  Write("columns.txt", text);
  const Case rest = Load("    dofs: dofs.csv\n    nodes: nodes.csv\n    elements: columns.txt\n    K: K.mtx\n    M: M.mtx\n");
  ASSERT_EQ(rest.model.num_elements(), 21);
  EXPECT_EQ(rest.model.elements()[20].id, 21);
  EXPECT_EQ(rest.model.elements()[20].group, "remainder");
  ASSERT_EQ(rest.notes.size(), 1u);
  EXPECT_HAS(rest.notes[0], "hold more than the element matrices on 60 DOFs");
  f1 = Frequencies(rest.model);
  for (int k = 0; k < 8; ++k) EXPECT_TRUE(test::RelClose(f1[k], f0[k], 1e-10)) << "remainder, mode " << k + 1;
  // The complete element file against K and M: no remainder.
  EXPECT_TRUE(Load("    dofs: dofs.csv\n    nodes: nodes.csv\n    elements: elements.txt\n    K: K.mtx\n    M: M.mtx\n").notes.empty());
}

// Group matrices are assembled on the node pairs they couple (Model::element_coupling), not on every pair of the
// DOFs they touch (each group touches nearly all 60 DOFs: 3600 pairs): the groups' pattern is the element model's,
// and K agrees with it to rounding (1e-14 of the largest entry: the same sums in another order). Updating keeps the
// groups' nonzeros only (sparse terms); its K(theta), eigenvalue sensitivities and derivative products agree with
// theta_c K_c + theta_b K_b, phi^T K_g phi and K_g phi computed from the files' matrices directly (1e-12 of the
// sums of absolute terms: the same products summed in another order, with cancellation of the axial terms).
TEST_F(MatrixFolder, GroupsAreAssembledOnTheNodePairsTheyCouple) {
  const Case all = WriteGroups();
  const Case groups = Load(
      "    dofs: dofs.csv\n    nodes: nodes.csv\n    groups:\n      columns: {K: Kc.mtx, M: Mc.mtx}\n"
      "      beams: {K: Kb.mtx, M: Mb.mtx}\n");
  const Model& m = groups.model;
  std::vector<std::pair<int, int>> pairs;
  ASSERT_TRUE(m.element_coupling(0, &pairs));
  const AssembledSystem a = assemble_system(all.model), g = assemble_system(m);
  EXPECT_EQ(g.K.nonZeros(), a.K.nonZeros());
  EXPECT_LT(g.K.nonZeros(), 3600);
  EXPECT_LT((test::Dense(g.K) - test::Dense(a.K)).cwiseAbs().maxCoeff(),
            1e-14 * test::Dense(a.K).cwiseAbs().maxCoeff());

  ParametricModel pm(m);
  for (int e = 0; e < 2; ++e) {
    Parameter p;
    p.name = m.elements()[e].group;
    p.elements = {e};
    pm.add(p);
  }
  const Eigen::Vector2d theta(0.9, 1.2);
  SparseMatrix K, M;
  pm.matrices(theta, &K, &M);
  const Eigen::MatrixXd Kc = OnModel("Kc.mtx", m), Kb = OnModel("Kb.mtx", m);
  const Eigen::MatrixXd Kref = theta[0] * Kc + theta[1] * Kb;
  const double scale = Kref.cwiseAbs().maxCoeff();
  EXPECT_LT((test::Dense(K) - Kref).cwiseAbs().maxCoeff(), 1e-12 * scale);
  EigenOptions eo;
  eo.num_modes = 4;
  const EigenSolution s = solve_eigen(K, M, eo);
  ASSERT_TRUE(s.summary.ok());
  const Eigen::MatrixXd S = pm.eigenvalue_sensitivities(theta, s.eigenvalues, s.modes);
  ParametricModel::SparseProducts sp;
  for (int p = 0; p < 2; ++p) {
    const Eigen::MatrixXd& Kg = p == 0 ? Kc : Kb;
    for (int i = 0; i < 4; ++i) {
      const Eigen::VectorXd phi = s.modes.col(i);
      const double size = phi.cwiseAbs().dot(Kg.cwiseAbs() * phi.cwiseAbs());  // the terms cancel (axial stiffness)
      EXPECT_LT(std::abs(S(i, p) - phi.dot(Kg * phi)), 1e-12 * size) << "group " << p << ", mode " << i + 1;
      pm.derivative_products(p, theta, phi, &sp);
      Eigen::VectorXd y = Eigen::VectorXd::Zero(m.num_dofs());
      for (std::size_t t = 0; t < sp.dof.size(); ++t) y[sp.dof[t]] += sp.dKv[t];
      EXPECT_LT((y - Kg * phi).norm(), 1e-12 * (Kg.cwiseAbs() * phi.cwiseAbs()).norm())
          << "group " << p << ", mode " << i + 1;
    }
  }
}

// Matrix input without friction (issue 19): a stiffness-only and a mass-only group (K.mtx, M.mtx as groups, no
// empty files) and no node table give the frame's frequencies (1e-10 as above); the missing coordinates are said
// once, and matching test points by position is refused with the reason.
TEST_F(MatrixFolder, StiffnessOnlyMassOnlyGroupsWithoutCoordinates) {
  const Eigen::VectorXd f0 = Frequencies(load_case(test::CasesDir() + "/paper-frame").model);
  const Case c = Load("    dofs: dofs.csv\n    groups:\n      stiffness: {K: K.mtx}\n      mass: {M: M.mtx}\n");
  ASSERT_EQ(c.model.num_elements(), 2);
  const Eigen::VectorXd f1 = Frequencies(c.model);
  for (int k = 0; k < 8; ++k) EXPECT_TRUE(test::RelClose(f1[k], f0[k], 1e-10)) << "mode " << k + 1;
  ASSERT_EQ(c.notes.size(), 1u);
  EXPECT_HAS(c.notes[0], "no node table (nodes:)");
  for (const Node& nd : c.model.nodes()) EXPECT_EQ(nd.x, Eigen::Vector3d::Zero());
  UffFile geo;
  geo.source = "points.uff";
  UffNodes pts;
  pts.nodes.resize(1);
  geo.datasets.push_back(UffDataset{15, 1, pts});
  EXPECT_HAS(ErrorOf([&] { map_test_points(c.model, geo, GeometrySpec{}); }),
             "points.uff: test points cannot be matched by position: the model's nodes have no coordinates");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: dofs.csv\n    groups:\n      nothing: {}\n"); }), "give K, M or both");
}

// The K/M consistency check with exact sums: the groups add up to the given K except for exporter rounding in
// entries where large contributions cancel (an entry that should be 0 holds 1e-13 of its row's scale in K.mtx
// and 3e-13 in the group, as SAP2000's influence matrices do): no remainder element. A real difference of 1e-6
// of the row's scale still is one (the tolerance is 1e-9 of the row's and column's largest entries).
TEST_F(MatrixFolder, ExactSumsGiveNoRemainder) {
  SparseMatrix K = read_matrix_market(Path("K.mtx"));
  const int i = 0;
  int j = -1;  // an equation not coupled to equation 0
  for (int q = 1; q < K.cols() && j < 0; ++q)
    if (K.coeff(i, q) == 0.0 && K.coeff(i, i) != 0.0 && K.coeff(q, q) != 0.0) j = q;
  ASSERT_GE(j, 0);
  const double s = std::max(std::abs(K.coeff(i, i)), std::abs(K.coeff(j, j)));
  auto with = [&](double v, const std::string& f) {
    SparseMatrix A = K;
    A.coeffRef(i, j) = v;
    A.coeffRef(j, i) = v;
    write_matrix_market(Path(f), A, true, true);
  };
  with(3e-13 * s, "Kg.mtx");
  with(1e-13 * s, "Kx.mtx");
  const std::string groups = "    dofs: dofs.csv\n    groups:\n      stiffness: {K: Kg.mtx}\n      mass: {M: M.mtx}\n    M: M.mtx\n";
  const Case exact = Load(groups + "    K: Kx.mtx\n");
  EXPECT_EQ(exact.model.num_elements(), 2);
  for (const std::string& n : exact.notes) EXPECT_EQ(n.find("remainder"), std::string::npos) << n;
  with(1e-6 * s, "Kd.mtx");
  const Case differs = Load(groups + "    K: Kd.mtx\n");
  EXPECT_EQ(differs.model.num_elements(), 3);
}

// Each malformed input gets a message naming the file, the line where there is one, and what to do.
TEST_F(MatrixFolder, ClearErrors) {
  const std::string base = "    nodes: nodes.csv\n    elements: elements.txt\n";
  Write("bad-dofs.csv", "node,dof\n5,ux\n5,uq\n");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: bad-dofs.csv\n" + base); }),
             "bad-dofs.csv:3: expected 'node, dof' (a node id and ux, uy, uz, rx, ry, rz or 1..6), got '5,uq'");
  Write("dup-dofs.csv", "5 1\n5 2\n5 1\n");  // Nastran component numbers
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: dup-dofs.csv\n" + base); }), "dup-dofs.csv:3: ux at node 5 is already equation 1");
  Write("few-dofs.csv", "5,ux\n5,uy\n");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: few-dofs.csv\n" + base); }), "elements.txt:6: element 1: DOF '3' is not an equation number 1..2");
  Write("far.csv", test::Slurp(Path("dofs.csv")) + "99,ux\n");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: far.csv\n" + base); }), "far.csv: equation 61 is at node 99, which");
  std::string el = test::Slurp(Path("elements.txt"));
  Write("asym.txt", el.replace(el.find("3 1 252\n"), 8, "1 3 252\n"));
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: dofs.csv\n    nodes: nodes.csv\n    elements: asym.txt\n"); }),
             "asym.txt:9: element 1: entries are the lower triangle (row >= col); got (1, 3)");
  Write("short.txt", "%%dynid element-matrices 1\nelement 1\ndofs 1 2\nK 3\n1 1 5\n");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: dofs.csv\n    nodes: nodes.csv\n    elements: short.txt\n"); }),
             "short.txt:5: element 1: file ends after 1 of 3 stiffness entries");
  Write("nohead.txt", "element 1\n");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: dofs.csv\n    nodes: nodes.csv\n    elements: nohead.txt\n"); }),
             "nohead.txt:1: not an element-matrices file");
  Write("K3.mtx", "%%MatrixMarket matrix coordinate real symmetric\n3 3 1\n1 1 1\n");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: dofs.csv\n" + base + "    K: K3.mtx\n    M: M.mtx\n"); }),
             "K3.mtx: a 3 x 3 matrix, but the DOF table");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: dofs.csv\n" + base + "    K: K.mtx\n"); }), "give both K and M");
  EXPECT_HAS(ErrorOf([&] { Load("    nodes: nodes.csv\n    elements: elements.txt\n"); }), "'dofs' is missing");
  EXPECT_HAS(ErrorOf([&] { Load("    dofs: dofs.csv\n    nodes: nodes.csv\n    elements: nowhere.txt\n"); }),
             "matrices elements: cannot open");
  // A matrix element whose mass matrix is not symmetric (built in memory).
  Model m;
  m.add_node(1, Eigen::Vector3d::Zero());
  MatrixElementData d;
  d.dofs = {{1, Dof::UX}, {1, Dof::UY}};
  d.K = Eigen::Matrix2d::Identity();
  d.M = (Eigen::Matrix2d() << 1, 0.5, 0.4, 1).finished();
  m.add_element(make_matrix_element(7, d));
  m.set_free_free(true);
  EXPECT_HAS(ErrorOf([&] { m.finalize(); }), "element 7 (matrix): its mass matrix is not symmetric (entries 2,1 and 1,2 differ)");
}

}  // namespace
}  // namespace dynid
