// dynid/engine/residual_force.hpp -- the residual-force equations of the paper (../shared/paper, section 6), one
// home each: detection (detect.hpp), discovery (discovery.hpp) and host codes call these.
#pragma once

#include <Eigen/Core>

#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// Eq. (6): the residual forces of measured modes on a model, column i R_i = (-K + lambda_i M) phi_i. R_i is zero
/// where the model agrees with the measured pair (lambda_i, phi_i) and concentrates on the DOFs of what changed.
/// Dense (K, M: a SEREP-reduced model on the measured DOFs) ...
Eigen::MatrixXd residual_forces(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M, const Eigen::VectorXd& lambda,
                                const Eigen::MatrixXd& Phi);
/// ... and sparse (the full model; OpenMP over rows, deterministic whatever the thread count).
Eigen::MatrixXd residual_forces(const SparseMatrix& K, const SparseMatrix& M, const Eigen::VectorXd& lambda,
                                const Eigen::MatrixXd& Phi);

/// Eqs. (7)-(8): the pseudo residual force, per DOF j the geometric mean over the p modes of |R_ji|,
/// r_j = (prod_i |R_ji|)^(1/p). A DOF with an exactly zero entry in any mode gets 0 (the product vanishes). Scaling
/// a mode's residual by c scales every r_j by c^(1/p): shares of the vector do not depend on mode normalisation.
Eigen::VectorXd pseudo_residual_force(const Eigen::MatrixXd& R);

}  // namespace dynid
