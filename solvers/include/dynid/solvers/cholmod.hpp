// dynid/solvers/cholmod.hpp -- an owned CHOLMOD factorization of a symmetric sparse matrix.
#pragma once

#include <Eigen/Core>
#include <memory>

#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// A CHOLMOD factorization that owns its own cholmod_common (no globals: two factorizations can live in
/// different threads). The symbolic analysis (fill-reducing ordering, elimination tree, supernodes) is done once
/// by analyze(); factorize() may then be called any number of times for matrices with the same pattern
/// (e.g. K - sigma M for several shifts, or K(theta) during updating).
///
/// Only the upper triangle of the matrix is read (the full symmetric storage of SparseMatrix is accepted).
/// Not thread-safe: one object, one thread at a time (solve() reuses workspace).
class CholmodFactor {
 public:
  enum class Kind {
    kSupernodalLLt,  ///< Cholesky L L^T, supernodal (BLAS-3) where CHOLMOD's rule finds enough flops per entry of
                     ///< L, else simplicial; requires a positive definite matrix
    kSimplicialLDLt  ///< simplicial L D L^T; works for indefinite matrices and gives the inertia
  };
  /// CHOLMOD's integer type: int, switching by itself to SuiteSparse_long when the analysis finds that the factor
  /// would store 2^31 values or more (kAuto); or SuiteSparse_long from the start (kLong: same results, more index
  /// memory; for tests and for callers who know their factor is that large).
  enum class Indices { kAuto, kLong };
  explicit CholmodFactor(Kind kind = Kind::kSupernodalLLt, Indices indices = Indices::kAuto);
  ~CholmodFactor();
  CholmodFactor(const CholmodFactor&) = delete;
  CholmodFactor& operator=(const CholmodFactor&) = delete;

  /// Ordering and symbolic factorization for A's pattern.
  void analyze(const SparseMatrix& A);
  /// Numeric factorization of A (A must have the analyzed pattern; a supernodal L L^T of at least 20,000 rows on two
  /// cores: src/internal/super_factor.hpp). Returns false on breakdown: LL^T of a matrix
  /// that is not positive definite, or a zero pivot in LDL^T; failed_index() then names the (original) row.
  bool factorize(const SparseMatrix& A);
  /// x = A^{-1} b (b and x may alias).
  void solve(const double* b, double* x) const;
  /// LL^T only, with P A P^T = L L^T: forward(b) = L^{-1} P b and backward(b) = P^T L^{-T} b, so that
  /// A^{-1} = backward o forward. Used to turn K phi = lambda M phi into a standard symmetric problem.
  void forward(const double* b, double* x) const;
  void backward(const double* b, double* x) const;
  /// X = A^{-1} B for the k columns of B at once (blocked, BLAS-3).
  void solve_block(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) const;
  /// backward() for the k columns of B at once (blocked, BLAS-3): X = P^T L^{-T} B. X may be &B.
  void backward_block(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) const;
  /// Row/column of A (original numbering) at which the last factorize() broke down, or -1.
  int failed_index() const { return failed_; }
  /// LDL^T only: the number of negative entries of D, i.e. the number of negative eigenvalues of A.
  int negative_pivots() const;
  /// Whether forward(), backward() and solve() of one right-hand side run on two cores (an L L^T factor of at least
  /// 20,000 rows: src/internal/tree_solve.hpp, super_solve.hpp); otherwise they are CHOLMOD's own solves.
  bool parallel_solves() const;
  /// Whether CHOLMOD's SuiteSparse_long routines are in use (Indices::kLong, or a factor too large for int).
  bool long_indices() const;
  long long factor_nonzeros() const;
  double factor_flops() const;  ///< floating point operations of the last numeric factorization
  int rows() const { return n_; }
  Kind kind() const { return kind_; }

 private:
  void solve_sys(int sys, const double* b, double* x, int ncol = 1) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Kind kind_;
  int n_ = 0;
  int failed_ = -1;
};

}  // namespace dynid
