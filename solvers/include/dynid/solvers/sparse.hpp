// dynid/solvers/sparse.hpp -- sparse matrix type and deterministic, OpenMP-parallel assembly.
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "dynid/mesh/element_source.hpp"

namespace dynid {

/// Compressed sparse column storage, both triangles stored (symmetric matrices are stored in full), sorted
/// row indices, 32-bit indices (up to 2^31 - 1 nonzeros).
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// Assembles global K and M from an ElementSource. The constructor does the symbolic work once: the CSC pattern
/// (union of all element DOF pairs, or of the coupled pairs of sparse elements (ElementSource::element_coupling);
/// K and M share it, so K - sigma M has the same pattern) and a colouring of the
/// elements such that no two elements of one colour share a DOF. Numeric assembly then runs colour by colour
/// with OpenMP; each matrix entry receives its contributions in colour order whatever the thread count, so the
/// result is bitwise identical for any number of threads.
class Assembler {
 public:
  explicit Assembler(const ElementSource& source);

  /// Assembles K and/or M (either may be null) on the shared pattern. Throws InputError if an element matrix
  /// holds a non-finite entry or has the wrong size.
  void assemble(SparseMatrix* K, SparseMatrix* M) const;

  int num_dofs() const { return n_; }
  long long nonzeros() const { return static_cast<long long>(rows_.size()); }
  int num_colors() const { return static_cast<int>(color_ptr_.size()) - 1; }
  /// An empty matrix with the assembly pattern (all values zero).
  SparseMatrix pattern() const;

 private:
  const ElementSource& src_;
  int n_ = 0;
  std::vector<int> colptr_, rows_;
  std::vector<int> color_ptr_, color_elems_;  // elements grouped by colour
  std::vector<char> sparse_;                  // per element: assembled on its coupling (element_coupling)
};

/// Parallel y = A x for a matrix stored with both triangles (uses symmetry: row i = column i). Deterministic.
void symmetric_multiply(const SparseMatrix& A, const double* x, double* y);

/// Residual forces R = -K Phi + M Phi diag(lambda) (column i: (-K + lambda_i M) phi_i, eq. (6) of the paper) for
/// K and M stored in full with the same pattern. OpenMP-parallel over rows, deterministic (each entry is one
/// sum in a fixed order whatever the thread count).
void residual_forces(const SparseMatrix& K, const SparseMatrix& M, const Eigen::MatrixXd& Phi,
                     const Eigen::VectorXd& lambda, Eigen::MatrixXd* R);

/// The 1-norm of a sparse matrix (max column sum of absolute values).
double norm1(const SparseMatrix& A);

}  // namespace dynid
