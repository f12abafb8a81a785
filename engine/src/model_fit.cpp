#include "dynid/engine/model_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "dynid/engine/correlation.hpp"
#include "dynid/engine/sensitivity.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/cholmod.hpp"
#include "dynid/solvers/eigen.hpp"
#include "dynid/solvers/sparse.hpp"
#include "internal/free_parameters.hpp"

namespace dynid {

std::string_view fit_objective_name(FitObjective o) {
  switch (o) {
    case FitObjective::kFrequency: return "frequency";
    case FitObjective::kFrequencyMac: return "f1";
    case FitObjective::kCombined: return "combined";
    case FitObjective::kSerep: return "f2";
  }
  return "?";
}

bool FitOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(frequency_noise > 0)) return fail("frequency_noise must be > 0");
  if (!(shape_noise > 0)) return fail("shape_noise must be > 0");
  for (const Eigen::VectorXd* v : {&frequency_noise_modes, &shape_noise_modes})
    for (Eigen::Index k = 0; k < v->size(); ++k)
      if (!((*v)[k] > 0) || !std::isfinite((*v)[k])) return fail("per-mode noise levels must be finite and > 0");
  if (!shape_noise_entries.allFinite() || (shape_noise_entries.array() < 0).any())
    return fail("per-entry shape noise levels must be finite and >= 0");
  for (Eigen::Index k = 0; k < shape_noise_entries.cols(); ++k)
    if ((shape_noise_entries.col(k).array() > 0).count() == 0)
      return fail("per-entry shape noise: every mode needs at least one entry with a std > 0");
  for (const Eigen::MatrixXd& F : shape_covariance_factors)
    if (!F.allFinite()) return fail("shape covariance factors must be finite");
  if (!(regularization >= 0)) return fail("regularization must be >= 0");
  if (!(loss_scale > 0)) return fail("loss_scale must be > 0");
  if (max_iterations < 0) return fail("max_iterations must be >= 0");
  if (!(min_mac >= 0 && min_mac <= 1)) return fail("min_mac must be in [0, 1]");
  if (!(max_frequency_ratio == 0 || max_frequency_ratio > 1)) return fail("max_frequency_ratio must be 0 (no bound) or > 1");
  if (!(min_visibility >= 0 && min_visibility < 1)) return fail("min_visibility must be in [0, 1)");
  if (extra_modes < 0) return fail("extra_modes must be >= 0");
  return true;
}

namespace {

// One evaluation of the model at theta against the measured modes: residual block and Jacobian per mode.
struct Evaluation {
  bool ok = false;
  std::string error;
  ModalState ms;
  std::vector<int> elastic;     // indices of elastic modes in ms
  std::vector<int> pair;        // measured k -> index in ms
  std::vector<char> forced;     // the pairing fell back to the best available MAC below min_mac
  Eigen::MatrixXd Pa;           // every mode at the measured rows (a x modes)
  Eigen::MatrixXd Y;            // surrogate: the reduced eigenvectors (basis coordinates x modes)
  Eigen::VectorXd mac;
  std::vector<Eigen::VectorXd> r;
  std::vector<Eigen::MatrixXd> J;  // rows x free parameters
  bool has_jacobian = false;
};

class Evaluator {
 public:
  // x (the optimiser's variables) drives the free parameters free[k]; tied parameters follow x[k] by a ratio.
  Evaluator(const ParametricModel& pm, const ModalData& meas, const Eigen::VectorXd& theta0, std::vector<int> free,
            const FitOptions& o)
      : pm_(pm), meas_(meas), theta0_(theta0), free_(std::move(free)), o_(o), solver_(EigenOptions{}) {
    xmap_.resize(free_.size());
    for (std::size_t k = 0; k < free_.size(); ++k) xmap_[k].push_back({free_[k], 1.0});
    for (const auto& [p, t] : o.ties) {
      const auto it = std::find(free_.begin(), free_.end(), t.first);
      if (it == free_.end()) continue;  // tied to a fixed parameter: constant, handled by theta0
      xmap_[static_cast<std::size_t>(it - free_.begin())].push_back({p, t.second});
    }
    for (const Eigen::VectorXd* v : {&o.frequency_noise_modes, &o.shape_noise_modes})
      if (v->size() != 0 && v->size() != meas.num_modes())
        throw InputError("fit: " + std::to_string(v->size()) + " per-mode noise levels for " + std::to_string(meas.num_modes()) +
                         " measured modes");
    if (o.shape_noise_entries.size() != 0 &&
        (o.shape_noise_entries.rows() != static_cast<Eigen::Index>(meas.dofs.size()) || o.shape_noise_entries.cols() != meas.num_modes()))
      throw InputError("fit: per-entry shape noise is " + std::to_string(o.shape_noise_entries.rows()) + " x " +
                       std::to_string(o.shape_noise_entries.cols()) + " for " + std::to_string(meas.dofs.size()) + " DOFs x " +
                       std::to_string(meas.num_modes()) + " measured modes");
    if (!o.shape_covariance_factors.empty()) {
      if (o.shape_covariance_factors.size() != static_cast<std::size_t>(meas.num_modes()))
        throw InputError("fit: " + std::to_string(o.shape_covariance_factors.size()) +
                         " shape covariance factors for " + std::to_string(meas.num_modes()) + " measured modes");
      for (const Eigen::MatrixXd& F : o.shape_covariance_factors)
        if (F.cols() > 0 && F.rows() != static_cast<Eigen::Index>(meas.dofs.size()))
          throw InputError("fit: a shape covariance factor has " + std::to_string(F.rows()) + " rows for " +
                           std::to_string(meas.dofs.size()) + " measured DOFs");
    }
    rows_ = measured_equations(pm.model(), meas.dofs);
    const Model& model = pm.model();
    translations_ = translation_equations(model);
    const int n = model.num_dofs();
    bool springs = false;
    for (int p = 0; p < pm.num_parameters(); ++p)  // springs (and custom terms) may tie a free-free model down
      springs = springs || pm.parameter(p).kind == ParameterKind::kSpring || pm.parameter(p).kind == ParameterKind::kCustom;
    EigenOptions& eo = solver_.options();
    // Free-free models: the rigid-body motions are deflated while K leaves them free; springs (and custom terms,
    // e.g. a suspension) may tie them down at some parameters, so each solve checks (solve()).
    if (model.free_free()) rigid_basis_ = model.free_rigid_body_modes();
    may_tie_ = springs;
    eo.rigid_body_basis = rigid_basis_;
    const int p = meas.num_modes();
    const int rigid = static_cast<int>(rigid_basis_.cols());
    int want = rigid + p + o.extra_modes;
    if (o.objective == FitObjective::kSerep) want = std::max(want, static_cast<int>(rows_.size()) + rigid);
    if (n <= o.dense_max_dofs) {  // small model: every mode, dense, exact expansions
      eo.method = EigenOptions::Method::kDense;
      eo.num_modes = n;
      complete_ = true;
    } else {
      eo.method = EigenOptions::Method::kSparse;
      eo.num_modes = std::min(want, n - 1);
    }
    // Measured shapes scaled to a largest entry of 1 (the shape noise is relative to it).
    U_ = meas.shapes;
    for (Eigen::Index k = 0; k < U_.cols(); ++k) U_.col(k) /= U_.col(k).cwiseAbs().maxCoeff();
    lam_meas_.resize(p);
    for (int k = 0; k < p; ++k) lam_meas_[k] = hz_to_eigenvalue(meas.frequencies_hz[k]);
    // Shape residual weights (1 / std; 0 for exact entries) and the weights of the model shape's scale c:
    // weighted least squares (1 / std^2), or, when a mode has exact entries, least squares over those alone
    // (the limit of infinite weight: the scaled model shape matches them).
    const Eigen::Index a = static_cast<Eigen::Index>(rows_.size());
    w_res_.resize(a, p);
    w_scale_.resize(a, p);
    exact_entries_ = 0;
    for (int k = 0; k < p; ++k) {
      if (o.shape_noise_entries.size() == 0) {
        w_res_.col(k).setConstant(1.0 / shape_noise(k));
        w_scale_.col(k).setOnes();
        continue;
      }
      const Eigen::ArrayXd sd = o.shape_noise_entries.col(k).array();
      const bool exact = (sd == 0).any();
      for (Eigen::Index r = 0; r < a; ++r) {
        w_res_(r, k) = sd[r] > 0 ? 1.0 / sd[r] : 0.0;
        w_scale_(r, k) = exact ? (sd[r] == 0 ? 1.0 : 0.0) : 1.0 / (sd[r] * sd[r]);
      }
      exact_entries_ += static_cast<int>((sd == 0).count());
    }
    // The whitening of each mode's shape residual by (I + G G^T)^(-1/2), G = diag(w_res) F (already whitened by
    // the per-entry noise): with G = Q S V^T, r -> r - Q diag(1 - 1 / sqrt(1 + s^2)) Q^T r.
    mix_Q_.assign(static_cast<std::size_t>(p), Eigen::MatrixXd());
    mix_d_.assign(static_cast<std::size_t>(p), Eigen::VectorXd());
    for (int k = 0; k < p && !o.shape_covariance_factors.empty(); ++k) {
      const Eigen::MatrixXd& F = o.shape_covariance_factors[static_cast<std::size_t>(k)];
      if (F.cols() == 0) continue;
      const Eigen::MatrixXd G = w_res_.col(k).asDiagonal() * F;
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeThinU);
      const Eigen::VectorXd& sv = svd.singularValues();
      int keep = 0;
      while (keep < sv.size() && sv[keep] > 1e-6) ++keep;
      if (keep == 0) continue;
      mix_Q_[static_cast<std::size_t>(k)] = svd.matrixU().leftCols(keep);
      mix_d_[static_cast<std::size_t>(k)] = (1.0 - (1.0 + sv.head(keep).array().square()).rsqrt()).matrix();
    }
    m_serep_ = std::min<int>(static_cast<int>(rows_.size()), eo.num_modes);
  }

  // Bounds are enforced by projection: a value outside [lower, upper] is evaluated at the bound (and its
  // derivative is zero there, see jacobians()). Ceres' own bound handling would add a projected line search
  // with a Jacobian evaluation - an eigen-solve and sensitivities - at every step.
  Eigen::VectorXd theta_of(const double* x) const {
    Eigen::VectorXd t = theta0_;
    for (std::size_t k = 0; k < xmap_.size(); ++k)
      for (const auto& [p, c] : xmap_[k]) {
        const Parameter& q = pm_.parameter(p);
        t[p] = std::min(std::max(c * x[k], q.lower), q.upper);
      }
    return t;
  }
  // Whether x_f's value is clamped at a bound (for one of the parameters it drives).
  bool clamped(std::size_t f, double xf) const {
    for (const auto& [p, c] : xmap_[f]) {
      const Parameter& q = pm_.parameter(p);
      if (c * xf < q.lower || c * xf > q.upper) return true;
    }
    return false;
  }
  // Column of dr/dx_f from the parameter columns: sum over the parameters x_f drives.
  template <class Col>
  Eigen::VectorXd xcol(std::size_t f, const Col& col) const {
    Eigen::VectorXd v = xmap_[f][0].second * col(xmap_[f][0].first);
    for (std::size_t q = 1; q < xmap_[f].size(); ++q) v += xmap_[f][q].second * col(xmap_[f][q].first);
    return v;
  }
  int rows_per_mode() const {
    switch (o_.objective) {
      case FitObjective::kCombined: return 1 + static_cast<int>(rows_.size());
      case FitObjective::kSerep: return static_cast<int>(rows_.size());
      default: return 1;
    }
  }
  /// Data values that carry a residual (exact shape entries do not).
  int data_values() const { return meas_.num_modes() * rows_per_mode() - (o_.objective == FitObjective::kCombined ? exact_entries_ : 0); }
  int evaluations() const { return evaluations_; }
  double time_eigen() const { return time_eigen_; }
  double time_sensitivity() const { return time_sens_; }
  const std::vector<int>& rows() const { return rows_; }

  const Evaluation& at(const double* x, bool jacobian) {
    const Eigen::Index nf = static_cast<Eigen::Index>(free_.size());
    const bool same = cached_ && Eigen::Map<const Eigen::VectorXd>(x, nf) == last_x_;
    if (!same) {
      last_x_ = Eigen::Map<const Eigen::VectorXd>(x, nf);
      cached_ = true;
      solve(theta_of(x));
    }
    if (jacobian && ev_.ok && !ev_.has_jacobian) {
      const auto t0 = std::chrono::steady_clock::now();
      jacobians();
      time_sens_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      for (std::size_t f = 0; f < free_.size(); ++f)
        if (clamped(f, x[f]))
          for (auto& J : ev_.J) J.col(static_cast<Eigen::Index>(f)).setZero();
    }
    return ev_;
  }

 private:
  void solve(const Eigen::VectorXd& theta) {
    ev_ = Evaluation{};
    if (sur_) {
      solve_reduced(theta);
      return;
    }
    ++evaluations_;
    const auto t0 = std::chrono::steady_clock::now();
    SparseMatrix& K = K_;
    SparseMatrix& M = M_;
    pm_.matrices(theta, &K, &M);
    if (may_tie_ && rigid_basis_.cols()) {
      // Deflate the rigid-body motions only while K leaves them free (to rounding); else K - sigma M may be
      // singular at the automatic shift, and the motions are low elastic modes on their springs.
      // Free: the motions' highest eigenvalue on K (their Rayleigh quotients, R^T K R against R^T M R) is zero by
      // the solvers' own test (rigid_eigenvalue_limit), which does not depend on the units of the DOFs.
      const Eigen::Index nr = rigid_basis_.cols();
      Eigen::MatrixXd KR(rigid_basis_.rows(), nr), MR(rigid_basis_.rows(), nr);
      for (Eigen::Index c = 0; c < nr; ++c) {
        symmetric_multiply(K, rigid_basis_.col(c).data(), KR.col(c).data());
        symmetric_multiply(M, rigid_basis_.col(c).data(), MR.col(c).data());
      }
      const Eigen::MatrixXd A = rigid_basis_.transpose() * KR, B = rigid_basis_.transpose() * MR;
      const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(
          0.5 * (A + A.transpose()), 0.5 * (B + B.transpose()), Eigen::EigenvaluesOnly);
      const bool free =
          es.info() == Eigen::Success &&
          es.eigenvalues().maxCoeff() <= rigid_eigenvalue_limit(K.diagonal(), M.diagonal(), solver_.options());
      solver_.options().rigid_body_basis = free ? rigid_basis_ : Eigen::MatrixXd();
      solver_.options().allow_singular_stiffness = !free;
    }
    EigenSolution s = solver_.solve(K, M);
    // Every measured mode must be in reach of the pairing: compute modes until the highest measured frequency is
    // exceeded by 10 % (measured modes need not be the lowest ones: sensors miss local modes).
    const double need = hz_to_eigenvalue(1.1 * meas_.frequencies_hz.maxCoeff());
    while (!complete_ && s.summary.ok() && s.eigenvalues.size() > 0 && s.eigenvalues.maxCoeff() < need &&
           solver_.options().num_modes < pm_.model().num_dofs() - 1) {
      solver_.options().num_modes = std::min(pm_.model().num_dofs() - 1, solver_.options().num_modes * 3 / 2 + 10);
      s = solver_.solve(K, M);
    }
    time_eigen_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!s.summary.ok()) {
      ev_.error = s.summary.message;
      return;
    }
    ev_.ms.theta = theta;
    ev_.ms.lambda = s.eigenvalues;
    ev_.ms.Phi = std::move(s.modes);
    ev_.ms.complete = complete_;
    ev_.ms.factor = solver_.factor();
    ev_.ms.sigma = s.summary.shift;
    if (!complete_ && !ev_.ms.factor) {
      ev_.error = "no factorization available for the sensitivities";
      return;
    }
    for (Eigen::Index j = 0; j < ev_.ms.lambda.size(); ++j)
      if (!s.rigid_body[j]) ev_.elastic.push_back(static_cast<int>(j));
    const Eigen::Index a = static_cast<Eigen::Index>(rows_.size()), m = ev_.ms.Phi.cols();
    ev_.Pa.resize(a, m);
    for (Eigen::Index r = 0; r < a; ++r) ev_.Pa.row(r) = ev_.ms.Phi.row(rows_[r]);
    Eigen::VectorXd vis = Eigen::VectorXd::Ones(m);
    if (o_.min_visibility > 0 && !translations_.empty())
      for (int j : ev_.elastic) vis[j] = sensor_visibility(ev_.ms.Phi.col(j), rows_, translations_);
    pair_and_score(vis);
  }

  // Pairs the elastic modes (ev_.elastic, ev_.ms.lambda, ev_.Pa; `vis` their sensor visibility) with the
  // measured ones and fills the residuals.
  void pair_and_score(const Eigen::VectorXd& vis) {
    const Eigen::Index a = static_cast<Eigen::Index>(rows_.size());
    Eigen::MatrixXd Pa(a, static_cast<Eigen::Index>(ev_.elastic.size()));
    Eigen::VectorXd fe(static_cast<Eigen::Index>(ev_.elastic.size()));
    for (std::size_t j = 0; j < ev_.elastic.size(); ++j) {
      Pa.col(static_cast<Eigen::Index>(j)) = ev_.Pa.col(ev_.elastic[j]);
      fe[static_cast<Eigen::Index>(j)] = eigenvalue_to_hz(ev_.ms.lambda[ev_.elastic[j]]);
    }
    Eigen::MatrixXd mac = mac_matrix(meas_.shapes, Pa);
    // Modes the sensors cannot see are no partners: their MAC with a measurement is noise.
    if (o_.min_visibility > 0 && !translations_.empty())
      for (std::size_t j = 0; j < ev_.elastic.size(); ++j)
        if (vis[ev_.elastic[j]] < o_.min_visibility) mac.col(static_cast<Eigen::Index>(j)).setZero();
    const Pairing pr = pair_modes(mac, meas_.frequencies_hz, fe, o_.min_mac, o_.max_frequency_ratio);
    const int p = meas_.num_modes();
    ev_.pair.assign(p, -1);
    ev_.forced.assign(p, 0);
    std::vector<char> used(ev_.elastic.size(), 0);
    for (const ModePair& q : pr.pairs) {
      ev_.pair[q.a] = ev_.elastic[q.b];
      used[q.b] = 1;
    }
    // Unpaired (no MAC >= min_mac left): the remaining mode with the best MAC less a frequency-distance penalty
    // |ln(f_model / f_measured)| (at most 1.5), flagged. MAC alone would reach for any mode of the complete
    // basis, however far in frequency, whose shape happens to correlate a little.
    auto forced_score = [&](int k, std::size_t j) {
      const double r = std::abs(std::log(std::max(fe[static_cast<Eigen::Index>(j)], 1e-300) / meas_.frequencies_hz[k]));
      return mac(k, static_cast<Eigen::Index>(j)) - std::min(1.5, r);
    };
    for (int k = 0; k < p; ++k) {
      if (ev_.pair[k] >= 0) continue;
      int best = -1;
      for (std::size_t j = 0; j < ev_.elastic.size(); ++j)
        if (!used[j] && (best < 0 || forced_score(k, j) > forced_score(k, static_cast<std::size_t>(best)))) best = static_cast<int>(j);
      if (best < 0) {
        ev_.error = "measured mode " + std::to_string(k + 1) + " has no model mode left to pair with";
        return;
      }
      used[best] = 1;
      ev_.pair[k] = ev_.elastic[best];
      ev_.forced[k] = 1;
    }
    ev_.mac.resize(p);
    for (int k = 0; k < p; ++k) {
      int j = 0;
      while (ev_.elastic[j] != ev_.pair[k]) ++j;
      ev_.mac[k] = mac(k, j);
    }
    residuals();
    ev_.ok = true;
  }

  double frequency_noise(int k) const {
    return o_.frequency_noise_modes.size() == meas_.num_modes() ? o_.frequency_noise_modes[k] : o_.frequency_noise;
  }
  double shape_noise(int k) const {
    if (o_.shape_noise_entries.cols() == meas_.num_modes()) {  // f2: the RMS of the mode's inexact entries
      const Eigen::ArrayXd sd = o_.shape_noise_entries.col(k).array();
      return std::sqrt((sd * sd).sum() / static_cast<double>((sd > 0).count()));
    }
    return o_.shape_noise_modes.size() == meas_.num_modes() ? o_.shape_noise_modes[k] : o_.shape_noise;
  }
  double sigma_lambda(int k) const { return 2.0 * frequency_noise(k) * lam_meas_[k]; }

  void residuals() {
    const int p = meas_.num_modes();
    const Eigen::Index a = static_cast<Eigen::Index>(rows_.size());
    ev_.r.assign(p, Eigen::VectorXd());
    if (o_.objective == FitObjective::kSerep) {
      serep_prepare();
      for (int k = 0; k < p; ++k) {
        const Eigen::VectorXd x = Ps_ * U_.col(k);
        const Eigen::VectorXd r = Ps_.transpose() * ((lam_m_.array() - lam_meas_[k]).matrix().cwiseProduct(x));
        if (serep_scale_.size() != p) serep_scale_.resize(p);
        if (!serep_scaled_) serep_scale_[k] = lam_meas_[k] * (Ps_.transpose() * (Ps_ * U_.col(k))).norm() * shape_noise(k);
        ev_.r[k] = r / serep_scale_[k];
      }
      serep_scaled_ = true;
      return;
    }
    for (int k = 0; k < p; ++k) {
      const int i = ev_.pair[k];
      const double li = ev_.ms.lambda[i];
      double rf = (li - lam_meas_[k]) / sigma_lambda(k);
      if (o_.objective == FitObjective::kFrequencyMac) rf /= std::max(ev_.mac[k], 1e-3);
      if (o_.objective != FitObjective::kCombined) {
        ev_.r[k] = Eigen::VectorXd::Constant(1, rf);
        continue;
      }
      const Eigen::VectorXd v = ev_.Pa.col(i);
      const double c = shape_scale(k, v);
      ev_.r[k].resize(1 + a);
      ev_.r[k][0] = rf;
      ev_.r[k].tail(a) = w_res_.col(k).cwiseProduct(c * v - U_.col(k));
      unmix(k, ev_.r[k].tail(a));
    }
  }

  // Whitens measured mode k's (noise-whitened) shape residuals, or their derivative, by the covariance of its
  // shape_covariance_factors (identity when it has none).
  template <class V>
  void unmix(int k, V&& x) const {
    const Eigen::MatrixXd& Q = mix_Q_[static_cast<std::size_t>(k)];
    if (Q.cols() == 0) return;
    x -= Q * mix_d_[static_cast<std::size_t>(k)].cwiseProduct(Q.transpose() * x);
  }

  // The scale c of model shape v that best matches measured mode k (weighted least squares, see w_scale_).
  double shape_scale(int k, const Eigen::VectorXd& v) const {
    return w_scale_.col(k).cwiseProduct(U_.col(k)).dot(v) / w_scale_.col(k).cwiseProduct(v).dot(v);
  }

  // SEREP of the current model to the measured DOFs with the lowest m modes: P = Phi_a^+ (m x a).
  void serep_prepare() {
    const Eigen::Index a = static_cast<Eigen::Index>(rows_.size()), m = m_serep_;
    Phi_a_.resize(a, m);
    lam_m_.resize(m);
    for (Eigen::Index j = 0; j < m; ++j) {
      lam_m_[j] = ev_.ms.lambda[j];
      for (Eigen::Index r = 0; r < a; ++r) Phi_a_(r, j) = ev_.ms.Phi(rows_[r], j);
    }
    G_ = (Phi_a_.transpose() * Phi_a_).inverse();
    Ps_ = G_ * Phi_a_.transpose();
  }

  void jacobians() {
    const int p = meas_.num_modes();
    const Eigen::Index nf = static_cast<Eigen::Index>(free_.size());
    const Eigen::Index a = static_cast<Eigen::Index>(rows_.size());
    ev_.J.assign(p, Eigen::MatrixXd());
    if (o_.objective == FitObjective::kSerep) {
      const Eigen::Index m = m_serep_;
      std::vector<int> modes(static_cast<std::size_t>(m));
      for (Eigen::Index j = 0; j < m; ++j) modes[j] = static_cast<int>(j);
      const Eigen::MatrixXd dlam = eigenvalue_derivatives(pm_, ev_.ms, modes);          // m x P
      const std::vector<Eigen::MatrixXd> dphi = shape_derivatives(pm_, ev_.ms, modes, rows_);  // m of (a x P)
      for (int k = 0; k < p; ++k) {
        const Eigen::VectorXd u = U_.col(k);
        const Eigen::VectorXd x = Ps_ * u;
        const Eigen::VectorXd lx = (lam_m_.array() - lam_meas_[k]).matrix().cwiseProduct(x);
        Eigen::MatrixXd Jk(a, nf);
        auto col = [&](int q) -> Eigen::VectorXd {
          Eigen::MatrixXd dPa(a, m);
          for (Eigen::Index j = 0; j < m; ++j) dPa.col(j) = dphi[j].col(q);
          // d(Phi_a^+) for full column rank: -P dPa P + G dPa^T (I - Phi_a P).
          const Eigen::MatrixXd dP = -Ps_ * dPa * Ps_ + G_ * dPa.transpose() * (Eigen::MatrixXd::Identity(a, a) - Phi_a_ * Ps_);
          const Eigen::VectorXd dx = dP * u;
          const Eigen::VectorXd dl = dlam.col(q);
          const Eigen::VectorXd dr = dP.transpose() * lx + Ps_.transpose() * (dl.cwiseProduct(x) + (lam_m_.array() - lam_meas_[k]).matrix().cwiseProduct(dx));
          return dr / serep_scale_[k];
        };
        for (Eigen::Index f = 0; f < nf; ++f) Jk.col(f) = xcol(static_cast<std::size_t>(f), col);
        ev_.J[k] = Jk;
      }
      ev_.has_jacobian = true;
      return;
    }
    std::vector<int> modes(ev_.pair.begin(), ev_.pair.end());
    Eigen::MatrixXd dlam;
    std::vector<Eigen::MatrixXd> dphi;
    const bool shapes = o_.objective == FitObjective::kCombined;
    if (sur_) {
      reduced_derivatives(modes, &dlam, shapes ? &dphi : nullptr);
    } else {
      dlam = eigenvalue_derivatives(pm_, ev_.ms, modes);
      if (shapes) dphi = shape_derivatives(pm_, ev_.ms, modes, rows_);
    }
    for (int k = 0; k < p; ++k) {
      double w = 1.0 / sigma_lambda(k);
      if (o_.objective == FitObjective::kFrequencyMac) w /= std::max(ev_.mac[k], 1e-3);
      Eigen::MatrixXd Jk(rows_per_mode(), nf);
      Eigen::VectorXd v(a), wv, wu;
      double vv = 1, c = 0;
      if (o_.objective == FitObjective::kCombined) {
        v = ev_.Pa.col(ev_.pair[k]);
        wv = w_scale_.col(k).cwiseProduct(v);
        wu = w_scale_.col(k).cwiseProduct(U_.col(k));
        vv = wv.dot(v);
        c = wu.dot(v) / vv;
      }
      auto col = [&](int q) -> Eigen::VectorXd {
        Eigen::VectorXd out(rows_per_mode());
        out[0] = dlam(k, q) * w;
        if (o_.objective == FitObjective::kCombined) {  // c = (u' W v) / (v' W v)
          const Eigen::VectorXd dv = dphi[k].col(q);
          const double dc = wu.dot(dv) / vv - 2.0 * c * wv.dot(dv) / vv;
          out.tail(a) = w_res_.col(k).cwiseProduct(dc * v + c * dv);
          unmix(k, out.tail(a));
        }
        return out;
      };
      for (Eigen::Index f = 0; f < nf; ++f) Jk.col(f) = xcol(static_cast<std::size_t>(f), col);
      ev_.J[k] = Jk;
      if (sur_ && sur_->corrected) ev_.J[k] += sur_->C1[static_cast<std::size_t>(k)];
    }
    ev_.has_jacobian = true;
  }

  // The reduced-basis surrogate (FitOptions::reduced_basis) about an expansion point theta_e: the model on the
  // basis V (the full model's modes there and one block of shift-invert Krylov vectors, M-orthonormal),
  //   K_r(theta) = V^T K(theta_e) V + sum_p (theta_p - theta_e,p) V^T dK_p V   (the same for M),
  // whose eigenpairs give frequencies and, through V's measured rows, shapes; plus the full residuals and
  // Jacobian at theta_e less the surrogate's own there (c0, C1), so that it matches the full model to first order.
  struct Surrogate {
    Eigen::VectorXd x, theta;  // the expansion point
    Eigen::MatrixXd Kr, Mr;
    std::vector<int> params;              // the parameters the free variables drive
    std::vector<Eigen::MatrixXd> dK, dM;  // per parameter (empty for the others)
    Eigen::MatrixXd Va;                   // V at the measured rows
    Eigen::MatrixXd Gt;                   // V_t^T V_t over the translational DOFs (visibility)
    std::vector<Eigen::VectorXd> c0;
    std::vector<Eigen::MatrixXd> C1;
    bool corrected = false;
  };

 public:
  // Whether the reduced-basis surrogate can stand in for this model (sparse, no rigid-body motions, not f2).
  bool reduced_basis_applies() const {
    return !complete_ && rigid_basis_.cols() == 0 && o_.objective != FitObjective::kSerep;
  }
  int basis_size() const { return sur_ ? static_cast<int>(sur_->Kr.rows()) : 0; }
  int surrogate_evaluations() const { return surrogate_evaluations_; }

  // Builds the surrogate about `full`'s current evaluation (at the variables x, with its Jacobian). False when
  // the surrogate's pairing there differs from the full model's (it cannot be corrected consistently).
  bool expand(const Evaluator& full, const double* x) {
    const Evaluation& F = full.ev_;
    const ModalState& ms = F.ms;
    const Eigen::Index n = ms.Phi.rows(), m = ms.Phi.cols();
    const SparseMatrix& K = full.K_;
    const SparseMatrix& M = full.M_;
    auto times = [&](const SparseMatrix& A, const Eigen::MatrixXd& X) {
      Eigen::MatrixXd Y(X.rows(), X.cols());
#pragma omp parallel for schedule(static)
      for (Eigen::Index c = 0; c < X.cols(); ++c) symmetric_multiply(A, X.col(c).data(), Y.col(c).data());
      return Y;
    };
    // Z = (K - sigma M)^{-1} M Phi, M-orthogonalised against Phi (twice) and orthonormalised in M.
    const Eigen::MatrixXd MPhi = times(M, ms.Phi);
    Eigen::MatrixXd Z;
    ms.factor->solve_block(MPhi, &Z);
    for (int pass = 0; pass < 2; ++pass) Z -= ms.Phi * (MPhi.transpose() * Z);
    {
      const Eigen::MatrixXd G = Z.transpose() * times(M, Z);
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (G + G.transpose()));
      const Eigen::VectorXd& d = es.eigenvalues();
      std::vector<Eigen::Index> keep;
      for (Eigen::Index j = 0; j < d.size(); ++j)
        if (d[j] > 1e-12 * d.maxCoeff()) keep.push_back(j);
      Eigen::MatrixXd Q(m, static_cast<Eigen::Index>(keep.size()));
      for (std::size_t j = 0; j < keep.size(); ++j)
        Q.col(static_cast<Eigen::Index>(j)) = es.eigenvectors().col(keep[j]) / std::sqrt(d[keep[j]]);
      Z = Z * Q;
    }
    const Eigen::Index r = m + Z.cols();
    Eigen::MatrixXd V(n, r);
    V << ms.Phi, Z;
    Z.resize(0, 0);
    auto sur = std::make_unique<Surrogate>();
    sur->theta = ms.theta;
    sur->x = Eigen::Map<const Eigen::VectorXd>(x, static_cast<Eigen::Index>(free_.size()));
    sur->Kr = V.transpose() * times(K, V);
    sur->Mr = V.transpose() * times(M, V);
    sur->Kr = 0.5 * (sur->Kr + sur->Kr.transpose()).eval();
    sur->Mr = 0.5 * (sur->Mr + sur->Mr.transpose()).eval();
    const Eigen::Index a = static_cast<Eigen::Index>(rows_.size());
    sur->Va.resize(a, r);
    for (Eigen::Index i = 0; i < a; ++i) sur->Va.row(i) = V.row(rows_[i]);
    sur->Gt = Eigen::MatrixXd::Zero(r, r);
    if (!translations_.empty()) {
      Eigen::MatrixXd Vt(static_cast<Eigen::Index>(translations_.size()), r);
      for (std::size_t i = 0; i < translations_.size(); ++i)
        Vt.row(static_cast<Eigen::Index>(i)) = V.row(translations_[i]);
      sur->Gt = Vt.transpose() * Vt;
    }
    std::vector<char> driven(static_cast<std::size_t>(pm_.num_parameters()), 0);
    for (const auto& xm : xmap_)
      for (const auto& pc : xm) driven[pc.first] = 1;
    for (int p = 0; p < pm_.num_parameters(); ++p)
      if (driven[p]) sur->params.push_back(p);
    sur->dK.assign(driven.size(), Eigen::MatrixXd());
    sur->dM.assign(driven.size(), Eigen::MatrixXd());
    const int np = static_cast<int>(sur->params.size());
    const ParametricModel::RowMatrix VR = V;
    V.resize(0, 0);
#pragma omp parallel for schedule(dynamic)
    for (int q = 0; q < np; ++q) {
      const int p = sur->params[q];
      Eigen::MatrixXd dK, dM;
      pm_.projected_derivatives(p, ms.theta, VR, &dK, &dM);
      sur->dK[p] = 0.5 * (dK + dK.transpose());
      sur->dM[p] = 0.5 * (dM + dM.transpose());
    }
    sur_ = std::move(sur);
    // The corrections: the full model's residuals and Jacobian less the surrogate's own at x.
    cached_ = false;
    const Evaluation& S = at(x, true);
    if (!S.ok || S.pair != F.pair) {
      sur_.reset();
      cached_ = false;
      return false;
    }
    sur_->c0.resize(F.r.size());
    sur_->C1.resize(F.J.size());
    for (std::size_t k = 0; k < F.r.size(); ++k) {
      sur_->c0[k] = F.r[k] - S.r[k];
      sur_->C1[k] = F.J[k] - S.J[k];
    }
    sur_->corrected = true;
    cached_ = false;
    return true;
  }

 private:
  void solve_reduced(const Eigen::VectorXd& theta) {
    ++surrogate_evaluations_;
    const Surrogate& S = *sur_;
    Eigen::MatrixXd Kr = S.Kr, Mr = S.Mr;
    for (int p : S.params) {
      const double d = theta[p] - S.theta[p];
      if (d == 0) continue;
      Kr += d * S.dK[p];
      Mr += d * S.dM[p];
    }
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Kr, Mr);
    if (es.info() != Eigen::Success) {
      ev_.error = "the reduced model's mass matrix is not positive definite at these parameters";
      return;
    }
    ev_.ms.theta = theta;
    ev_.ms.lambda = es.eigenvalues();
    ev_.Y = es.eigenvectors();
    ev_.Pa = S.Va * ev_.Y;
    const Eigen::Index m = ev_.Y.cols();
    for (Eigen::Index j = 0; j < m; ++j) ev_.elastic.push_back(static_cast<int>(j));
    Eigen::VectorXd vis = Eigen::VectorXd::Ones(m);
    if (o_.min_visibility > 0 && !translations_.empty())
      for (Eigen::Index j = 0; j < m; ++j) {
        const double all = ev_.Y.col(j).dot(S.Gt * ev_.Y.col(j)) / static_cast<double>(translations_.size());
        const double seen = ev_.Pa.col(j).squaredNorm() / static_cast<double>(rows_.size());
        vis[j] = rows_.empty() || !(all > 0) ? 0.0 : seen / all;
      }
    pair_and_score(vis);
    if (ev_.ok && S.corrected) {
      const Eigen::VectorXd dx = last_x_ - S.x;
      for (std::size_t k = 0; k < ev_.r.size(); ++k) ev_.r[k] += S.c0[k] + S.C1[k] * dx;
    }
  }

  // The surrogate's eigenvalue derivatives (modes x parameters) and shape derivatives at the measured rows (one
  // a x parameters matrix per mode): exact for the reduced model, whose modal basis is complete.
  void reduced_derivatives(const std::vector<int>& modes, Eigen::MatrixXd* dlam,
                           std::vector<Eigen::MatrixXd>* dphi) const {
    const Surrogate& S = *sur_;
    const Eigen::MatrixXd& Y = ev_.Y;
    const Eigen::VectorXd& lam = ev_.ms.lambda;
    const Eigen::Index r = Y.cols(), a = ev_.Pa.rows();
    const Eigen::Index nm = static_cast<Eigen::Index>(modes.size());
    const int P = pm_.num_parameters();
    Eigen::MatrixXd Yp(r, nm);
    for (Eigen::Index k = 0; k < nm; ++k) Yp.col(k) = Y.col(modes[k]);
    *dlam = Eigen::MatrixXd::Zero(nm, P);
    if (dphi) dphi->assign(modes.size(), Eigen::MatrixXd::Zero(a, P));
    const int np = static_cast<int>(S.params.size());
#pragma omp parallel for schedule(dynamic)
    for (int q = 0; q < np; ++q) {
      const int p = S.params[q];
      const Eigen::MatrixXd Dk = Y.transpose() * (S.dK[p] * Yp), Dm = Y.transpose() * (S.dM[p] * Yp);
      Eigen::VectorXd c(r);
      for (Eigen::Index k = 0; k < nm; ++k) {
        const int i = modes[k];
        const double li = lam[i];
        (*dlam)(k, p) = Dk(i, k) - li * Dm(i, k);
        if (!dphi) continue;
        for (Eigen::Index j = 0; j < r; ++j) {
          const double gap = li - lam[j];
          c[j] =
              j == i || std::abs(gap) < 1e-9 * std::max(std::abs(li), 1e-300) ? 0.0 : (Dk(j, k) - li * Dm(j, k)) / gap;
        }
        c[i] = -0.5 * Dm(i, k);
        (*dphi)[static_cast<std::size_t>(k)].col(p) = ev_.Pa * c;
      }
    }
  }

  const ParametricModel& pm_;
  const ModalData& meas_;
  Eigen::VectorXd theta0_;
  std::vector<int> free_;
  std::vector<std::vector<std::pair<int, double>>> xmap_;  // x_k -> (parameter, coefficient)
  FitOptions o_;
  EigenSolver solver_;
  std::vector<int> rows_;
  std::vector<int> translations_;  // free translational equations (visibility of model modes)
  Eigen::MatrixXd rigid_basis_;     // free-free models: the rigid-body motions
  bool may_tie_ = false;            // springs or custom terms may tie the rigid-body motions down
  bool complete_ = false;
  Eigen::MatrixXd U_;
  Eigen::MatrixXd w_res_, w_scale_;  // per shape entry and mode: residual weight, weight in the scale c
  std::vector<Eigen::MatrixXd> mix_Q_;  // per mode: the whitened shape covariance factors' directions ...
  std::vector<Eigen::VectorXd> mix_d_;  // ... and how much of the residual along each is removed
  int exact_entries_ = 0;            // shape entries with std 0 (no residual)
  Eigen::VectorXd lam_meas_;
  int m_serep_ = 0;
  Eigen::MatrixXd Phi_a_, G_, Ps_;
  Eigen::VectorXd lam_m_, serep_scale_;
  bool serep_scaled_ = false;
  Eigen::VectorXd last_x_;
  bool cached_ = false;
  Evaluation ev_;
  SparseMatrix K_, M_;              // K(theta), M(theta) of the last full evaluation
  std::unique_ptr<Surrogate> sur_;  // set: evaluations are the surrogate's
  int surrogate_evaluations_ = 0;
  int evaluations_ = 0;
  double time_eigen_ = 0, time_sens_ = 0;
};

// Rows [first, first + count) of measured mode k's residual block (its frequency, or its shape), so that a
// robust loss acts on each separately: a bad frequency does not silence a good shape.
class ModeCost : public ceres::CostFunction {
 public:
  ModeCost(std::shared_ptr<Evaluator> ev, int k, int first, int count, int nfree)
      : ev_(std::move(ev)), k_(k), first_(first) {
    set_num_residuals(count);
    mutable_parameter_block_sizes()->push_back(nfree);
  }
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    const bool want = jacobians != nullptr && jacobians[0] != nullptr;
    const Evaluation& e = ev_->at(params[0], want);
    if (!e.ok) return false;
    Eigen::Map<Eigen::VectorXd>(residuals, num_residuals()) = e.r[k_].segment(first_, num_residuals());
    if (want) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          jacobians[0], num_residuals(), parameter_block_sizes()[0]) = e.J[k_].middleRows(first_, num_residuals());
    }
    return true;
  }

 private:
  std::shared_ptr<Evaluator> ev_;
  int k_, first_;
};

// Tikhonov regularisation toward the nominal values: sqrt(w) (theta_p - nominal_p) / scale_p, at the projected
// value as the data see it (beyond a bound: the bound, and no derivative). On the raw variable the prior would
// pull back a variable the data push beyond its bound, a kink at the bound on which the trust region zigzags.
class PriorCost : public ceres::CostFunction {
 public:
  PriorCost(Eigen::VectorXd nominal, Eigen::VectorXd weight, Eigen::VectorXd lower, Eigen::VectorXd upper)
      : nominal_(std::move(nominal)), w_(std::move(weight)), lower_(std::move(lower)), upper_(std::move(upper)) {
    set_num_residuals(static_cast<int>(nominal_.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(nominal_.size()));
  }
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override {
    const Eigen::Index n = nominal_.size();
    for (Eigen::Index i = 0; i < n; ++i)
      residuals[i] = w_[i] * (std::min(std::max(params[0][i], lower_[i]), upper_[i]) - nominal_[i]);
    if (jacobians && jacobians[0]) {
      std::fill(jacobians[0], jacobians[0] + n * n, 0.0);
      for (Eigen::Index i = 0; i < n; ++i)
        jacobians[0][i * n + i] = params[0][i] < lower_[i] || params[0][i] > upper_[i] ? 0.0 : w_[i];
    }
    return true;
  }

 private:
  Eigen::VectorXd nominal_, w_, lower_, upper_;
};

class CostRecorder : public ceres::IterationCallback {
 public:
  explicit CostRecorder(std::vector<double>* h) : h_(h) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    h_->push_back(s.cost);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  std::vector<double>* h_;
};

Eigen::VectorXd paired_hz(const Evaluation& e) {
  Eigen::VectorXd f(static_cast<Eigen::Index>(e.pair.size()));
  for (std::size_t k = 0; k < e.pair.size(); ++k) f[static_cast<Eigen::Index>(k)] = eigenvalue_to_hz(e.ms.lambda[e.pair[k]]);
  return f;
}

}  // namespace

MeasuredNoise measured_noise(const ModalData& d, const FitOptions& options) {
  MeasuredNoise m;
  m.options = options;
  FitOptions& o = m.options;
  const int p = d.num_modes();
  auto pct = [](double v) {
    std::ostringstream s;
    s << 100 * v;
    return s.str();
  };
  if (d.frequency_std_hz.size() == p && p > 0 && (d.frequency_std_hz.array() > 0).all()) {
    o.frequency_noise_modes = d.frequency_std_hz.cwiseQuotient(d.frequencies_hz);
    m.frequency = true;
  } else {
    m.warnings.push_back("the measured data carry no frequency standard deviations (or a zero one): the stated frequency "
                         "noise applies (" + pct(o.frequency_noise) + " % for every mode)");
  }
  if (d.shape_entry_std.cols() == p && d.shape_entry_std.rows() == d.shapes.rows() && p > 0) {
    o.shape_noise_entries = d.shape_entry_std;
    for (int k = 0; k < p; ++k) o.shape_noise_entries.col(k) /= d.shapes.col(k).cwiseAbs().maxCoeff();
    o.shape_noise_modes.resize(0);
    m.shape = true;
  } else if (d.shape_std.size() == p && p > 0 && (d.shape_std.array() > 0).all()) {
    o.shape_noise_modes = d.shape_std;
    m.shape = true;
  } else {
    m.warnings.push_back("the measured data carry no shape standard deviations: the stated shape noise applies (" +
                         pct(o.shape_noise) + " % of each mode's largest entry, for every entry)");
  }
  return m;
}

namespace internal {

std::vector<int> free_parameters(const ParametricModel& pm, const std::vector<char>& is_free, const FitOptions& o) {
  if (!is_free.empty() && static_cast<int>(is_free.size()) != pm.num_parameters())
    throw InputError("fit: free-parameter mask has the wrong size");
  std::vector<char> tied(static_cast<std::size_t>(pm.num_parameters()), 0);
  for (const auto& [p, t] : o.ties) {
    if (p < 0 || p >= pm.num_parameters() || t.first < 0 || t.first >= pm.num_parameters() || p == t.first)
      throw InputError("fit: invalid tie between parameters " + std::to_string(p) + " and " + std::to_string(t.first));
    tied[p] = 1;
  }
  for (const auto& [p, t] : o.ties)
    if (tied[t.first])
      throw InputError("fit: parameter '" + pm.parameter(p).name + "' is tied to '" + pm.parameter(t.first).name +
                       "', which is itself tied; tie both to the same free parameter");
  std::vector<int> free;
  for (int p = 0; p < pm.num_parameters(); ++p)
    if ((is_free.empty() || is_free[p]) && !tied[p]) free.push_back(p);
  return free;
}

}  // namespace internal

namespace {

// The inputs' checks; the free parameters (not fixed by is_free, not tied).
std::vector<int> check_fit_input(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta0,
                                 const std::vector<char>& is_free, const FitOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("fit options: " + why);
  measured.validate("measured modal data");
  if (theta0.size() != pm.num_parameters())
    throw InputError("fit: " + std::to_string(theta0.size()) + " start values for " + std::to_string(pm.num_parameters()) + " parameters");
  std::vector<int> free = internal::free_parameters(pm, is_free, o);
  if (free.empty()) throw InputError("fit: no free parameters");
  for (int p = 0; p < pm.num_parameters(); ++p) {
    const Parameter& q = pm.parameter(p);
    if (!(theta0[p] >= q.lower && theta0[p] <= q.upper))
      throw InputError("fit: start value of parameter '" + q.name + "' is outside its bounds");
  }
  return free;
}

// The least-squares problem on x (the free parameters): one residual block per mode (two for the combined
// objective: frequency and shape), each with the chosen loss, and the prior toward the nominal values.
void add_cost(ceres::Problem* problem, const std::shared_ptr<Evaluator>& ev, const ParametricModel& pm,
              const std::vector<int>& free, int modes, const FitOptions& o, double* x) {
  const int nf = static_cast<int>(free.size());
  auto make_loss = [&]() -> ceres::LossFunction* {
    const double s2 = o.loss_scale * o.loss_scale;
    if (o.loss == FitOptions::Loss::kHuber) return new ceres::HuberLoss(s2);
    if (o.loss == FitOptions::Loss::kCauchy) return new ceres::CauchyLoss(s2);
    return nullptr;
  };
  const int rows = ev->rows_per_mode();
  for (int k = 0; k < modes; ++k) {
    if (o.objective == FitObjective::kCombined) {  // frequency and shape as separate blocks
      problem->AddResidualBlock(new ModeCost(ev, k, 0, 1, nf), make_loss(), x);
      problem->AddResidualBlock(new ModeCost(ev, k, 1, rows - 1, nf), make_loss(), x);
    } else {
      problem->AddResidualBlock(new ModeCost(ev, k, 0, rows, nf), make_loss(), x);
    }
  }
  if (o.regularization > 0) {
    Eigen::VectorXd nom(nf), w(nf), lo(nf), hi(nf);
    for (int k = 0; k < nf; ++k) {
      const Parameter& q = pm.parameter(free[k]);
      nom[k] = q.nominal;
      w[k] = std::sqrt(o.regularization) / q.scale;
      lo[k] = q.lower;
      hi[k] = q.upper;
    }
    problem->AddResidualBlock(new PriorCost(nom, w, lo, hi), nullptr, x);
  }
}

ceres::Solver::Options solver_options(const FitOptions& o) {
  ceres::Solver::Options so;
  so.trust_region_strategy_type = o.dogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = o.max_iterations;
  so.function_tolerance = o.function_tolerance;
  so.parameter_tolerance = o.parameter_tolerance;
  so.gradient_tolerance = o.gradient_tolerance;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.num_threads = 1;
  return so;
}

// Covariance from the final Jacobian (whitened residuals): (J^T J)^+ by SVD; rank, information matrices and the
// standard deviations of the estimable parameters into `out`.
void estimate_covariance(const Evaluation& ef, const ParametricModel& pm, const std::vector<int>& free,
                         const FitOptions& o, FitSummary* out_ptr) {
  FitSummary& out = *out_ptr;
  const int nf = static_cast<int>(free.size());
  out.stddev = Eigen::VectorXd::Constant(pm.num_parameters(), std::numeric_limits<double>::quiet_NaN());
  {
    Eigen::Index rows = 0;
    for (const auto& J : ef.J) rows += J.rows();
    Eigen::MatrixXd J(rows + (o.regularization > 0 ? nf : 0), nf);
    Eigen::Index r0 = 0;
    for (const auto& Jk : ef.J) {
      J.middleRows(r0, Jk.rows()) = Jk;
      r0 += Jk.rows();
    }
    if (o.regularization > 0)
      for (int k = 0; k < nf; ++k) {
        J.row(r0 + k).setZero();
        J(r0 + k, k) = std::sqrt(o.regularization) / pm.parameter(free[k]).scale;
      }
    out.information = J.topRows(rows).transpose() * J.topRows(rows);
    out.information_frequency = Eigen::MatrixXd::Zero(nf, nf);
    if (o.objective != FitObjective::kSerep)
      for (const auto& Jk : ef.J) out.information_frequency += Jk.row(0).transpose() * Jk.row(0);
    // Full V: its columns beyond the numerical rank span the null space of J (directions the data do not see).
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
    const Eigen::VectorXd& sv = svd.singularValues();
    const double tol = 1e-8 * (sv.size() ? sv[0] : 0.0);
    Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(nf);
    for (Eigen::Index i = 0; i < sv.size(); ++i)
      if (sv[i] > tol) {
        inv2[i] = 1.0 / (sv[i] * sv[i]);
        ++out.covariance_rank;
      }
    if (o.covariance) {
      const Eigen::MatrixXd& V = svd.matrixV();
      const Eigen::MatrixXd C = V * inv2.asDiagonal() * V.transpose();
      out.covariance_ok = out.covariance_rank == nf;
      for (int k = 0; k < nf; ++k) {
        // A parameter is estimable when it has no component in the null space of J.
        double in_null = 0;
        for (Eigen::Index i = out.covariance_rank; i < nf; ++i) in_null += V(k, i) * V(k, i);
        if (in_null < 1e-6) out.stddev[free[k]] = std::sqrt(C(k, k));
      }
    }
    for (const auto& [p, t] : o.ties)
      if (!std::isnan(out.stddev[t.first])) out.stddev[p] = std::abs(t.second) * out.stddev[t.first];
    if (out.covariance_rank < nf)
      out.warnings.push_back("the data determine only " + std::to_string(out.covariance_rank) + " of the " +
                             std::to_string(nf) + " free parameters (J^T J is rank-deficient): the others trade off "
                             "against each other; fix or tie parameters, or add modes or DOFs");
  }
}

// The reduced-basis fit (FitOptions::reduced_basis): outer trust-region steps on the full model, each the
// minimum of a first-order consistent surrogate (Evaluator::expand) within a box of half-width `radius` (in
// units of the parameters' scales) about the current point. A step is taken when the full model's cost falls by
// at least a tenth of what the surrogate predicted; the radius then grows (good prediction at the box's edge) or
// shrinks (poor prediction, rejected step). Stops when the surrogate, which matches the full cost and gradient at
// the current point, predicts no decrease beyond function_tolerance, or when a step is too small to matter.
// `x` (the full problem's variables) holds the start and returns the result; false if the surrogate could not be
// built (at the start, or after a step, with a warning): the caller then runs the direct fit from `x`.
bool reduced_basis_fit(ceres::Problem* full_problem, Evaluator* full, const ParametricModel& pm,
                       const ModalData& measured, const Eigen::VectorXd& theta0, const std::vector<int>& free,
                       const FitOptions& o, std::vector<double>* x, FitSummary* out) {
  const int nf = static_cast<int>(free.size());
  auto sur = std::make_shared<Evaluator>(pm, measured, theta0, free, o);
  if (!full->at(x->data(), true).ok) return false;
  const auto t0 = std::chrono::steady_clock::now();
  if (!sur->expand(*full, x->data())) return false;
  out->time_surrogate += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<double> xs(*x);
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem inner(po);
  add_cost(&inner, sur, pm, free, measured.num_modes(), o, xs.data());
  auto cost = [&]() {
    double c = 0;
    return full_problem->Evaluate(ceres::Problem::EvaluateOptions(), &c, nullptr, nullptr, nullptr)
               ? c
               : std::numeric_limits<double>::infinity();
  };
  ceres::Solver::Options so = solver_options(o);
  so.max_num_iterations = 200;
  double f = cost();
  out->initial_cost = f;
  out->cost_history.push_back(f);
  double radius = 1.0;
  out->termination = "NO_CONVERGENCE";
  bool expanded = true;
  std::ostringstream log;
  log << "reduced-basis fit: outer step, surrogate iterations, predicted and actual cost change, radius\n";
  for (int step = 0; step < o.max_iterations;) {
    const auto te = std::chrono::steady_clock::now();
    if (!expanded && !sur->expand(*full, x->data())) {
      out->warnings.push_back("the reduced-basis surrogate could not be built after step " + std::to_string(step) +
                              " (it pairs the modes differently from the full model there): the direct fit "
                              "continued from that point");
      return false;
    }
    expanded = true;
    out->time_surrogate += std::chrono::duration<double>(std::chrono::steady_clock::now() - te).count();
    const auto ti = std::chrono::steady_clock::now();
    xs = *x;
    for (int k = 0; k < nf; ++k) {
      const Parameter& q = pm.parameter(free[k]);
      inner.SetParameterLowerBound(xs.data(), k, std::max(q.lower, (*x)[k] - radius * q.scale));
      inner.SetParameterUpperBound(xs.data(), k, std::min(q.upper, (*x)[k] + radius * q.scale));
    }
    ceres::Solver::Summary ss;
    ceres::Solve(so, &inner, &ss);
    out->time_surrogate += std::chrono::duration<double>(std::chrono::steady_clock::now() - ti).count();
    out->surrogate_iterations += static_cast<int>(ss.iterations.size()) - 1;
    const double predicted = ss.initial_cost - ss.final_cost;
    double moved = 0;  // the step's largest change in units of the scales
    for (int k = 0; k < nf; ++k) moved = std::max(moved, std::abs(xs[k] - (*x)[k]) / pm.parameter(free[k]).scale);
    if (!(predicted > o.function_tolerance * f) || moved < o.parameter_tolerance) {
      out->termination = "CONVERGENCE";
      log << "  the surrogate predicts " << predicted << ": converged\n";
      break;
    }
    const std::vector<double> x_old = *x;
    *x = xs;
    const double f_new = cost();
    const double rho = (f - f_new) / predicted;
    log << "  " << step + 1 << ", " << ss.iterations.size() - 1 << ", " << -predicted << ", " << f_new - f << ", "
        << radius;
    if (f_new < f && rho > 0.1) {
      const double f_old = f;
      f = f_new;
      out->cost_history.push_back(f);
      ++step;
      ++out->iterations;
      if (!full->at(x->data(), true).ok) {
        out->termination = "FAILURE";
        break;
      }
      expanded = false;
      if (rho > 0.75 && moved > 0.9 * radius)
        radius *= 2;
      else if (rho < 0.25)
        radius = 0.5 * moved;
      log << " (taken)\n";
      if (f_old - f < o.function_tolerance * f_old) {
        out->termination = "CONVERGENCE";
        break;
      }
    } else {
      *x = x_old;
      ++out->rejected_steps;
      radius = 0.25 * moved;
      log << " (rejected)\n";
      // The full Jacobian's static correction truncates the modes not computed (a relative gradient error of
      // ~1e-3 measured), and the surrogate inherits it: a decrease the full model refuses that is smaller than
      // sqrt(function_tolerance) of the cost is within that error, not a step towards the minimum.
      if (predicted < std::sqrt(o.function_tolerance) * f) {
        out->termination = "CONVERGENCE";
        break;
      }
      if (out->rejected_steps > o.max_iterations) break;
    }
  }
  out->final_cost = f;
  out->converged = out->termination == "CONVERGENCE";
  out->reduced_basis = true;
  log << "basis of " << sur->basis_size() << " vectors; " << sur->surrogate_evaluations() << " surrogate evaluations\n";
  out->report = log.str();
  return true;
}

}  // namespace

FitSummary fit_parameters(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta0,
                          const std::vector<char>& is_free, const FitOptions& o) {
  const std::vector<int> free = check_fit_input(pm, measured, theta0, is_free, o);
  const auto t_start = std::chrono::steady_clock::now();
  auto ev = std::make_shared<Evaluator>(pm, measured, theta0, free, o);
  const int nf = static_cast<int>(free.size());
  std::vector<double> x(free.size());
  for (int k = 0; k < nf; ++k) x[k] = theta0[free[k]];

  FitSummary out;
  out.free_parameters = nf;
  const Evaluation& e0 = ev->at(x.data(), false);
  if (!e0.ok) throw NumericalError("fit: the model cannot be evaluated at the start values: " + e0.error);
  out.measured_hz = measured.frequencies_hz;
  out.initial_hz = paired_hz(e0);
  out.initial_mac = e0.mac;

  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  add_cost(&problem, ev, pm, free, measured.num_modes(), o, x.data());
  const bool want_reduced =
      o.reduced_basis == FitOptions::ReducedBasis::kOn ||
      (o.reduced_basis == FitOptions::ReducedBasis::kAuto && pm.model().num_dofs() >= o.reduced_basis_min_dofs);
  bool reduced = false;
  if (want_reduced && !ev->reduced_basis_applies() && o.reduced_basis == FitOptions::ReducedBasis::kOn)
    out.warnings.push_back(
        "the reduced-basis fit does not apply here (f2 objective, a model solved densely, or a "
        "free-free model): the direct fit ran");
  if (want_reduced && ev->reduced_basis_applies()) {
    const std::size_t warned = out.warnings.size();
    reduced = reduced_basis_fit(&problem, ev.get(), pm, measured, theta0, free, o, &x, &out);
    if (!reduced && out.warnings.size() == warned)
      out.warnings.push_back("the reduced-basis surrogate could not be built at the start values: the direct fit ran");
    if (!reduced) out.cost_history.clear();
  }
  if (!reduced) {
    ceres::Solver::Options so = solver_options(o);
    CostRecorder rec(&out.cost_history);
    so.callbacks.push_back(&rec);
    so.update_state_every_iteration = false;
    ceres::Solver::Summary sum;
    ceres::Solve(so, &problem, &sum);
    out.iterations = static_cast<int>(sum.iterations.size()) - 1;
    out.termination = ceres::TerminationTypeToString(sum.termination_type);
    out.converged = sum.termination_type == ceres::CONVERGENCE;
    out.initial_cost = sum.initial_cost;
    out.final_cost = sum.final_cost;
    out.report = sum.FullReport();
  }
  out.theta = ev->theta_of(x.data());
  for (int k = 0; k < nf; ++k) x[k] = out.theta[free[k]];  // the projected (evaluated) values

  const Evaluation& ef = ev->at(x.data(), true);
  if (!ef.ok) throw NumericalError("fit: the model cannot be evaluated at the solution: " + ef.error);
  out.final_hz = paired_hz(ef);
  out.final_mac = ef.mac;
  out.final_forced = ef.forced;
  {
    Eigen::Index n = 0;
    for (const Eigen::VectorXd& r : ef.r) n += r.size();
    out.final_residuals.resize(n);
    n = 0;
    for (const Eigen::VectorXd& r : ef.r) out.final_residuals.segment(n, r.size()) = r, n += r.size();
  }
  for (const Eigen::VectorXd& r : ef.r)
    out.final_chi2_frequency += o.objective == FitObjective::kSerep ? 0.0 : r[0] * r[0];
  if (!out.converged)
    out.warnings.push_back("the fit stopped without converging (Ceres " + out.termination + " after " +
                           std::to_string(out.iterations) + " iterations, cost " + std::to_string(out.initial_cost) +
                           " -> " + std::to_string(out.final_cost) +
                           "): the parameters are the last iterate, not a minimum; raise max_iterations, or fix or "
                           "tie the parameters the data cannot determine");
  for (int k = 0; k < measured.num_modes(); ++k)
    if (ef.forced[k])
      out.warnings.push_back("measured mode " + std::to_string(k + 1) + " (" +
                             std::to_string(measured.frequencies_hz[k]) +
                             " Hz) pairs with no model mode at MAC >= " + std::to_string(o.min_mac) +
                             "; it was matched to the best remaining one (MAC " + std::to_string(ef.mac[k]) + ")");

  estimate_covariance(ef, pm, free, o, &out);
  const int ndata = ev->data_values();
  if (ndata > nf) out.residual_scale = std::sqrt(2.0 * out.final_cost / (ndata - nf));
  if (nf > ndata)
    out.warnings.push_back(std::to_string(nf) + " free parameters but only " + std::to_string(ndata) + " data values");
  for (int k = 0; k < nf; ++k) {
    const Parameter& q = pm.parameter(free[k]);
    const double tol = 1e-6 * std::max(1.0, std::abs(q.scale));
    if ((std::isfinite(q.lower) && x[k] - q.lower < tol) || (std::isfinite(q.upper) && q.upper - x[k] < tol)) {
      out.at_bound.push_back(free[k]);
      out.warnings.push_back("parameter '" + q.name + "' ended on its bound (" + std::to_string(x[k]) +
                             "): the data push it further than allowed");
    }
  }
  out.evaluations = ev->evaluations();
  out.time_eigen = ev->time_eigen();
  out.time_sensitivity = ev->time_sensitivity();
  out.time_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  return out;
}

Linearization linearize(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta,
                        const FitOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("fit options: " + why);
  measured.validate("measured modal data");
  std::vector<int> all(static_cast<std::size_t>(pm.num_parameters()));
  for (int p = 0; p < pm.num_parameters(); ++p) all[p] = p;
  Evaluator ev(pm, measured, theta, all, o);
  const Evaluation& e = ev.at(theta.data(), true);
  if (!e.ok) throw NumericalError("linearize: " + e.error);
  Linearization L;
  Eigen::Index rows = 0;
  for (const auto& r : e.r) {
    L.block_start.push_back(static_cast<int>(rows));
    rows += r.size();
  }
  L.r.resize(rows);
  L.J.resize(rows, pm.num_parameters());
  for (std::size_t k = 0; k < e.r.size(); ++k) {
    L.r.segment(L.block_start[k], e.r[k].size()) = e.r[k];
    L.J.middleRows(L.block_start[k], e.J[k].rows()) = e.J[k];
  }
  L.model_hz = paired_hz(e);
  L.mac = e.mac;
  L.forced = e.forced;
  return L;
}

struct FitProblem::Impl {
  std::unique_ptr<Evaluator> ev;
  std::vector<int> all;
};

FitProblem::FitProblem(const ParametricModel& pm, const ModalData& measured, const FitOptions& o)
    : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("fit options: " + why);
  measured.validate("measured modal data");
  for (int p = 0; p < pm.num_parameters(); ++p) impl_->all.push_back(p);
  impl_->ev = std::make_unique<Evaluator>(pm, measured, pm.nominal(), impl_->all, o);
}
FitProblem::~FitProblem() = default;

bool FitProblem::residuals(const Eigen::VectorXd& theta, Eigen::VectorXd* r) {
  const Evaluation& e = impl_->ev->at(theta.data(), false);
  if (!e.ok) return false;
  Eigen::Index n = 0;
  for (const auto& b : e.r) n += b.size();
  r->resize(n);
  n = 0;
  for (const auto& b : e.r) {
    r->segment(n, b.size()) = b;
    n += b.size();
  }
  return true;
}

double FitProblem::cost(const Eigen::VectorXd& theta) {
  Eigen::VectorXd r;
  return residuals(theta, &r) ? 0.5 * r.squaredNorm() : std::numeric_limits<double>::infinity();
}

int FitProblem::evaluations() const { return impl_->ev->evaluations(); }

Correlation correlate(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta, const FitOptions& options) {
  FitOptions o = options;
  o.objective = FitObjective::kFrequency;
  Evaluator ev(pm, measured, theta, {}, o);
  const Evaluation& e = ev.at(nullptr, false);
  if (!e.ok) throw NumericalError("correlate: " + e.error);
  Correlation c;
  c.measured_hz = measured.frequencies_hz;
  c.model_hz = paired_hz(e);
  c.mac = e.mac;
  for (std::size_t k = 0; k < e.pair.size(); ++k) {
    int j = 0;
    while (e.elastic[j] != e.pair[k]) ++j;
    c.model_mode.push_back(e.forced[k] ? -1 : j);
  }
  return c;
}

PlausibleModes plausible_modes(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta,
                               const FitOptions& options) {
  PlausibleModes out;
  out.correlation = correlate(pm, measured, theta, options);
  for (int k = 0; k < measured.num_modes(); ++k)
    (out.correlation.model_mode[static_cast<std::size_t>(k)] >= 0 ? out.paired : out.unpaired).push_back(k);
  return out;
}

}  // namespace dynid
