// The distributed backend (solvers/distributed.hpp) against the local one, run by ctest as
// `mpiexec -n 2 test_distributed` (and once with 1 rank). Every rank runs every test and checks its own copy of the
// gathered result.
//
// Tolerances: both paths stop at a relative Ritz-value tolerance of 1e-12 here, so each eigenvalue is within
// ~1e-12 of the exact one and the two agree to 1e-10 (the requirement) with a margin of 100; mode shapes
// by MAC > 1 - 1e-10 for simple eigenvalues (a shape error e gives 1 - MAC ~ e^2, so this allows e ~ 1e-5 but the
// paths agree far closer), the rigid-body subspace as a whole by its gap.
#include <gtest/gtest.h>

#include "dynid/engine/modal.hpp"
#include "dynid/mesh/generators.hpp"
#include "dynid/solvers/distributed.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

Material Steel() { return {"steel", 2.1e11, 0, 0.3, 7800}; }

// ~1,000 DOFs.
Frame3DSpec Frame() { return test::SteelFrame3D(3, 2, 4); }

EigenOptions Options(int modes, EigenOptions::Backend backend) {
  EigenOptions o;
  o.num_modes = modes;
  o.method = EigenOptions::Method::kSparse;
  o.tolerance = 1e-12;
  o.backend = backend;
  return o;
}

void ExpectSameModes(const ModalResult& a, const ModalResult& b, double rtol) {
  ASSERT_TRUE(a.ok()) << a.summary.BriefReport();
  ASSERT_TRUE(b.ok()) << b.summary.BriefReport();
  const Eigen::Index m = a.eigenvalues.size();
  ASSERT_EQ(b.eigenvalues.size(), m);
  int nr = 0;
  while (nr < m && a.rigid_body[nr]) ++nr;
  for (Eigen::Index k = 0; k < m; ++k) {
    EXPECT_EQ(a.rigid_body[k], b.rigid_body[k]) << "mode " << k;
    if (k < nr) continue;
    EXPECT_TRUE(test::RelClose(a.eigenvalues[k], b.eigenvalues[k], rtol)) << "mode " << k;
    const bool simple = (k + 1 >= m || a.eigenvalues[k + 1] > a.eigenvalues[k] * (1 + 1e-6)) &&
                        (k == nr || a.eigenvalues[k - 1] < a.eigenvalues[k] * (1 - 1e-6));
    if (simple) {
      // Up to sign: the convention (largest entry positive) picks either of two mirror-image entries of equal
      // magnitude on a symmetric frame, by rounding.
      EXPECT_GT(test::Mac(a.modes.col(k), b.modes.col(k)), 1 - 1e-10) << "mode " << k;
    }
  }
  if (nr > 0) {
    EXPECT_LT(test::SubspaceGap(a.modes.leftCols(nr), b.modes.leftCols(nr)), 1e-8);
  }
  EXPECT_LT(b.summary.max_residual, 1e-10);
}

TEST(Distributed, MatchesLocalOnA3DFrame) {
  const Model m = make_frame3d(Frame());
  const ModalResult local = modal_analysis(m, Options(20, EigenOptions::Backend::kLocal));
  const ModalResult dist = modal_analysis(m, Options(20, EigenOptions::Backend::kDistributed));
  ExpectSameModes(local, dist, 1e-10);
  EXPECT_EQ(dist.summary.ranks, distributed_size());
  EXPECT_EQ(dist.nonzeros, local.nonzeros);  // the same global K, assembled in pieces
  EXPECT_GT(dist.summary.factor_nonzeros, 0);
  EXPECT_GT(dist.summary.solves, 20);
}

TEST(Distributed, MatchesLocalFreeFreeWithRigidBodyModes) {
  const Model m = test::WithoutSupports(make_frame3d(Frame()));
  const ModalResult local = modal_analysis(m, Options(14, EigenOptions::Backend::kLocal));
  const ModalResult dist = modal_analysis(m, Options(14, EigenOptions::Backend::kDistributed));
  ExpectSameModes(local, dist, 1e-10);
  EXPECT_EQ(std::count(dist.rigid_body.begin(), dist.rigid_body.end(), 1), 6);
  EXPECT_LT(dist.summary.shift, 0);  // the free-free shift, as the local path chooses it
  EXPECT_EQ(dist.summary.shift, local.summary.shift);
}

TEST(Distributed, MatricesInputMatchesLocal) {
  // solve_eigen on given matrices with backend kDistributed: contiguous blocks of rows, no repartition.
  const Model m = make_frame3d(Frame());
  const AssembledSystem sys = assemble_system(m);
  const EigenSolution a = solve_eigen(sys.K, sys.M, Options(12, EigenOptions::Backend::kLocal));
  const EigenSolution b = solve_eigen(sys.K, sys.M, Options(12, EigenOptions::Backend::kDistributed));
  ASSERT_TRUE(b.summary.ok()) << b.summary.BriefReport();
  for (Eigen::Index k = 0; k < 12; ++k) EXPECT_TRUE(test::RelClose(a.eigenvalues[k], b.eigenvalues[k], 1e-10));
}

TEST(Distributed, IterativeSolveAgreesToItsTolerance) {
  // CG + BoomerAMG inside shift-and-invert, each solve to 1e-12: the eigenvalues to ~1e-9 (the solves' error
  // enters the Ritz values at about the solve tolerance times the condition of the shifted system's scale).
  const Model m = make_frame3d(Frame());
  EigenOptions o = Options(8, EigenOptions::Backend::kDistributed);
  o.tolerance = 1e-10;
  o.distributed_solver = EigenOptions::DistributedSolver::kIterative;
  const ModalResult it = modal_analysis(m, o);
  const ModalResult local = modal_analysis(m, Options(8, EigenOptions::Backend::kLocal));
  ASSERT_TRUE(it.ok()) << it.summary.BriefReport();
  for (Eigen::Index k = 0; k < 8; ++k) EXPECT_TRUE(test::RelClose(it.eigenvalues[k], local.eigenvalues[k], 1e-7));
  EXPECT_NE(it.summary.method.find("BoomerAMG"), std::string::npos);
}

TEST(Distributed, MechanismIsReportedNotSolved) {
  // A clamped cantilever beside a loose beam: K is singular; MUMPS's null-pivot detection reports it.
  Model m;
  m.add_material(Steel());
  m.add_section({"s", 1e-3, 0, 1e-6, 0});
  for (int i = 1; i <= 40; ++i) m.add_node(i, Eigen::Vector3d(i, 0, 0));
  for (int i = 1; i < 40; ++i) {
    if (i == 20) continue;  // nodes 21..40 form a separate, unsupported beam
    Element e;
    e.id = i;
    e.type = ElementType::Beam2D;
    e.node_ids = {{i, i + 1}};
    e.material = e.section = 0;
    m.add_element(e);
  }
  m.restrain(1, kAllDofs);
  m.finalize();
  const ModalResult r = modal_analysis(m, Options(4, EigenOptions::Backend::kDistributed));
  EXPECT_EQ(r.summary.status, EigenStatus::kFactorizationFailed) << r.summary.BriefReport();
  EXPECT_HAS(r.summary.message, "K is singular");
}

TEST(Distributed, BandModeIsRefused) {
  const Model m = make_frame3d(Frame());
  EigenOptions o = Options(4, EigenOptions::Backend::kDistributed);
  o.band_lo = 0;
  o.band_hi = 100;
  EXPECT_HAS(test::ErrorOf([&] { modal_analysis(m, o); }), "a band needs the local backend");
}

TEST(Distributed, PartitionIsBalancedAndKeepsNodesTogether) {
  const Model m = make_frame3d(Frame());
  const std::vector<int> part = partition_dofs(m, 3);
  std::vector<int> count(3, 0);
  for (int p : part) ++count[static_cast<std::size_t>(p)];
  for (int c : count) EXPECT_GT(c, m.num_dofs() / 3 * 0.8) << "unbalanced: " << c << " of " << m.num_dofs();
  // A node's DOFs carry the same elements: one supervariable, one part.
  for (std::size_t n = 0; n < m.nodes().size(); ++n) {
    int p = -1;
    for (int t = 0; t < kNumDofTypes; ++t) {
      const int eq = m.dof_map().eq(static_cast<int>(n), static_cast<Dof>(t));
      if (eq < 0) continue;
      if (p < 0) p = part[static_cast<std::size_t>(eq)];
      EXPECT_EQ(part[static_cast<std::size_t>(eq)], p) << "node index " << n;
    }
  }
}

}  // namespace
}  // namespace dynid
