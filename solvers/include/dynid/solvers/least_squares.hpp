// dynid/solvers/least_squares.hpp -- rank-revealing dense least squares.
#pragma once

#include <Eigen/Core>
#include <string>

namespace dynid {

struct LeastSquaresResult {
  Eigen::VectorXd x;                ///< least-squares solution of min ||A x - b||; if A is rank-deficient, the one
                                    ///< of minimum norm in the column-scaled variables x_j ||A_j||
  int rank = 0;                     ///< numerical rank: singular values > rcond * sigma_max
  double condition = 0;             ///< sigma_max / sigma_min over all singular values (inf if rank-deficient)
  Eigen::VectorXd singular_values;  ///< descending
  double residual_norm = 0;         ///< ||A x - b||
};

/// min ||A x - b|| by SVD with rank truncation at rcond * sigma_max (rows >= or < cols both fine). Column
/// scaling is applied internally (so that parameters of different units do not distort the rank decision) and
/// undone in x. Eq. (21) of the paper, D = (L^T L)^{-1} L^T dlambda, is the full-rank case of this.
LeastSquaresResult least_squares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, double rcond = 1e-10);

}  // namespace dynid
