// Sparse assembly: equal to a straightforward dense assembly, symmetric, and bitwise identical for any number
// of threads.
#include <cstring>

#include "dynid/engine/modal.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/mesh/generators.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

Frame3DSpec Small3D() {
  Frame3DSpec s;
  s.bays_x = 3;
  s.bays_y = 2;
  s.stories = 4;
  s.divisions = 2;
  s.material = {"steel", 2.1e11, 0, 0.3, 7800};
  s.column = {"col", 4e-3, 8e-6, 1.2e-5, 0};
  s.beam = {"beam", 3e-3, 5e-6, 9e-6, 0};
  return s;
}

// Reference: every element matrix added entry by entry into a dense matrix.
void DenseAssembly(const ElementSource& src, Eigen::MatrixXd* K, Eigen::MatrixXd* M) {
  K->setZero(src.num_dofs(), src.num_dofs());
  M->setZero(src.num_dofs(), src.num_dofs());
  std::vector<int> d;
  Eigen::MatrixXd Ke, Me;
  for (int e = 0; e < src.num_elements(); ++e) {
    src.element_dofs(e, &d);
    src.element_matrices(e, &Ke, &Me);
    for (std::size_t a = 0; a < d.size(); ++a)
      for (std::size_t b = 0; b < d.size(); ++b)
        if (d[a] >= 0 && d[b] >= 0) {
          (*K)(d[a], d[b]) += Ke(a, b);
          (*M)(d[a], d[b]) += Me(a, b);
        }
  }
}

TEST(Assembly, MatchesDenseAssembly) {
  const Model m = make_frame3d(Small3D());
  const AssembledSystem s = assemble_system(m);
  Eigen::MatrixXd K, M;
  DenseAssembly(m, &K, &M);
  // Same sums in a different order: agreement to a few ulps of the largest entry.
  EXPECT_LT((test::Dense(s.K) - K).cwiseAbs().maxCoeff(), 1e-14 * K.cwiseAbs().maxCoeff());
  EXPECT_LT((test::Dense(s.M) - M).cwiseAbs().maxCoeff(), 1e-14 * M.cwiseAbs().maxCoeff());
  EXPECT_EQ(test::Dense(s.K), test::Dense(s.K).transpose());  // bitwise symmetric
}

TEST(Assembly, BitwiseIdenticalForOneAndTwoThreads) {
  const Model m = make_frame3d(Small3D());
  const auto [a, b] = test::OnOneThreadAndTwo([&] { return assemble_system(m); });
  ASSERT_EQ(a.K.nonZeros(), b.K.nonZeros());
  EXPECT_EQ(0, std::memcmp(a.K.valuePtr(), b.K.valuePtr(), sizeof(double) * a.K.nonZeros()));
  EXPECT_EQ(0, std::memcmp(a.M.valuePtr(), b.M.valuePtr(), sizeof(double) * a.M.nonZeros()));
  EXPECT_EQ(0, std::memcmp(a.K.innerIndexPtr(), b.K.innerIndexPtr(), sizeof(int) * a.K.nonZeros()));
}

TEST(Assembly, ColoursSeparateElementsSharingDofs) {
  const Model m = make_frame3d(Small3D());
  const Assembler a(m);
  // A frame joint joins up to 6 members: at least 2 colours, and few enough to keep threads busy.
  EXPECT_GE(a.num_colors(), 2);
  EXPECT_LE(a.num_colors(), 12);
  EXPECT_EQ(a.num_dofs(), m.num_dofs());
  EXPECT_EQ(frame3d_dofs(Small3D()), m.num_dofs());
}

TEST(Assembly, RejectsNonFiniteElementMatrices) {
  struct Bad : ElementSource {
    int num_dofs() const override { return 2; }
    int num_elements() const override { return 1; }
    void element_dofs(int, std::vector<int>* d) const override { *d = {0, 1}; }
    void element_matrices(int, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const override {
      if (K) *K = Eigen::Matrix2d::Identity() * std::nan("");
      if (M) *M = Eigen::Matrix2d::Identity();
    }
  } bad;
  try {
    assemble_system(bad);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos) << e.what();
  }
}

// A sparse element (ElementSource::element_coupling): one element on 4 DOFs coupling only (0, 1) and (2, 3) is
// assembled on those pairs and the diagonal (8 entries, not 16), with the dense reference's values (exact: one
// contribution per entry); a nonzero entry outside its stated coupling is refused with the element named.
TEST(Assembly, SparseElementsOnTheirCouplingOnly) {
  struct Sparse : ElementSource {
    double outside = 0;
    int num_dofs() const override { return 4; }
    int num_elements() const override { return 1; }
    void element_dofs(int, std::vector<int>* d) const override { *d = {3, 2, 1, 0}; }
    void element_matrices(int, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const override {
      Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
      A.topLeftCorner<2, 2>() << 2, -1, -1, 3;
      A.bottomRightCorner<2, 2>() << 4, -2, -2, 5;
      A(0, 3) = A(3, 0) = outside;
      if (K) *K = A;
      if (M) *M = Eigen::Vector4d(1, 2, 3, 4).asDiagonal();
    }
    bool element_coupling(int, std::vector<std::pair<int, int>>* pairs) const override {
      *pairs = {{0, 1}, {2, 3}};
      return true;
    }
  } src;
  const AssembledSystem s = assemble_system(src);
  EXPECT_EQ(s.K.nonZeros(), 8);
  Eigen::MatrixXd K, M;
  DenseAssembly(src, &K, &M);
  EXPECT_EQ(test::Dense(s.K), K);
  EXPECT_EQ(test::Dense(s.M), M);
  src.outside = 0.5;
  EXPECT_HAS(test::ErrorOf([&] { assemble_system(src); }),
             "element 0: a nonzero entry between DOFs its coupling leaves out");
}

}  // namespace
}  // namespace dynid
