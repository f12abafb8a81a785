// Triangular solves with a simplicial CHOLMOD L L^T factor on two cores: independent subtrees at once.
#pragma once

#include <cholmod.h>

#include <utility>
#include <vector>

#include "internal/tree_split.hpp"

namespace dynid::detail {

/// Forward (L y = b) and backward (L^T x = y) solves with a numeric simplicial CHOLMOD L L^T factor (the factor
/// CHOLMOD chooses where columns are short: plane frames, members split into chains of elements), one right-hand
/// side, in the factor's (permuted) numbering.
///
/// CHOLMOD's own simplicial solve is a walk over the factor on one core, and the Lanczos run of solve_eigen makes
/// 60-110 of them. Columns in different subtrees of the elimination tree do not touch each other's entries, so the
/// tree is split once into kBins subtree sets of about equal work and a "top" (every ancestor of a set's root; 1.6 %
/// of the entries on the 995,100-DOF plane frame): forward, the sets run at once (pair.hpp), each adding its
/// updates of top rows into its own accumulator, then the accumulators are subtracted in a fixed order and the top
/// is solved; backward, the top first, then the sets at once (they only read top rows). The split depends on the
/// factor alone, so the result is the same with one thread or two; its rounding differs from CHOLMOD's solve,
/// which adds the top rows' updates in another order. Consecutive columns that form a chain (each the next one's
/// only child) are done four at a time, as CHOLMOD does, so that x at the rows below is read once per four.
///
/// Supernodal factors have their own two-core solves (super_solve.hpp, dense blocks). ok() is false for them, and
/// for any factor whose rows are not ascending below the diagonal or whose subtrees are not contiguous (CHOLMOD's
/// postordered analysis gives both):
/// the caller then uses CHOLMOD's solves.
class TreeSolve {
 public:
  static constexpr int kBins = kTreeBins;

  TreeSolve() = default;
  explicit TreeSolve(const cholmod_factor* L);
  bool ok() const { return ok_; }
  /// x <- L^{-1} x.
  void forward(double* x) const;
  /// x <- L^{-T} x.
  void backward(double* x) const;

 private:
  // Columns lo .. hi - 1 of one set, by chains (group_); forward adds its updates of top rows into acc.
  void forward_columns(int lo, int hi, double* x, double* acc) const;
  void backward_columns(int lo, int hi, double* x) const;
  template <class F>
  void run_sets(F&& set) const;  // set(b) for b = 0 .. kBins - 1, at once where threads allow

  bool ok_ = false;
  int n_ = 0;
  // CHOLMOD's column pointers, counts, rows and values; each column's split (its first row in the top); each set's
  // column ranges [lo, hi) (subtrees are contiguous in CHOLMOD's postordered numbering).
  const int *p_ = nullptr, *nz_ = nullptr, *i_ = nullptr;
  const double* x_ = nullptr;
  std::vector<int> split_;
  std::vector<unsigned char> group_;  // at a group's first column: its number of columns (1-4); 0 inside a group
  std::vector<std::vector<std::pair<int, int>>> bin_ranges_;
  std::vector<int> top_slot_;     // per column: its index among the top's columns, or -1
  std::vector<int> top_columns_;  // the top's columns by that index (ascending)
  int top_cols_ = 0;
};

}  // namespace dynid::detail
