// Eigen-solvers: the sparse shift-invert Lanczos path against the dense path (1e-8 relative) on every model
// small enough for the dense path; free-free structures, singular mass matrices, band mode, mechanisms.
#include <cholmod.h>

#include <Eigen/Dense>
#include <random>

#include "dynid/engine/modal.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/mesh/generators.hpp"
#include "dynid/solvers/cholmod.hpp"
#include "internal/lanczos.hpp"
#include "internal/super_factor.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

Material Steel() { return {"steel", 2.1e11, 0, 0.3, 7800}; }

Frame2DSpec Frame2D(int bays, int stories, int div) {
  Frame2DSpec s;
  s.bays = bays;
  s.stories = stories;
  s.divisions = div;
  s.span = 4.0;
  s.height = 3.0;
  s.material = Steel();
  s.column = {"col", 5e-3, 0, 4e-5, 0};
  s.beam = {"beam", 4e-3, 0, 6e-5, 0};
  return s;
}

Frame3DSpec Frame3D() { return test::SteelFrame3D(2, 2, 3); }

// Solves a model with both paths and checks: eigenvalues to 1e-8 relative (elastic modes; rigid ones ~0 are
// compared in absolute terms against the first elastic eigenvalue), mode shapes (MAC > 1 - 1e-8 for simple
// eigenvalues; the rigid-body subspace as a whole), mass normalisation (1e-10), residuals (1e-10).
void CompareSparseDense(const Model& m, int modes) {
  const AssembledSystem sys = assemble_system(m);
  EigenOptions o;
  o.num_modes = modes;
  o.method = EigenOptions::Method::kSparse;
  const ModalResult sp = modal_analysis(m, sys, o);
  o.method = EigenOptions::Method::kDense;
  const ModalResult de = modal_analysis(m, sys, o);
  ASSERT_TRUE(sp.ok()) << sp.summary.BriefReport();
  ASSERT_TRUE(de.ok()) << de.summary.BriefReport();
  ASSERT_EQ(sp.eigenvalues.size(), modes);
  ASSERT_EQ(de.eigenvalues.size(), modes);
  int nr = 0;
  while (nr < modes && sp.rigid_body[nr]) ++nr;
  for (int k = 0; k < modes; ++k) EXPECT_EQ(sp.rigid_body[k], de.rigid_body[k]) << "mode " << k;
  const double lam1 = nr < modes ? sp.eigenvalues[nr] : 1.0;
  for (int k = 0; k < modes; ++k) {
    if (k < nr) {
      EXPECT_LT(std::abs(sp.eigenvalues[k]), 1e-8 * lam1);
      EXPECT_LT(std::abs(de.eigenvalues[k]), 1e-8 * lam1);
      continue;
    }
    EXPECT_TRUE(test::RelClose(sp.eigenvalues[k], de.eigenvalues[k], 1e-8)) << "mode " << k;
    const bool simple = (k + 1 >= modes || sp.eigenvalues[k + 1] > sp.eigenvalues[k] * (1 + 1e-6)) &&
                        (k == nr || sp.eigenvalues[k - 1] < sp.eigenvalues[k] * (1 - 1e-6));
    if (simple) {
      EXPECT_GT(test::Mac(sp.modes.col(k), de.modes.col(k)), 1 - 1e-8) << "mode " << k;
    }
  }
  if (nr > 0) {
    EXPECT_LT(test::SubspaceGap(sp.modes.leftCols(nr), de.modes.leftCols(nr)), 1e-8);
  }
  const Eigen::MatrixXd M = test::Dense(sys.M);
  const Eigen::MatrixXd G = sp.modes.transpose() * M * sp.modes;
  EXPECT_LT((G - Eigen::MatrixXd::Identity(modes, modes)).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT(sp.summary.max_residual, 1e-10);
  EXPECT_LT(de.summary.max_residual, 1e-10);
}

TEST(Eigen, SparseMatchesDensePaperBeam) {
  CompareSparseDense(load_case(test::CasesDir() + "/paper-beam").model, 7);
}
TEST(Eigen, SparseMatchesDensePaperFrame) {
  CompareSparseDense(load_case(test::CasesDir() + "/paper-frame").model, 12);
}
TEST(Eigen, SparseMatchesDenseAnalyticBeams) {
  CompareSparseDense(load_case(test::CasesDir() + "/cantilever-beam").model, 8);
  CompareSparseDense(load_case(test::CasesDir() + "/simply-supported-beam").model, 8);
}
TEST(Eigen, SparseMatchesDense2DFrame) { CompareSparseDense(make_frame2d(Frame2D(3, 6, 3)), 20); }
TEST(Eigen, SparseMatchesDense3DFrame) { CompareSparseDense(make_frame3d(Frame3D()), 20); }

TEST(Eigen, SparseMatchesDenseFreeFree3DFrame) {
  // Remove the supports: 6 rigid-body modes, found from the geometry and reported first.
  const Model m = test::WithoutSupports(make_frame3d(Frame3D()));
  CompareSparseDense(m, 16);
  EigenOptions o;
  o.num_modes = 8;
  const ModalResult r = modal_analysis(m, o);
  EXPECT_EQ(std::count(r.rigid_body.begin(), r.rigid_body.end(), 1), 6);
  ASSERT_EQ(r.rigid_body_descriptions.size(), 6u);
  EXPECT_EQ(r.rigid_body_descriptions[0], "translation x");
  EXPECT_EQ(r.rigid_body_descriptions[5], "rotation about z");
}

TEST(Eigen, SingularMassMatrixLumped) {
  // Lumped mass leaves the rotations massless: M is singular, the finite modes are still returned and agree
  // with the dense path (which solves the shifted standard problem instead of factorising M).
  Frame2DSpec s = Frame2D(2, 4, 2);
  s.mass = MassType::Lumped;
  const Model m = make_frame2d(s);
  const AssembledSystem sys = assemble_system(m);
  ASSERT_LT(sys.M.diagonal().minCoeff(), 1e-300);  // really singular
  CompareSparseDense(m, 15);
}

TEST(Eigen, BandModeFindsEveryModeInTheBand) {
  const Model m = make_frame2d(Frame2D(3, 6, 3));
  EigenOptions o;
  o.num_modes = 30;
  o.method = EigenOptions::Method::kSparse;
  const ModalResult all = modal_analysis(m, o);
  ASSERT_TRUE(all.ok());
  // A band between modes 6 and 21 (edges placed between eigenvalues).
  o.band_lo = 0.5 * (all.eigenvalues[5] + all.eigenvalues[6]);
  o.band_hi = 0.5 * (all.eigenvalues[20] + all.eigenvalues[21]);
  const ModalResult band = modal_analysis(m, o);
  ASSERT_TRUE(band.ok()) << band.summary.BriefReport();
  ASSERT_EQ(band.eigenvalues.size(), 15);
  for (int k = 0; k < 15; ++k) EXPECT_TRUE(test::RelClose(band.eigenvalues[k], all.eigenvalues[6 + k], 1e-9));
}

TEST(Eigen, MechanismIsReportedWithItsDof) {
  // A clamped cantilever plus a separate, unsupported beam that is not tied to it: no global rigid-body
  // motion is free (the cantilever is clamped), but K is singular; the message names a DOF of the loose beam.
  Model m;
  m.add_material(Steel());
  m.add_section({"s", 1e-3, 0, 1e-6, 0});
  for (int i = 1; i <= 4; ++i) m.add_node(i, Eigen::Vector3d(i, 0, 0));
  for (int i = 0; i < 2; ++i) {
    Element e;
    e.id = i + 1;
    e.type = ElementType::Beam2D;
    e.node_ids = {{2 * i + 1, 2 * i + 2}};
    e.material = e.section = 0;
    m.add_element(e);
  }
  m.restrain(1, kAllDofs);
  m.finalize();
  EigenOptions o;
  o.num_modes = 2;
  o.method = EigenOptions::Method::kSparse;
  const ModalResult r = modal_analysis(m, o);
  EXPECT_EQ(r.summary.status, EigenStatus::kFactorizationFailed);
  EXPECT_NE(r.summary.message.find("K is singular"), std::string::npos) << r.summary.message;
  EXPECT_TRUE(r.summary.message.find("node 3") != std::string::npos ||
              r.summary.message.find("node 4") != std::string::npos)
      << r.summary.message;
}

TEST(Eigen, NonConvergenceIsReported) {
  // One restart and the smallest basis cannot converge 20 modes of a 2D frame: a status and a message that says
  // what to change, not a crash or a silent partial answer.
  const Model m = make_frame2d(Frame2D(3, 6, 3));
  EigenOptions o;
  o.num_modes = 20;
  o.method = EigenOptions::Method::kSparse;
  o.max_restarts = 1;
  o.subspace = 22;
  const ModalResult r = modal_analysis(m, o);
  EXPECT_EQ(r.summary.status, EigenStatus::kNotConverged);
  EXPECT_NE(r.summary.message.find("raise max_restarts"), std::string::npos) << r.summary.message;
}

TEST(Eigen, RejectsNonFiniteMatrices) {
  SparseMatrix K(2, 2), M(2, 2);
  K.insert(0, 0) = 1;
  K.insert(1, 1) = std::nan("");
  M.insert(0, 0) = M.insert(1, 1) = 1;
  EXPECT_THROW(solve_eigen(K, M, EigenOptions{}), InputError);
}

// The two-core triangular solves of a simplicial factor (tree_solve.hpp; a plane frame of 40 x 40 bays, members in
// 4 elements: 34,440 DOFs, the factor CHOLMOD chooses for short columns) against CHOLMOD's own solve of the same
// factor (solve_block): the same x to 1e-12 relative (both are backward-stable triangular solves with one factor;
// they differ by the order of their sums, ~ cond(L) eps with cond(L) = sqrt(cond(K)) ~ 1e4 here), a residual
// |K x - b| / |b| below 1e-8 (cond(K) eps ~ 1e-8 is what any solve reaches), and bitwise the same x with one thread
// and with two (the split does not depend on the thread count). CHOLMOD's own solves stay below pair.hpp's 20,000
// rows (the same frame with 20 x 20 bays). The same checks for the two-core solves of a supernodal factor
// (super_solve.hpp; a 3D frame of 16 x 16 x 16 bays, 29,478 DOFs, whose factor CHOLMOD makes supernodal).
TEST(Eigen, TwoCoreSolvesMatchCholmodForAnyThreadCount) {
  for (const Model& model : {make_frame2d(Frame2D(40, 40, 4)), make_frame3d(test::SteelFrame3D(16, 16, 16))}) {
    SCOPED_TRACE(model.num_dofs());
    const AssembledSystem sys = assemble_system(model);
    CholmodFactor F;
    F.analyze(sys.K);
    ASSERT_TRUE(F.factorize(sys.K));
    ASSERT_TRUE(F.parallel_solves());
    const Eigen::Index n = sys.K.rows();
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    Eigen::VectorXd b(n);
    for (Eigen::Index i = 0; i < n; ++i) b[i] = u(rng);
    const auto [x1, x] = test::OnOneThreadAndTwo([&] {
      Eigen::VectorXd xt(n);
      F.forward(b.data(), xt.data());
      F.backward(xt.data(), xt.data());
      return xt;
    });
    EXPECT_EQ((x1 - x).cwiseAbs().maxCoeff(), 0.0);
    Eigen::MatrixXd ref;
    F.solve_block(b, &ref);
    EXPECT_LT((x - ref.col(0)).norm(), 1e-12 * ref.norm());
    EXPECT_LT((sys.K.selfadjointView<Eigen::Upper>() * x - b).norm(), 1e-8 * b.norm());
    Eigen::VectorXd y(n);
    F.solve(b.data(), y.data());
    EXPECT_EQ((y - x).cwiseAbs().maxCoeff(), 0.0);
  }

  for (const Model& small : {make_frame2d(Frame2D(20, 20, 4)), make_frame3d(test::SteelFrame3D(6, 6, 6))}) {
    ASSERT_LT(small.num_dofs(), 20000);
    const AssembledSystem other = assemble_system(small);
    CholmodFactor G;
    G.analyze(other.K);
    ASSERT_TRUE(G.factorize(other.K));
    EXPECT_FALSE(G.parallel_solves()) << other.K.rows();
  }
}

// The two-core supernodal factorization (super_factor.hpp) against CHOLMOD's own of the same symbolic factor, on a
// 3D frame of 14 x 14 x 14 bays (20,250 DOFs; the factor CHOLMOD makes supernodal). Every entry of L within
// 1e-13 of the largest (both are Cholesky factorizations of one matrix in one pattern and differ by the order of
// the updates' sums: entry errors ~ n_updates eps |L|); bitwise the same L with one thread and with two (the split
// depends on the factor alone); the solve's residual |K x - b| / |b| below 1e-8 (cond(K) eps). K - sigma M with
// sigma between the 5th and 6th eigenvalues is not positive definite: the same failing column as CHOLMOD's (the
// first in column order), and CholmodFactor reports it. Below pair.hpp's 20,000 rows CHOLMOD factors.
TEST(Eigen, TwoCoreSupernodalFactorMatchesCholmodForAnyThreadCount) {
  const Model m = make_frame3d(test::SteelFrame3D(14, 14, 14));
  const AssembledSystem sys = assemble_system(m);
  SparseMatrix K = sys.K;
  K.makeCompressed();
  ASSERT_GE(K.rows(), 20000);
  cholmod_common c;
  cholmod_start(&c);
  c.print = 0;
  c.error_handler = nullptr;
  c.supernodal = CHOLMOD_SUPERNODAL;
  c.final_ll = 1;
  c.quick_return_if_not_posdef = 1;
  auto view = [](const SparseMatrix& A) {
    cholmod_sparse v{};
    v.nrow = v.ncol = static_cast<size_t>(A.rows());
    v.nzmax = static_cast<size_t>(A.nonZeros());
    v.p = const_cast<int*>(A.outerIndexPtr());
    v.i = const_cast<int*>(A.innerIndexPtr());
    v.x = const_cast<double*>(A.valuePtr());
    v.stype = 1;
    v.itype = CHOLMOD_INT;
    v.xtype = CHOLMOD_REAL;
    v.dtype = CHOLMOD_DOUBLE;
    v.sorted = v.packed = 1;
    return v;
  };
  cholmod_sparse A = view(K);
  cholmod_factor* ref = cholmod_analyze(&A, &c);
  ASSERT_NE(ref, nullptr);
  ASSERT_TRUE(ref->is_super);
  cholmod_factor* mine = cholmod_copy_factor(ref, &c);
  ASSERT_TRUE(cholmod_factorize(&A, ref, &c));
  ASSERT_EQ(c.status, CHOLMOD_OK);
  const auto [one, two] = test::OnOneThreadAndTwo([&] {
    EXPECT_TRUE(detail::factorize_supernodal_pair(&A, mine, &c));
    EXPECT_EQ(c.status, CHOLMOD_OK);
    EXPECT_EQ(mine->minor, mine->n);
    return Eigen::VectorXd(
        Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(mine->x), static_cast<Eigen::Index>(mine->xsize)));
  });
  EXPECT_EQ((one - two).cwiseAbs().maxCoeff(), 0.0);
  ASSERT_EQ(mine->xsize, ref->xsize);
  const Eigen::Map<const Eigen::VectorXd> lref(static_cast<const double*>(ref->x),
                                               static_cast<Eigen::Index>(ref->xsize));
  EXPECT_LT((two - lref).cwiseAbs().maxCoeff(), 1e-13 * lref.cwiseAbs().maxCoeff());

  CholmodFactor F;
  F.analyze(K);
  ASSERT_TRUE(F.factorize(K));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd b(K.rows()), x(K.rows());
  for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = u(rng);
  F.solve(b.data(), x.data());
  EXPECT_LT((K.selfadjointView<Eigen::Upper>() * x - b).norm(), 1e-8 * b.norm());

  EigenOptions o;
  o.num_modes = 6;
  o.method = EigenOptions::Method::kSparse;
  const ModalResult r = modal_analysis(m, sys, o);
  ASSERT_TRUE(r.ok()) << r.summary.message;
  const double sigma = 0.5 * (r.eigenvalues[4] + r.eigenvalues[5]);
  SparseMatrix S = K - sigma * SparseMatrix(sys.M);
  S.makeCompressed();
  ASSERT_EQ(S.nonZeros(), K.nonZeros());  // M's pattern within K's: the analysed pattern
  cholmod_sparse As = view(S);
  cholmod_factorize(&As, ref, &c);
  ASSERT_EQ(c.status, CHOLMOD_NOT_POSDEF);
  const size_t minor = ref->minor;
  ASSERT_TRUE(detail::factorize_supernodal_pair(&As, mine, &c));
  EXPECT_EQ(c.status, CHOLMOD_NOT_POSDEF);
  EXPECT_EQ(mine->minor, minor);
  EXPECT_FALSE(F.factorize(S));
  EXPECT_EQ(F.failed_index(), static_cast<const int*>(ref->Perm)[minor]);

  cholmod_free_factor(&ref, &c);
  cholmod_free_factor(&mine, &c);
  cholmod_finish(&c);
  const AssembledSystem small = assemble_system(make_frame3d(test::SteelFrame3D(6, 6, 6)));
  ASSERT_LT(small.K.rows(), 20000);
  cholmod_start(&c);
  c.supernodal = CHOLMOD_SUPERNODAL;
  cholmod_sparse As2 = view(small.K);
  cholmod_factor* L2 = cholmod_analyze(&As2, &c);
  EXPECT_FALSE(detail::factorize_supernodal_pair(&As2, L2, &c));
  cholmod_free_factor(&L2, &c);
  cholmod_finish(&c);
}

// CHOLMOD's SuiteSparse_long routines (CholmodFactor::Indices::kLong; taken by themselves when a factor has 2^31
// entries or more, which no test can afford: the 980,100-DOF 3D frame of bench/README.md) give the int routines'
// results: the same ordering and the same arithmetic in the same order, so the solves agree bitwise (asserted to
// 1e-15 of |x|, rounding's scale, in case a BLAS orders a sum differently). On the 14 x 14 x 14 frame (20,250 DOFs:
// the two-core supernodal factorization and solves, super_factor.hpp, super_solve.hpp) and the 6 x 6 x 6 frame
// (CHOLMOD's own factorization and solves; there also L D L^T with its inertia), K and K - sigma M with sigma above the
// 5th eigenvalue, between two distinct ones (not positive definite: the same failing row and the same inertia).
TEST(Eigen, LongIndicesGiveTheIntRoutinesResults) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const int bays : {14, 6}) {
    const Model m = make_frame3d(test::SteelFrame3D(bays, bays, bays));
    const AssembledSystem sys = assemble_system(m);
    SparseMatrix K = sys.K;
    K.makeCompressed();
    EigenOptions o;
    o.num_modes = 10;
    o.method = EigenOptions::Method::kSparse;
    const ModalResult r = modal_analysis(m, sys, o);
    ASSERT_TRUE(r.ok()) << r.summary.message;
    int below = 5;  // sigma between two distinct eigenvalues (the square frames have pairs)
    while (below < 9 && r.eigenvalues[below] < (1 + 1e-6) * r.eigenvalues[below - 1]) ++below;
    ASSERT_LT(below, 9);
    SparseMatrix S = K - 0.5 * (r.eigenvalues[below - 1] + r.eigenvalues[below]) * SparseMatrix(sys.M);
    S.makeCompressed();
    const Eigen::Index n = K.rows();
    Eigen::MatrixXd B(n, 3);
    for (Eigen::Index i = 0; i < B.size(); ++i) B.data()[i] = u(rng);
    CholmodFactor fi, fl(CholmodFactor::Kind::kSupernodalLLt, CholmodFactor::Indices::kLong);
    EXPECT_TRUE(fl.long_indices());
    for (CholmodFactor* f : {&fi, &fl}) {
      f->analyze(K);
      ASSERT_TRUE(f->factorize(K));
    }
    EXPECT_FALSE(fi.long_indices());
    EXPECT_EQ(fi.parallel_solves(), n >= 20000);
    EXPECT_EQ(fl.parallel_solves(), fi.parallel_solves());
    EXPECT_EQ(fl.factor_nonzeros(), fi.factor_nonzeros());
    auto same = [](const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
      EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-15 * a.cwiseAbs().maxCoeff());
    };
    Eigen::VectorXd xi(n), xl(n);
    fi.solve(B.col(0).data(), xi.data());
    fl.solve(B.col(0).data(), xl.data());
    same(xi, xl);
    fi.forward(B.col(1).data(), xi.data());
    fl.forward(B.col(1).data(), xl.data());
    same(xi, xl);
    fi.backward(B.col(2).data(), xi.data());
    fl.backward(B.col(2).data(), xl.data());
    same(xi, xl);
    Eigen::MatrixXd Xi, Xl;
    fi.solve_block(B, &Xi);
    fl.solve_block(B, &Xl);
    same(Xi, Xl);
    EXPECT_FALSE(fi.factorize(S));
    EXPECT_FALSE(fl.factorize(S));
    EXPECT_GE(fi.failed_index(), 0);
    EXPECT_EQ(fl.failed_index(), fi.failed_index());
    if (n >= 20000) continue;  // a simplicial L D L^T of the large frame's fill takes seconds
    CholmodFactor di(CholmodFactor::Kind::kSimplicialLDLt),
        dl(CholmodFactor::Kind::kSimplicialLDLt, CholmodFactor::Indices::kLong);
    for (CholmodFactor* f : {&di, &dl}) {
      f->analyze(S);
      ASSERT_TRUE(f->factorize(S));
    }
    EXPECT_EQ(di.negative_pivots(), below);
    EXPECT_EQ(dl.negative_pivots(), below);
    di.solve(B.col(0).data(), xi.data());
    dl.solve(B.col(0).data(), xl.data());
    same(xi, xl);
  }
}

// The Lanczos steps' vector work on two row halves (LanczosOptions::pair_vectors): the same Ritz pairs, bitwise,
// with one thread and with two, and the known eigenvalues (a diagonal operator of 30,000 rows) to the Lanczos
// tolerance.
TEST(Lanczos, SameRitzPairsOnOneThreadAndTwo) {
  const Eigen::Index n = 30000;
  Eigen::VectorXd d(n);
  for (Eigen::Index i = 0; i < n; ++i) d[i] = 1.0 / (1.0 + static_cast<double>(i));
  auto diag = [&](const double* x, double* y) {
    for (Eigen::Index i = 0; i < n; ++i) y[i] = d[i] * x[i];
  };
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd v0(n);
  for (Eigen::Index i = 0; i < n; ++i) v0[i] = u(rng);
  const auto [one, two] = test::OnOneThreadAndTwo([&] {
    return detail::thick_restart_lanczos(diag, n, v0, detail::LanczosOptions{6, 20, 200, 1e-10, true});
  });
  ASSERT_TRUE(one.converged);
  ASSERT_TRUE(two.converged);
  EXPECT_EQ((one.theta - two.theta).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((one.Y - two.Y).cwiseAbs().maxCoeff(), 0.0);
  for (Eigen::Index i = 0; i < 6; ++i) EXPECT_NEAR(two.theta[i], d[i], 1e-10 * d[i]) << i;
}

// The thick-restart Lanczos on operators whose answer is known. A diagonal operator with 5 distinct values,
// each 40 times: the Krylov space of any start vector has dimension 5, so the run meets invariant subspaces and
// must continue from fresh vectors to find the 8 largest eigenvalues with their multiplicity (4 -> 40 x 4, ...).
// A random symmetric operator: Ritz values against Eigen's dense solver, Ritz vectors orthonormal with small
// residuals. Tolerances: the Lanczos tolerance 1e-10 relative, 1e-9 on the residual norm of unit vectors.
TEST(Lanczos, RepeatedEigenvaluesAndADenseReference) {
  const Eigen::Index n = 200;
  Eigen::VectorXd d(n);
  for (Eigen::Index i = 0; i < n; ++i) d[i] = 1.0 + static_cast<double>(i % 5);
  auto diag = [&](const double* x, double* y) {
    for (Eigen::Index i = 0; i < n; ++i) y[i] = d[i] * x[i];
  };
  const Eigen::VectorXd v0 = Eigen::VectorXd::Ones(n);
  const detail::LanczosResult r = detail::thick_restart_lanczos(diag, n, v0, detail::LanczosOptions{8, 24, 100, 1e-10});
  ASSERT_TRUE(r.converged);
  ASSERT_EQ(r.theta.size(), 8);
  for (Eigen::Index i = 0; i < 8; ++i) EXPECT_NEAR(r.theta[i], 5.0, 1e-9) << i;
  EXPECT_LT((r.Y.transpose() * r.Y - Eigen::MatrixXd::Identity(8, 8)).cwiseAbs().maxCoeff(), 1e-10);

  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  Eigen::MatrixXd A(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) A(i, j) = g(rng);
  A = (A + A.transpose()).eval();
  auto dense = [&](const double* x, double* y) {
    Eigen::Map<Eigen::VectorXd>(y, n).noalias() = A * Eigen::Map<const Eigen::VectorXd>(x, n);
  };
  Eigen::VectorXd start(n);
  for (Eigen::Index i = 0; i < n; ++i) start[i] = g(rng);
  const detail::LanczosResult q =
      detail::thick_restart_lanczos(dense, n, start, detail::LanczosOptions{10, 30, 500, 1e-10});
  ASSERT_TRUE(q.converged);
  const Eigen::VectorXd exact = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues().reverse();
  for (Eigen::Index i = 0; i < 10; ++i) {
    EXPECT_NEAR(q.theta[i], exact[i], 1e-10 * std::abs(exact[i])) << i;
    EXPECT_LT((A * q.Y.col(i) - q.theta[i] * q.Y.col(i)).norm(), 1e-9 * std::abs(exact[0])) << i;
  }
  EXPECT_LT((q.Y.transpose() * q.Y - Eigen::MatrixXd::Identity(10, 10)).cwiseAbs().maxCoeff(), 1e-10);
}

// An operator whose range (rank 10 in 40 dimensions) is smaller than the basis asked for (24 columns): the Krylov
// space closes and no fresh direction exists, so the basis spans the whole range and its Ritz pairs are exact.
// The run returns the 6 largest of them, converged, against the known diagonal (1e-11 absolute on values up to
// 10: exact but for rounding); before, it returned nothing. The same through solve_eigen: a spring chain with mass on 4
// of its 30 DOFs has 4 finite modes; the sparse path (basis 23 > 4) returns the lowest 3 as the dense path does.
TEST(Lanczos, ABasisLargerThanTheOperatorsRangeGivesItsExactPairs) {
  const Eigen::Index n = 40;
  Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < 10; ++i) d[4 * i] = 1.0 + static_cast<double>(i);
  auto diag = [&](const double* x, double* y) {
    for (Eigen::Index i = 0; i < n; ++i) y[i] = d[i] * x[i];
  };
  const Eigen::VectorXd v0 = d;  // in the operator's range, as solve_eigen's start vector is
  const detail::LanczosResult r = detail::thick_restart_lanczos(diag, n, v0, detail::LanczosOptions{6, 24, 100, 1e-10});
  ASSERT_TRUE(r.converged);
  ASSERT_EQ(r.theta.size(), 6);
  for (Eigen::Index i = 0; i < 6; ++i) EXPECT_NEAR(r.theta[i], 10.0 - static_cast<double>(i), 1e-11) << i;
  EXPECT_LT((r.Y.transpose() * r.Y - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff(), 1e-10);

  const int dofs = 30;
  SparseMatrix K(dofs, dofs), M(dofs, dofs);
  for (int i = 0; i < dofs; ++i) {
    K.insert(i, i) = 2e3;
    if (i + 1 < dofs) K.insert(i, i + 1) = K.insert(i + 1, i) = -1e3;
  }
  for (int i : {3, 11, 19, 27}) M.insert(i, i) = 1.0 + 0.25 * i;
  EigenOptions o;
  o.num_modes = 3;
  o.method = EigenOptions::Method::kSparse;
  const EigenSolution sp = solve_eigen(K, M, o);
  ASSERT_EQ(sp.summary.status, EigenStatus::kSuccess) << sp.summary.message;
  const EigenSolution de = solve_eigen_dense(test::Dense(K), test::Dense(M), o);
  ASSERT_EQ(de.summary.status, EigenStatus::kSuccess) << de.summary.message;
  ASSERT_EQ(sp.eigenvalues.size(), 3);
  ASSERT_EQ(de.eigenvalues.size(), 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(test::RelClose(sp.eigenvalues[k], de.eigenvalues[k], 1e-10)) << k;
    EXPECT_GT(test::Mac(sp.modes.col(k), de.modes.col(k)), 1 - 1e-10) << k;
  }
  // Asking for 6: both paths return the 4 finite modes and say so.
  o.num_modes = 6;
  const EigenSolution sp6 = solve_eigen(K, M, o);
  const EigenSolution de6 = solve_eigen_dense(test::Dense(K), test::Dense(M), o);
  for (const EigenSolution* s : {&sp6, &de6}) {
    EXPECT_EQ(s->summary.status, EigenStatus::kSuccess) << s->summary.message;
    EXPECT_EQ(s->eigenvalues.size(), 4);
    EXPECT_EQ(s->summary.message.rfind("the model has only 4 finite modes", 0), 0u) << s->summary.message;
  }
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(test::RelClose(sp6.eigenvalues[k], de6.eigenvalues[k], 1e-10)) << k;
}

}  // namespace
}  // namespace dynid
