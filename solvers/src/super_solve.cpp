#include "internal/super_solve.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <limits>

#include "internal/pair.hpp"
#include "internal/tree_split.hpp"

namespace dynid::detail {

namespace {

// A top supernode is solved by blocks of kBlock columns; the products of a block are split between the cores from
// kSplitRows rows below it on (below that the hand-off, tens of microseconds, costs more than half the product).
constexpr int kBlock = 256;
constexpr int kSplitRows = 512;

using Block = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;

// A copy of CHOLMOD's index array a[0 .. n - 1] (int or SuiteSparse_long) as T; false if an entry does not fit.
template <typename T>
bool copy_index(const cholmod_factor* L, const void* a, std::size_t n, std::vector<T>* out) {
  out->resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const long v = L->itype == CHOLMOD_INT ? static_cast<const int*>(a)[k] : static_cast<const SuiteSparse_long*>(a)[k];
    if (v < std::numeric_limits<T>::min() || v > std::numeric_limits<T>::max()) return false;
    (*out)[k] = static_cast<T>(v);
  }
  return true;
}
}  // namespace

SuperSolve::SuperSolve(const cholmod_factor* L) {
  if (!L || !L->is_ll || !L->is_super || L->xtype != CHOLMOD_REAL || L->dtype != CHOLMOD_DOUBLE ||
      (L->itype != CHOLMOD_INT && L->itype != CHOLMOD_LONG) || !L->super || !L->pi || !L->px || !L->s || !L->x ||
      L->nsuper < 1 || L->n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    return;
  n_ = static_cast<int>(L->n);
  const int nsuper = static_cast<int>(L->nsuper);
  const auto at = [](int k) { return static_cast<std::size_t>(k); };
  if (!copy_index(L, L->super, at(nsuper) + 1, &super_) || !copy_index(L, L->pi, at(nsuper) + 1, &pi_) ||
      !copy_index(L, L->px, at(nsuper) + 1, &px_))
    return;
  if (L->itype == CHOLMOD_INT) {
    ls_ = static_cast<const int*>(L->s);
  } else {
    if (!copy_index(L, L->s, static_cast<std::size_t>(pi_[at(nsuper)]), &ls_own_)) return;
    ls_ = ls_own_.data();
  }
  x_ = static_cast<const double*>(L->x);
  std::vector<int> supermap(at(n_));
  for (int s = 0; s < nsuper; ++s)
    for (int k = super_[s]; k < super_[s + 1]; ++k) supermap[at(k)] = s;
  // The supernodal tree (a supernode's parent holds its first row below its columns) and each supernode's entries.
  std::vector<int> parent(at(nsuper), -1);
  std::vector<double> work(at(nsuper));
  for (int s = 0; s < nsuper; ++s) {
    const int nscol = super_[s + 1] - super_[s], nsrow = pi_[s + 1] - pi_[s];
    if (nsrow < nscol) return;
    for (int k = 0; k < nscol; ++k)  // its own columns first, in order
      if (ls_[pi_[s] + k] != super_[s] + k) return;
    if (nsrow > nscol) parent[at(s)] = supermap[at(ls_[pi_[s] + nscol])];
    if (parent[at(s)] >= 0 && parent[at(s)] <= s) return;
    work[at(s)] = static_cast<double>(nsrow) * nscol;
    max_rows_ = std::max(max_rows_, nsrow);
  }
  const std::vector<int> bin = split_tree(parent, work, 0.5);  // the top's work is shared (forward_top, ...)
  sets_.assign(kTreeBins, {});
  top_slot_.assign(at(n_), -1);
  for (int s = 0; s < nsuper; ++s) {
    if (bin[at(s)] >= 0) {
      sets_[at(bin[at(s)])].push_back(s);
      continue;
    }
    top_.push_back(s);
    for (int k = super_[s]; k < super_[s + 1]; ++k) {
      top_slot_[at(k)] = static_cast<int>(top_rows_.size());
      top_rows_.push_back(k);
    }
  }
  // The rows below a top supernode are its ancestors', all in the top.
  for (int s : top_)
    for (int p = pi_[s] + super_[s + 1] - super_[s]; p < pi_[s + 1]; ++p)
      if (top_slot_[at(ls_[p])] < 0) return;
  for (auto& b : buf_) b.resize(at(max_rows_));
  ok_ = true;
}

void SuperSolve::forward_set(int b, double* x, double* acc) const {
  double* t = buf_[static_cast<std::size_t>(b)].data();
  for (int s : sets_[static_cast<std::size_t>(b)]) {
    const int k1 = super_[s], nscol = super_[s + 1] - k1, psi = pi_[s], nsrow = pi_[s + 1] - psi, nb = nsrow - nscol;
    const Block L(x_ + px_[s], nsrow, nscol, Eigen::OuterStride<>(nsrow));
    Eigen::Map<Eigen::VectorXd> x1(x + k1, nscol);
    L.topRows(nscol).triangularView<Eigen::Lower>().solveInPlace(x1);
    if (nb == 0) continue;
    Eigen::Map<Eigen::VectorXd> tt(t, nb);
    tt.noalias() = L.bottomRows(nb) * x1;
    const int* R = ls_ + psi + nscol;
    for (int i = 0; i < nb; ++i) {
      const int slot = top_slot_[static_cast<std::size_t>(R[i])];
      if (slot < 0)
        x[R[i]] -= t[i];
      else
        acc[slot] += t[i];
    }
  }
}

void SuperSolve::backward_set(int b, double* x) const {
  double* g = buf_[static_cast<std::size_t>(b)].data();
  const std::vector<int>& set = sets_[static_cast<std::size_t>(b)];
  for (auto it = set.rbegin(); it != set.rend(); ++it) {
    const int s = *it, k1 = super_[s], nscol = super_[s + 1] - k1, psi = pi_[s], nsrow = pi_[s + 1] - psi;
    const int nb = nsrow - nscol;
    const Block L(x_ + px_[s], nsrow, nscol, Eigen::OuterStride<>(nsrow));
    Eigen::Map<Eigen::VectorXd> x1(x + k1, nscol);
    if (nb > 0) {
      const int* R = ls_ + psi + nscol;
      for (int i = 0; i < nb; ++i) g[i] = x[R[i]];
      x1.noalias() -= L.bottomRows(nb).transpose() * Eigen::Map<const Eigen::VectorXd>(g, nb);
    }
    L.topRows(nscol).triangularView<Eigen::Lower>().transpose().solveInPlace(x1);
  }
}

void SuperSolve::forward_top(int s, double* x) const {
  const int k1 = super_[s], nscol = super_[s + 1] - k1, psi = pi_[s], nsrow = pi_[s + 1] - psi;
  const Block L(x_ + px_[s], nsrow, nscol, Eigen::OuterStride<>(nsrow));
  for (int c0 = 0; c0 < nscol; c0 += kBlock) {
    const int cb = std::min(kBlock, nscol - c0);
    Eigen::Map<Eigen::VectorXd> xb(x + k1 + c0, cb);
    L.block(c0, c0, cb, cb).triangularView<Eigen::Lower>().solveInPlace(xb);
    // Rows r0 .. r1 - 1 below the block (their own columns' rows, then the ancestors'): x -= L(r, block) xb.
    const auto rows = [&](int r0, int r1, double* t) {
      Eigen::Map<Eigen::VectorXd> tt(t, r1 - r0);
      tt.noalias() = L.block(r0, c0, r1 - r0, cb) * xb;
      for (int r = r0; r < r1; ++r) x[r < nscol ? k1 + r : ls_[psi + r]] -= t[r - r0];
    };
    const int lo = c0 + cb, n = nsrow - lo;
    if (n < kSplitRows) {
      rows(lo, nsrow, buf_[0].data());
    } else {
      const int mid = lo + n / 2;
      run_pair([&] { rows(lo, mid, buf_[0].data()); }, [&] { rows(mid, nsrow, buf_[1].data()); });
    }
  }
}

void SuperSolve::backward_top(int s, double* x) const {
  const int k1 = super_[s], nscol = super_[s + 1] - k1, psi = pi_[s], nsrow = pi_[s + 1] - psi, nb = nsrow - nscol;
  const Block L(x_ + px_[s], nsrow, nscol, Eigen::OuterStride<>(nsrow));
  double* g = buf_[0].data();  // the ancestors' rows below, final already
  for (int i = 0; i < nb; ++i) g[i] = x[ls_[psi + nscol + i]];
  const Eigen::Map<const Eigen::VectorXd> below(g, nb);
  for (int c0 = (nscol - 1) / kBlock * kBlock; c0 >= 0; c0 -= kBlock) {
    const int cb = std::min(kBlock, nscol - c0), lo = c0 + cb, own = nscol - lo;
    Eigen::Map<Eigen::VectorXd> xb(x + k1 + c0, cb);
    // Columns j0 .. j1 - 1 of the block: xb -= L(rows below, j)^T x(rows below); each half writes its own entries.
    const auto cols = [&](int j0, int j1) {
      Eigen::Map<Eigen::VectorXd> out(x + k1 + c0 + j0, j1 - j0);
      if (own > 0)
        out.noalias() -=
            L.block(lo, c0 + j0, own, j1 - j0).transpose() * Eigen::Map<const Eigen::VectorXd>(x + k1 + lo, own);
      if (nb > 0) out.noalias() -= L.block(nscol, c0 + j0, nb, j1 - j0).transpose() * below;
    };
    if (nsrow - lo < kSplitRows || cb < 2)
      cols(0, cb);
    else
      run_pair([&] { cols(0, cb / 2); }, [&] { cols(cb / 2, cb); });
    L.block(c0, c0, cb, cb).triangularView<Eigen::Lower>().transpose().solveInPlace(xb);
  }
}

void SuperSolve::forward(double* x) const {
  const std::size_t tr = top_rows_.size();
  acc_.assign(kTreeBins * tr, 0.0);
  static_assert(kTreeBins == 2, "run_pair runs the two sets");
  run_pair([&] { forward_set(0, x, acc_.data()); }, [&] { forward_set(1, x, acc_.data() + tr); });
  // The sets' updates of the top rows, in a fixed order, then the top.
  for (std::size_t k = 0; k < tr; ++k) {
    x[top_rows_[k]] -= acc_[k];
    x[top_rows_[k]] -= acc_[tr + k];
  }
  for (int s : top_) forward_top(s, x);
}

void SuperSolve::backward(double* x) const {
  for (auto s = top_.rbegin(); s != top_.rend(); ++s) backward_top(*s, x);
  run_pair([&] { backward_set(0, x); }, [&] { backward_set(1, x); });
}

}  // namespace dynid::detail
