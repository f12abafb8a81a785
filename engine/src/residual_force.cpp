#include "dynid/engine/residual_force.hpp"

#include <cmath>

namespace dynid {

Eigen::MatrixXd residual_forces(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M, const Eigen::VectorXd& lambda,
                                const Eigen::MatrixXd& Phi) {
  return -K * Phi + (M * Phi) * lambda.asDiagonal();
}

Eigen::MatrixXd residual_forces(const SparseMatrix& K, const SparseMatrix& M, const Eigen::VectorXd& lambda,
                                const Eigen::MatrixXd& Phi) {
  Eigen::MatrixXd R;
  residual_forces(K, M, Phi, lambda, &R);
  return R;
}

Eigen::VectorXd pseudo_residual_force(const Eigen::MatrixXd& R) {
  Eigen::VectorXd out(R.rows());
  for (Eigen::Index j = 0; j < R.rows(); ++j) {
    double s = 0;
    for (Eigen::Index i = 0; i < R.cols(); ++i) s += std::log(std::abs(R(j, i)));  // log 0 = -inf: r_j = 0
    out[j] = R.cols() ? std::exp(s / static_cast<double>(R.cols())) : 0.0;
  }
  return out;
}

}  // namespace dynid
