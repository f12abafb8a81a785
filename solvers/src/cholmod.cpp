#include "dynid/solvers/cholmod.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "dynid/mesh/error.hpp"
#include "internal/pair.hpp"
#include "internal/super_factor.hpp"
#include "internal/super_solve.hpp"
#include "internal/tree_solve.hpp"

namespace dynid {

struct CholmodFactor::Impl {
  cholmod_common c;
  cholmod_factor* L = nullptr;
  mutable cholmod_dense* X = nullptr;
  mutable cholmod_dense* Y = nullptr;
  mutable cholmod_dense* E = nullptr;
  detail::TreeSolve tree;           // simplicial L L^T solves of one right-hand side on two cores (tree_solve.hpp)
  detail::SuperSolve super;         // supernodal ones (super_solve.hpp)
  mutable Eigen::VectorXd scratch;  // a copy of the right-hand side of those solves, for the permutations
  Impl() { cholmod_start(&c); }
  ~Impl() {
    if (L) cholmod_free_factor(&L, &c);
    for (cholmod_dense** d : {&X, &Y, &E})
      if (*d) cholmod_free_dense(d, &c);
    cholmod_finish(&c);
  }
};

namespace {
// A read-only CHOLMOD view of an Eigen CSC matrix; stype = 1: only the upper triangle is used.
cholmod_sparse view(const SparseMatrix& A) {
  cholmod_sparse s;
  std::memset(&s, 0, sizeof(s));
  s.nrow = static_cast<size_t>(A.rows());
  s.ncol = static_cast<size_t>(A.cols());
  s.nzmax = static_cast<size_t>(A.nonZeros());
  s.p = const_cast<int*>(A.outerIndexPtr());
  s.i = const_cast<int*>(A.innerIndexPtr());
  s.x = const_cast<double*>(A.valuePtr());
  s.stype = 1;
  s.itype = CHOLMOD_INT;
  s.xtype = CHOLMOD_REAL;
  s.dtype = CHOLMOD_DOUBLE;
  s.sorted = 1;
  s.packed = 1;
  return s;
}
}  // namespace

CholmodFactor::CholmodFactor(Kind kind) : impl_(std::make_unique<Impl>()), kind_(kind) {
  cholmod_common& c = impl_->c;
  c.print = 0;
  c.error_handler = nullptr;
  if (kind == Kind::kSupernodalLLt) {
    // CHOLMOD's own choice (supernodal_switch: supernodal when the factorization's flops exceed 40 per entry of
    // L): a factor with short columns (members split into chains of elements) is solved in plain loops at memory
    // speed, where supernodal solves spend their time in one small BLAS call per supernode (bench/README.md:
    // 995,100-DOF plane frame, 54-66 -> 21 ms per solve).
    c.supernodal = CHOLMOD_AUTO;
    c.final_ll = 1;
  } else {
    c.supernodal = CHOLMOD_SIMPLICIAL;
    c.final_ll = 0;
  }
  c.quick_return_if_not_posdef = 1;
}

CholmodFactor::~CholmodFactor() = default;

void CholmodFactor::analyze(const SparseMatrix& A) {
  if (A.rows() != A.cols()) throw InputError("CholmodFactor: matrix is not square");
  if (!A.isCompressed()) throw InputError("CholmodFactor: matrix must be compressed");
  cholmod_common& c = impl_->c;
  impl_->tree = detail::TreeSolve();  // they point into the factor freed here
  impl_->super = detail::SuperSolve();
  if (impl_->L) cholmod_free_factor(&impl_->L, &c);
  n_ = static_cast<int>(A.rows());
  cholmod_sparse s = view(A);
  impl_->L = cholmod_analyze(&s, &c);
  if (!impl_->L || c.status < CHOLMOD_OK)
    throw NumericalError("CHOLMOD analysis failed (status " + std::to_string(c.status) +
                         (c.status == CHOLMOD_OUT_OF_MEMORY ? ": out of memory" : "") + ")");
}

bool CholmodFactor::factorize(const SparseMatrix& A) {
  if (!impl_->L) throw InternalError("CholmodFactor::factorize called before analyze");
  if (A.rows() != n_) throw InputError("CholmodFactor: matrix size differs from the analyzed one");
  cholmod_common& c = impl_->c;
  cholmod_sparse s = view(A);
  failed_ = -1;
  impl_->tree = detail::TreeSolve();  // they point into the factor's arrays, which the factorization may replace
  impl_->super = detail::SuperSolve();
  // Supernodal factors of kPairRows rows or more on two cores (super_factor.hpp), the others by CHOLMOD.
  const int ok = detail::factorize_supernodal_pair(&s, impl_->L, &c) ? c.status >= CHOLMOD_OK
                                                                     : cholmod_factorize(&s, impl_->L, &c);
  if (!ok && c.status != CHOLMOD_NOT_POSDEF)
    throw NumericalError("CHOLMOD factorization failed (status " + std::to_string(c.status) +
                         (c.status == CHOLMOD_OUT_OF_MEMORY ? ": out of memory" : "") + ")");
  cholmod_factor* L = impl_->L;
  if (c.status == CHOLMOD_NOT_POSDEF || L->minor < L->n) {
    const size_t k = std::min<size_t>(L->minor, L->n - 1);
    failed_ = L->Perm ? static_cast<int*>(L->Perm)[k] : static_cast<int>(k);
    return false;
  }
  // Two-core solves for large factors (tree_solve.hpp, super_solve.hpp); CHOLMOD's own below pair.hpp's kPairRows.
  if (kind_ == Kind::kSupernodalLLt && n_ >= detail::kPairRows) {
    if (L->is_super)
      impl_->super = detail::SuperSolve(L);
    else
      impl_->tree = detail::TreeSolve(L);
  }
  return true;
}

void CholmodFactor::solve_sys(int sys, const double* b, double* x, int ncol) const {
  if (!impl_->L) throw InternalError("CholmodFactor: solve before analyze/factorize");
  cholmod_common& c = impl_->c;
  cholmod_dense B;
  std::memset(&B, 0, sizeof(B));
  B.nrow = static_cast<size_t>(n_);
  B.ncol = static_cast<size_t>(ncol);
  B.nzmax = static_cast<size_t>(n_) * static_cast<size_t>(ncol);
  B.d = static_cast<size_t>(n_);
  B.x = const_cast<double*>(b);
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  if (!cholmod_solve2(sys, impl_->L, &B, nullptr, &impl_->X, nullptr, &impl_->Y, &impl_->E, &c))
    throw NumericalError("CHOLMOD solve failed (status " + std::to_string(c.status) + ")");
  std::memcpy(x, impl_->X->x, sizeof(double) * static_cast<size_t>(n_) * static_cast<size_t>(ncol));
}

void CholmodFactor::solve(const double* b, double* x) const {
  if (!parallel_solves()) return solve_sys(CHOLMOD_A, b, x);
  forward(b, x);
  backward(x, x);
}

void CholmodFactor::forward(const double* b, double* x) const {
  if (kind_ != Kind::kSupernodalLLt) throw InternalError("CholmodFactor::forward needs an LL^T factor");
  if (!parallel_solves()) {
    solve_sys(CHOLMOD_P, b, x);
    solve_sys(CHOLMOD_L, x, x);
    return;
  }
  // x = L^{-1} P b: (P b)[k] = b[Perm[k]], gathered into x and solved there (b copied first where it is x).
  const int* perm = static_cast<const int*>(impl_->L->Perm);
  if (b == x) {
    impl_->scratch = Eigen::Map<const Eigen::VectorXd>(b, n_);
    b = impl_->scratch.data();
  }
  for (int k = 0; k < n_; ++k) x[k] = b[perm ? perm[k] : k];
  if (impl_->super.ok())
    impl_->super.forward(x);
  else
    impl_->tree.forward(x);
}

void CholmodFactor::backward(const double* b, double* x) const {
  if (kind_ != Kind::kSupernodalLLt) throw InternalError("CholmodFactor::backward needs an LL^T factor");
  if (!parallel_solves()) {
    solve_sys(CHOLMOD_Lt, b, x);
    solve_sys(CHOLMOD_Pt, x, x);
    return;
  }
  // x = P^T L^{-T} b: x[Perm[k]] = (L^{-T} b)[k].
  const int* perm = static_cast<const int*>(impl_->L->Perm);
  Eigen::VectorXd& y = impl_->scratch;
  y = Eigen::Map<const Eigen::VectorXd>(b, n_);
  if (impl_->super.ok())
    impl_->super.backward(y.data());
  else
    impl_->tree.backward(y.data());
  for (int k = 0; k < n_; ++k) x[perm ? perm[k] : k] = y[k];
}

void CholmodFactor::solve_block(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) const {
  if (B.rows() != n_) throw InternalError("CholmodFactor::solve_block: wrong number of rows");
  X->resize(n_, B.cols());
  if (B.cols() > 0) solve_sys(CHOLMOD_A, B.data(), X->data(), static_cast<int>(B.cols()));
}

void CholmodFactor::backward_block(const Eigen::MatrixXd& B, Eigen::MatrixXd* X) const {
  if (kind_ != Kind::kSupernodalLLt) throw InternalError("CholmodFactor::backward_block needs an LL^T factor");
  if (B.rows() != n_) throw InternalError("CholmodFactor::backward_block: wrong number of rows");
  X->resize(n_, B.cols());
  if (B.cols() == 0) return;
  const int k = static_cast<int>(B.cols());
  solve_sys(CHOLMOD_Lt, B.data(), X->data(), k);
  solve_sys(CHOLMOD_Pt, X->data(), X->data(), k);
}

int CholmodFactor::negative_pivots() const {
  const cholmod_factor* L = impl_->L;
  if (!L || L->is_ll || L->is_super) throw InternalError("negative_pivots needs a simplicial LDL^T factor");
  const int* p = static_cast<const int*>(L->p);
  const double* x = static_cast<const double*>(L->x);
  int neg = 0;
  for (size_t j = 0; j < L->n; ++j)
    if (x[p[j]] < 0) ++neg;
  return neg;
}

bool CholmodFactor::parallel_solves() const { return impl_->tree.ok() || impl_->super.ok(); }

long long CholmodFactor::factor_nonzeros() const {
  const cholmod_common& c = impl_->c;
  return static_cast<long long>(c.lnz);
}

double CholmodFactor::factor_flops() const { return impl_->c.fl; }

}  // namespace dynid
