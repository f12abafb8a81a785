#include "dynid/solvers/least_squares.hpp"

#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "dynid/mesh/error.hpp"

namespace dynid {

LeastSquaresResult least_squares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, double rcond) {
  if (A.rows() != b.size()) throw InputError("least_squares: A has " + std::to_string(A.rows()) + " rows, b " + std::to_string(b.size()));
  if (!A.allFinite() || !b.allFinite()) throw InputError("least_squares: NaN or Inf in the data");
  LeastSquaresResult r;
  const Eigen::Index n = A.cols();
  r.x = Eigen::VectorXd::Zero(n);
  if (n == 0 || A.rows() == 0) return r;
  Eigen::VectorXd scale(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double c = A.col(j).norm();
    scale[j] = c > 0 ? 1.0 / c : 1.0;
  }
  const Eigen::MatrixXd As = A * scale.asDiagonal();
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(As, Eigen::ComputeThinU | Eigen::ComputeThinV);
  r.singular_values = svd.singularValues();
  const double smax = r.singular_values.size() ? r.singular_values[0] : 0.0;
  Eigen::VectorXd y = Eigen::VectorXd::Zero(r.singular_values.size());
  const Eigen::VectorXd utb = svd.matrixU().transpose() * b;
  for (Eigen::Index i = 0; i < r.singular_values.size(); ++i)
    if (r.singular_values[i] > rcond * smax) {
      y[i] = utb[i] / r.singular_values[i];
      ++r.rank;
    }
  r.x = scale.asDiagonal() * (svd.matrixV() * y);
  const double smin = r.singular_values.size() == n ? r.singular_values[n - 1] : 0.0;
  r.condition = smin > 0 ? smax / smin : std::numeric_limits<double>::infinity();
  r.residual_norm = (A * r.x - b).norm();
  return r;
}

}  // namespace dynid
