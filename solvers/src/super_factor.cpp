#include "internal/super_factor.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <array>
#include <new>
#include <vector>

#include "internal/pair.hpp"
#include "internal/tree_split.hpp"

extern "C" {
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* beta, double* c, const int* ldc);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* b, const int* ldb, const double* beta, double* c,
            const int* ldc);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m, const int* n,
            const double* alpha, const double* a, const int* lda, double* b, const int* ldb);
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
}

namespace dynid::detail {

namespace {

using Index = long;

// The largest number of a descendant's rows whose update is computed at once (update()).
constexpr int kBlock = 256;

// OpenBLAS's thread count, set to one while two threads of ours call it (each call then runs on its caller's core)
// and restored after. Other BLAS libraries are left as they are.
class BlasThreads {
 public:
  BlasThreads()
      : get_(reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"))),
        set_(reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))),
        own_(get_ && set_ ? get_() : 0) {}
  ~BlasThreads() { restore(); }
  BlasThreads(const BlasThreads&) = delete;
  BlasThreads& operator=(const BlasThreads&) = delete;
  void one() const {
    if (own_ > 1) set_(1);
  }
  void restore() const {
    if (own_ > 1) set_(own_);
  }

 private:
  int (*get_)();
  void (*set_)(int);
  int own_;
};

// One worker's scratch: the map from a row of L to its position in the current supernode (set by the worker that
// assembles the supernode), the positions of a descendant's rows there, and the update block.
struct Scratch {
  std::vector<int> map, rel;
  std::vector<double> C;
  int failed = -1;  // the first column (in L's order) whose pivot failed
};

// Int: the factor's and the matrix's index type (int, or SuiteSparse_long for factors of 2^31 stored values or more).
// Column and row numbers are below n and kept as int; positions in L's row lists and values as Index.
template <typename Int>
class Factorization {
 public:
  Factorization(const cholmod_sparse* S, cholmod_factor* L)
      : n_(static_cast<int>(L->n)),
        nsuper_(static_cast<int>(L->nsuper)),
        super_(static_cast<const Int*>(L->super)),
        pi_(static_cast<const Int*>(L->pi)),
        px_(static_cast<const Int*>(L->px)),
        ls_(static_cast<const Int*>(L->s)),
        x_(static_cast<double*>(L->x)),
        sp_(static_cast<const Int*>(S->p)),
        si_(static_cast<const Int*>(S->i)),
        sx_(static_cast<const double*>(S->x)) {}

  // Returns the first failing column, or -1.
  int run() {
    const auto at = [](int k) { return static_cast<std::size_t>(k); };
    supermap_.resize(at(n_));
    for (int s = 0; s < nsuper_; ++s)
      for (int k = col(s); k < col(s + 1); ++k) supermap_[at(k)] = s;
    std::vector<int> parent(at(nsuper_), -1);
    std::vector<double> work(at(nsuper_));
    int max_rows = 0;
    for (int s = 0; s < nsuper_; ++s) {
      const double c = static_cast<double>(super_[s + 1] - super_[s]), r = static_cast<double>(rows(s)) - c;
      work[at(s)] = c * c * c / 3 + c * c * r + c * r * r;  // dpotrf, dtrsm, and its updates of its ancestors
      if (r > 0) parent[at(s)] = supermap_[at(row(pi_[s] + super_[s + 1] - super_[s]))];
      max_rows = std::max(max_rows, rows(s));
    }
    const std::vector<int> bin = split_tree(parent, work, 0.5);  // the top's work is shared (factor_top)
    for (auto& h : head_) h.assign(at(nsuper_), -1);
    next_.assign(at(nsuper_), -1);
    lpos_.assign(at(nsuper_), 0);
    for (Scratch& w : scratch_) {
      w.map.assign(at(n_), -1);
      w.rel.resize(at(max_rows));
    }
    std::array<std::vector<int>, kTreeBins> sets;
    std::vector<int> top;
    for (int s = 0; s < nsuper_; ++s) (bin[at(s)] < 0 ? top : sets[at(bin[at(s)])]).push_back(s);

    BlasThreads blas;
    blas.one();
    static_assert(kTreeBins == 2, "one set per core of run_pair");
    run_pair([&] { factor_set(sets[0], 0); }, [&] { factor_set(sets[1], 1); });
    int failed = -1;
    for (const Scratch& w : scratch_)
      if (w.failed >= 0 && (failed < 0 || w.failed < failed)) failed = w.failed;
    // The top in column order; after a failed pivot in a set, up to its column only, as the first failure in column
    // order is the one to report: a top supernode before it has all its descendants done (their columns are lower,
    // and each set stopped at its own first failure).
    for (int s : top) {
      if (failed >= 0 && col(s) >= failed) break;
      if (!factor_top(s, blas)) return failed >= 0 ? std::min(failed, scratch_[0].failed) : scratch_[0].failed;
    }
    return failed;
  }

 private:
  int col(int s) const { return static_cast<int>(super_[s]); }             // supernode s's first column
  int rows(int s) const { return static_cast<int>(pi_[s + 1] - pi_[s]); }  // its rows (its own columns first)
  int row(Index p) const { return static_cast<int>(ls_[p]); }              // the row at position p of the row lists

  // Clears supernode s's block, maps its rows into w's map and scatters its columns of P A P^T (S: lower part).
  void assemble(int s, Scratch* w) {
    const int k1 = col(s), k2 = col(s + 1), nsrow = rows(s);
    const Index psi = pi_[s], psx = px_[s];
    std::fill(x_ + psx, x_ + psx + static_cast<Index>(nsrow) * (k2 - k1), 0.0);
    for (int k = 0; k < nsrow; ++k) w->map[static_cast<std::size_t>(row(psi + k))] = k;
    for (int k = k1; k < k2; ++k) {
      double* c = x_ + psx + static_cast<Index>(k - k1) * nsrow;
      for (Index p = sp_[k]; p < sp_[k + 1]; ++p)
        if (si_[p] >= k) c[w->map[static_cast<std::size_t>(si_[p])]] = sx_[p];
    }
  }

  // Subtracts L_d(r0:end, :) L_d(r0:r1, :)^T from supernode s, for the rows at positions r0 .. r1 - 1 of
  // descendant d's pattern (rows in s's columns); map holds s's rows. By blocks of at most kBlock of those rows, so
  // that the workspace stays at kBlock columns (CHOLMOD's holds the largest update whole: 408 MB on the 249,900-DOF
  // frame).
  void update(int s, int d, Index r0, Index r1, const std::vector<int>& map, Scratch* w) const {
    const Index pdi = pi_[d], pdend = pi_[d + 1];
    const int ndrow = rows(d), ndcol = col(d + 1) - col(d), nsrow = rows(s);
    const Index psx = px_[s];
    const double one = 1, zero = 0;
    int* rel = w->rel.data();
    for (Index i = r0; i < pdend; ++i) rel[i - r0] = map[static_cast<std::size_t>(row(i))];
    for (Index b0 = r0; b0 < r1; b0 += kBlock) {
      const int n1 = static_cast<int>(std::min<Index>(kBlock, r1 - b0)), n2 = static_cast<int>(pdend - b0),
                n3 = n2 - n1;
      const std::size_t size = static_cast<std::size_t>(n1) * static_cast<std::size_t>(n2);
      if (w->C.size() < size) w->C.resize(size);
      double* C = w->C.data();
      const double* L1 = x_ + px_[d] + (b0 - pdi);
      dsyrk_("L", "N", &n1, &ndcol, &one, L1, &ndrow, &zero, C, &n2);
      if (n3 > 0) dgemm_("N", "T", &n3, &n1, &ndcol, &one, L1 + n1, &ndrow, L1, &ndrow, &zero, C + n1, &n2);
      const int* R = rel + (b0 - r0);
      for (int j = 0; j < n1; ++j) {
        double* out = x_ + psx + static_cast<Index>(R[j]) * nsrow;
        const double* c = C + static_cast<Index>(n2) * j;
        for (int i = j; i < n2; ++i) out[R[i]] -= c[i];
      }
    }
  }

  // The positions of descendant d's rows in s's columns: [lpos, end) of its pattern.
  Index rows_in(int s, int d) const {
    const Index end = pi_[d + 1];
    const int k2 = col(s + 1);
    Index p = pi_[d] + lpos_[static_cast<std::size_t>(d)];
    while (p < end && row(p) < k2) ++p;
    return p;
  }

  // After d has updated s (its rows up to position r1): on to the next supernode its rows reach, into list h.
  void move_on(int d, Index r1, std::vector<int>* h) {
    const auto at = [](int k) { return static_cast<std::size_t>(k); };
    lpos_[at(d)] = static_cast<int>(r1 - pi_[d]);
    if (r1 < pi_[d + 1]) {
      const int a = supermap_[at(row(r1))];
      next_[at(d)] = (*h)[at(a)];
      (*h)[at(a)] = d;
    }
  }

  // dpotrf and dtrsm of supernode s's block, then s joins its parent's list h. False when a pivot fails.
  bool finish(int s, std::vector<int>* h, Scratch* w) {
    const int k1 = col(s), nscol = col(s + 1) - k1, nsrow = rows(s);
    double* Ls = x_ + px_[s];
    int info = 0;
    dpotrf_("L", &nscol, Ls, &nsrow, &info);
    if (info != 0) {
      w->failed = k1 + info - 1;
      return false;
    }
    const int below = nsrow - nscol;
    if (below > 0) {
      const double one = 1;
      dtrsm_("R", "L", "T", "N", &below, &nscol, &one, Ls, &nsrow, Ls + nscol, &nsrow);
      const int a = supermap_[static_cast<std::size_t>(row(pi_[s] + nscol))];
      lpos_[static_cast<std::size_t>(s)] = nscol;
      next_[static_cast<std::size_t>(s)] = (*h)[static_cast<std::size_t>(a)];
      (*h)[static_cast<std::size_t>(a)] = s;
    }
    return true;
  }

  // One subtree set, in column order, on one core: its descendants are its own, its lists head_[b].
  void factor_set(const std::vector<int>& set, int b) {
    Scratch* w = &scratch_[static_cast<std::size_t>(b)];
    std::vector<int>* h = &head_[static_cast<std::size_t>(b)];
    for (int s : set) {
      assemble(s, w);
      for (int d = (*h)[static_cast<std::size_t>(s)], dnext; d >= 0; d = dnext) {
        dnext = next_[static_cast<std::size_t>(d)];
        const Index r0 = pi_[d] + lpos_[static_cast<std::size_t>(d)], r1 = rows_in(s, d);
        update(s, d, r0, r1, w->map, w);
        move_on(d, r1, h);
      }
      if (!finish(s, h, w)) return;
    }
  }

  // A top supernode: the updates of every descendant (the sets' lists, then the top's) with s's columns in two
  // halves of about equal work, one per core; then its dpotrf and dtrsm with the BLAS's threads.
  bool factor_top(int s, const BlasThreads& blas) {
    const auto at = [](int k) { return static_cast<std::size_t>(k); };
    Scratch* w0 = &scratch_[0];
    assemble(s, w0);
    const int k1 = col(s), nscol = col(s + 1) - k1, nsrow = rows(s);
    struct Pending {
      int d;
      Index r0, mid, r1;
    };
    std::vector<Pending> pending;
    // The work of each column of s: its entries (the assembly and the scatter) and the products of the updates it
    // receives (a descendant's row at position q costs its columns times its rows from q on).
    std::vector<double> cost(static_cast<std::size_t>(nscol));
    for (int j = 0; j < nscol; ++j) cost[at(j)] = nsrow - j;
    for (int list = 0; list <= kTreeBins; ++list)
      for (int d = head_[at(list)][at(s)]; d >= 0; d = next_[at(d)]) {
        const Index r0 = pi_[d] + lpos_[at(d)], r1 = rows_in(s, d);
        const int ndcol = col(d + 1) - col(d);
        for (Index q = r0; q < r1; ++q)
          cost[at(row(q) - k1)] += static_cast<double>(ndcol) * static_cast<double>(pi_[d + 1] - q);
        pending.push_back({d, r0, r0, r1});
      }
    // Columns below m to this core, the others to the helper: about half the work each.
    double total = 0;
    for (double c : cost) total += c;
    int m = 0;
    for (double part = 0; m < nscol && part + cost[at(m)] <= 0.5 * total; ++m) part += cost[at(m)];
    for (Pending& q : pending)
      while (q.mid < q.r1 && row(q.mid) < k1 + m) ++q.mid;
    blas.one();
    run_pair(
        [&] {
          for (const Pending& q : pending)
            if (q.mid > q.r0) update(s, q.d, q.r0, q.mid, w0->map, w0);
        },
        [&] {
          for (const Pending& q : pending)
            if (q.r1 > q.mid) update(s, q.d, q.mid, q.r1, w0->map, &scratch_[1]);
        });
    std::vector<int>* h = &head_[kTreeBins];
    for (const Pending& q : pending) move_on(q.d, q.r1, h);
    blas.restore();
    return finish(s, h, w0);
  }

  int n_, nsuper_;
  const Int *super_, *pi_, *px_, *ls_;
  double* x_;
  const Int *sp_, *si_;
  const double* sx_;
  std::vector<int> supermap_, next_, lpos_;
  std::array<std::vector<int>, kTreeBins + 1> head_;  // descendants pending per supernode: each set's, the top's
  std::array<Scratch, kTreeBins> scratch_;
};

}  // namespace

namespace {

// CHOLMOD's int or SuiteSparse_long routines for the factor's index type.
template <typename Int>
struct Api;
template <>
struct Api<int> {
  static constexpr int itype = CHOLMOD_INT;
  static int change_factor(cholmod_factor* L, cholmod_common* c) {
    return cholmod_change_factor(CHOLMOD_REAL, true, true, true, true, L, c);
  }
  static cholmod_sparse* ptranspose(cholmod_sparse* A, void* perm, cholmod_common* c) {
    return cholmod_ptranspose(A, 2, static_cast<int*>(perm), nullptr, 0, c);
  }
  static void free_sparse(cholmod_sparse** S, cholmod_common* c) { cholmod_free_sparse(S, c); }
};
template <>
struct Api<SuiteSparse_long> {
  static constexpr int itype = CHOLMOD_LONG;
  static int change_factor(cholmod_factor* L, cholmod_common* c) {
    return cholmod_l_change_factor(CHOLMOD_REAL, true, true, true, true, L, c);
  }
  static cholmod_sparse* ptranspose(cholmod_sparse* A, void* perm, cholmod_common* c) {
    return cholmod_l_ptranspose(A, 2, static_cast<SuiteSparse_long*>(perm), nullptr, 0, c);
  }
  static void free_sparse(cholmod_sparse** S, cholmod_common* c) { cholmod_l_free_sparse(S, c); }
};

template <typename Int>
bool factorize_pair(cholmod_sparse* A, cholmod_factor* L, cholmod_common* c) {
  using F = Api<Int>;
  // L's numeric part, as cholmod_super_numeric allocates it.
  if (L->xtype == CHOLMOD_PATTERN && !F::change_factor(L, c)) return true;
  if (L->xtype != CHOLMOD_REAL) return false;
  L->is_ll = true;
  // tril(P A P^T), as cholmod_factorize forms it for a matrix with its upper triangle stored.
  cholmod_sparse* S = F::ptranspose(A, L->Perm, c);
  if (!S) return true;  // c->status says why
  int failed = -1;
  try {
    Factorization<Int> f(S, L);
    failed = f.run();
  } catch (const std::bad_alloc&) {
    F::free_sparse(&S, c);
    c->status = CHOLMOD_OUT_OF_MEMORY;
    return true;
  }
  F::free_sparse(&S, c);
  c->status = failed >= 0 ? CHOLMOD_NOT_POSDEF : CHOLMOD_OK;
  L->minor = failed >= 0 ? static_cast<size_t>(failed) : L->n;
  return true;
}

}  // namespace

bool factorize_supernodal_pair(cholmod_sparse* A, cholmod_factor* L, cholmod_common* c) {
  if (!A || !L || !L->is_super || L->itype != A->itype || L->itype != c->itype || L->dtype != CHOLMOD_DOUBLE ||
      A->xtype != CHOLMOD_REAL || A->dtype != CHOLMOD_DOUBLE || A->stype <= 0 || static_cast<long>(L->n) < kPairRows)
    return false;
  if (L->itype == CHOLMOD_INT) return factorize_pair<int>(A, L, c);
  if (L->itype == CHOLMOD_LONG) return factorize_pair<SuiteSparse_long>(A, L, c);
  return false;
}

}  // namespace dynid::detail
