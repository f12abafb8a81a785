// dynid/engine/sensitivity.hpp -- analytic eigenvalue and mode-shape sensitivities of a ParametricModel.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "dynid/engine/parametric.hpp"
#include "dynid/solvers/cholmod.hpp"

namespace dynid {

/// One solved state of a parametric model.
struct ModalState {
  Eigen::VectorXd theta;
  Eigen::VectorXd lambda;  ///< computed eigenvalues (ascending, rigid-body modes first)
  Eigen::MatrixXd Phi;     ///< n x m, mass-normalised to M(theta)
  /// Every finite mode was computed (dense path): modal expansions are exact. Otherwise `factor` (an LL^T of
  /// K - sigma M) supplies the static correction for the modes that were not computed.
  bool complete = false;
  const CholmodFactor* factor = nullptr;
  double sigma = 0;
};

/// d lambda_i / d theta_p = phi_i^T (dK_p - lambda_i dM_p) phi_i, for the modes `modes` (rows) and every
/// parameter (columns). Exact, from element matrices.
Eigen::MatrixXd eigenvalue_derivatives(const ParametricModel& pm, const ModalState& s, const std::vector<int>& modes);

/// d phi_i / d theta_p at the DOFs `rows` for each mode i in `modes`: one (rows x parameters) matrix per mode.
///   d phi_i = sum_{j != i} phi_j (phi_j^T f)/(lambda_j - lambda_i) - 1/2 (phi_i^T dM phi_i) phi_i,
///   f = -(dK - lambda_i dM - dlambda_i M) phi_i   (mass-normalised modes; Fox & Kapoor, Nelson)
/// The sum runs over the computed modes; the modes not computed enter through the static correction
/// (K - sigma M)^{-1} f - sum_{j computed} phi_j (phi_j^T f)/(lambda_j - sigma), which reuses the eigen-solve's
/// factorization: one block solve with as many right-hand sides as `rows`, whatever the number of parameters.
/// Exact when s.complete; otherwise the error is of order (lambda_i - sigma) / (lambda_{m+1} - lambda_i).
/// Repeated eigenvalues (|lambda_j - lambda_i| < 1e-9 lambda_i) have no derivative; such pairs are skipped.
std::vector<Eigen::MatrixXd> shape_derivatives(const ParametricModel& pm, const ModalState& s,
                                               const std::vector<int>& modes, const std::vector<int>& rows);

}  // namespace dynid
