#include "dynid/solvers/eigen.hpp"

#include <Spectra/SymGEigsShiftSolver.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>

#include "dynid/mesh/error.hpp"
#include "dynid/solvers/cholmod.hpp"
#include "dynid/solvers/distributed.hpp"
#include "internal/eigen_detail.hpp"
#include "internal/lanczos.hpp"

namespace dynid {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void report(const EigenOptions& o, std::string_view stage, double f) {
  if (o.progress) o.progress(stage, f);
}

// Removes a deflation basis P from y (n entries): y <- y - P (Q^T y), with Q = M P for an M-orthonormal P (the
// generalized operator) or Q = P for an orthonormal one (the standard form). Nothing to do without a basis.
void deflate(double* y, Eigen::Index n, const Eigen::MatrixXd& P, const Eigen::MatrixXd& Q) {
  if (P.cols() == 0) return;
  Eigen::Map<Eigen::VectorXd> yv(y, n);
  const Eigen::VectorXd c = Q.transpose() * yv;
  yv.noalias() -= P * c;
}

// (K - sigma M)^{-1} x on a CHOLMOD factor, meeting Spectra's operator contract (rows, cols, set_shift,
// perform_op). The factorization is done by the caller before the solver is built, so that failures are
// reported with the DOF; set_shift only checks the shift. With a deflation basis Phi (M-orthonormal) the result
// is projected: y <- y - Phi (M Phi)^T y, which removes the rigid-body directions exactly.
class ShiftInvertOperator {
 public:
  using Scalar = double;
  ShiftInvertOperator(const CholmodFactor& f, double sigma, const Eigen::MatrixXd& Phi, const Eigen::MatrixXd& MPhi)
      : f_(f), sigma_(sigma), Phi_(Phi), MPhi_(MPhi) {}
  Eigen::Index rows() const { return f_.rows(); }
  Eigen::Index cols() const { return f_.rows(); }
  void set_shift(double sigma) {
    if (sigma != sigma_) throw InternalError("ShiftInvertOperator: shift differs from the factorized one");
  }
  void perform_op(const double* x, double* y) const {
    f_.solve(x, y);
    ++count_;
    deflate(y, f_.rows(), Phi_, MPhi_);
  }
  int count() const { return count_; }

 private:
  const CholmodFactor& f_;
  double sigma_;
  const Eigen::MatrixXd& Phi_;
  const Eigen::MatrixXd& MPhi_;
  mutable int count_ = 0;
};

// Sequential y = A x: inside the Lanczos loop the BLAS threads of the triangular solves are active, and OpenMP
// threads here would compete with them for the two cores.
void symmetric_multiply_seq(const SparseMatrix& A, const double* x, double* y) {
  const int n = static_cast<int>(A.cols());
  const int* cp = A.outerIndexPtr();
  const int* ri = A.innerIndexPtr();
  const double* v = A.valuePtr();
  for (int i = 0; i < n; ++i) {
    double s = 0.0;
    for (int k = cp[i]; k < cp[i + 1]; ++k) s += v[k] * x[ri[k]];
    y[i] = s;
  }
}

// y = M x with M stored in full; Spectra's B operator.
class MassOperator {
 public:
  using Scalar = double;
  explicit MassOperator(const SparseMatrix& M) : M_(M) {}
  Eigen::Index rows() const { return M_.rows(); }
  Eigen::Index cols() const { return M_.cols(); }
  void perform_op(const double* x, double* y) const { symmetric_multiply(M_, x, y); }

 private:
  const SparseMatrix& M_;
};

// The shift-invert operator in standard form on the Cholesky factor P (K - sigma M) P^T = L L^T:
//   C = L^{-1} P M P^T L^{-T},  C y = theta y  <=>  K phi = lambda M phi,  theta = 1 / (lambda - sigma),
//   phi = P^T L^{-T} y / sqrt(theta).
// One solve and one M product per Lanczos step, and Euclidean orthogonalisation (the generalized form needs an
// M product for every inner product). With a deflation basis Y (orthonormal eigenvectors of C, the rigid-body
// modes) the result is projected: y <- y - Y Y^T y.
class TransformedOperator {
 public:
  using Scalar = double;
  TransformedOperator(const CholmodFactor& f, const SparseMatrix& M, const Eigen::MatrixXd& Y)
      : f_(f), M_(M), Y_(Y), t_(f.rows()), u_(f.rows()) {}
  Eigen::Index rows() const { return f_.rows(); }
  Eigen::Index cols() const { return f_.rows(); }
  void perform_op(const double* x, double* y) const {
    f_.backward(x, t_.data());
    symmetric_multiply_seq(M_, t_.data(), u_.data());
    f_.forward(u_.data(), y);
    ++count_;
    deflate(y, f_.rows(), Y_, Y_);
  }
  int count() const { return count_; }

 private:
  const CholmodFactor& f_;
  const SparseMatrix& M_;
  const Eigen::MatrixXd& Y_;
  mutable Eigen::VectorXd t_, u_;
  mutable int count_ = 0;
};

// Runs a Spectra compute(); Spectra reports a failed decomposition of its small projected matrix (e.g. a NaN from
// an operator on a nearly singular system) by throwing std::runtime_error. That is a numerical failure of this
// solve, returned in the summary like the others, never an exception through the caller.
template <class F>
bool lanczos(EigenSummary& sum, F&& compute) {
  try {
    compute();
    return true;
  } catch (const std::runtime_error& e) {
    sum.status = EigenStatus::kNotConverged;
    sum.message = std::string("Lanczos failed: ") + e.what() + " (the shifted system may be nearly singular; move the shift)";
    return false;
  }
}

// Makes the entry of largest magnitude of each column positive (ties: the first one).
void normalize_signs(Eigen::MatrixXd* V) {
  for (Eigen::Index j = 0; j < V->cols(); ++j) {
    Eigen::Index imax = 0;
    V->col(j).cwiseAbs().maxCoeff(&imax);
    if ((*V)(imax, j) < 0) V->col(j) *= -1.0;
  }
}

void check_finite(const double* v, Eigen::Index n, const char* name) {
  for (Eigen::Index i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) throw InputError(std::string("eigen-solve: ") + name + " holds a NaN or Inf entry");
}

bool in_band(double lam, const EigenOptions& o) { return lam >= o.band_lo && lam <= o.band_hi; }
bool band_mode(const EigenOptions& o) { return !std::isnan(o.band_lo); }

}  // namespace

namespace detail {

void check_inputs(Eigen::Index kr, Eigen::Index kc, Eigen::Index mr, Eigen::Index mc, const EigenOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("eigen-solve options: " + why);
  if (kr != kc || mr != mc || kr != mr)
    throw InputError("eigen-solve: K is " + std::to_string(kr) + "x" + std::to_string(kc) + " but M is " +
                     std::to_string(mr) + "x" + std::to_string(mc) + "; both must be square and of the same size");
  if (o.rigid_body_basis.size() > 0 && o.rigid_body_basis.rows() != kr)
    throw InputError("eigen-solve: rigid-body basis has " + std::to_string(o.rigid_body_basis.rows()) +
                     " rows, the matrices " + std::to_string(kr));
}

// M-orthonormalises the columns of B (n x r): returns Phi with Phi^T M Phi = I spanning the same space.
Eigen::MatrixXd m_orthonormalize(const Eigen::MatrixXd& B, const Eigen::MatrixXd& MB) {
  const Eigen::MatrixXd G = B.transpose() * MB;
  const Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (G + G.transpose()));
  if (llt.info() != Eigen::Success)
    throw InputError("rigid-body basis: the rigid-body motions have no mass (B^T M B is not positive definite)");
  // G = L L^T  =>  Phi = B L^{-T} = (L^{-1} B^T)^T satisfies Phi^T M Phi = L^{-1} G L^{-T} = I.
  return llt.matrixL().solve(B.transpose()).transpose();
}

double max_stiffness_to_mass(const Eigen::VectorXd& kd, const Eigen::VectorXd& md) {
  double r = 0;
  for (Eigen::Index i = 0; i < kd.size(); ++i)
    if (md[i] > 0) r = std::max(r, std::abs(kd[i]) / md[i]);
  if (r == 0) r = kd.cwiseAbs().maxCoeff();
  return r > 0 ? r : 1.0;
}

// Sorts modes (rigid-body first, then by eigenvalue) and applies the sign convention; the mode block is permuted
// in place, one column at a time.
void finish(EigenSolution* s) {
  const Eigen::Index m = s->eigenvalues.size();
  std::vector<Eigen::Index> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
    if (s->rigid_body[a] != s->rigid_body[b]) return s->rigid_body[a] > s->rigid_body[b];
    return s->eigenvalues[a] < s->eigenvalues[b];
  });
  Eigen::VectorXd lam(m);
  std::vector<char> rig(static_cast<std::size_t>(m));
  for (Eigen::Index k = 0; k < m; ++k) {
    lam[k] = s->eigenvalues[order[k]];
    rig[k] = s->rigid_body[order[k]];
  }
  // Position k receives column order[k]: follow the cycles of the permutation with one spare column.
  std::vector<char> done(static_cast<std::size_t>(m), 0);
  Eigen::VectorXd tmp;
  for (Eigen::Index start = 0; start < m; ++start) {
    if (done[start] || order[start] == start) continue;
    tmp = s->modes.col(start);
    Eigen::Index k = start;
    while (order[k] != start) {
      s->modes.col(k) = s->modes.col(order[k]);
      done[k] = 1;
      k = order[k];
    }
    s->modes.col(k) = tmp;
    done[k] = 1;
  }
  normalize_signs(&s->modes);
  s->eigenvalues = lam;
  s->rigid_body = rig;
}

}  // namespace detail

using detail::check_inputs;
using detail::finish;
using detail::m_orthonormalize;
using detail::max_stiffness_to_mass;

bool EigenOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  const bool lo = !std::isnan(band_lo), hi = !std::isnan(band_hi);
  if (lo != hi) return fail("band needs both band_lo and band_hi");
  if (lo && !(band_lo >= 0 && band_hi > band_lo && std::isfinite(band_hi)))
    return fail("band must satisfy 0 <= band_lo < band_hi < inf");
  if (!lo && num_modes < 1) return fail("num_modes must be >= 1");
  if (!(tolerance > 0 && tolerance < 1)) return fail("tolerance must be in (0, 1)");
  if (max_restarts < 1) return fail("max_restarts must be >= 1");
  if (subspace < 0) return fail("subspace must be >= 0");
  if (!std::isnan(shift) && !std::isfinite(shift)) return fail("shift must be finite");
  if (!(rigid_eigenvalue_tolerance > 0 && rigid_eigenvalue_tolerance < 1))
    return fail("rigid_eigenvalue_tolerance must be in (0, 1)");
  if (backend == Backend::kDistributed && lo)
    return fail("the distributed backend solves the lowest modes only; a band needs the local backend");
  if (!(iterative_tolerance > 0 && iterative_tolerance < 1)) return fail("iterative_tolerance must be in (0, 1)");
  return true;
}

std::string EigenSummary::BriefReport() const {
  std::ostringstream s;
  static const char* names[] = {"success", "not converged", "factorization failed", "invalid input"};
  s << method << ": " << names[static_cast<int>(status)];
  if (!message.empty()) s << " (" << message << ")";
  return s.str();
}

std::string EigenSummary::FullReport() const {
  std::ostringstream s;
  s << BriefReport() << "\n"
    << "  shift sigma          " << shift << "\n"
    << "  rigid-body modes     " << num_rigid << "\n"
    << "  factor nonzeros      " << factor_nonzeros << "\n"
    << "  factor flops         " << factor_flops << "\n"
    << "  triangular solves    " << solves << "\n"
    << "  Lanczos restarts     " << restarts << "\n"
    << "  time analyze (s)     " << time_analyze << "\n"
    << "  time factorize (s)   " << time_factorize << "\n"
    << "  time Lanczos (s)     " << time_lanczos << "\n"
    << "  max rel. residual    " << max_residual << "\n";
  return s.str();
}

void refine_eigenpairs(const SparseMatrix& K, const SparseMatrix& M, Eigen::VectorXd* lambda, Eigen::MatrixXd* Phi,
                       std::vector<long double>* phi_extended, int iterations) {
  using LD = long double;
  const int n = static_cast<int>(K.rows());
  if (Phi->rows() != n || Phi->cols() != lambda->size()) throw InputError("refine_eigenpairs: sizes do not match");
  if (n > 5000) throw InputError("refine_eigenpairs: dense refinement is limited to 5000 DOFs");
  const Eigen::MatrixXd Kd(K), Md(M);
  auto spmv = [&](const SparseMatrix& A, const std::vector<LD>& x, std::vector<LD>* y) {
    y->assign(n, 0.0L);
    for (int j = 0; j < n; ++j)
      for (SparseMatrix::InnerIterator it(A, j); it; ++it) (*y)[it.row()] += static_cast<LD>(it.value()) * x[j];
  };
  if (phi_extended) phi_extended->assign(static_cast<std::size_t>(n) * Phi->cols(), 0.0L);
  std::vector<LD> phi(n), kp, mp;
  const double lmax = lambda->size() ? lambda->cwiseAbs().maxCoeff() : 0.0;
  auto residual = [&](const std::vector<LD>& x, LD l) {
    spmv(K, x, &kp);
    spmv(M, x, &mp);
    LD r = 0;
    for (int k = 0; k < n; ++k) r += (kp[k] - l * mp[k]) * (kp[k] - l * mp[k]);
    return std::sqrt(r);
  };
  for (Eigen::Index i = 0; i < Phi->cols(); ++i) {
    LD lam = (*lambda)[i];
    for (int k = 0; k < n; ++k) phi[k] = (*Phi)(k, i);
    // A repeated eigenvalue (e.g. the rigid-body modes) makes the bordered Jacobian singular: left as it is.
    bool repeated = false;
    for (Eigen::Index j = 0; j < Phi->cols(); ++j)
      if (j != i && std::abs((*lambda)[j] - (*lambda)[i]) <=
                        1e-6 * std::max(std::abs((*lambda)[i]), std::abs((*lambda)[j])) + 1e-12 * lmax)
        repeated = true;
    const LD r0 = residual(phi, lam);
    const std::vector<LD> phi0 = phi;
    const LD lam0 = lam;
    for (int it = 0; it < iterations && !repeated; ++it) {
      spmv(K, phi, &kp);
      spmv(M, phi, &mp);
      Eigen::VectorXd rhs(n + 1), mph(n);
      LD nn = 0;
      for (int k = 0; k < n; ++k) {
        rhs[k] = -static_cast<double>(kp[k] - lam * mp[k]);
        nn += phi[k] * mp[k];
        mph[k] = static_cast<double>(mp[k]);
      }
      rhs[n] = -static_cast<double>((1.0L - nn) / 2.0L);
      Eigen::MatrixXd J(n + 1, n + 1);
      J.topLeftCorner(n, n) = Kd - static_cast<double>(lam) * Md;
      J.topRightCorner(n, 1) = -mph;
      J.bottomLeftCorner(1, n) = -mph.transpose();
      J(n, n) = 0;
      const Eigen::VectorXd d = J.partialPivLu().solve(rhs);
      if (!d.allFinite()) break;  // singular bordered matrix (repeated eigenvalue): keep what we have
      for (int k = 0; k < n; ++k) phi[k] += d[k];
      lam += d[n];
    }
    if (!(residual(phi, lam) <= r0)) {  // refinement did not help (ill-conditioned): keep the input
      phi = phi0;
      lam = lam0;
    }
    (*lambda)[i] = static_cast<double>(lam);
    for (int k = 0; k < n; ++k) {
      (*Phi)(k, i) = static_cast<double>(phi[k]);
      if (phi_extended) (*phi_extended)[static_cast<std::size_t>(i) * n + k] = phi[k];
    }
  }
}

double rigid_eigenvalue_limit(const Eigen::VectorXd& k_diagonal, const Eigen::VectorXd& m_diagonal,
                              const EigenOptions& options) {
  return options.rigid_eigenvalue_tolerance * max_stiffness_to_mass(k_diagonal, m_diagonal);
}

double eigen_residual(const SparseMatrix& K, const SparseMatrix& M, double lambda, const Eigen::VectorXd& phi) {
  const Eigen::Index n = phi.size();
  Eigen::VectorXd kp(n), mp(n);
  symmetric_multiply(K, phi.data(), kp.data());
  symmetric_multiply(M, phi.data(), mp.data());
  const double den = (norm1(K) + std::abs(lambda) * norm1(M)) * phi.norm();
  return den > 0 ? (kp - lambda * mp).norm() / den : 0.0;
}

// Factorizations kept between solves of matrices with one pattern: the symbolic analysis is reused.
struct EigenSolver::Cache {
  std::unique_ptr<CholmodFactor> factor[2];  // [0] LL^T, [1] LDL^T
  bool llt_valid = false;                    // factor[0] holds K - sigma M of the last solve
  std::vector<int> outer[2], inner[2];       // the pattern each was analysed for
  CholmodFactor& get(CholmodFactor::Kind kind, const SparseMatrix& A, double* t_analyze) {
    const int k = kind == CholmodFactor::Kind::kSupernodalLLt ? 0 : 1;
    const int n = static_cast<int>(A.cols());
    const bool same = factor[k] && static_cast<int>(outer[k].size()) == n + 1 &&
                      static_cast<Eigen::Index>(inner[k].size()) == A.nonZeros() &&
                      std::equal(outer[k].begin(), outer[k].end(), A.outerIndexPtr()) &&
                      std::equal(inner[k].begin(), inner[k].end(), A.innerIndexPtr());
    if (!same) {
      const auto t0 = Clock::now();
      factor[k] = std::make_unique<CholmodFactor>(kind);
      factor[k]->analyze(A);
      outer[k].assign(A.outerIndexPtr(), A.outerIndexPtr() + n + 1);
      inner[k].assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
      *t_analyze += seconds_since(t0);
    }
    return *factor[k];
  }
};

EigenSolver::EigenSolver(const EigenOptions& options) : cache_(std::make_unique<Cache>()), options_(options) {}
EigenSolver::~EigenSolver() = default;

const CholmodFactor* EigenSolver::factor() const { return cache_->llt_valid ? cache_->factor[0].get() : nullptr; }

EigenSolution solve_eigen(const SparseMatrix& K, const SparseMatrix& M, const EigenOptions& opt) {
  return EigenSolver(opt).solve(K, M);
}

EigenSolution EigenSolver::solve(const SparseMatrix& K, const SparseMatrix& M) {
  const EigenOptions& opt = options_;
  cache_->llt_valid = false;
  check_inputs(K.rows(), K.cols(), M.rows(), M.cols(), opt);
  check_finite(K.valuePtr(), K.nonZeros(), "K");
  check_finite(M.valuePtr(), M.nonZeros(), "M");
  if (opt.backend == EigenOptions::Backend::kDistributed) return solve_eigen_distributed(K, M, opt);
  const Eigen::Index n = K.rows();
  const bool band = band_mode(opt);
  const Eigen::Index r = opt.rigid_body_basis.cols();
  const bool want_dense = opt.method == EigenOptions::Method::kDense ||
                          (opt.method == EigenOptions::Method::kAuto &&
                           (n <= 300 || (!band && 2 * static_cast<Eigen::Index>(opt.num_modes) + 20 > n)));
  if (want_dense) return solve_eigen_dense(Eigen::MatrixXd(K), Eigen::MatrixXd(M), opt);

  // Both matrices must share one pattern, so that K - sigma M is a sum of value arrays. Matrices assembled by
  // dynid already do; others are brought to their union pattern (copies only then).
  const bool same_pattern = K.nonZeros() == M.nonZeros() &&
                            std::equal(K.outerIndexPtr(), K.outerIndexPtr() + n + 1, M.outerIndexPtr()) &&
                            std::equal(K.innerIndexPtr(), K.innerIndexPtr() + K.nonZeros(), M.innerIndexPtr());
  SparseMatrix Kcopy, Mcopy;
  if (!same_pattern) {
    const SparseMatrix P = K.cwiseAbs() + M.cwiseAbs();  // union pattern
    Kcopy = P * 0.0 + K;
    Mcopy = P * 0.0 + M;
    Kcopy.makeCompressed();
    Mcopy.makeCompressed();
  }
  const SparseMatrix& Ku = same_pattern ? K : Kcopy;
  const SparseMatrix& Mu = same_pattern ? M : Mcopy;
  // The M products (every Lanczos step, the residuals) on M's nonzeros alone when they are few of the shared
  // pattern's entries (lumped masses, massless DOFs): a diagonal M then costs n per product, not nnz(K).
  const Eigen::Index m_nonzero = (Eigen::Map<const Eigen::ArrayXd>(Mu.valuePtr(), Mu.nonZeros()) != 0.0).count();
  SparseMatrix Mpruned;
  if (2 * m_nonzero < Mu.nonZeros()) Mpruned = Mu.pruned(0.0, 0.0);
  const SparseMatrix& Mp = 2 * m_nonzero < Mu.nonZeros() ? Mpruned : Mu;

  EigenSolution sol;
  EigenSummary& sum = sol.summary;

  // Rigid-body modes from the supplied null-space basis: exact, M-orthonormal, deflated from the Lanczos run.
  Eigen::MatrixXd Phi(n, 0), MPhi(n, 0);
  if (r > 0) {
    Eigen::MatrixXd MB(n, r);
    for (Eigen::Index j = 0; j < r; ++j)
      symmetric_multiply(Mu, opt.rigid_body_basis.col(j).data(), MB.col(j).data());
    Phi = m_orthonormalize(opt.rigid_body_basis, MB);
    MPhi.resize(n, r);
    for (Eigen::Index j = 0; j < r; ++j) symmetric_multiply(Mu, Phi.col(j).data(), MPhi.col(j).data());
  }

  const Eigen::VectorXd kd = Ku.diagonal(), md = Mu.diagonal();
  const double s0 = std::sqrt(std::numeric_limits<double>::epsilon()) * max_stiffness_to_mass(kd, md);
  SparseMatrix A;  // K - sigma M, formed only for sigma != 0
  auto form = [&](double sigma) -> const SparseMatrix& {
    if (sigma == 0.0) return Ku;
    if (A.nonZeros() != Ku.nonZeros()) A = Ku;
    Eigen::Map<Eigen::VectorXd>(A.valuePtr(), A.nonZeros()) =
        Eigen::Map<const Eigen::VectorXd>(Ku.valuePtr(), Ku.nonZeros()) -
        sigma * Eigen::Map<const Eigen::VectorXd>(Mu.valuePtr(), Mu.nonZeros());
    return A;
  };

  report(opt, "analyze", -1);
  CholmodFactor& F = cache_->get(band ? CholmodFactor::Kind::kSimplicialLDLt : CholmodFactor::Kind::kSupernodalLLt,
                                 Ku, &sum.time_analyze);

  auto factor_at = [&](double sigma) {
    auto tf = Clock::now();
    const SparseMatrix& shifted = form(sigma);
    report(opt, "factorize", -1);
    const bool ok = F.factorize(shifted);
    sum.time_factorize += seconds_since(tf);
    sum.factor_nonzeros = F.factor_nonzeros();
    sum.factor_flops = F.factor_flops();
    return ok;
  };
  auto fail_factor = [&](double sigma, const std::string& why) {
    sum.status = EigenStatus::kFactorizationFailed;
    sum.shift = sigma;
    sum.failed_dof = F.failed_index();
    sum.message = why;
    return sol;
  };

  double sigma = 0;
  int nev = 0;
  int band_count = 0;
  Spectra::SortRule selection = Spectra::SortRule::LargestAlge;
  if (!band) {
    nev = opt.num_modes - static_cast<int>(r);
    if (!std::isnan(opt.shift)) {
      sigma = opt.shift;
    } else {
      sigma = (r > 0) ? -s0 : 0.0;
    }
    if (nev > 0) {
      bool ok = factor_at(sigma);
      if (!ok && std::isnan(opt.shift) && sigma == 0.0 && opt.allow_singular_stiffness) {
        sigma = -s0;
        ok = factor_at(sigma);
      }
      if (!ok) {
        if (sigma == 0.0)
          return fail_factor(sigma, "K is singular: the structure is a mechanism or is not supported (Cholesky "
                                    "broke down at this DOF)");
        return fail_factor(sigma, "K - sigma M is not positive definite at this DOF: a mechanism with no mass, "
                                  "or the shift lies above the lowest eigenvalue");
      }
    }
  } else {
    // Spectrum slicing: Sylvester's inertia of L D L^T(K - x M) counts the eigenvalues below x.
    auto count_below = [&](double x, int* count) {
      for (int attempt = 0; attempt < 4; ++attempt) {
        if (factor_at(x)) {
          *count = F.negative_pivots();
          return true;
        }
        x -= (std::abs(x) + s0) * 1e-8;  // exactly on an eigenvalue: a zero pivot; step off it
      }
      return false;
    };
    int below_lo = 0, below_hi = 0;
    const double lo = opt.band_lo > 0 ? opt.band_lo : -s0;
    if (!count_below(lo, &below_lo) || !count_below(opt.band_hi, &below_hi))
      return fail_factor(lo, "L D L^T of K - x M broke down while counting eigenvalues in the band");
    band_count = below_hi - below_lo;
    const int rigid_in_band = opt.band_lo <= 0 ? static_cast<int>(r) : 0;
    nev = band_count - rigid_in_band;
    if (band_count > 2000)
      return fail_factor(lo, "the band holds " + std::to_string(band_count) +
                                 " modes; split it into narrower bands (at most 2000 modes per solve)");
    sigma = !std::isnan(opt.shift) ? opt.shift : 0.5 * (std::max(opt.band_lo, 0.0) + opt.band_hi);
    if (nev > 0) {
      bool ok = factor_at(sigma);
      for (int a = 0; !ok && a < 3; ++a) ok = factor_at(sigma *= (1 + 1e-7));
      if (!ok) return fail_factor(sigma, "L D L^T of K - sigma M broke down at this DOF");
    }
    selection = Spectra::SortRule::LargestMagn;
  }
  sum.shift = sigma;
  sum.num_rigid = static_cast<int>(r);

  // Rigid-body modes (from the basis).
  std::vector<double> lam;
  std::vector<char> rigid;
  Eigen::MatrixXd elastic;       // Lanczos eigenvectors (n x found)
  std::vector<int> elastic_keep;  // which of their columns are returned
  const int rigid_take = band ? (opt.band_lo <= 0 ? static_cast<int>(r) : 0)
                              : std::min<int>(static_cast<int>(r), opt.num_modes);
  for (int j = 0; j < rigid_take; ++j) {
    Eigen::VectorXd kp(n);
    symmetric_multiply(Ku, Phi.col(j).data(), kp.data());
    lam.push_back(Phi.col(j).dot(kp));
    rigid.push_back(1);
  }

  // The standard (Cholesky-transformed) form needs an LL^T factor: the lowest-modes mode. Band mode works on an
  // indefinite L D L^T factor and uses the generalized form.
  const bool standard = !band && opt.formulation == EigenOptions::Formulation::kCholeskyStandard;
  sum.method = standard ? "sparse shift-invert Lanczos (Cholesky standard form)"
                        : "sparse shift-invert Lanczos (generalized, M inner product)";
  Eigen::MatrixXd Yr(n, 0);
  if (standard && r > 0 && nev > 0) {
    // Rigid modes in the transformed space: y = L^T P phi = -sigma L^{-1} P M phi (from (K - sigma M) phi =
    // -sigma M phi), orthonormalised.
    Yr.resize(n, r);
    for (Eigen::Index j = 0; j < r; ++j) F.forward(MPhi.col(j).data(), Yr.col(j).data());
    Yr = Eigen::HouseholderQR<Eigen::MatrixXd>(Yr).householderQ() * Eigen::MatrixXd::Identity(n, r);
  }
  bool converged = true;
  bool exhausted = false;  // the Lanczos basis spanned the operator's whole range
  if (nev > 0) {
    auto tl = Clock::now();
    const int n_eff = static_cast<int>(n - r);
    int extra = band ? 2 : 0;
    for (int attempt = 0; attempt < 3; ++attempt) {
      const int want = std::min(nev + extra, n_eff - 1);
      int ncv = opt.subspace > 0 ? opt.subspace : std::max(2 * want + 1, want + 20);
      ncv = std::min(ncv, n_eff);
      if (want < 1 || ncv <= want) {
        sum.status = EigenStatus::kInvalidInput;
        sum.message = "too many modes requested for the sparse solver; use the dense path";
        return sol;
      }
      // Start vector: random with a fixed seed, then mapped through the operator so that it lies in its range
      // (purified of massless and rigid-body directions).
      std::mt19937_64 rng(20241121);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      Eigen::VectorXd x0(n), b0(n), v0(n);
      for (Eigen::Index i = 0; i < n; ++i) x0[i] = u(rng);
      Eigen::VectorXd ev;
      Eigen::MatrixXd V;
      bool ok = false;
      report(opt, "lanczos", -1);
      if (standard) {
        TransformedOperator op(F, Mp, Yr);
        op.perform_op(x0.data(), v0.data());
        detail::LanczosResult lr = detail::thick_restart_lanczos(
            [&](const double* x, double* y) { op.perform_op(x, y); }, n, v0,
            detail::LanczosOptions{want, ncv, opt.max_restarts, opt.tolerance, F.parallel_solves()});
        sum.solves += op.count();
        sum.restarts += lr.restarts;
        // A range with fewer dimensions than wanted (fewer massive DOFs): every finite mode, as the dense path.
        ok = lr.converged || lr.exhausted;
        exhausted = lr.exhausted;
        const Eigen::VectorXd& th = lr.theta;  // descending theta = ascending lambda
        ev.resize(th.size());
        V = std::move(lr.Y);
        // A run the operator broke off returns no Ritz vectors (lr.Y empty): no modes, not converged.
        if (V.rows() != n) V.resize(n, 0);
        F.backward_block(V, &V);  // in place: the Ritz vectors' storage becomes the modes' (B may be X)
        for (Eigen::Index k = 0; k < th.size(); ++k) {
          ev[k] = sigma + 1.0 / th[k];
          V.col(k) /= std::sqrt(th[k]);
        }
      } else {
        ShiftInvertOperator op(F, sigma, Phi, MPhi);
        MassOperator Bop(Mp);
        using Solver = Spectra::SymGEigsShiftSolver<ShiftInvertOperator, MassOperator, Spectra::GEigsMode::ShiftInvert>;
        Solver eigs(op, Bop, want, ncv, sigma);
        symmetric_multiply(Mp, x0.data(), b0.data());
        op.perform_op(b0.data(), v0.data());
        eigs.init(v0.data());
        if (!lanczos(sum, [&] { eigs.compute(selection, opt.max_restarts, opt.tolerance, Spectra::SortRule::SmallestAlge); }))
          return sol;
        sum.solves += op.count();
        sum.restarts += static_cast<int>(eigs.num_iterations());
        ok = eigs.info() == Spectra::CompInfo::Successful;
        ev = eigs.eigenvalues();
        V = eigs.eigenvectors();
      }
      if (!ok && ev.size() < want) {
        converged = false;
        sum.message = "Lanczos converged " + std::to_string(ev.size()) + " of " + std::to_string(want) +
                      " modes in " + std::to_string(opt.max_restarts) +
                      " restarts; raise max_restarts or the subspace size, or move the shift";
      }
      std::vector<int> keep;
      for (Eigen::Index k = 0; k < ev.size(); ++k)
        if (!band || in_band(ev[k], opt)) keep.push_back(static_cast<int>(k));
      if (band && static_cast<int>(keep.size()) < nev && converged) {
        extra += nev;  // the nearest eigenvalues to sigma were not all in the band: widen and retry
        continue;
      }
      for (int k : keep) {
        if (!band && static_cast<int>(lam.size()) >= opt.num_modes) break;
        lam.push_back(ev[k]);
        elastic_keep.push_back(k);
        rigid.push_back(0);
      }
      elastic = std::move(V);
      break;
    }
    sum.time_lanczos = seconds_since(tl);
  }

  const Eigen::Index m = static_cast<Eigen::Index>(lam.size());
  sol.eigenvalues = Eigen::Map<Eigen::VectorXd>(lam.data(), m);
  const bool all_in_order = rigid_take == 0 && static_cast<Eigen::Index>(elastic_keep.size()) == elastic.cols() &&
                            std::is_sorted(elastic_keep.begin(), elastic_keep.end());
  if (all_in_order) {
    sol.modes = std::move(elastic);  // the common case: no copy of the n x m block
  } else {
    sol.modes.resize(n, m);
    sol.modes.leftCols(rigid_take) = Phi.leftCols(rigid_take);
    for (std::size_t k = 0; k < elastic_keep.size(); ++k)
      sol.modes.col(rigid_take + static_cast<Eigen::Index>(k)) = elastic.col(elastic_keep[k]);
    elastic.resize(0, 0);
  }
  sol.rigid_body = rigid;

  // Without a rigid basis, zero-energy modes of a singular K are recognised by their eigenvalue (EigenOptions).
  const double nK = norm1(Ku), nM = norm1(Mu);
  if (r == 0 && sigma < 0 && opt.allow_singular_stiffness) {
    const double zero = rigid_eigenvalue_limit(kd, md, opt);
    for (Eigen::Index k = 0; k < m; ++k)
      if (sol.eigenvalues[k] <= zero) sol.rigid_body[k] = 1;
    sum.num_rigid = static_cast<int>(std::count(sol.rigid_body.begin(), sol.rigid_body.end(), 1));
  }
  finish(&sol);
  // A supported structure whose K is singular to rounding (a mechanism: e.g. its only supports are springs of
  // stiffness 0) may pass the LL^T of K with tiny positive pivots; its zero-energy motions then come back with
  // eigenvalues at or below the rounding of the stiffness (1e3 eps max K_ii / M_ii). That is the breakdown the
  // factorization missed: reported as such, at the DOF where the lowest motion is largest.
  if (!band && r == 0 && !opt.allow_singular_stiffness && m > 0 &&
      sol.eigenvalues[0] <= 1e3 * std::numeric_limits<double>::epsilon() * max_stiffness_to_mass(kd, md)) {
    Eigen::Index at = 0;
    sol.modes.col(0).cwiseAbs().maxCoeff(&at);
    EigenSolution failed;
    failed.summary = sum;
    failed.summary.status = EigenStatus::kFactorizationFailed;
    failed.summary.failed_dof = static_cast<int>(at);
    failed.summary.message = "K is singular to rounding (an eigenvalue of " + std::to_string(sol.eigenvalues[0]) +
                             "): the structure is a mechanism or is not supported; the zero-energy motion is largest "
                             "at this DOF";
    return failed;
  }
  sol.residuals.resize(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    Eigen::VectorXd kp(n), mp(n);
    symmetric_multiply(Ku, sol.modes.col(k).data(), kp.data());
    symmetric_multiply(Mp, sol.modes.col(k).data(), mp.data());
    const double lamk = sol.eigenvalues[k];
    sol.residuals[k] = (kp - lamk * mp).norm() / ((nK + std::abs(lamk) * nM) * sol.modes.col(k).norm());
  }
  sum.max_residual = m > 0 ? sol.residuals.maxCoeff() : 0.0;
  if (band && m != band_count && converged) {
    converged = false;
    sum.message = "found " + std::to_string(m) + " modes in the band, the inertia count says " +
                  std::to_string(band_count);
  }
  sum.status = converged ? EigenStatus::kSuccess : EigenStatus::kNotConverged;
  // The Krylov space closed with no fresh direction left: every other eigenvalue is infinite (massless
  // directions) or more than 1e8 times farther from the shift than the lowest (nearly massless ones).
  if (converged && exhausted && m < opt.num_modes)
    sum.message = "the model has only " + std::to_string(m) +
                  " finite modes (the others belong to massless or nearly massless DOFs)";
  cache_->llt_valid = !band && nev > 0;  // F holds K - sigma M (LL^T)
  report(opt, "done", 1.0);
  return sol;
}

EigenSolution solve_eigen_dense(const Eigen::MatrixXd& K, const Eigen::MatrixXd& M, const EigenOptions& opt) {
  check_inputs(K.rows(), K.cols(), M.rows(), M.cols(), opt);
  if (!K.allFinite()) throw InputError("eigen-solve: K holds a NaN or Inf entry");
  if (!M.allFinite()) throw InputError("eigen-solve: M holds a NaN or Inf entry");
  const Eigen::Index n = K.rows();
  EigenSolution sol;
  EigenSummary& sum = sol.summary;
  sum.method = "dense";
  auto t0 = Clock::now();
  const Eigen::MatrixXd Ks = 0.5 * (K + K.transpose()), Ms = 0.5 * (M + M.transpose());
  Eigen::VectorXd lam;
  Eigen::MatrixXd V;
  const Eigen::LLT<Eigen::MatrixXd> lltM(Ms);
  const Eigen::VectorXd Ld = lltM.info() == Eigen::Success ? Eigen::VectorXd(lltM.matrixLLT().diagonal())
                                                            : Eigen::VectorXd();
  const bool m_pd = lltM.info() == Eigen::Success && Ld.minCoeff() > 1e-7 * Ld.maxCoeff();
  if (m_pd) {
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Ks, Ms);
    if (es.info() != Eigen::Success) {
      sum.status = EigenStatus::kNotConverged;
      sum.message = "dense generalized eigen-solver did not converge";
      return sol;
    }
    V = es.eigenvectors();
    // Rayleigh quotients: accurate relative to each eigenvalue, while the eigen-decomposition of
    // L^{-1} K L^{-T} is accurate only to ~eps * lambda_max in absolute terms (frames: lambda_max / lambda_1 ~ 1e8).
    lam = (V.transpose() * Ks * V).diagonal().cwiseQuotient((V.transpose() * Ms * V).diagonal());
  } else {
    // Singular (or nearly singular) M: with A = K - sigma M = L L^T positive definite (sigma < 0), the pencil
    // becomes the standard problem C y = theta y, C = L^{-1} M L^{-T}, theta = 1 / (lambda - sigma);
    // theta = 0 are the infinite eigenvalues of the massless directions and are dropped.
    const double sigma = -std::sqrt(std::numeric_limits<double>::epsilon()) *
                         max_stiffness_to_mass(Ks.diagonal(), Ms.diagonal());
    sum.shift = sigma;
    const Eigen::LLT<Eigen::MatrixXd> llt(Ks - sigma * Ms);
    if (llt.info() != Eigen::Success) {
      sum.status = EigenStatus::kFactorizationFailed;
      sum.message = "K - sigma M is not positive definite: a mechanism with no mass";
      return sol;
    }
    const Eigen::MatrixXd Li = llt.matrixL().solve(Eigen::MatrixXd::Identity(n, n));
    const Eigen::MatrixXd C = Li * Ms * Li.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (C + C.transpose()));
    const Eigen::VectorXd th = es.eigenvalues();
    const double tmax = th.cwiseAbs().maxCoeff();
    std::vector<Eigen::Index> idx;
    for (Eigen::Index i = n - 1; i >= 0; --i)
      if (th[i] > 1e3 * std::numeric_limits<double>::epsilon() * tmax) idx.push_back(i);
    lam.resize(static_cast<Eigen::Index>(idx.size()));
    V.resize(n, static_cast<Eigen::Index>(idx.size()));
    for (std::size_t k = 0; k < idx.size(); ++k) {
      const Eigen::Index i = idx[k];
      lam[static_cast<Eigen::Index>(k)] = sigma + 1.0 / th[i];
      V.col(static_cast<Eigen::Index>(k)) = llt.matrixU().solve(es.eigenvectors().col(i)) / std::sqrt(th[i]);
    }
  }
  // Rigid-body modes: as many as the supplied basis has (they are the lowest), else by their eigenvalue
  // (EigenOptions::rigid_eigenvalue_tolerance: the same test whatever the units of the DOFs).
  const Eigen::Index r = opt.rigid_body_basis.cols();
  const double nK = Ks.cwiseAbs().colwise().sum().maxCoeff(), nM = Ms.cwiseAbs().colwise().sum().maxCoeff();
  const double zero = rigid_eigenvalue_limit(Ks.diagonal(), Ms.diagonal(), opt);
  std::vector<char> rigid(static_cast<std::size_t>(lam.size()), 0);
  for (Eigen::Index k = 0; k < lam.size(); ++k) rigid[k] = r > 0 ? k < r : lam[k] <= zero;
  std::vector<Eigen::Index> keep;
  for (Eigen::Index k = 0; k < lam.size(); ++k) {
    if (band_mode(opt) ? (rigid[k] ? opt.band_lo <= 0 : in_band(lam[k], opt))
                       : static_cast<int>(keep.size()) < opt.num_modes)
      keep.push_back(k);
  }
  const Eigen::Index m = static_cast<Eigen::Index>(keep.size());
  sol.eigenvalues.resize(m);
  sol.modes.resize(n, m);
  sol.rigid_body.resize(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    sol.eigenvalues[k] = lam[keep[k]];
    sol.modes.col(k) = V.col(keep[k]);
    sol.rigid_body[k] = rigid[keep[k]];
  }
  sum.num_rigid = static_cast<int>(std::count(sol.rigid_body.begin(), sol.rigid_body.end(), 1));
  finish(&sol);
  sol.residuals.resize(m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double l = sol.eigenvalues[k];
    sol.residuals[k] = (Ks * sol.modes.col(k) - l * (Ms * sol.modes.col(k))).norm() /
                       ((nK + std::abs(l) * nM) * sol.modes.col(k).norm());
  }
  sum.max_residual = m > 0 ? sol.residuals.maxCoeff() : 0.0;
  sum.time_lanczos = seconds_since(t0);
  sum.status = EigenStatus::kSuccess;
  if (!band_mode(opt) && m < opt.num_modes) sum.message = "the model has only " + std::to_string(m) + " finite modes";
  return sol;
}

}  // namespace dynid
