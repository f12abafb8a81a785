// Thick-restart Lanczos for the largest eigenvalues of a symmetric operator (solve_eigen's standard form).
#pragma once

#include <Eigen/Core>
#include <functional>

namespace dynid::detail {

struct LanczosOptions {
  int nev = 0;  ///< eigenvalues wanted (the largest)
  int ncv = 0;  ///< basis size, > nev
  int max_restarts = 500;
  double tolerance = 1e-10;  ///< |beta y_last| <= tolerance max(|theta|, eps^(2/3) theta_max), Spectra's test
  /// The steps' vector work on two row halves at once (lanczos.cpp): set where the operator's solves run on two
  /// cores (CholmodFactor::parallel_solves()).
  bool pair_vectors = false;
};

struct LanczosResult {
  Eigen::VectorXd theta;  ///< converged Ritz values, descending (up to nev)
  Eigen::MatrixXd Y;      ///< their Ritz vectors (n x theta.size()), orthonormal
  int restarts = 0;
  bool converged = false;  ///< all nev converged
  /// The basis came to span the operator's whole range (no fresh direction left: random vectors through the
  /// operator keep less than 1e-8 of their norm outside it): every pair is exact, and theta holds all of them
  /// when the range has fewer than nev dimensions (e.g. fewer massive DOFs).
  bool exhausted = false;
};

/// Thick-restart Lanczos (Wu & Simon, SIAM J. Matrix Anal. Appl. 22, 2000) for the nev largest eigenvalues of
/// the symmetric operator `op` (y = A x, n x n) from the start vector v0. Each step applies the three-term
/// recurrence, then orthogonalizes against the whole basis by classical Gram-Schmidt, a pass repeated only when it
/// removed more than 1 - 1/sqrt(2) of the vector's norm (Daniel, Gragg, Kaufman & Stewart 1976): one pass over the
/// basis per step where Spectra's test against machine epsilon makes several. The projected matrix is the
/// Rayleigh quotient V^T A V as the passes compute it. At a restart the nev + min(converged, (ncv - nev) / 2) best Ritz
/// vectors are kept (ARPACK's rule) with the residual vector. An invariant subspace (beta ~ 0) continues from a random
/// vector orthogonal to the basis (fixed seed).
LanczosResult thick_restart_lanczos(const std::function<void(const double* x, double* y)>& op, Eigen::Index n,
                                    const Eigen::VectorXd& v0, const LanczosOptions& o);

}  // namespace dynid::detail
