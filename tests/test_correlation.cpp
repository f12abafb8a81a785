// Correlation and reduction kernels against independent computations.
#include <Eigen/Dense>
#include <cstring>

#include "dynid/engine/correlation.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/serep.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/solvers/least_squares.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

TEST(Correlation, MacPairingComac) {
  Eigen::MatrixXd A(4, 2), B(4, 3);
  A << 1, 0, 2, 1, 3, 0, 4, -1;
  B.col(0) = A.col(1) * -3.0;  // mode 2 first, scaled and flipped
  B.col(1) << 1, 1, 1, 1;
  B.col(2) = A.col(0) * 0.5;
  const Eigen::MatrixXd mac = mac_matrix(A, B);
  EXPECT_NEAR(mac(0, 2), 1.0, 1e-15);
  EXPECT_NEAR(mac(1, 0), 1.0, 1e-15);
  EXPECT_NEAR(mac(0, 1), 100.0 / (30 * 4), 1e-15);  // (1+2+3+4)^2 / (30 * 4)
  const Pairing p = pair_modes(mac, Eigen::Vector2d(10, 20), Eigen::Vector3d(21, 15, 9.5));
  ASSERT_EQ(p.pairs.size(), 2u);
  EXPECT_EQ(p.pairs[0].b, 2);
  EXPECT_EQ(p.pairs[1].b, 0);
  EXPECT_NEAR(p.pairs[0].freq_error, -0.05, 1e-15);
  EXPECT_EQ(p.unpaired_b, std::vector<int>{1});
  const Eigen::VectorXd c = comac(A, B, p);
  for (Eigen::Index i = 0; i < 4; ++i) EXPECT_NEAR(c[i], 1.0, 1e-14);
}

TEST(Correlation, PairingBreaksMacTiesByFrequency) {
  // Two model modes equally similar in shape: the one at the closer frequency wins.
  Eigen::MatrixXd mac(1, 2);
  mac << 0.9, 0.9;
  const Pairing p = pair_modes(mac, Eigen::VectorXd::Constant(1, 10.0), Eigen::Vector2d(14.0, 10.5));
  ASSERT_EQ(p.pairs.size(), 1u);
  EXPECT_EQ(p.pairs[0].b, 1);
}

TEST(Correlation, PairingWeighsFrequencyLikeMac) {
  // Two model modes alike at few sensors (a frame at 7 sensors: MAC 0.96 to each other): the measured mode's MAC
  // of 0.92 with the one 15 % away and 0.90 with the one 2.5 % away cannot tell them apart; the frequency does
  // (scores 0.92 - 0.15 against 0.90 - 0.025). A clear MAC difference still wins over a closer frequency.
  Eigen::MatrixXd mac(1, 2);
  mac << 0.92, 0.90;
  Pairing p = pair_modes(mac, Eigen::VectorXd::Constant(1, 42.17), Eigen::Vector2d(36.55, 43.21));
  ASSERT_EQ(p.pairs.size(), 1u);
  EXPECT_EQ(p.pairs[0].b, 1);
  mac << 0.95, 0.6;
  p = pair_modes(mac, Eigen::VectorXd::Constant(1, 10.0), Eigen::Vector2d(11.0, 10.1));
  ASSERT_EQ(p.pairs.size(), 1u);
  EXPECT_EQ(p.pairs[0].b, 0);
}

TEST(Correlation, PairingRefusesPartnersMoreThanTwiceApart) {
  // Issue 16, item 5: a measured mode whose only similar model mode is 2.5x its frequency stays unpaired (a
  // spurious mode or a spatial alias), however high the MAC; one 1.9x away is still a partner (the bound is 2x).
  Eigen::MatrixXd mac(2, 2);
  mac << 0.99, 0.1,
         0.1, 0.95;
  const Pairing p = pair_modes(mac, Eigen::Vector2d(10, 40), Eigen::Vector2d(25, 76));
  ASSERT_EQ(p.pairs.size(), 1u);
  EXPECT_EQ(p.pairs[0].a, 1);
  EXPECT_EQ(p.pairs[0].b, 1);
  EXPECT_EQ(p.unpaired_a, std::vector<int>{0});
  // A tighter bound given by the caller wins; without frequencies there is no bound.
  EXPECT_TRUE(pair_modes(mac, Eigen::Vector2d(10, 40), Eigen::Vector2d(25, 76), 0.5, 1.5).pairs.empty());
  EXPECT_EQ(pair_modes(mac, Eigen::VectorXd(), Eigen::VectorXd()).pairs.size(), 2u);
}

TEST(Serep, ReducedModelReproducesTheModes) {
  // Paper beam, masters = the 11 translations, 11 modes: K~, M~ reproduce the 11 eigenvalues (dense
  // generalized eigen-solve of the reduced pair, 1e-9 relative) and T expands the modes exactly.
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  EigenOptions o;
  o.num_modes = 22;
  o.method = EigenOptions::Method::kDense;
  const ModalResult r = modal_analysis(c.model, o);
  const std::vector<int> masters = measured_equations(c.model, dofs_of_types(c.model, dof_bit(Dof::UY)));
  ASSERT_EQ(masters.size(), 11u);
  const SerepReduction s = serep_reduce(r.modes.leftCols(11), r.eigenvalues.head(11), masters);
  EXPECT_EQ(s.rank, 11);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(s.K, s.M);
  for (int k = 2; k < 11; ++k) EXPECT_TRUE(test::RelClose(es.eigenvalues()[k], r.eigenvalues[k], 1e-9)) << k;
  Eigen::MatrixXd Pa(11, 11);
  for (int i = 0; i < 11; ++i) Pa.row(i) = r.modes.row(masters[i]).head(11);
  const Eigen::MatrixXd expanded = serep_expand(s, Pa);
  EXPECT_LT((expanded - r.modes.leftCols(11)).norm(), 1e-10 * r.modes.leftCols(11).norm());
}

TEST(Serep, MoreMastersThanModesAndDependentModes) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  EigenOptions o;
  o.num_modes = 8;
  const ModalResult r = modal_analysis(c.model, o);
  const std::vector<int> masters = measured_equations(c.model, dofs_of_types(c.model, dof_bit(Dof::UY)));
  // 11 masters, 6 modes: least squares; the modes are still reproduced.
  const SerepReduction s = serep_reduce(r.modes.leftCols(6), r.eigenvalues.head(6), masters);
  EXPECT_EQ(s.rank, 6);
  Eigen::MatrixXd Pa(11, 6);
  for (int i = 0; i < 11; ++i) Pa.row(i) = r.modes.row(masters[i]).head(6);
  EXPECT_LT((serep_expand(s, Pa) - r.modes.leftCols(6)).norm(), 1e-10);
  // Two copies of one mode: rank 5 reported, no blow-up.
  Eigen::MatrixXd dup = r.modes.leftCols(6);
  dup.col(5) = dup.col(4);
  const SerepReduction d = serep_reduce(dup, r.eigenvalues.head(6), masters);
  EXPECT_EQ(d.rank, 5);
  EXPECT_TRUE(d.K.allFinite());
  EXPECT_TRUE(d.M.allFinite());
}

TEST(ResidualForces, ParallelKernelMatchesDenseAndIsDeterministic) {
  const Case c = load_case(test::CasesDir() + "/frame3d-generated");
  const AssembledSystem s = assemble_system(c.model);
  const Eigen::MatrixXd Phi = Eigen::MatrixXd::Random(s.K.rows(), 7);
  const Eigen::VectorXd lam = Eigen::VectorXd::LinSpaced(7, 10, 1000);
  const auto [R1, R2] = test::OnOneThreadAndTwo([&] {
    Eigen::MatrixXd R;
    residual_forces(s.K, s.M, Phi, lam, &R);
    return R;
  });
  EXPECT_EQ(0, std::memcmp(R1.data(), R2.data(), sizeof(double) * R1.size()));
  const Eigen::MatrixXd ref = -(test::Dense(s.K) * Phi) + test::Dense(s.M) * Phi * lam.asDiagonal();
  EXPECT_LT((R1 - ref).cwiseAbs().maxCoeff(), 1e-12 * ref.cwiseAbs().maxCoeff());
}

TEST(LeastSquares, MatchesNormalEquationsAndRevealsRank) {
  // Full rank: equals eq. (21) D = (L^T L)^{-1} L^T b.
  Eigen::MatrixXd L = Eigen::MatrixXd::Random(6, 2);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(6);
  const LeastSquaresResult r = least_squares(L, b);
  const Eigen::VectorXd ne = (L.transpose() * L).inverse() * L.transpose() * b;
  EXPECT_LT((r.x - ne).norm(), 1e-12 * ne.norm());
  EXPECT_EQ(r.rank, 2);
  // Rank-deficient: dependent columns are detected; the solution is the minimum-norm one in the column-scaled
  // variables (x_j ||L_j||), so the two columns get equal weight: x[1] ||L_1|| = x[0] ||L_0||.
  L.col(1) = 3 * L.col(0);
  const LeastSquaresResult d = least_squares(L, b);
  EXPECT_EQ(d.rank, 1);
  EXPECT_TRUE(std::isinf(d.condition) || d.condition > 1e12);
  EXPECT_NEAR(d.x[1] * L.col(1).norm(), d.x[0] * L.col(0).norm(), 1e-10 * std::abs(d.x[0] * L.col(0).norm()));
  const Eigen::VectorXd proj = L.col(0) * (L.col(0).dot(b) / L.col(0).squaredNorm());
  EXPECT_NEAR(d.residual_norm, (b - proj).norm(), 1e-12);
}

}  // namespace
}  // namespace dynid
