#include "internal/tree_solve.hpp"

#include <Eigen/Core>
#include <algorithm>

#include "internal/pair.hpp"
#include "internal/tree_split.hpp"

namespace dynid::detail {

namespace {

// split_tree's balance: the sets' subtrees within 3 % of an even share (tree_split.hpp).
constexpr double kBalance = 1.03;

// Largest-first packing of the candidates into kTreeBins sets: the set of each candidate, and the largest load.
double pack(const std::vector<int>& cands, const std::vector<double>& W, std::vector<int>* bin_of) {
  std::vector<int> order(cands);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return W[static_cast<std::size_t>(a)] > W[static_cast<std::size_t>(b)]; });
  double load[kTreeBins] = {};
  for (int c : order) {
    int b = 0;
    for (int k = 1; k < kTreeBins; ++k)
      if (load[k] < load[b]) b = k;
    load[b] += W[static_cast<std::size_t>(c)];
    if (bin_of) (*bin_of)[static_cast<std::size_t>(c)] = b;
  }
  return *std::max_element(load, load + kTreeBins);
}

}  // namespace

std::vector<int> split_tree(const std::vector<int>& parent, const std::vector<double>& work, double top_share) {
  const int N = static_cast<int>(parent.size());
  std::vector<std::vector<int>> children(static_cast<std::size_t>(N));
  std::vector<double> W(work);
  double total = 0;
  std::vector<int> cands;
  for (int k = 0; k < N; ++k) {
    const int q = parent[static_cast<std::size_t>(k)];
    total += work[static_cast<std::size_t>(k)];
    if (q >= 0) {
      children[static_cast<std::size_t>(q)].push_back(k);
      W[static_cast<std::size_t>(q)] += W[static_cast<std::size_t>(k)];
    } else {
      cands.push_back(k);
    }
  }
  std::vector<int> top, best_cands = cands, best_top;
  double top_work = 0, best_cost = -1;
  for (;;) {
    double sum = 0;
    for (int c : cands) sum += W[static_cast<std::size_t>(c)];
    const double largest = pack(cands, W, nullptr);
    if (best_cost < 0 || largest + top_share * top_work < best_cost)
      best_cost = largest + top_share * top_work, best_cands = cands, best_top = top;
    if (largest <= kBalance * sum / kTreeBins || top_work > 0.5 * total || cands.empty()) break;
    auto h = std::max_element(cands.begin(), cands.end(), [&](int a, int b) {
      return W[static_cast<std::size_t>(a)] < W[static_cast<std::size_t>(b)];
    });
    const int node = *h;
    cands.erase(h);
    top.push_back(node);
    top_work += work[static_cast<std::size_t>(node)];
    for (int c : children[static_cast<std::size_t>(node)]) cands.push_back(c);
  }
  std::vector<int> bin(static_cast<std::size_t>(N), -2), bin_of(static_cast<std::size_t>(N), -1);
  pack(best_cands, W, &bin_of);
  for (int c : best_cands) bin[static_cast<std::size_t>(c)] = bin_of[static_cast<std::size_t>(c)];
  for (int t : best_top) bin[static_cast<std::size_t>(t)] = -1;
  for (int k = N - 1; k >= 0; --k)  // from each candidate down its subtree
    if (bin[static_cast<std::size_t>(k)] == -2)
      bin[static_cast<std::size_t>(k)] = bin[static_cast<std::size_t>(parent[static_cast<std::size_t>(k)])];
  return bin;
}

TreeSolve::TreeSolve(const cholmod_factor* L) {
  if (!L || !L->is_ll || L->is_super || L->xtype != CHOLMOD_REAL || L->dtype != CHOLMOD_DOUBLE ||
      L->itype != CHOLMOD_INT)
    return;
  n_ = static_cast<int>(L->n);
  p_ = static_cast<const int*>(L->p);
  i_ = static_cast<const int*>(L->i);
  nz_ = static_cast<const int*>(L->nz);
  x_ = static_cast<const double*>(L->x);
  if (!p_ || !i_ || !nz_ || !x_) return;
  const auto at = [](int k) { return static_cast<std::size_t>(k); };
  // The elimination tree (a column's parent is its first row below the diagonal) and each column's work.
  std::vector<int> parent(at(n_), -1);
  std::vector<double> work(at(n_));
  for (int j = 0; j < n_; ++j) {
    const int* R = i_ + p_[j];
    if (nz_[j] < 1 || R[0] != j) return;  // the diagonal first
    for (int r = 2; r < nz_[j]; ++r)
      if (R[r] <= R[r - 1]) return;
    if (nz_[j] > 1) {
      if (R[1] <= j) return;
      parent[at(j)] = R[1];
    }
    work[at(j)] = nz_[j];
  }
  const std::vector<int> bin = split_tree(parent, work);

  top_slot_.assign(at(n_), -1);
  for (int j = 0; j < n_; ++j)
    if (bin[at(j)] < 0) {
      top_slot_[at(j)] = top_cols_++;
      top_columns_.push_back(j);
    }
  // Each set's subtrees as column ranges: a subtree of the postordered tree holds the columns root - size + 1 ..
  // root (checked: its lowest column is there).
  std::vector<int> size(at(n_), 1), lowest(at(n_));
  for (int j = 0; j < n_; ++j) lowest[at(j)] = j;
  for (int j = 0; j < n_; ++j) {
    const int q = parent[at(j)];
    if (q < 0) continue;
    size[at(q)] += size[at(j)];
    lowest[at(q)] = std::min(lowest[at(q)], lowest[at(j)]);
  }
  bin_ranges_.assign(kBins, {});
  split_.assign(at(n_), 0);
  for (int j = 0; j < n_; ++j) {
    const int b = bin[at(j)];
    if (b < 0) {
      split_[at(j)] = nz_[j];  // the top writes its rows directly
      continue;
    }
    const int q = parent[at(j)];
    if (q < 0 || bin[at(q)] < 0) {  // a set's subtree root
      if (lowest[at(j)] != j - size[at(j)] + 1) return;
      bin_ranges_[at(b)].emplace_back(j - size[at(j)] + 1, j + 1);
    }
    // A set's column updates rows of its own set (ancestors below the subtree's root) and then rows of the top
    // (the root's ancestors), in this order since rows ascend: its split is its first row in the top.
    const int* R = i_ + p_[j];
    int r = 1;
    while (r < nz_[j] && top_slot_[at(R[r])] < 0) ++r;
    split_[at(j)] = r;
    for (; r < nz_[j]; ++r)
      if (top_slot_[at(R[r])] < 0) return;
  }
  // Chains of up to 4 columns inside each range: column j + g is the next of the chain when it is row g of column j
  // and its pattern is column j's less the rows before it.
  group_.assign(at(n_), 1);
  for (const auto& ranges : bin_ranges_)
    for (const auto& [lo, hi] : ranges)
      for (int j = lo; j < hi;) {
        int g = 1;
        while (g < 4 && j + g < hi && g < nz_[j] && nz_[j + g] == nz_[j] - g && i_[p_[j] + g] == j + g) ++g;
        group_[at(j)] = static_cast<unsigned char>(g);
        for (int q = 1; q < g; ++q) group_[at(j + q)] = 0;
        j += g;
      }
  ok_ = true;
}

namespace {

// Forward over one chain of G simplicial columns j .. j + G - 1: column j + m holds row j + q (q >= m) at its
// position q - m, and the rows below the chain (column j's positions G ..) at position k - m.
template <int G>
void forward_chain(int j, const int* p, const int* nz, const int* rows, const double* vals, int split, const int* slot,
                   double* x, double* acc) {
  const double* V[G];
  for (int m = 0; m < G; ++m) V[m] = vals + p[j + m];
  double y[G];
  for (int q = 0; q < G; ++q) {
    double s = x[j + q];
    for (int m = 0; m < q; ++m) s -= V[m][q - m] * y[m];
    y[q] = s / V[q][0];
    x[j + q] = y[q];
  }
  const int* R = rows + p[j];
  for (int k = G; k < split; ++k) {
    double s = 0;
    for (int m = 0; m < G; ++m) s += V[m][k - m] * y[m];
    x[R[k]] -= s;
  }
  for (int k = split; k < nz[j]; ++k) {
    double s = 0;
    for (int m = 0; m < G; ++m) s += V[m][k - m] * y[m];
    acc[slot[R[k]]] += s;
  }
}

template <int G>
void backward_chain(int j, const int* p, const int* nz, const int* rows, const double* vals, double* x) {
  const double* V[G];
  for (int m = 0; m < G; ++m) V[m] = vals + p[j + m];
  double s[G];
  for (int m = 0; m < G; ++m) s[m] = x[j + m];
  const int* R = rows + p[j];
  for (int k = G; k < nz[j]; ++k) {
    const double xi = x[R[k]];
    for (int m = 0; m < G; ++m) s[m] -= V[m][k - m] * xi;
  }
  for (int q = G - 1; q >= 0; --q) {
    for (int m = q + 1; m < G; ++m) s[q] -= V[q][m - q] * x[j + m];
    x[j + q] = s[q] / V[q][0];
  }
}

}  // namespace

void TreeSolve::forward_columns(int lo, int hi, double* x, double* acc) const {
  const int* slot = top_slot_.data();
  for (int j = lo; j < hi;) {
    const int g = group_[static_cast<std::size_t>(j)];
    const int split = split_[static_cast<std::size_t>(j)];
    switch (g) {
      case 4:
        forward_chain<4>(j, p_, nz_, i_, x_, split, slot, x, acc);
        break;
      case 3:
        forward_chain<3>(j, p_, nz_, i_, x_, split, slot, x, acc);
        break;
      case 2:
        forward_chain<2>(j, p_, nz_, i_, x_, split, slot, x, acc);
        break;
      default:
        forward_chain<1>(j, p_, nz_, i_, x_, split, slot, x, acc);
        break;
    }
    j += std::max(g, 1);
  }
}

void TreeSolve::backward_columns(int lo, int hi, double* x) const {
  // Descending by chains: a chain's first column is the lowest with a nonzero group_ at or below its last one.
  for (int j = hi - 1; j >= lo;) {
    int first = j;
    while (group_[static_cast<std::size_t>(first)] == 0) --first;
    switch (group_[static_cast<std::size_t>(first)]) {
      case 4:
        backward_chain<4>(first, p_, nz_, i_, x_, x);
        break;
      case 3:
        backward_chain<3>(first, p_, nz_, i_, x_, x);
        break;
      case 2:
        backward_chain<2>(first, p_, nz_, i_, x_, x);
        break;
      default:
        backward_chain<1>(first, p_, nz_, i_, x_, x);
        break;
    }
    j = first - 1;
  }
}

void TreeSolve::forward(double* x) const {
  const std::size_t tc = static_cast<std::size_t>(top_cols_);
  std::vector<double> acc(kBins * tc, 0.0);
  run_sets([&](int b) {
    for (const auto& [lo, hi] : bin_ranges_[static_cast<std::size_t>(b)])
      forward_columns(lo, hi, x, acc.data() + static_cast<std::size_t>(b) * tc);
  });
  // The sets' updates of the top rows, in a fixed order, then the top.
  for (std::size_t s = 0; s < tc; ++s)
    for (int b = 0; b < kBins; ++b) x[top_columns_[s]] -= acc[static_cast<std::size_t>(b) * tc + s];
  for (int j : top_columns_) forward_chain<1>(j, p_, nz_, i_, x_, nz_[j], nullptr, x, nullptr);
}

void TreeSolve::backward(double* x) const {
  for (auto j = top_columns_.rbegin(); j != top_columns_.rend(); ++j) backward_chain<1>(*j, p_, nz_, i_, x_, x);
  run_sets([&](int b) {
    const auto& ranges = bin_ranges_[static_cast<std::size_t>(b)];
    for (auto r = ranges.rbegin(); r != ranges.rend(); ++r) backward_columns(r->first, r->second, x);
  });
}

template <class F>
void TreeSolve::run_sets(F&& set) const {
  static_assert(kBins == 2, "run_pair runs the two sets");
  run_pair([&] { set(0); }, [&] { set(1); });
}

}  // namespace dynid::detail
