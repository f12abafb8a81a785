// dynid/engine/serep.hpp -- System Equivalent Reduction Expansion Process (paper eq. 1).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// SEREP of a model to master DOFs a, from m of its modes Phi (n x m, mass-normalised eigenvectors of (K, M)):
///   T = Phi Phi_a^+   (n x a),   K~ = T^T K T,   M~ = T^T M T     (eq. 1)
/// Phi_a^+ is the pseudo-inverse of the master rows by SVD with rank truncation at rcond * sigma_max, which stays
/// stable when masters outnumber modes (least squares) and when modes are nearly dependent at the masters
/// (those directions are dropped and reported through `rank`). Because Phi are eigenvectors,
/// T^T K T = P^T Lambda P and T^T M T = P^T P with P = Phi_a^+, which is how they are computed (no product
/// with K). The reduced model reproduces the m modes exactly at the masters when rank = m <= a.
struct SerepReduction {
  std::vector<int> masters;  ///< equation numbers of the master DOFs, in order
  Eigen::MatrixXd T;         ///< n x a transformation
  Eigen::MatrixXd P;         ///< m x a pseudo-inverse of the master rows
  Eigen::MatrixXd K, M;      ///< a x a reduced stiffness and mass
  int modes = 0;             ///< m
  int rank = 0;              ///< numerical rank of Phi_a
  double condition = 0;      ///< sigma_max / sigma_min of Phi_a (inf if rank-deficient)
};

SerepReduction serep_reduce(const Eigen::MatrixXd& Phi, const Eigen::VectorXd& lambda, const std::vector<int>& masters,
                            double rcond = 1e-8);

/// SEREP expansion of shapes known at the masters (a x k) to all DOFs: T * shapes.
Eigen::MatrixXd serep_expand(const SerepReduction& s, const Eigen::MatrixXd& shapes);

}  // namespace dynid
