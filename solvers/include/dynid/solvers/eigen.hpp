// dynid/solvers/eigen.hpp -- the generalized symmetric eigenproblem K phi = lambda M phi.
//
// Sparse path: shift-invert Lanczos on a CHOLMOD factorization of K - sigma M (the standard form below, or Spectra
// SymGEigsShiftSolver's (K - sigma M)^{-1} M in the M inner product), so M may be singular (massless DOFs): those
// directions map to infinite eigenvalues, which shift-invert never returns.
// Dense path: LAPACK-style dense solvers (Eigen), for small models and as an independent cross-check.
//
// Modes are mass-normalised (phi^T M phi = 1), sorted by eigenvalue, with a sign convention (the entry of
// largest magnitude is positive). Rigid-body modes come first and are flagged.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/solvers/sparse.hpp"

namespace dynid {

class CholmodFactor;

struct EigenOptions {
  /// Number of lowest modes wanted, rigid-body modes included. Ignored in band mode.
  int num_modes = 10;
  /// Band mode: all eigenvalues lambda = omega^2 in [band_lo, band_hi] (both set, band_lo >= 0).
  double band_lo = std::numeric_limits<double>::quiet_NaN();
  double band_hi = std::numeric_limits<double>::quiet_NaN();
  /// Shift sigma. NaN = automatic: 0 for a supported structure; for a free-free one a small negative shift
  /// -sqrt(eps) * max_i(K_ii / M_ii) (K - sigma M must be positive definite for the supernodal LL^T).
  double shift = std::numeric_limits<double>::quiet_NaN();
  /// A basis (n x r) of the rigid-body motions null(K), e.g. Model::free_rigid_body_modes(). These modes are
  /// returned exactly (lambda = Rayleigh quotient, ~0) and deflated from the Lanczos run. Empty: if K turns out
  /// singular, `allow_singular_stiffness` decides.
  Eigen::MatrixXd rigid_body_basis;
  /// With no rigid basis: if K is singular, either fail naming the DOF (false) or shift below zero and report
  /// zero-energy modes as rigid by their eigenvalue (below).
  bool allow_singular_stiffness = false;
  /// A mode found without a rigid basis is a zero-energy (rigid-body) mode when its eigenvalue is at most this
  /// times max_i K_ii / M_ii (the stiffest DOF's own eigenvalue, a bound on the highest one). The ratio does not
  /// change with the units of the DOFs (lengths in mm scale rotational and translational rows differently), where
  /// a residual ||K phi|| against ||K|| does: in mm a clamped cantilever's first mode passed for rigid. The lowest
  /// elastic mode of a line of n beam elements sits near 0.03 / n^4 of that bound (1e-12 at n ~ 400).
  double rigid_eigenvalue_tolerance = 1e-12;
  /// Lanczos basis size (ncv); 0 = min(n, max(2 nev + 1, nev + 20)).
  int subspace = 0;
  /// Restart limit and relative Ritz-value tolerance: stop when every wanted Ritz value theta satisfies
  /// |theta - theta_exact| <= tolerance * |theta| (Spectra's criterion).
  int max_restarts = 500;
  double tolerance = 1e-10;
  /// How the shift-invert Lanczos run is set up (lowest-modes mode; band mode always uses kGeneralized):
  ///  kCholeskyStandard: thick-restart Lanczos (solvers/src/internal/lanczos.hpp: classical Gram-Schmidt with a
  ///    second pass only when needed) on C = L^{-1} P M P^T L^{-T} (P (K - sigma M) P^T = L L^T), one solve and
  ///    one M product per step, Euclidean orthogonalisation. Default: several times faster.
  ///  kGeneralized: Spectra SymGEigsShiftSolver (shift-invert mode) with (K - sigma M)^{-1} M in the M inner
  ///    product; every inner product costs an M product.
  enum class Formulation { kCholeskyStandard, kGeneralized };
  Formulation formulation = Formulation::kCholeskyStandard;
  enum class Method { kAuto, kSparse, kDense };
  /// kAuto: dense for n <= 300 (or when the wanted modes approach n), sparse otherwise.
  Method method = Method::kAuto;
  /// Where the solve runs. kLocal: this process (CHOLMOD + Spectra, above). kDistributed: every rank of
  /// MPI_COMM_WORLD together (PETSc + SLEPc: Krylov-Schur shift-and-invert on a MUMPS Cholesky factorization, or on
  /// an iterative solve; solvers/distributed.hpp). Lowest-modes mode only (no band); dense is never used.
  enum class Backend { kLocal, kDistributed };
  Backend backend = Backend::kLocal;
  /// The distributed backend's linear solve of (K - sigma M) x = b inside shift-and-invert.
  ///  kMumpsCholesky: MUMPS's distributed L D L^T (direct; the default).
  ///  kIterative: conjugate gradients preconditioned by algebraic multigrid (hypre BoomerAMG), each solve to the
  ///    relative residual `iterative_tolerance`; for models whose factor does not fit the machines. The eigenvalue
  ///    accuracy is then limited to about iterative_tolerance.
  enum class DistributedSolver { kMumpsCholesky, kIterative };
  DistributedSolver distributed_solver = DistributedSolver::kMumpsCholesky;
  double iterative_tolerance = 1e-12;
  /// Progress callback (stage name, fraction in [0, 1] or -1 when unknown). Called from the calling thread.
  std::function<void(std::string_view stage, double fraction)> progress;

  bool IsValid(std::string* why) const;
};

enum class EigenStatus { kSuccess, kNotConverged, kFactorizationFailed, kInvalidInput };

struct EigenSummary {
  EigenStatus status = EigenStatus::kInvalidInput;
  std::string message;
  std::string method;     ///< "sparse shift-invert Lanczos" or "dense"
  double shift = 0;       ///< sigma used
  int failed_dof = -1;    ///< on kFactorizationFailed: the DOF where the factorization broke down
  long long factor_nonzeros = 0;
  double factor_flops = 0;
  int solves = 0;         ///< triangular solve pairs (operator applications)
  int restarts = 0;
  int num_rigid = 0;
  double time_analyze = 0, time_factorize = 0, time_lanczos = 0;  ///< seconds
  double max_residual = 0;
  long long matrix_nonzeros = 0;      ///< distributed backend: nonzeros of K (all ranks); the local path leaves 0
  int ranks = 1;                      ///< MPI ranks that took part (distributed backend), else 1
  double time_assembly = 0;           ///< distributed backend: partition + this rank's assembly (seconds)
  double factor_memory_max_mb = 0;    ///< distributed: MUMPS's factorization memory on the largest rank (INFOG(21))
  double factor_memory_total_mb = 0;  ///< distributed: the same summed over the ranks (INFOG(22))
  bool ok() const { return status == EigenStatus::kSuccess; }
  std::string BriefReport() const;
  std::string FullReport() const;
};

struct EigenSolution {
  Eigen::VectorXd eigenvalues;      ///< lambda = omega^2, ascending
  Eigen::MatrixXd modes;            ///< n x m, mass-normalised
  std::vector<char> rigid_body;     ///< per mode
  Eigen::VectorXd residuals;        ///< ||K phi - lambda M phi|| / (||K||_1 + |lambda| ||M||_1) / ||phi||
  EigenSummary summary;
};

/// Solves K phi = lambda M phi for the lowest num_modes modes (or a band). Never throws for numerical failures:
/// they come back in summary.status / message. Throws InputError for invalid options or mismatched matrices.
EigenSolution solve_eigen(const SparseMatrix& K, const SparseMatrix& M, const EigenOptions& options);

/// The same, for repeated solves (model updating, nonlinear refinement): the symbolic analysis of K - sigma M
/// (fill-reducing ordering, supernodes) is kept and reused while the sparsity pattern stays the same, so each
/// further solve costs a numeric factorization and the Lanczos run. One object per thread.
class EigenSolver {
 public:
  explicit EigenSolver(const EigenOptions& options);
  ~EigenSolver();
  EigenSolver(const EigenSolver&) = delete;
  EigenSolver& operator=(const EigenSolver&) = delete;
  EigenSolution solve(const SparseMatrix& K, const SparseMatrix& M);
  EigenOptions& options() { return options_; }
  /// The LL^T factorization of K - sigma M from the last sparse lowest-modes solve (sigma = its
  /// summary.shift), or nullptr (dense path, band mode, failure). Valid until the next solve.
  const CholmodFactor* factor() const;

 private:
  struct Cache;
  std::unique_ptr<Cache> cache_;
  EigenOptions options_;
};

/// The eigenvalue at or below which a mode is a rigid-body motion: options.rigid_eigenvalue_tolerance times
/// max_i |K_ii| / M_ii over M_ii > 0 (else max |K_ii|, else 1), from the diagonals of K and M. The solvers' own
/// test; callers that must decide as they do (is a model still free?) use it too.
double rigid_eigenvalue_limit(const Eigen::VectorXd& k_diagonal, const Eigen::VectorXd& m_diagonal,
                              const EigenOptions& options);

/// Dense reference path (O(n^3)); the same options and result conventions.
EigenSolution solve_eigen_dense(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M, const EigenOptions& options);

/// Refines eigenpairs of (K, M) by Newton iterations on [(K - lambda M) phi; (1 - phi^T M phi)/2] = 0, the
/// residual evaluated in long double and the bordered Jacobian solved in double (dense LU, so n <= ~3000):
/// mixed-precision iterative refinement to ~1e-18 relative. Phi is mass-normalised on return. If
/// `phi_extended` is given it receives the refined vectors in long double (column-major, n per mode).
void refine_eigenpairs(const SparseMatrix& K, const SparseMatrix& M, Eigen::VectorXd* lambda, Eigen::MatrixXd* Phi,
                       std::vector<long double>* phi_extended = nullptr, int iterations = 3);

/// Relative residual ||K phi - lambda M phi|| / ((||K||_1 + |lambda| ||M||_1) ||phi||) of one mode.
double eigen_residual(const SparseMatrix& K, const SparseMatrix& M, double lambda, const Eigen::VectorXd& phi);

}  // namespace dynid
