#include "internal/lanczos.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "internal/pair.hpp"

namespace dynid::detail {

namespace {

constexpr double kEta = 0.7071067811865476;  // DGKS: repeat the pass when it removed more than 1 - 1/sqrt(2)

// With LanczosOptions::pair_vectors (the operator's solves run on two cores, tree_solve.hpp), the basis's vector
// work runs on two fixed row halves at once (pair.hpp): the sums over the rows (dots, projections) are the halves'
// sums added in a fixed order, so the result does not depend on the thread count, and it does not go through the
// optimized BLAS, whose threads spin-yield after each call and slowed the two-core solves between the steps
// (bench/README.md, "Two-core Lanczos steps"). Otherwise the whole vectors through Eigen and the BLAS, as always.
template <class F>
void halves(Eigen::Index n, F&& f) {
  const Eigen::Index h = n / 2;
  run_pair([&] { f(0, 0, h); }, [&] { f(1, h, n - h); });
}

#ifdef __clang__
// The sanitizer builds (clang, -O1) do not vectorize the `omp simd` loops below and would say so for each: a hint,
// not a requirement.
#pragma clang diagnostic ignored "-Wpass-failed"
#endif

// c = V^T w over `cols` columns of a row block (V column-major, leading dimension ld; len rows): four columns at a
// time, so that w is read once per four.
[[gnu::always_inline]] inline void project_body(const double* V, Eigen::Index ld, Eigen::Index cols, const double* w,
                                                Eigen::Index len, double* c) {
  Eigen::Index j = 0;
  for (; j + 4 <= cols; j += 4) {
    const double *a = V + j * ld, *b = a + ld, *e = b + ld, *d = e + ld;
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
#pragma omp simd reduction(+ : s0, s1, s2, s3)
    for (Eigen::Index i = 0; i < len; ++i) {
      const double wi = w[i];
      s0 += a[i] * wi, s1 += b[i] * wi, s2 += e[i] * wi, s3 += d[i] * wi;
    }
    c[j] = s0, c[j + 1] = s1, c[j + 2] = s2, c[j + 3] = s3;
  }
  for (; j < cols; ++j) {
    const double* a = V + j * ld;
    double s0 = 0;
#pragma omp simd reduction(+ : s0)
    for (Eigen::Index i = 0; i < len; ++i) s0 += a[i] * w[i];
    c[j] = s0;
  }
}

// w -= V c over `cols` columns of a row block, four columns at a time; returns ||w||^2 of the block after.
[[gnu::always_inline]] inline double subtract_body(const double* V, Eigen::Index ld, Eigen::Index cols, const double* c,
                                                   double* w, Eigen::Index len) {
  Eigen::Index j = 0;
  for (; j + 4 <= cols; j += 4) {
    const double *a = V + j * ld, *b = a + ld, *e = b + ld, *d = e + ld;
    const double c0 = c[j], c1 = c[j + 1], c2 = c[j + 2], c3 = c[j + 3];
#pragma omp simd
    for (Eigen::Index i = 0; i < len; ++i) w[i] -= a[i] * c0 + b[i] * c1 + e[i] * c2 + d[i] * c3;
  }
  for (; j < cols; ++j) {
    const double* a = V + j * ld;
    const double c0 = c[j];
#pragma omp simd
    for (Eigen::Index i = 0; i < len; ++i) w[i] -= a[i] * c0;
  }
  double sq = 0;
#pragma omp simd reduction(+ : sq)
  for (Eigen::Index i = 0; i < len; ++i) sq += w[i] * w[i];
  return sq;
}

// The two kernels compiled for AVX2 and for the baseline x86-64 this project targets, the first where the CPU has
// it (chosen at run time by a plain test, not an ifunc: a resolver runs before the sanitizers' run-times start).
[[gnu::target("avx2,fma")]] void project_avx2(const double* V, Eigen::Index ld, Eigen::Index cols, const double* w,
                                              Eigen::Index len, double* c) {
  project_body(V, ld, cols, w, len, c);
}
[[gnu::target("avx2,fma")]] double subtract_avx2(const double* V, Eigen::Index ld, Eigen::Index cols, const double* c,
                                                 double* w, Eigen::Index len) {
  return subtract_body(V, ld, cols, c, w, len);
}
bool has_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return yes;
}
void project(const double* V, Eigen::Index ld, Eigen::Index cols, const double* w, Eigen::Index len, double* c) {
  if (has_avx2()) return project_avx2(V, ld, cols, w, len, c);
  project_body(V, ld, cols, w, len, c);
}
double subtract(const double* V, Eigen::Index ld, Eigen::Index cols, const double* c, double* w, Eigen::Index len) {
  return has_avx2() ? subtract_avx2(V, ld, cols, c, w, len) : subtract_body(V, ld, cols, c, w, len);
}

// w <- w - V h with h = V^T w over the first `cols` columns, repeated while a pass shrinks w below kEta of its
// norm before the pass (at most 3 passes). Adds the coefficients to `h` (size cols, zeroed unless `keep`) and
// returns ||w||. `before`: ||w|| if known (negative: computed here).
double orthogonalize(const Eigen::MatrixXd& V, Eigen::Index cols, Eigen::VectorXd& w, Eigen::VectorXd& h,
                     bool keep = false, double before = -1, bool pair = false) {
  const Eigen::Index n = w.size();
  if (!keep) h.setZero(cols);
  if (!pair) {
    if (before < 0) before = w.norm();
    for (int pass = 0; pass < 3; ++pass) {
      const Eigen::VectorXd c = V.leftCols(cols).transpose() * w;
      w.noalias() -= V.leftCols(cols) * c;
      h += c;
      const double after = w.norm();
      if (after >= kEta * before) return after;
      before = after;
    }
    return w.norm();
  }
  Eigen::MatrixXd part(cols, 2);
  double sq[2];
  if (before < 0) {
    halves(n, [&](int k, Eigen::Index lo, Eigen::Index len) { sq[k] = w.segment(lo, len).squaredNorm(); });
    before = std::sqrt(sq[0] + sq[1]);
  }
  for (int pass = 0; pass < 3; ++pass) {
    halves(n, [&](int k, Eigen::Index lo, Eigen::Index len) {
      project(V.data() + lo, V.rows(), cols, w.data() + lo, len, part.col(k).data());
    });
    const Eigen::VectorXd c = part.col(0) + part.col(1);
    halves(n, [&](int k, Eigen::Index lo, Eigen::Index len) {
      sq[k] = subtract(V.data() + lo, V.rows(), cols, c.data(), w.data() + lo, len);
    });
    h += c;
    const double after = std::sqrt(sq[0] + sq[1]);
    if (after >= kEta * before) return after;
    before = after;
  }
  return before;
}

// V.leftCols(Y.cols()) <- V.leftCols(Y.rows()) Y, in place: by blocks of rows, each of which needs only its own
// rows of V, so that a restart needs no second basis-sized buffer (240 MB on the 995,100-DOF plane frame).
void rotate_in_place(Eigen::MatrixXd& V, const Eigen::Ref<const Eigen::MatrixXd>& Y) {
  constexpr Eigen::Index kRows = 4096;
  const Eigen::Index n = V.rows(), m = Y.rows(), k = Y.cols();
  Eigen::MatrixXd block(std::min(kRows, n), k);
  for (Eigen::Index r = 0; r < n; r += kRows) {
    const Eigen::Index h = std::min(kRows, n - r);
    block.topRows(h).noalias() = V.block(r, 0, h, m) * Y;
    V.block(r, 0, h, k) = block.topRows(h);
  }
}

}  // namespace

LanczosResult thick_restart_lanczos(const std::function<void(const double* x, double* y)>& op, Eigen::Index n,
                                    const Eigen::VectorXd& v0, const LanczosOptions& o) {
  LanczosResult out;
  const int m = o.ncv, nev = o.nev;
  const bool pair = o.pair_vectors;
  const double eps = std::numeric_limits<double>::epsilon();
  const double eps23 = std::pow(eps, 2.0 / 3.0);
  Eigen::MatrixXd V(n, m), T = Eigen::MatrixXd::Zero(m, m);
  Eigen::VectorXd w(n), h;
  std::mt19937_64 rng(20241121);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  double anorm = 0;  // largest |T| entry seen: the scale of a breakdown
  auto negligible = [&](double b) { return b <= std::sqrt(static_cast<double>(n)) * eps * anorm; };

  // A unit vector orthogonal to the first `cols` columns (a restart after an invariant subspace).
  auto fresh = [&](Eigen::Index cols) {
    for (int attempt = 0; attempt < 4; ++attempt) {
      for (Eigen::Index i = 0; i < n; ++i) w[i] = uni(rng);
      op(w.data(), V.col(cols).data());  // in the operator's range (purified as the start vector is)
      w = V.col(cols);
      const double before = w.norm();
      const double nrm = orthogonalize(V, cols, w, h);
      if (nrm > 1e-8 * before) {
        V.col(cols) = w / nrm;
        return true;
      }
    }
    return false;
  };

  double beta = v0.norm();
  if (!(beta > 0)) return out;
  V.col(0) = v0 / beta;
  int k = 0;  // kept Ritz vectors at the start of the sweep
  // Basis columns in use: m, or fewer once the basis spans the operator's whole range (no fresh direction is
  // left, e.g. a mass matrix with fewer massive DOFs than m): T is then exact and every Ritz pair converged.
  int active = m;
  for (out.restarts = 0; out.restarts <= o.max_restarts; ++out.restarts) {
    // Extend the basis from column k to m: T = V^T A V as the passes compute it.
    for (int j = k; j < active; ++j) {
      op(V.col(j).data(), w.data());
      // The three-term recurrence first (cheap: two vectors), so that the pass over the whole basis removes only
      // the rounding's loss of orthogonality and one pass suffices (DGKS); the first step after a restart couples
      // to every kept vector and goes straight to the full passes.
      h.setZero(j + 1);
      double before = -1;
      if (j > k && !pair) {
        h[j - 1] = T(j, j - 1);
        w.noalias() -= h[j - 1] * V.col(j - 1);
        h[j] = V.col(j).dot(w);
        w.noalias() -= h[j] * V.col(j);
      } else if (j > k) {
        h[j - 1] = T(j, j - 1);
        double dot[2], sq[2];
        halves(n, [&](int q, Eigen::Index lo, Eigen::Index len) {
          w.segment(lo, len).noalias() -= h[j - 1] * V.col(j - 1).segment(lo, len);
          dot[q] = V.col(j).segment(lo, len).dot(w.segment(lo, len));
        });
        h[j] = dot[0] + dot[1];
        halves(n, [&](int q, Eigen::Index lo, Eigen::Index len) {
          w.segment(lo, len).noalias() -= h[j] * V.col(j).segment(lo, len);
          sq[q] = w.segment(lo, len).squaredNorm();
        });
        before = std::sqrt(sq[0] + sq[1]);
      }
      const double nrm = orthogonalize(V, j + 1, w, h, true, before, pair);
      if (!std::isfinite(nrm) || !h.allFinite()) return out;  // the operator broke down (e.g. a NaN solve)
      T.col(j).head(j + 1) = h;
      T.row(j).head(j + 1) = h.transpose();
      anorm = std::max(anorm, h.cwiseAbs().maxCoeff());
      beta = nrm;
      if (j + 1 == m) break;
      if (negligible(beta)) {  // an invariant subspace
        beta = 0;
        if (!fresh(j + 1)) {
          active = j + 1;
          break;
        }
      } else if (!pair) {
        V.col(j + 1) = w / beta;
      } else {
        halves(n, [&](int, Eigen::Index lo, Eigen::Index len) {
          V.col(j + 1).segment(lo, len) = w.segment(lo, len) / beta;
        });
      }
      T(j + 1, j) = T(j, j + 1) = beta;
    }
    // w: the residual direction, norm beta (untouched until the restart below)
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(T.topLeftCorner(active, active));
    // Descending Ritz values and their coordinates.
    Eigen::VectorXd theta = es.eigenvalues().reverse();
    Eigen::MatrixXd Yt = es.eigenvectors().rowwise().reverse();
    const double tmax = std::max(std::abs(theta[0]), std::abs(theta[active - 1]));
    const int wanted = std::min(nev, active);  // an exhausted range may hold fewer than nev
    int nconv = 0;
    std::vector<char> conv(static_cast<std::size_t>(wanted), 0);
    for (int i = 0; i < wanted; ++i) {
      const double resid = std::abs(beta * Yt(active - 1, i));
      if (resid <= o.tolerance * std::max(std::abs(theta[i]), eps23 * tmax))
        conv[static_cast<std::size_t>(i)] = 1, ++nconv;
    }
    if (nconv == nev || out.restarts == o.max_restarts || active < m) {
      std::vector<int> keep;
      for (int i = 0; i < wanted; ++i)
        if (conv[static_cast<std::size_t>(i)]) keep.push_back(i);
      out.theta.resize(static_cast<Eigen::Index>(keep.size()));
      Eigen::MatrixXd Ys(active, static_cast<Eigen::Index>(keep.size()));
      for (std::size_t q = 0; q < keep.size(); ++q) {
        out.theta[static_cast<Eigen::Index>(q)] = theta[keep[q]];
        Ys.col(static_cast<Eigen::Index>(q)) = Yt.col(keep[q]);
      }
      rotate_in_place(V, Ys);
      V.conservativeResize(n, Ys.cols());
      out.Y = std::move(V);
      out.converged = nconv == nev;
      out.exhausted = active < m;
      return out;
    }
    // Thick restart: keep the best k Ritz vectors and continue from the residual.
    k = std::min(m - 2, nev + std::min(nconv, (m - nev) / 2));
    rotate_in_place(V, Yt.leftCols(k));
    T.setZero();
    for (int i = 0; i < k; ++i) {
      T(i, i) = theta[i];
      T(i, k) = T(k, i) = beta * Yt(m - 1, i);
    }
    if (negligible(beta)) {
      beta = 0;
      for (int i = 0; i < k; ++i) T(i, k) = T(k, i) = 0;
      if (!fresh(k)) active = k;  // the kept Ritz vectors span the whole range: the next sweep only returns them
    } else {
      V.col(k) = w / beta;
    }
  }
  return out;
}

}  // namespace dynid::detail
