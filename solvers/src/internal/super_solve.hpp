// Triangular solves with a supernodal CHOLMOD L L^T factor on two cores: independent subtrees at once, then the top
// split by rows (forward) or columns (backward).
#pragma once

#include <cholmod.h>

#include <array>
#include <vector>

#include "internal/tree_split.hpp"

namespace dynid::detail {

/// Forward (L y = b) and backward (L^T x = y) solves with a numeric supernodal CHOLMOD L L^T factor, one right-hand
/// side, in the factor's (permuted) numbering.
///
/// A solve reads the whole factor once for two flops per entry: it runs at memory speed, and one core streams about
/// half of what two do (8.7 against 16.9 GB/s on the 2-core AMD EPYC of bench/README.md). As for the factorization
/// (super_factor.hpp), the supernodal tree is split once into two subtree sets and a top (tree_split.hpp, work =
/// each supernode's entries, the top's counted half as it is shared): forward, the sets run at once, each adding
/// its updates of top rows into its own accumulator, then the accumulators are subtracted in a fixed order and the
/// top is solved by blocks of columns, each block's product with the rows below it split by rows between the two
/// cores; backward, the top first (each block's product split by its columns), then the sets at once (they only
/// read top rows). The top holds the root separators' dense blocks (40-50 % of the stored entries on the 3D
/// frames): solved on one core, it took away the sets' gain (bench/README.md, "Two-core Lanczos steps"). The split
/// depends on the factor alone, so the result is the same with one thread or two; it differs from CHOLMOD's solve
/// by rounding. The dense kernels are Eigen's: the work is memory-bound, and no BLAS threads share the cores.
///
/// Both of CHOLMOD's index types are accepted. ok() is false for other factors (simplicial, other value types, rows
/// not in CHOLMOD's supernodal layout): the caller then uses CHOLMOD's solves.
class SuperSolve {
 public:
  SuperSolve() = default;
  explicit SuperSolve(const cholmod_factor* L);
  SuperSolve(const SuperSolve&) = delete;  // ls_ may point into ls_own_
  SuperSolve& operator=(const SuperSolve&) = delete;
  SuperSolve(SuperSolve&&) = default;
  SuperSolve& operator=(SuperSolve&&) = default;
  bool ok() const { return ok_; }
  /// x <- L^{-1} x.
  void forward(double* x) const;
  /// x <- L^{-T} x.
  void backward(double* x) const;

 private:
  void forward_set(int b, double* x, double* acc) const;
  void backward_set(int b, double* x) const;
  void forward_top(int s, double* x) const;
  void backward_top(int s, double* x) const;

  bool ok_ = false;
  int n_ = 0;
  // CHOLMOD's supernodes (first columns), row and value offsets (copied: nsuper + 1 entries each), rows (L's own,
  // or a copy as int for a SuiteSparse_long factor) and values.
  std::vector<int> super_, pi_;
  std::vector<long> px_;
  std::vector<int> ls_own_;
  const int* ls_ = nullptr;
  const double* x_ = nullptr;
  std::vector<std::vector<int>> sets_;  // each set's supernodes, ascending
  std::vector<int> top_;                // the top's supernodes, ascending
  std::vector<int> top_slot_;           // per row: its index among the top's rows, or -1
  std::vector<int> top_rows_;           // the top's rows by that index
  int max_rows_ = 0;
  mutable std::array<std::vector<double>, kTreeBins> buf_;  // per core: a supernode's products or gathered rows
  mutable std::vector<double> acc_;                         // per set: its updates of the top's rows
};

}  // namespace dynid::detail
