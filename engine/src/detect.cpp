#include "dynid/engine/detect.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>

#include "dynid/engine/residual_force.hpp"
#include "dynid/engine/sensitivity.hpp"
#include "dynid/engine/serep.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/mesh/symmetry.hpp"
#include "dynid/solvers/least_squares.hpp"

namespace dynid {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Model frequencies this close (relative) are one repeated eigenvalue (symmetric structures; the solver's
// rounding separates them by about 1e-12).
constexpr double kRepeatedTolerance = 1e-6;

// Chi-square quantile with 2 degrees of freedom: P(X > q) = alpha  <=>  q = -2 ln(alpha).
double chi2_2dof(double alpha) { return -2.0 * std::log(alpha); }

std::string fmt(double v, int prec = 4) {
  std::ostringstream s;
  s.precision(prec);
  s << v;
  return s.str();
}

struct Paired {
  std::vector<int> used;        // changed-state modes used (0-based)
  std::vector<int> model_mode;  // their partners (indices into the modal result, rigid modes included)
  Eigen::MatrixXd partner;      // the partners' shapes at the measured rows; for a repeated eigenvalue, the
                                // member of its subspace the measured shape shows (subspace_coefficients)
  Eigen::VectorXd mac;
  std::vector<std::string> warnings;
};

// Pairs the modes of `data` (shapes at rows) with the model's elastic modes by MAC.
Paired pair_with_model(const ModalData& data, const std::vector<int>& rows, const std::vector<int>& translations, const ModalResult& ref,
                       int max_modes, double min_mac, const std::string& what) {
  std::vector<int> elastic;
  for (Eigen::Index j = 0; j < ref.eigenvalues.size(); ++j)
    if (!ref.rigid_body[j]) elastic.push_back(static_cast<int>(j));
  Eigen::MatrixXd Pa(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(elastic.size()));
  Eigen::VectorXd fe(static_cast<Eigen::Index>(elastic.size()));
  for (std::size_t j = 0; j < elastic.size(); ++j) {
    for (std::size_t r = 0; r < rows.size(); ++r) Pa(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(j)) = ref.modes(rows[r], elastic[j]);
    fe[static_cast<Eigen::Index>(j)] = ref.frequencies_hz[elastic[j]];
  }
  // Repeated eigenvalues (symmetric structures) are compared as subspaces: the solver's basis is arbitrary.
  const std::vector<std::vector<int>> groups = repeated_groups(fe, kRepeatedTolerance);
  std::vector<int> group_of(elastic.size(), -1);
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int j : groups[g]) group_of[static_cast<std::size_t>(j)] = static_cast<int>(g);
  Eigen::MatrixXd mac = subspace_mac_matrix(data.shapes, Pa, groups);
  // Modes the sensors cannot see are no partners: their MAC with a measurement is noise.
  for (std::size_t j = 0; j < elastic.size(); ++j)
    if (sensor_visibility(ref.modes.col(elastic[j]), rows, translations) < kMinPairingVisibility) mac.col(static_cast<Eigen::Index>(j)).setZero();
  const Pairing pr = pair_modes(mac, data.frequencies_hz, fe, min_mac);
  Paired out;
  for (int k : pr.unpaired_a) {
    double best = 0;
    for (Eigen::Index j = 0; j < mac.cols(); ++j) best = std::max(best, mac(k, j));
    out.warnings.push_back(what + " mode " + std::to_string(k + 1) + " (" + fmt(data.frequencies_hz[k]) +
                           " Hz) pairs with no model mode (MAC >= " + fmt(min_mac, 3) + " with a mode the sensors see, within a factor " +
                           fmt(kMaxPairingRatio, 2) + " in frequency; best MAC " + fmt(best, 3) +
                           "); it is left out. Check the DOF labels and directions, or lower min_mac");
  }
  for (const ModePair& q : pr.pairs) {
    if (max_modes > 0 && static_cast<int>(out.used.size()) >= max_modes) break;
    out.used.push_back(q.a);
    out.model_mode.push_back(elastic[q.b]);
  }
  out.mac.resize(static_cast<Eigen::Index>(out.used.size()));
  out.partner.resize(Pa.rows(), static_cast<Eigen::Index>(out.used.size()));
  for (std::size_t k = 0; k < out.used.size(); ++k) {
    const auto* q = pr.of_a(out.used[k]);
    out.mac[static_cast<Eigen::Index>(k)] = q->mac;
    const std::vector<int>& g = groups[static_cast<std::size_t>(group_of[static_cast<std::size_t>(q->b)])];
    if (g.size() > 1)
      out.partner.col(static_cast<Eigen::Index>(k)) = subspace_member(data.shapes.col(q->a), Pa, g);
    else
      out.partner.col(static_cast<Eigen::Index>(k)) = Pa.col(q->b);
  }
  return out;
}

// Shapes of the used modes scaled to best match their model partners (sign and size of mass-normalised modes).
Eigen::MatrixXd scaled_shapes(const ModalData& d, const Paired& p) {
  Eigen::MatrixXd U(p.partner.rows(), static_cast<Eigen::Index>(p.used.size()));
  for (std::size_t k = 0; k < p.used.size(); ++k) {
    const Eigen::VectorXd v = p.partner.col(static_cast<Eigen::Index>(k));
    const Eigen::VectorXd u = d.shapes.col(p.used[k]);
    U.col(static_cast<Eigen::Index>(k)) = u * (u.dot(v) / u.squaredNorm());
  }
  return U;
}

Eigen::VectorXd lambdas(const ModalData& d, const std::vector<int>& used) {
  Eigen::VectorXd l(static_cast<Eigen::Index>(used.size()));
  for (std::size_t k = 0; k < used.size(); ++k) l[static_cast<Eigen::Index>(k)] = hz_to_eigenvalue(d.frequencies_hz[used[k]]);
  return l;
}

// Residual forces R = (-K0 + lambda M0) phi of eigenpairs of (K, M) refined in extended precision
// (refine_eigenpairs), formed in long double; phi scaled back to the given shapes, which the element fits use.
Eigen::MatrixXd extended_residuals(const SparseMatrix& K, const SparseMatrix& M, const SparseMatrix& K0,
                                   const SparseMatrix& M0, const Eigen::VectorXd& lam_in, const Eigen::MatrixXd& Phi_in) {
  using LD = long double;
  const int n = static_cast<int>(K.rows());
  Eigen::VectorXd lam = lam_in;
  Eigen::MatrixXd Phi = Phi_in;
  const Eigen::MatrixXd Md(M);
  for (Eigen::Index i = 0; i < Phi.cols(); ++i) Phi.col(i) /= std::sqrt(Phi.col(i).dot(Md * Phi.col(i)));
  std::vector<LD> ext;
  refine_eigenpairs(K, M, &lam, &Phi, &ext, 4);
  Eigen::MatrixXd R(n, Phi.cols());
  std::vector<LD> kp, mp;
  for (Eigen::Index i = 0; i < Phi.cols(); ++i) {
    const LD* phi = ext.data() + static_cast<std::size_t>(i) * n;
    LD num = 0, den = 0;
    for (int k = 0; k < n; ++k) {
      num += static_cast<LD>(Phi_in(k, i)) * phi[k];
      den += phi[k] * phi[k];
    }
    const LD scale = num / den;
    kp.assign(n, 0.0L);
    mp.assign(n, 0.0L);
    for (int j = 0; j < n; ++j) {
      for (SparseMatrix::InnerIterator it(K0, j); it; ++it) kp[it.row()] += static_cast<LD>(it.value()) * phi[j];
      for (SparseMatrix::InnerIterator it(M0, j); it; ++it) mp[it.row()] += static_cast<LD>(it.value()) * phi[j];
    }
    for (int k = 0; k < n; ++k) R(k, i) = static_cast<double>(scale * (-kp[k] + static_cast<LD>(lam[i]) * mp[k]));
  }
  return R;
}

}  // namespace

Model changed_model(const Model& reference, const std::vector<std::pair<int, std::pair<double, double>>>& changes) {
  Model m = reference;
  for (const auto& [id, d] : changes) {
    const int e = m.element_index(id);
    if (e < 0) throw InputError("change: element " + std::to_string(id) + " does not exist");
    if (!(d.first > -1 && d.second > -1))
      throw InputError("change of element " + std::to_string(id) + ": dk and dm must be > -1 (-0.15 = 15 % loss)");
    m.element(e).factors.E *= 1.0 + d.first;
    m.element(e).factors.rho *= 1.0 + d.second;
  }
  m.finalize();
  return m;
}

namespace {

void check_detect_inputs(const ModalData& changed_in, const DetectOptions& o, const ModalData* reference_measured) {
  changed_in.validate("changed-state modal data");
  if (reference_measured) {
    reference_measured->validate("reference-state modal data");
    if (!(reference_measured->dofs == changed_in.dofs))
      throw InputError("the reference-state and changed-state modal data must be given at the same DOFs, in the same order");
  }
  if (o.max_changed < 1) throw InputError("detect: max_changed must be >= 1");
  if (!(o.significance > 0 && o.significance < 1)) throw InputError("detect: significance must be in (0, 1)");
}

// The elements detect() examines: the given ids, or every element with both stiffness and mass (members and
// matrix elements).
std::vector<int> candidate_elements(const Model& model, const DetectOptions& o) {
  std::vector<int> cand;
  if (o.candidates.empty()) {
    for (int e = 0; e < model.num_elements(); ++e) {
      const ElementKind& k = element_kind(model.elements()[e].type);  // members and matrix elements
      if (k.has_stiffness() && k.has_mass()) cand.push_back(e);
    }
  } else {
    for (int id : o.candidates) {
      const int e = model.element_index(id);
      if (e < 0) throw InputError("detect: candidate element " + std::to_string(id) + " does not exist");
      cand.push_back(e);
    }
  }
  if (cand.empty()) throw InputError("detect: the model has no beam, frame or matrix elements to examine");
  return cand;
}

// The state detect() passes between its stages; each stage is a member function, in the order detect() calls them.
class DetectRun {
 public:
  DetectRun(const Model& model, const ModalData& changed_in, const DetectOptions& o,
            const ModalData* reference_measured)
      : model(model),
        o(o),
        reference_measured(reference_measured),
        changed(changed_in),
        refmeas(reference_measured ? *reference_measured : ModalData{}) {}

  void order_measured_rows();
  void reference_modes();
  void pair_changed_modes();
  void residual_forces_stage();
  void pseudo_residual_scores();
  void localize();
  void rank_flags_and_twins();
  void quantify();

  const Model& model;
  const DetectOptions& o;
  const ModalData* reference_measured;
  DetectSummary S;
  int n = 0;                           // model DOFs
  std::vector<int> rows;               // equations of the measured DOFs
  ModalData changed, refmeas;          // the data, rows in equation order when full_dofs
  std::vector<int> cand;               // candidate element indices
  int a = 0, m_serep = 0;              // measured DOFs, SEREP modes
  ModalResult ref;                     // the reference model's modes
  std::vector<int> translations;       // translational equations
  Paired pc;                           // changed-state modes paired with the model
  int p = 0;                           // modes used
  Eigen::VectorXd lam_c;               // their eigenvalues
  AssembledSystem sys;                 // full DOFs: K0, M0
  SerepReduction red;                  // reduced DOFs: SEREP model
  Eigen::MatrixXd Uc;                  // scaled changed-state shapes
  std::map<int, ElementScore> scores;  // by element index
  std::vector<Symmetry> syms;
  std::vector<int> flagged;
  Eigen::VectorXd theta_fit;  // refined factors (E, rho per flagged element) when fitted
  FitSummary fit;
  bool have_fit = false;
  std::optional<ParametricModel> pm;
  std::map<int, int> par_E, par_rho;  // element index -> parameter index

  // Seconds since the last call (stage timings).
  double lap() {
    const double t = std::chrono::duration<double>(Clock::now() - t_stage).count();
    t_stage = Clock::now();
    return t;
  }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point t_stage = Clock::now();

  void add_params(int e);
  void localize_full_dofs();
  void localize_by_sensitivity();
  Eigen::MatrixXd residuals_of(const Eigen::MatrixXd& U, const Eigen::VectorXd& lam) const {
    return S.full_dofs ? residual_forces(sys.K, sys.M, lam, U) : residual_forces(red.K, red.M, lam, U);
  }
  void element_system(int e, const Eigen::MatrixXd& R, Eigen::VectorXd* y, Eigen::MatrixXd* A,
                      std::vector<int>* rr) const;
  std::vector<int> residual_support(double total);
  Eigen::MatrixXd joint_refit(const std::vector<int>& sel) const;
  void confirm_greedily(const ModalData& used, const FitOptions& fo, Linearization L, double thr, double best_chi2);
  std::pair<double, Eigen::VectorXd> single_fit(const Linearization& lin, int e) {
    Eigen::MatrixXd Je(lin.J.rows(), 2);
    Je.col(0) = lin.J.col(par_E[e]);
    Je.col(1) = lin.J.col(par_rho[e]);
    const LeastSquaresResult ls = least_squares(Je, -lin.r);
    return std::make_pair(ls.residual_norm * ls.residual_norm, ls.x);
  }
  void refine_amounts(const LeastSquaresResult& fo_ls);
};

// Full DOFs: the measured rows in equation order (data reordered with them).
void DetectRun::order_measured_rows() {
  n = model.num_dofs();
  rows = measured_equations(model, changed.dofs);
  S.full_dofs = static_cast<int>(rows.size()) == n;
  if (S.full_dofs) {  // equation order
    std::vector<int> order(rows.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int x, int y) { return rows[x] < rows[y]; });
    auto reorder = [&](ModalData& d) {
      ModalData t = d;
      for (std::size_t r = 0; r < order.size(); ++r) {
        t.dofs[r] = d.dofs[order[r]];
        t.shapes.row(static_cast<Eigen::Index>(r)) = d.shapes.row(order[r]);
      }
      d = t;
    };
    reorder(changed);
    if (reference_measured) reorder(refmeas);
    std::sort(rows.begin(), rows.end());
  }
  S.dofs = changed.dofs;
}

// Reference modal analysis: enough modes to pair and, for reduced data, for SEREP.
void DetectRun::reference_modes() {
  a = static_cast<int>(rows.size());
  const int nrb = model.free_free() ? static_cast<int>(model.free_rigid_body_modes().cols()) : 0;
  m_serep = S.full_dofs ? 0 : (o.serep_modes > 0 ? o.serep_modes : a);
  EigenOptions eo;
  if (n <= 400) {
    eo.method = EigenOptions::Method::kDense;
    eo.num_modes = n;
  } else {
    eo.num_modes = std::min(n - 1, std::max(nrb + changed.num_modes() + std::max(10, changed.num_modes() / 2), m_serep));
  }
  lap();
  ref = modal_analysis(model, eo);
  if (!ref.ok()) throw NumericalError("detect: modal analysis of the reference model failed: " + ref.summary.message);
  S.time_modal = lap();
  m_serep = std::min<int>(m_serep, static_cast<int>(ref.eigenvalues.size()));
}

void DetectRun::pair_changed_modes() {
  translations = translation_equations(model);
  pc = pair_with_model(changed, rows, translations, ref, o.modes, o.min_mac, "changed-state");
  S.warnings.insert(S.warnings.end(), pc.warnings.begin(), pc.warnings.end());
  if (pc.used.empty()) throw InputError("detect: no changed-state mode pairs with a model mode; nothing to compare");
  S.used_modes = pc.used;
  p = static_cast<int>(pc.used.size());
  S.changed_hz.resize(p);
  S.model_hz.resize(p);
  for (int k = 0; k < p; ++k) {
    S.changed_hz[k] = changed.frequencies_hz[pc.used[k]];
    S.model_hz[k] = ref.frequencies_hz[pc.model_mode[k]];
  }
  S.mac = pc.mac;
  lam_c = lambdas(changed, pc.used);
}

// Residual forces (eq. 6) and pseudo residual forces (eq. 7-8), on every DOF or on the SEREP-reduced model.
void DetectRun::residual_forces_stage() {
  if (S.full_dofs) {
    sys = assemble_system(model);
  } else {
    Eigen::VectorXd lam_ref = ref.eigenvalues.head(m_serep);
    red = serep_reduce(ref.modes.leftCols(m_serep), lam_ref, rows);
    S.serep_modes = red.modes;
    S.serep_rank = red.rank;
    if (red.rank < red.modes)
      S.warnings.push_back("SEREP: the " + std::to_string(red.modes) + " modes are dependent at the " + std::to_string(a) +
                           " measured DOFs (rank " + std::to_string(red.rank) + "); the reduced model keeps " +
                           std::to_string(red.rank) + " of them");
  }
  Uc = scaled_shapes(changed, pc);
  if (S.full_dofs && o.simulated_changed && n <= 3000) {
    const AssembledSystem chs = assemble_system(*o.simulated_changed);
    S.residuals = extended_residuals(chs.K, chs.M, sys.K, sys.M, lam_c, Uc);
  } else {
    S.residuals = residuals_of(Uc, lam_c);
  }
  S.pseudo = pseudo_residual_force(S.residuals);
  S.pseudo_reference = Eigen::VectorXd::Zero(S.pseudo.size());
  if (reference_measured) {
    const Paired pr = pair_with_model(refmeas, rows, translations, ref, o.modes, o.min_mac, "reference-state");
    S.warnings.insert(S.warnings.end(), pr.warnings.begin(), pr.warnings.end());
    if (!pr.used.empty())
      S.pseudo_reference = pseudo_residual_force(residuals_of(scaled_shapes(refmeas, pr), lambdas(refmeas, pr.used)));
  }
  S.delta_pseudo = S.pseudo - S.pseudo_reference;
}

// The paper's mapping: DOFs -> nodes -> elements (geometric mean of the node scores), and its ranking.
void DetectRun::pseudo_residual_scores() {
  std::vector<double> node_score(model.nodes().size(), kNaN);
  for (int r = 0; r < static_cast<int>(S.dofs.size()); ++r) {
    const int nd = model.node_index(S.dofs[r].node);
    const double v = std::max(0.0, S.delta_pseudo[r]);
    node_score[nd] = std::isnan(node_score[nd]) ? v : std::max(node_score[nd], v);
  }
  for (int e : cand) {
    ElementScore es;
    es.element = model.elements()[e].id;
    const auto& en = model.element_nodes(e);
    double logsum = 0;
    int k = 0;
    for (int q = 0; q < model.elements()[e].num_nodes; ++q)
      if (!std::isnan(node_score[en[q]])) {
        logsum += std::log(node_score[en[q]]);
        ++k;
      }
    es.pseudo = k ? std::exp(logsum / k) : kNaN;
    scores[e] = es;
  }
  std::vector<int> order = cand;
  auto val = [&](int e) { return std::isnan(scores[e].pseudo) ? -1.0 : scores[e].pseudo; };
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return val(x) > val(y); });
  for (std::size_t k = 0; k < order.size(); ++k) scores[order[k]].pseudo_rank = static_cast<int>(k) + 1;
}

// dynid's localization: by residual forces on every DOF, or by a sensitivity fit on the measured DOFs.
void DetectRun::localize() {
  syms = find_symmetries(model);
  pm.emplace(model);
  if (S.full_dofs)
    localize_full_dofs();
  else
    localize_by_sensitivity();
}

void DetectRun::add_params(int e) {
  if (par_E.count(e)) return;
  const std::string id = std::to_string(model.elements()[e].id);
  Parameter pe;
  pe.name = "E:" + id;
  pe.kind = ParameterKind::kStiffness;
  pe.elements = {e};
  pe.lower = 0.01;
  pe.upper = 10;
  par_E[e] = pm->add(pe);
  Parameter pr = pe;
  pr.name = "rho:" + id;
  pr.kind = ParameterKind::kMass;
  par_rho[e] = pm->add(pr);
}

// One element's least-squares system on its own DOFs: y = R there (mode-major), A = [K_e phi_i, -lambda_i M_e phi_i];
// rr gets the DOFs (equations).
void DetectRun::element_system(int e, const Eigen::MatrixXd& R, Eigen::VectorXd* y, Eigen::MatrixXd* A,
                               std::vector<int>* rr) const {
  std::vector<int> dofs;
  Eigen::MatrixXd Ke, Me;
  model.element_dofs(e, &dofs);
  model.element_matrices(e, &Ke, &Me);
  rr->clear();
  std::vector<int> loc;
  for (std::size_t q = 0; q < dofs.size(); ++q)
    if (dofs[q] >= 0) {
      rr->push_back(dofs[q]);
      loc.push_back(static_cast<int>(q));
    }
  const Eigen::Index nl = static_cast<Eigen::Index>(rr->size());
  y->resize(nl * p);
  A->resize(nl * p, 2);
  for (int i = 0; i < p; ++i) {
    Eigen::VectorXd ph(static_cast<Eigen::Index>(dofs.size()));
    for (std::size_t q = 0; q < dofs.size(); ++q)
      ph[static_cast<Eigen::Index>(q)] = dofs[q] >= 0 ? Uc(dofs[q], i) : 0.0;
    const Eigen::VectorXd kp = Ke * ph, mp = Me * ph;
    for (Eigen::Index l = 0; l < nl; ++l) {
      (*y)[i * nl + l] = R((*rr)[l], i);
      (*A)(i * nl + l, 0) = kp[loc[l]];
      (*A)(i * nl + l, 1) = -lam_c[i] * mp[loc[l]];
    }
  }
}

// Only elements with residual force on their DOFs can explain any of it; the others score 0.
std::vector<int> DetectRun::residual_support(double total) {
  const Eigen::VectorXd row_energy = S.residuals.rowwise().squaredNorm();
  std::vector<int> support, dofs;
  for (int e : cand) {
    model.element_dofs(e, &dofs);
    double en = 0;
    for (int d : dofs)
      if (d >= 0) en = std::max(en, row_energy[d]);
    if (en > 1e-24 * total) support.push_back(e);
    scores[e].probability = 0;
    scores[e].chi2 = 1;
  }
  return support;
}

// Joint fit of the selected elements on the union of their rows; returns the residual forces it leaves.
Eigen::MatrixXd DetectRun::joint_refit(const std::vector<int>& sel) const {
  std::vector<int> urows, dofs;
  for (int e : sel) {
    model.element_dofs(e, &dofs);
    for (int d : dofs)
      if (d >= 0) urows.push_back(d);
  }
  std::sort(urows.begin(), urows.end());
  urows.erase(std::unique(urows.begin(), urows.end()), urows.end());
  std::map<int, Eigen::Index> pos;
  for (std::size_t q = 0; q < urows.size(); ++q) pos[urows[q]] = static_cast<Eigen::Index>(q);
  const Eigen::Index nu = static_cast<Eigen::Index>(urows.size());
  Eigen::MatrixXd AJ = Eigen::MatrixXd::Zero(nu * p, 2 * static_cast<Eigen::Index>(sel.size()));
  Eigen::VectorXd yJ(nu * p), y;
  Eigen::MatrixXd A;
  std::vector<int> rr;
  for (int i = 0; i < p; ++i)
    for (Eigen::Index q = 0; q < nu; ++q) yJ[i * nu + q] = S.residuals(urows[q], i);
  for (std::size_t s = 0; s < sel.size(); ++s) {
    element_system(sel[s], S.residuals, &y, &A, &rr);
    const Eigen::Index nl = static_cast<Eigen::Index>(rr.size());
    for (int i = 0; i < p; ++i)
      for (Eigen::Index l = 0; l < nl; ++l) {
        AJ(i * nu + pos[rr[l]], 2 * s) = A(i * nl + l, 0);
        AJ(i * nu + pos[rr[l]], 2 * s + 1) = A(i * nl + l, 1);
      }
  }
  const LeastSquaresResult ls = least_squares(AJ, yJ);
  const Eigen::VectorXd fitv = AJ * ls.x;
  Eigen::MatrixXd Rleft = S.residuals;
  for (int i = 0; i < p; ++i)
    for (Eigen::Index q = 0; q < nu; ++q) Rleft(urows[q], i) -= fitv[i * nu + q];
  return Rleft;
}

// Full DOFs: exact residual forces live on the DOFs of the changed elements only: R_i = sum_e (dk_e K_e - lambda_i
// dm_e M_e) phi_i. Each element's share is a least-squares fit on its own DOFs; elements are taken greedily.
void DetectRun::localize_full_dofs() {
  S.method = "residual-force element fit (full DOFs)";
  S.threshold_rule =
      "an element is flagged while it explains at least 1 % of the residual-force energy still "
      "unexplained, and that energy is above 1e-12 of the total (rounding level)";
  const double total = S.residuals.squaredNorm();
  const std::vector<int> support = residual_support(total);
  // Single-element explained energy (the ranking).
  Eigen::VectorXd y;
  Eigen::MatrixXd A;
  std::vector<int> rr;
  for (int e : support) {
    element_system(e, S.residuals, &y, &A, &rr);
    const LeastSquaresResult ls = least_squares(A, y);
    const double expl = total > 0 ? (y.squaredNorm() - ls.residual_norm * ls.residual_norm) / total : 0.0;
    scores[e].probability = std::max(0.0, expl);  // explained fraction of the residual-force energy
    scores[e].chi2 = 1.0 - scores[e].probability;
  }
  // Greedy selection with a joint refit of the selected elements on the union of their DOFs.
  Eigen::MatrixXd Rleft = S.residuals;
  std::vector<int> sel;
  while (static_cast<int>(sel.size()) < o.max_changed && !o.localize_only) {
    const double left = Rleft.squaredNorm();
    if (!(left > 1e-12 * total)) break;
    int best = -1;
    double best_expl = 0;
    for (int e : support) {
      if (std::find(sel.begin(), sel.end(), e) != sel.end()) continue;
      element_system(e, Rleft, &y, &A, &rr);
      const LeastSquaresResult ls = least_squares(A, y);
      const double expl = y.squaredNorm() - ls.residual_norm * ls.residual_norm;
      if (expl > best_expl) {
        best_expl = expl;
        best = e;
      }
    }
    if (best < 0 || best_expl < 0.01 * left) break;
    sel.push_back(best);
    Rleft = joint_refit(sel);
  }
  flagged = sel;
  S.chi2_unchanged = 1.0;
  S.chi2_final = total > 0 ? Rleft.squaredNorm() / total : 0.0;
}

// Reduced DOFs: each single-element hypothesis (dk, dm of one element) is fitted to the whitened frequencies and
// shapes by one Gauss-Newton step from the reference model; flags by likelihood ratio.
void DetectRun::localize_by_sensitivity() {
  S.method = "whitened sensitivity fit of frequencies and shapes (measured DOFs)";
  const double thr = chi2_2dof(o.significance);
  S.threshold_rule =
      "an element is flagged when fitting it (dk, dm) lowers the chi-square of the frequencies and "
      "shapes by more than " +
      fmt(thr, 4) + " (chi-square quantile, 2 dof, level " + fmt(o.significance, 3) +
      "), with the stated noise: frequencies " + fmt(100 * o.frequency_noise, 3) + " %, shapes " +
      fmt(100 * o.shape_noise, 3) + " % of each mode's largest entry";
  for (int e : cand) add_params(e);
  FitOptions fo;
  fo.objective = FitObjective::kCombined;
  fo.frequency_noise = o.frequency_noise * (reference_measured ? std::sqrt(2.0) : 1.0);
  fo.shape_noise = o.shape_noise * (reference_measured ? std::sqrt(2.0) : 1.0);
  fo.min_mac = o.min_mac;
  const ModalData used = modes_subset(changed, pc.used);
  const Linearization L = linearize(*pm, used, pm->nominal(), fo);
  S.chi2_unchanged = L.r.squaredNorm();
  double best_chi2 = std::numeric_limits<double>::infinity();
  for (int e : cand) {
    scores[e].chi2 = single_fit(L, e).first;
    best_chi2 = std::min(best_chi2, scores[e].chi2);
  }
  double z = 0;
  for (int e : cand) z += std::exp(-0.5 * (scores[e].chi2 - best_chi2));
  for (int e : cand) scores[e].probability = std::exp(-0.5 * (scores[e].chi2 - best_chi2)) / z;
  if (!o.localize_only) confirm_greedily(used, fo, L, thr, best_chi2);
}

// Greedy forward selection; each step is confirmed by a nonlinear fit (eigen-solves) of the whole set.
void DetectRun::confirm_greedily(const ModalData& used, const FitOptions& fo, Linearization L, double thr,
                                 double best_chi2) {
  std::vector<char> freemask(static_cast<std::size_t>(pm->num_parameters()), 0);
  Eigen::VectorXd theta = pm->nominal();
  double chi2_cur = S.chi2_unchanged;
  while (static_cast<int>(flagged.size()) < o.max_changed) {
    int best = -1;
    double bc = std::numeric_limits<double>::infinity();
    Eigen::VectorXd bx;
    for (int e : cand) {
      if (std::find(flagged.begin(), flagged.end(), e) != flagged.end()) continue;
      const auto f = single_fit(L, e);
      if (f.first < bc) {
        bc = f.first;
        best = e;
        bx = f.second;
      }
    }
    if (best < 0) break;
    std::vector<char> mask = freemask;
    mask[par_E[best]] = mask[par_rho[best]] = 1;
    Eigen::VectorXd start = theta;
    start[par_E[best]] = std::clamp(1.0 + bx[0], 0.02, 9.0);
    start[par_rho[best]] = std::clamp(1.0 + bx[1], 0.02, 9.0);
    FitSummary f = fit_parameters(*pm, used, start, mask, fo);
    const double chi2_new = 2.0 * f.final_cost;
    if (!(chi2_cur - chi2_new > thr)) break;
    flagged.push_back(best);
    freemask = mask;
    theta = f.theta;
    chi2_cur = chi2_new;
    fit = f;
    have_fit = true;
    L = linearize(*pm, used, theta, fo);
  }
  S.chi2_final = chi2_cur;
  theta_fit = theta;
  if (flagged.empty())
    S.warnings.push_back(
        "no element change is significant: the best single-element fit lowers the chi-square "
        "from " +
        fmt(S.chi2_unchanged) + " to " + fmt(best_chi2) + ", less than the threshold " + fmt(thr) + " requires");
}

// Rank, flags, the 95 % confidence set and mirror twins.
void DetectRun::rank_flags_and_twins() {
  std::vector<int> order = cand;
  if (S.full_dofs)
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return scores[x].probability > scores[y].probability; });
  else
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return scores[x].chi2 < scores[y].chi2; });
  for (std::size_t k = 0; k < order.size(); ++k) scores[order[k]].rank = static_cast<int>(k) + 1;
  for (int e : flagged) scores[e].flagged = true;
  std::vector<int> conf;  // element indices in the 95 % confidence set
  for (int e : order) {
    const ElementScore& b = scores[order.front()];
    const bool in = S.full_dofs ? scores[e].probability >= b.probability - 1e-9
                                : scores[e].chi2 - b.chi2 < chi2_2dof(0.05);
    if (in) {
      conf.push_back(e);
      S.confidence_set.push_back(model.elements()[e].id);
    }
  }
  // Mirror twins of the elements still in question (flagged or in the confidence set) that fit as well.
  const double twin_tol = S.full_dofs ? 1e-9 : chi2_2dof(0.05);
  for (int e : cand) {
    if (!scores[e].flagged && std::find(conf.begin(), conf.end(), e) == conf.end()) continue;
    for (int t : element_twins(syms, e)) {
      if (!scores.count(t)) continue;
      const double d = S.full_dofs ? std::abs(scores[t].probability - scores[e].probability)
                                   : std::abs(scores[t].chi2 - scores[e].chi2);
      if (d < twin_tol) scores[e].twins.push_back(model.elements()[t].id);
    }
  }
  for (int e : order) S.elements.push_back(scores[e]);
  if (S.confidence_set.size() > 1 && !S.confidence_set.empty()) {
    std::string ids;
    for (int id : S.confidence_set) ids += (ids.empty() ? "" : ", ") + std::to_string(id);
    S.warnings.push_back("the data cannot tell apart elements " + ids +
                         " (each fits within the 95 % chi-square band of the best); the ranking among them is not "
                         "significant");
  }
  for (int e : flagged)
    if (!scores[e].twins.empty()) {
      std::string t;
      for (int id : scores[e].twins) t += (t.empty() ? "" : ", ") + std::to_string(id);
      S.warnings.push_back("element " + std::to_string(model.elements()[e].id) + " has mirror twin(s) " + t +
                           " that the data cannot tell apart: the change is in one of them");
    }
}

// Quantification of the flagged elements: first order (eq. 14-21), dlambda_i = sum_j A_ij dk_j + B_ij dm_j with
// the reference modes, then (o.refine) a nonlinear fit.
void DetectRun::quantify() {
  if (flagged.empty() || o.localize_only) return;
  for (int e : flagged) add_params(e);
  const int nc = static_cast<int>(flagged.size());
  ModalState ms;
  ms.theta = pm->nominal();
  ms.lambda = ref.eigenvalues;
  ms.Phi = ref.modes;
  ms.complete = true;  // only eigenvalue derivatives are needed
  const Eigen::MatrixXd dl = eigenvalue_derivatives(*pm, ms, pc.model_mode);
  Eigen::MatrixXd Lm(p, 2 * nc);
  for (int j = 0; j < nc; ++j) {
    Lm.col(j) = dl.col(par_E[flagged[j]]);
    Lm.col(nc + j) = dl.col(par_rho[flagged[j]]);
  }
  Eigen::VectorXd dlam(p);
  for (int k = 0; k < p; ++k) dlam[k] = lam_c[k] - ref.eigenvalues[pc.model_mode[k]];
  const LeastSquaresResult fo_ls = least_squares(Lm, dlam);
  S.first_order_condition = fo_ls.condition;
  if (p < 2 * nc)
    S.warnings.push_back("first-order quantification: " + std::to_string(p) + " modes for " + std::to_string(2 * nc) +
                         " unknowns (p < 2 n_c): the amounts are not unique; the minimum-norm solution is reported");
  else if (fo_ls.condition > 1e8)
    S.warnings.push_back("first-order quantification: L is ill-conditioned (cond " + fmt(fo_ls.condition, 3) +
                         "): stiffness and mass changes trade off; add modes");
  for (int j = 0; j < nc; ++j) {
    ElementAmount am;
    am.element = model.elements()[flagged[j]].id;
    am.dk_first_order = fo_ls.x[j];
    am.dm_first_order = fo_ls.x[nc + j];
    am.dk = am.dk_first_order;
    am.dm = am.dm_first_order;
    am.dk_std = am.dm_std = kNaN;
    S.amounts.push_back(am);
  }
  if (o.refine) refine_amounts(fo_ls);
}

// The amounts from a nonlinear fit: the localization's (reduced DOFs), or one on the frequencies started from the
// first-order amounts (full DOFs: exact eigen-solves).
void DetectRun::refine_amounts(const LeastSquaresResult& fo_ls) {
  const int nc = static_cast<int>(flagged.size());
  if (!have_fit) {
    std::vector<char> mask(static_cast<std::size_t>(pm->num_parameters()), 0);
    Eigen::VectorXd start = pm->nominal();
    for (int j = 0; j < nc; ++j) {
      mask[par_E[flagged[j]]] = mask[par_rho[flagged[j]]] = 1;
      start[par_E[flagged[j]]] = std::clamp(1.0 + fo_ls.x[j], 0.02, 9.0);
      start[par_rho[flagged[j]]] = std::clamp(1.0 + fo_ls.x[nc + j], 0.02, 9.0);
    }
    FitOptions fo;
    fo.objective = FitObjective::kFrequency;
    fo.frequency_noise = o.frequency_noise;
    fo.min_mac = o.min_mac;
    fit = fit_parameters(*pm, modes_subset(changed, pc.used), start, mask, fo);
    theta_fit = fit.theta;
    have_fit = true;
  }
  S.refine_iterations = fit.iterations;
  for (const std::string& w : fit.warnings) S.warnings.push_back("refinement: " + w);
  for (int j = 0; j < nc; ++j) {
    ElementAmount& am = S.amounts[j];
    am.dk = theta_fit[par_E[flagged[j]]] - 1.0;
    am.dm = theta_fit[par_rho[flagged[j]]] - 1.0;
    am.dk_std = fit.stddev[par_E[flagged[j]]];
    am.dm_std = fit.stddev[par_rho[flagged[j]]];
  }
}

}  // namespace

// The driver: locate the measured rows, pair, form residual forces, localize, rank, quantify.
DetectSummary detect(const Model& model, const ModalData& changed_in, const DetectOptions& o,
                     const ModalData* reference_measured) {
  check_detect_inputs(changed_in, o, reference_measured);
  DetectRun run(model, changed_in, o, reference_measured);
  run.order_measured_rows();
  run.cand = candidate_elements(model, o);
  run.reference_modes();
  run.pair_changed_modes();
  run.residual_forces_stage();
  run.pseudo_residual_scores();
  run.localize();
  run.rank_flags_and_twins();
  run.S.time_localization = run.lap();
  run.quantify();
  run.S.time_quantification = run.lap();
  return std::move(run.S);
}

std::vector<NoiseStudyRow> noise_study(const Model& reference, const Model& changed, int element_id,
                                       const NoiseStudyOptions& o) {
  if (o.trials < 1) throw InputError("noise study: trials must be >= 1");
  if (o.dofs.empty()) throw InputError("noise study: no measured DOFs");
  const int e = reference.element_index(element_id);
  if (e < 0) throw InputError("noise study: element " + std::to_string(element_id) + " does not exist");
  EigenOptions eo;
  const int nrb = changed.free_free() ? static_cast<int>(changed.free_rigid_body_modes().cols()) : 0;
  eo.num_modes = nrb + o.modes;
  const ModalResult r = modal_analysis(changed, eo);
  if (!r.ok()) throw NumericalError("noise study: modal analysis of the changed model failed: " + r.summary.message);
  const ModalData exact = sample_modes(changed, r, o.dofs, nrb, o.modes, "noise study");
  const std::vector<Symmetry> syms = find_symmetries(reference);
  const std::vector<int> twins = element_twins(syms, e);
  std::vector<int> twin_ids;
  for (int t : twins) twin_ids.push_back(reference.elements()[t].id);
  std::vector<NoiseStudyRow> rows;
  for (double sn : o.shape_noise) {
    NoiseStudyRow row;
    row.shape_noise = sn;
    row.trials = o.trials;
    std::mt19937_64 rng(o.seed);
    std::normal_distribution<double> N(0.0, 1.0);
    DetectOptions d;
    d.frequency_noise = o.frequency_noise;
    d.shape_noise = sn;
    d.localize_only = true;
    for (int t = 0; t < o.trials; ++t) {
      ModalData m = exact;
      for (Eigen::Index k = 0; k < m.shapes.cols(); ++k) {
        m.frequencies_hz[k] *= 1.0 + o.frequency_noise * N(rng);
        const double big = m.shapes.col(k).cwiseAbs().maxCoeff();
        for (Eigen::Index i = 0; i < m.shapes.rows(); ++i) m.shapes(i, k) += sn * big * N(rng);
      }
      const DetectSummary s = detect(reference, m, d);
      for (const ElementScore& es : s.elements) {
        if (es.element == element_id) {
          row.pseudo_first += es.pseudo_rank == 1;
          row.pseudo_top3 += es.pseudo_rank <= 3;
          row.dynid_first += es.rank == 1;
          row.dynid_top3 += es.rank <= 3;
          for (int tid : twin_ids)
            if (std::find(es.twins.begin(), es.twins.end(), tid) != es.twins.end()) ++row.twin_called;
        }
        if (es.rank == 1 && std::find(twin_ids.begin(), twin_ids.end(), es.element) != twin_ids.end()) ++row.twin_first;
      }
      row.in_confidence_set += std::count(s.confidence_set.begin(), s.confidence_set.end(), element_id) > 0;
      row.mean_set_size += static_cast<double>(s.confidence_set.size()) / o.trials;
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace dynid
