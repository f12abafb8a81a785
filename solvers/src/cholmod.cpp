#include "dynid/solvers/cholmod.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "dynid/mesh/error.hpp"
#include "internal/pair.hpp"
#include "internal/super_factor.hpp"
#include "internal/super_solve.hpp"
#include "internal/tree_solve.hpp"

namespace dynid {

// CHOLMOD's int routines, or its SuiteSparse_long ones (wide) once the int analysis has reported that the factor's
// storage does not fit in an int (CHOLMOD_TOO_LARGE: 2^31 stored values or more, e.g. a 3D frame of 10^6 DOFs): the
// matrix's indices are then copied as SuiteSparse_long for each call, and the factor, the common and the solves'
// workspaces are the long ones.
struct CholmodFactor::Impl {
  cholmod_common c;
  bool wide = false;
  cholmod_factor* L = nullptr;
  mutable cholmod_dense* X = nullptr;
  mutable cholmod_dense* Y = nullptr;
  mutable cholmod_dense* E = nullptr;
  detail::TreeSolve tree;           // simplicial L L^T solves of one right-hand side on two cores (tree_solve.hpp)
  detail::SuperSolve super;         // supernodal ones (super_solve.hpp)
  mutable Eigen::VectorXd scratch;  // a copy of the right-hand side of those solves, for the permutations
  std::vector<SuiteSparse_long> p, i;  // the matrix's indices as SuiteSparse_long (wide only, during a call)
  Impl() { cholmod_start(&c); }
  ~Impl() { finish(); }
  void finish() {
    if (wide) {
      if (L) cholmod_l_free_factor(&L, &c);
      for (cholmod_dense** d : {&X, &Y, &E})
        if (*d) cholmod_l_free_dense(d, &c);
      cholmod_l_finish(&c);
    } else {
      if (L) cholmod_free_factor(&L, &c);
      for (cholmod_dense** d : {&X, &Y, &E})
        if (*d) cholmod_free_dense(d, &c);
      cholmod_finish(&c);
    }
  }
  // The same settings in a long common (the int one is finished, its factor and workspaces freed).
  void widen() {
    cholmod_common old = c;
    finish();
    wide = true;
    cholmod_l_start(&c);
    c.print = old.print;
    c.error_handler = old.error_handler;
    c.supernodal = old.supernodal;
    c.final_ll = old.final_ll;
    c.quick_return_if_not_posdef = old.quick_return_if_not_posdef;
    for (int k = 0; k < 3; ++k) c.zrelax[k] = old.zrelax[k], c.nrelax[k] = old.nrelax[k];
  }
  // A read-only CHOLMOD view of an Eigen CSC matrix; stype = 1: only the upper triangle is used. Wide: its
  // indices copied into p and i (valid until the next view).
  cholmod_sparse view(const SparseMatrix& A) {
    cholmod_sparse s;
    std::memset(&s, 0, sizeof(s));
    s.nrow = static_cast<size_t>(A.rows());
    s.ncol = static_cast<size_t>(A.cols());
    s.nzmax = static_cast<size_t>(A.nonZeros());
    if (wide) {
      p.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.cols() + 1);
      i.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
      s.p = p.data();
      s.i = i.data();
      s.itype = CHOLMOD_LONG;
    } else {
      s.p = const_cast<int*>(A.outerIndexPtr());
      s.i = const_cast<int*>(A.innerIndexPtr());
      s.itype = CHOLMOD_INT;
    }
    s.x = const_cast<double*>(A.valuePtr());
    s.stype = 1;
    s.xtype = CHOLMOD_REAL;
    s.dtype = CHOLMOD_DOUBLE;
    s.sorted = 1;
    s.packed = 1;
    return s;
  }
  void release() {  // the long copies of the indices, after a call
    p = {};
    i = {};
  }
  // Entry k of an integer array of the factor (int or SuiteSparse_long).
  long at(const void* a, size_t k) const {
    return wide ? static_cast<long>(static_cast<const SuiteSparse_long*>(a)[k]) : static_cast<const int*>(a)[k];
  }
};

namespace {
std::string status_text(const cholmod_common& c) {
  std::string t = "status " + std::to_string(c.status);
  if (c.status == CHOLMOD_OUT_OF_MEMORY) t += ": out of memory";
  if (c.status == CHOLMOD_TOO_LARGE) t += ": the problem is too large for CHOLMOD's integers";
  return t;
}
}  // namespace

CholmodFactor::CholmodFactor(Kind kind, Indices indices) : impl_(std::make_unique<Impl>()), kind_(kind) {
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
  // Relaxed amalgamation only up to nrelax[0] = 4 columns (zrelax 0; CHOLMOD's default also merges larger
  // supernodes while their explicit zeros stay below 80 %, 10 % or 5 %, for longer BLAS calls). On the 3D frames
  // the factor is then about a tenth smaller at the same speed (bench/README.md, "Supernode relaxation").
  // Simplicial factors are not affected.
  c.zrelax[0] = c.zrelax[1] = c.zrelax[2] = 0.0;
  if (indices == Indices::kLong) impl_->widen();
}

CholmodFactor::~CholmodFactor() = default;

void CholmodFactor::analyze(const SparseMatrix& A) {
  if (A.rows() != A.cols()) throw InputError("CholmodFactor: matrix is not square");
  if (!A.isCompressed()) throw InputError("CholmodFactor: matrix must be compressed");
  cholmod_common& c = impl_->c;
  impl_->tree = detail::TreeSolve();  // they point into the factor freed here
  impl_->super = detail::SuperSolve();
  if (impl_->L) impl_->wide ? cholmod_l_free_factor(&impl_->L, &c) : cholmod_free_factor(&impl_->L, &c);
  n_ = static_cast<int>(A.rows());
  if (!impl_->wide) {
    cholmod_sparse s = impl_->view(A);
    impl_->L = cholmod_analyze(&s, &c);
    if (c.status == CHOLMOD_TOO_LARGE) {
      if (impl_->L) cholmod_free_factor(&impl_->L, &c);
      impl_->widen();
    }
  }
  if (impl_->wide) {
    cholmod_sparse s = impl_->view(A);
    impl_->L = cholmod_l_analyze(&s, &c);
    impl_->release();
  }
  if (!impl_->L || c.status < CHOLMOD_OK) {
    if (impl_->L) impl_->wide ? cholmod_l_free_factor(&impl_->L, &c) : cholmod_free_factor(&impl_->L, &c);
    throw NumericalError("CHOLMOD analysis of a " + std::to_string(n_) + "-row matrix with " +
                         std::to_string(A.nonZeros()) + " entries failed (" + status_text(c) + ")");
  }
}

bool CholmodFactor::factorize(const SparseMatrix& A) {
  if (!impl_->L) throw InternalError("CholmodFactor::factorize called before analyze");
  if (A.rows() != n_) throw InputError("CholmodFactor: matrix size differs from the analyzed one");
  cholmod_common& c = impl_->c;
  cholmod_sparse s = impl_->view(A);
  failed_ = -1;
  impl_->tree = detail::TreeSolve();  // they point into the factor's arrays, which the factorization may replace
  impl_->super = detail::SuperSolve();
  // Supernodal factors of kPairRows rows or more on two cores (super_factor.hpp), the others by CHOLMOD.
  int ok = 0;
  if (detail::factorize_supernodal_pair(&s, impl_->L, &c))
    ok = c.status >= CHOLMOD_OK;
  else
    ok = impl_->wide ? cholmod_l_factorize(&s, impl_->L, &c) : cholmod_factorize(&s, impl_->L, &c);
  impl_->release();
  if (!ok && c.status != CHOLMOD_NOT_POSDEF)
    throw NumericalError("CHOLMOD factorization of a " + std::to_string(n_) + "-row matrix failed (" + status_text(c) +
                         ")");
  cholmod_factor* L = impl_->L;
  if (c.status == CHOLMOD_NOT_POSDEF || L->minor < L->n) {
    const size_t k = std::min<size_t>(L->minor, L->n - 1);
    failed_ = static_cast<int>(L->Perm ? impl_->at(L->Perm, k) : static_cast<long>(k));
    return false;
  }
  // Two-core solves for large factors (tree_solve.hpp, super_solve.hpp); CHOLMOD's own below pair.hpp's kPairRows
  // (and for simplicial factors with long indices, which tree_solve.hpp does not read).
  if (kind_ == Kind::kSupernodalLLt && n_ >= detail::kPairRows) {
    if (L->is_super)
      impl_->super = detail::SuperSolve(L);
    else if (!impl_->wide)
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
  const int ok = impl_->wide
                     ? cholmod_l_solve2(sys, impl_->L, &B, nullptr, &impl_->X, nullptr, &impl_->Y, &impl_->E, &c)
                     : cholmod_solve2(sys, impl_->L, &B, nullptr, &impl_->X, nullptr, &impl_->Y, &impl_->E, &c);
  if (!ok) throw NumericalError("CHOLMOD solve failed (" + status_text(c) + ")");
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
  const void* perm = impl_->L->Perm;
  if (b == x) {
    impl_->scratch = Eigen::Map<const Eigen::VectorXd>(b, n_);
    b = impl_->scratch.data();
  }
  for (int k = 0; k < n_; ++k) x[k] = b[perm ? impl_->at(perm, static_cast<size_t>(k)) : k];
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
  const void* perm = impl_->L->Perm;
  Eigen::VectorXd& y = impl_->scratch;
  y = Eigen::Map<const Eigen::VectorXd>(b, n_);
  if (impl_->super.ok())
    impl_->super.backward(y.data());
  else
    impl_->tree.backward(y.data());
  for (int k = 0; k < n_; ++k) x[perm ? impl_->at(perm, static_cast<size_t>(k)) : k] = y[k];
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
  const double* x = static_cast<const double*>(L->x);
  int neg = 0;
  for (size_t j = 0; j < L->n; ++j)
    if (x[impl_->at(L->p, j)] < 0) ++neg;
  return neg;
}

bool CholmodFactor::long_indices() const { return impl_->wide; }

bool CholmodFactor::parallel_solves() const { return impl_->tree.ok() || impl_->super.ok(); }

long long CholmodFactor::factor_nonzeros() const {
  const cholmod_common& c = impl_->c;
  return static_cast<long long>(c.lnz);
}

double CholmodFactor::factor_flops() const { return impl_->c.fl; }

}  // namespace dynid
