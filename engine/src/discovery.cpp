#include "dynid/engine/discovery.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <set>

#include "dynid/engine/modal.hpp"
#include "dynid/engine/serep.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/candidates.hpp"

namespace dynid {

bool DiscoveryOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(frequency_noise > 0) || !(shape_noise > 0)) return fail("noise levels must be > 0");
  if (screen_fit < 1) return fail("screen_fit must be >= 1");
  if (max_effects < 1) return fail("max_effects must be >= 1");
  if (!(decisive > 0) || !(ambiguity >= 0)) return fail("decisive must be > 0 and ambiguity >= 0");
  if (!(min_misfit >= 0)) return fail("min_misfit must be >= 0");
  return fit.IsValid(why);
}

std::vector<std::unique_ptr<Candidate>> candidate_library(const Model& model, const ModalData& measured,
                                                          const DiscoveryOptions& options) {
  return internal::library(model, measured, options);
}

std::vector<int> install_candidates(ParametricModel* pm, const std::vector<const Candidate*>& set) {
  std::vector<int> first;
  for (const Candidate* c : set) {
    first.push_back(pm->num_parameters());
    for (const CandidateParameter& q : c->parameters()) {
      Parameter p;
      p.name = c->kind() + "." + q.name;
      p.kind = ParameterKind::kCustom;
      p.nominal = q.nominal;
      p.lower = q.lower;
      p.upper = q.upper;
      pm->add(p);
    }
  }
  for (std::size_t k = 0; k < set.size(); ++k)
    for (CustomTerm& t : set[k]->terms(pm->model(), first[k])) pm->add_term(std::move(t));
  return first;
}

namespace {

using internal::fmt_value;

// A set of candidates installed on a ParametricModel (parameters in candidate order).
struct Installed {
  std::unique_ptr<ParametricModel> pm;
  std::vector<int> first;  // first parameter of each candidate
};

Installed install(const Model& model, const std::vector<const Candidate*>& set) {
  Installed in;
  in.pm = std::make_unique<ParametricModel>(model);
  in.first = install_candidates(in.pm.get(), set);
  return in;
}

struct SetFit {
  bool ok = false;
  std::vector<Eigen::VectorXd> theta, stddev;  // per candidate
  double chi2 = 0;
  FitQuality quality;
  bool at_bound = false;
  int evaluations = 0;
};

FitQuality quality_of(const Eigen::VectorXd& meas, const Eigen::VectorXd& model_hz, const Eigen::VectorXd& mac, double chi2) {
  FitQuality q;
  q.measured_hz = meas;
  q.model_hz = model_hz;
  q.mac = mac;
  q.chi2 = chi2;
  // Frequency errors of the modes that pair (MAC >= 0.5); a measured mode without a counterpart in the model
  // (a new local mode) is counted as unpaired instead of as an error against whatever mode it was forced to.
  for (Eigen::Index k = 0; k < meas.size(); ++k) {
    if (mac[k] < 0.5) {
      ++q.unpaired;
      continue;
    }
    q.max_freq_error_pct = std::max(q.max_freq_error_pct, 100.0 * std::abs(model_hz[k] - meas[k]) / meas[k]);
  }
  q.mean_mac = mac.size() ? mac.mean() : 0.0;
  return q;
}

SetFit fit_set(const Model& model, const ModalData& meas, const std::vector<const Candidate*>& set,
               const std::vector<Eigen::VectorXd>& start, const FitOptions& fo) {
  SetFit out;
  try {
    Installed in = install(model, set);
    Eigen::VectorXd theta0 = in.pm->nominal();
    for (std::size_t k = 0; k < start.size() && k < set.size(); ++k)
      if (start[k].size()) theta0.segment(in.first[k], start[k].size()) = start[k];
    const FitSummary s = fit_parameters(*in.pm, meas, theta0, {}, fo);
    out.evaluations = s.evaluations;
    if (!std::isfinite(s.final_cost)) return out;
    out.chi2 = 2.0 * s.final_cost;
    out.quality = quality_of(s.measured_hz, s.final_hz, s.final_mac, out.chi2);
    out.at_bound = !s.at_bound.empty();
    for (std::size_t k = 0; k < set.size(); ++k) {
      const Eigen::Index np = static_cast<Eigen::Index>(set[k]->parameters().size());
      out.theta.push_back(s.theta.segment(in.first[k], np));
      out.stddev.push_back(s.stddev.segment(in.first[k], np));
    }
    out.ok = true;
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

// Smallest |theta - nominal| / std over candidate k's parameters, the std scaled a posteriori by the misfit
// (sqrt(chi2 / (n - p)) when that exceeds 1: with model-form error the stated noise understates it).
double significance(const SetFit& f, std::size_t k, const Candidate& c, int n, int p) {
  const double scale = std::max(1.0, std::sqrt(f.chi2 / std::max(1, n - p)));
  const std::vector<CandidateParameter> ps = c.parameters();
  double z = std::numeric_limits<double>::infinity();
  for (std::size_t q = 0; q < ps.size(); ++q) {
    const double sd = f.stddev[k][static_cast<Eigen::Index>(q)] * scale;
    const double th = f.theta[k][static_cast<Eigen::Index>(q)];
    const double d = std::abs(th - ps[q].nominal);
    const double tol = 1e-6 * (ps[q].upper - ps[q].lower);
    if (std::abs(th - ps[q].lower) < tol || std::abs(th - ps[q].upper) < tol) return 0.0;  // on a bound
    z = std::min(z, std::isfinite(sd) && sd > 0 ? d / sd : 0.0);
  }
  return z;
}

double bic(double chi2, int n, int k, double penalty) {
  return n * std::log(std::max(chi2, 1e-300) / n) + k * std::log(static_cast<double>(n)) + penalty;
}

bool near(const Model& m, const Site& a, const Site& b) {
  std::set<int> na(a.nodes.begin(), a.nodes.end()), nb(b.nodes.begin(), b.nodes.end());
  for (int id : a.elements) {
    const int e = m.element_index(id);
    for (int k = 0; k < 2; ++k) na.insert(m.nodes()[m.element_nodes(e)[k]].id);
  }
  for (int id : b.elements) {
    const int e = m.element_index(id);
    for (int k = 0; k < 2; ++k) nb.insert(m.nodes()[m.element_nodes(e)[k]].id);
  }
  for (int n : na)
    if (nb.count(n)) return true;
  return false;
}

// A share as a whole percentage: "27", "100".
std::string pct(double share) { return std::to_string(static_cast<int>(std::lround(100.0 * share))); }

Localization locate(const Model& model, const ModalData& meas, const std::vector<int>& rows) {
  Localization L;
  L.dofs = meas.dofs;
  const int a = static_cast<int>(rows.size());
  EigenOptions eo;
  const int n = model.num_dofs();
  eo.num_modes = std::min(n, a + 6 + 10);
  if (n <= 400) eo.method = EigenOptions::Method::kDense;
  const ModalResult mr = modal_analysis(model, eo);
  if (!mr.ok()) throw NumericalError("discover: modal analysis of the model failed: " + mr.summary.message);
  // Few modes in the SEREP basis: the measured ones and a margin. With as many modes as masters the reduced
  // stiffness carries the highest modes, which amplify every bit of shape noise into residual force.
  const int m = std::min<int>({a, static_cast<int>(mr.eigenvalues.size()), meas.num_modes() + 4});
  const SerepReduction sr = serep_reduce(mr.modes.leftCols(m), mr.eigenvalues.head(m), rows);
  const int p = meas.num_modes();
  L.residuals.resize(a, p);
  Eigen::VectorXd logsum = Eigen::VectorXd::Zero(a);
  double align = 0;
  for (int k = 0; k < p; ++k) {
    Eigen::VectorXd u = meas.shapes.col(k);
    const double mm = u.dot(sr.M * u);
    if (mm > 0) u /= std::sqrt(mm);
    const double lam = hz_to_eigenvalue(meas.frequencies_hz[k]);
    const Eigen::VectorXd r = sr.K * u - lam * (sr.M * u);
    const Eigen::VectorXd f = lam * (sr.M * u);
    L.residuals.col(k) = r;
    const double rn = std::max(r.norm(), 1e-300);
    for (int d = 0; d < a; ++d) logsum[d] += std::log(std::max(std::abs(r[d]) / rn, 1e-12));
    align += std::abs(r.dot(f)) / (rn * std::max(f.norm(), 1e-300));
  }
  L.mass_alignment = p ? align / p : 0.0;
  L.pseudo = (logsum / std::max(p, 1)).array().exp();
  const double tot = std::max(L.pseudo.squaredNorm(), 1e-300);
  std::map<int, Localization::NodeShare> by;
  for (int d = 0; d < a; ++d) {
    const double s = L.pseudo[d] * L.pseudo[d] / tot;
    auto& ns = by[meas.dofs[d].node];
    ns.node = meas.dofs[d].node;
    ns.share += s;
    const int t = static_cast<int>(meas.dofs[d].dof);
    if (t == 0) ns.x += s;
    if (t == 1) ns.y += s;
    if (t == 2) ns.z += s;
    if (t < 3) L.direction_share[t] += s;
  }
  for (auto& [id, ns] : by) L.nodes.push_back(ns);
  std::sort(L.nodes.begin(), L.nodes.end(), [](const auto& x, const auto& y) { return x.share > y.share; });
  const int top = std::max(1, static_cast<int>(std::ceil(0.2 * static_cast<double>(L.nodes.size()))));
  for (int k = 0; k < top && k < static_cast<int>(L.nodes.size()); ++k) L.concentration += L.nodes[k].share;
  L.localized = L.nodes.size() >= 3 && L.concentration > 0.5;
  return L;
}

// Physical values of a candidate, with SI unit labels or, for models in other consistent units, "model units".
std::vector<PhysicalValue> values_of(const Candidate& c, const Eigen::VectorXd& th, const Eigen::VectorXd& sd, bool si) {
  std::vector<PhysicalValue> v = c.physical(th, sd);
  if (!si)
    for (PhysicalValue& p : v)
      if (!p.unit.empty() && p.unit != "%") p.unit = "(model units)";
  return v;
}

// Candidate `k` of a fitted set, scored by the set's BIC `score` (+inf if the fit failed).
ScoredHypothesis scored(const Candidate& c, const SetFit& f, std::size_t k, double score, bool si) {
  ScoredHypothesis h;
  h.kind = c.kind();
  h.description = c.description();
  h.site = c.site();
  h.global = c.global();
  h.parameters = static_cast<int>(c.parameters().size());
  h.fitted = f.ok;
  h.bic = std::numeric_limits<double>::infinity();
  if (!f.ok) return h;
  h.chi2 = f.chi2;
  h.bic = score;
  h.values = values_of(c, f.theta[k], f.stddev[k], si);
  h.finding = c.finding(h.values);
  h.max_freq_error_pct = f.quality.max_freq_error_pct;
  h.mean_mac = f.quality.mean_mac;
  h.at_bound = f.at_bound;
  return h;
}

}  // namespace

DiscoverySummary discover(const Model& model, const ModalData& measured, const DiscoveryOptions& options,
                          std::vector<std::unique_ptr<Candidate>> extra) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!options.IsValid(&why)) throw InputError("discover options: " + why);
  measured.validate("measured modal data");
  if (measured.num_modes() < 2) throw InputError("discover: at least 2 measured modes are needed");
  const std::vector<int> rows = measured_equations(model, measured.dofs);
  DiscoverySummary S;
  FitOptions fo = options.fit;
  fo.objective = FitObjective::kCombined;
  fo.frequency_noise = options.frequency_noise;
  fo.shape_noise = options.shape_noise;
  fo.regularization = 0;
  fo.ties.clear();
  fo.dense_max_dofs = std::min(fo.dense_max_dofs, 40);
  if (measured.frequency_std_hz.size() == measured.num_modes() && measured.num_modes() > 0) {
    // Identified data carry their own frequency scatter (over model orders): use its median when it is larger
    // than the floor (one poorly stabilised mode does not loosen every other).
    Eigen::VectorXd relv = measured.frequency_std_hz.array() / measured.frequencies_hz.array();
    std::sort(relv.data(), relv.data() + relv.size());
    const double rel = relv[relv.size() / 2];
    if (std::isfinite(rel) && rel > fo.frequency_noise) fo.frequency_noise = rel;
  }

  // ---- candidates ----
  std::vector<std::unique_ptr<Candidate>> lib = internal::library(model, measured, options);
  for (auto& c : extra) lib.push_back(std::move(c));
  const std::unique_ptr<Candidate> recal = internal::make_recalibration(model);
  std::map<std::string, int> per_kind;
  for (const auto& c : lib) ++per_kind[c->kind()];
  auto penalty = [&](const Candidate& c) { return 2.0 * std::log(static_cast<double>(std::max(per_kind[c.kind()], 1))); };
  std::vector<int> local, global;
  for (int k = 0; k < static_cast<int>(lib.size()); ++k) {
    const auto& c = lib[k];
    if (c->parameters().size() != 1 && !c->global()) continue;
    (c->global() ? global : local).push_back(k);
  }

  // ---- step 1: locate (residual forces) and screen every local candidate (one linearisation) ----
  S.localization = locate(model, measured, rows);
  std::vector<const Candidate*> screen_set;
  for (int k : local) screen_set.push_back(lib[k].get());
  Installed scr = install(model, screen_set);
  const Linearization lin = linearize(*scr.pm, measured, scr.pm->nominal(), fo);
  const int n = static_cast<int>(lin.r.size());
  S.data = n;
  const double chi2_0 = lin.r.squaredNorm();
  {
    double cf = 0;
    for (int b : lin.block_start) cf += lin.r[b] * lin.r[b];
    const int p = static_cast<int>(lin.block_start.size());
    S.chi2_frequency_before = cf / std::max(p, 1);
    S.chi2_shape_before = (chi2_0 - cf) / std::max(n - p, 1);
    S.chi2_per_datum_before = std::max(S.chi2_frequency_before, S.chi2_shape_before);
  }
  S.before = quality_of(measured.frequencies_hz, lin.model_hz, lin.mac, chi2_0);
  S.after = S.before;
  const double bic0 = bic(chi2_0, n, 0, 0.0);
  S.eigen_solves = 2;
  // Linear chi-square drop of one column, honouring the bound at the nominal value; columns in C are refitted.
  auto drop = [&](const Eigen::MatrixXd& J, const Eigen::VectorXd& r, int col, const Eigen::MatrixXd* C, const Parameter& q) {
    Eigen::VectorXd j = J.col(col);
    if (C && C->cols()) j -= *C * C->colPivHouseholderQr().solve(j);
    const double h = j.squaredNorm();
    if (!(h > 0)) return 0.0;
    const double g = j.dot(r), step = -g / h;
    if ((q.nominal <= q.lower && step < 0) || (q.nominal >= q.upper && step > 0)) return 0.0;
    return g * g / h;
  };
  std::vector<double> screening(lib.size(), 0.0);
  for (std::size_t k = 0; k < local.size(); ++k)
    screening[local[k]] = drop(lin.J, lin.r, scr.first[k], nullptr, scr.pm->parameter(scr.first[k]));

  // Nature of the mismatch from the screening: stiffness-type or mass-type candidates explain more.
  double best_k = 0, best_m = 0;
  for (int k : local) {
    const std::string kd = lib[k]->kind();
    const bool mass = kd == "lumped_mass" || kd == "element_mass";
    (mass ? best_m : best_k) = std::max(mass ? best_m : best_k, screening[k]);
  }
  {
    Localization& L = S.localization;
    L.mean_frequency_error_pct = 100.0 * ((lin.model_hz - measured.frequencies_hz).array() / measured.frequencies_hz.array()).mean();
    L.nature = best_m > best_k ? "mass" : "stiffness";
    std::string where;
    for (std::size_t k = 0; k < L.nodes.size() && k < 3; ++k)
      where += (k ? ", " : "") + std::to_string(L.nodes[k].node) + " (" + pct(L.nodes[k].share) + " %)";
    const Eigen::Vector3d& ds = L.direction_share;
    const char* dir = ds[0] >= ds[1] && ds[0] >= ds[2] ? "x" : ds[1] >= ds[2] ? "y" : "z";
    L.words = L.nodes.size() < 3
                  ? "Only " + std::to_string(L.nodes.size()) + " measured node" + (L.nodes.size() > 1 ? "s" : "") +
                        ": the residual forces cannot say where. The model is "
                  : std::string("The residual forces are ") + (L.localized ? "localized" : "spread over the structure") +
                        ": largest at nodes " + where + "; " + pct(L.concentration) +
                        " % in the top fifth of the measured nodes, mostly in " + dir + ". The model is ";
    L.words += std::string() +
              (L.mean_frequency_error_pct > 0 ? "stiffer" : "softer") + " than the data on average (mean frequency error " +
              fmt_value(L.mean_frequency_error_pct, 3) + " %); the mismatch is " + L.nature + "-like (residual alignment with inertia forces " +
              fmt_value(L.mass_alignment, 2) + ").";
    if (S.chi2_per_datum_before <= options.min_misfit)
      L.words = "The model fits within the stated noise, so what follows describes noise, not a mismatch. " + L.words;
  }

  // ---- steps 2-3: fit the screened local candidates, every global one, and the recalibration ----
  std::vector<int> order(local);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return screening[x] > screening[y]; });
  std::vector<int> to_fit(order.begin(), order.begin() + std::min<std::size_t>(order.size(), static_cast<std::size_t>(options.screen_fit)));
  // The linear screening can mislead when a measured mode has no counterpart in the model (a new local mode):
  // the node-site candidates at the three nodes carrying most residual force are fitted too.
  for (std::size_t t = 0; t < S.localization.nodes.size() && t < 3; ++t)
    for (int k : local)
      if (lib[k]->site().nodes.size() == 1 && lib[k]->site().nodes[0] == S.localization.nodes[t].node &&
          std::find(to_fit.begin(), to_fit.end(), k) == to_fit.end())
        to_fit.push_back(k);
  to_fit.insert(to_fit.end(), global.begin(), global.end());
  std::vector<SetFit> fits(to_fit.size());
  SetFit recal_fit;
#pragma omp parallel for schedule(dynamic)
  for (int k = 0; k <= static_cast<int>(to_fit.size()); ++k) {
    if (k == static_cast<int>(to_fit.size())) recal_fit = fit_set(model, measured, {recal.get()}, {}, fo);
    else fits[k] = fit_set(model, measured, {lib[to_fit[k]].get()}, {}, fo);
  }
  for (std::size_t k = 0; k < to_fit.size(); ++k) {
    S.eigen_solves += fits[k].evaluations;
    const Candidate& c = *lib[to_fit[k]];
    ScoredHypothesis h = scored(c, fits[k], 0, bic(fits[k].chi2, n, static_cast<int>(c.parameters().size()), penalty(c)), options.si_units);
    h.screening = screening[to_fit[k]];
    h.delta_bic = bic0 - h.bic;
    S.candidates.push_back(std::move(h));
  }
  S.eigen_solves += recal_fit.evaluations;
  S.recalibration = scored(*recal, recal_fit, 0, bic(recal_fit.chi2, n, static_cast<int>(recal->parameters().size()), 0.0), options.si_units);
  S.recalibration.delta_bic = bic0 - S.recalibration.bic;
  // Ranked best first; the fitted index of each ranked hypothesis kept for the greedy stage.
  std::vector<int> rank(to_fit.size());
  std::iota(rank.begin(), rank.end(), 0);
  std::stable_sort(rank.begin(), rank.end(), [&](int x, int y) { return S.candidates[x].bic < S.candidates[y].bic; });
  {
    std::vector<ScoredHypothesis> sorted;
    for (int r : rank) sorted.push_back(S.candidates[r]);
    S.candidates = std::move(sorted);
  }

  const bool misfit = S.chi2_per_datum_before > options.min_misfit;
  if (S.candidates.empty() || !misfit || !(S.candidates[0].delta_bic > options.decisive)) {
    // Consistent only when the model fits within the noise; a misfit that no candidate explains is inconclusive.
    S.verdict = misfit ? "inconclusive" : "consistent";
    S.explanation = misfit ? "The model misfits the data (chi-square per datum: frequencies " + fmt_value(S.chi2_frequency_before, 3) +
                                 ", shapes " + fmt_value(S.chi2_shape_before, 3) + "; max frequency error " +
                                 fmt_value(S.before.max_freq_error_pct, 3) + " %) but " :
                           "No missing physics found: ";
    if (!misfit)
      S.explanation += "the model fits the data within the stated noise (chi-square per datum: frequencies " +
                       fmt_value(S.chi2_frequency_before, 3) + ", shapes " + fmt_value(S.chi2_shape_before, 3) +
                       " <= " + fmt_value(options.min_misfit, 3) + "; max frequency error " + fmt_value(S.before.max_freq_error_pct, 3) +
                       " %, mean MAC " + fmt_value(S.before.mean_mac, 5) + ").";
    else
      S.explanation += "no candidate in the library explains it decisively (best: " +
                       (S.candidates.empty() ? std::string("none") : S.candidates[0].description) + ", BIC improvement " +
                       fmt_value(S.candidates.empty() ? 0.0 : S.candidates[0].delta_bic, 3) + " < " + fmt_value(options.decisive, 3) +
                       "). More modes or more measured DOFs would constrain the candidates; an effect outside the library "
                       "(e.g. several properties off at once) is also possible.";
    S.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return S;
  }

  // The misfit left is within the noise: nothing further to explain.
  auto explained = [&](const SetFit& f) {
    return f.chi2 / n <= options.min_misfit && f.quality.max_freq_error_pct < 300 * fo.frequency_noise;
  };
  auto grow = [&](std::vector<const Candidate*>& chosen, SetFit& chosen_fit, double& chosen_bic) {
    for (int effect = 1; effect < options.max_effects; ++effect) {
      // Re-screen the local candidates with the chosen effects in the model (their parameters refitted).
      std::vector<const Candidate*> set = chosen;
      std::vector<int> others;
      for (int k : local) {
        bool used = false;
        for (const Candidate* c : chosen) used = used || c == lib[k].get();
        if (!used) {
          set.push_back(lib[k].get());
          others.push_back(k);
        }
      }
      Installed in = install(model, set);
      Eigen::VectorXd th = in.pm->nominal();
      int nc = 0;
      for (std::size_t k = 0; k < chosen.size(); ++k) {
        th.segment(in.first[k], chosen_fit.theta[k].size()) = chosen_fit.theta[k];
        nc += static_cast<int>(chosen_fit.theta[k].size());
      }
      Linearization l2;
      try {
        l2 = linearize(*in.pm, measured, th, fo);
      } catch (const std::exception&) {
        break;
      }
      ++S.eigen_solves;
      const Eigen::MatrixXd C = l2.J.leftCols(nc);
      std::vector<std::pair<double, int>> sc;
      for (std::size_t k = 0; k < others.size(); ++k) {
        const int col = in.first[chosen.size() + k];
        sc.push_back({drop(l2.J, l2.r, col, &C, in.pm->parameter(col)), others[k]});
      }
      std::stable_sort(sc.begin(), sc.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
      std::vector<int> tries;
      for (std::size_t k = 0; k < sc.size() && static_cast<int>(k) < std::max(2, options.screen_fit / 2); ++k) tries.push_back(sc[k].second);
      for (int g : global) {
        bool used = false;
        for (const Candidate* c : chosen) used = used || c == lib[g].get();
        if (!used) tries.push_back(g);
      }
      std::vector<SetFit> f2(tries.size());
  #pragma omp parallel for schedule(dynamic)
      for (int k = 0; k < static_cast<int>(tries.size()); ++k) {
        std::vector<const Candidate*> s2 = chosen;
        s2.push_back(lib[tries[k]].get());
        f2[k] = fit_set(model, measured, s2, chosen_fit.theta, fo);
      }
      int best = -1;
      double best_bic = chosen_bic - options.decisive;
      // A further effect only while the misfit left is beyond the noise, and only with parameters that the data
      // determine (|theta| > min_significance std, a posteriori).
      if (explained(chosen_fit)) break;
      for (std::size_t k = 0; k < tries.size(); ++k) {
        S.eigen_solves += f2[k].evaluations;
        if (!f2[k].ok) continue;
        int ptot = 0;
        for (const Candidate* c : chosen) ptot += static_cast<int>(c->parameters().size());
        ptot += static_cast<int>(lib[tries[k]]->parameters().size());
        if (significance(f2[k], chosen.size(), *lib[tries[k]], n, ptot) < options.min_significance) continue;
      // At most one fitted parameter per two measured modes: the frequencies are the data to trust.
      if (2 * ptot > std::max(2, measured.num_modes())) continue;
        int np = 0;
        double pen = 0;
        for (const Candidate* c : chosen) {
          np += static_cast<int>(c->parameters().size());
          pen += penalty(*c);
        }
        np += static_cast<int>(lib[tries[k]]->parameters().size());
        pen += penalty(*lib[tries[k]]);
        const double b = bic(f2[k].chi2, n, np, pen);
        if (b < best_bic) {
          best_bic = b;
          best = static_cast<int>(k);
        }
      }
      if (best < 0) break;
      chosen.push_back(lib[tries[best]].get());
      chosen_fit = f2[best];
      chosen_bic = best_bic;
    }
  };

  // ---- greedy: add further effects while the score improves decisively ----
  // A small beam search: when the growth from the best single effect still leaves a misfit beyond the noise
  // (two effects at once can make the best single one a compromise that misleads the growth), it also starts
  // from the second and third best single effects, and the best final combination is kept. When the best
  // single effect's growth explains the data to the noise, the alternatives are not explored: more effects
  // fitting systematic identification errors must not outbid a complete, simpler explanation.
  std::vector<const Candidate*> chosen;
  SetFit chosen_fit;
  double chosen_bic = std::numeric_limits<double>::infinity();
  for (int start = 0; start < std::min<int>(3, static_cast<int>(rank.size())); ++start) {
    if (!S.candidates[static_cast<std::size_t>(start)].fitted) continue;
    if (start > 0 && (explained(chosen_fit) || !(S.candidates[static_cast<std::size_t>(start)].delta_bic > options.decisive))) break;
    std::vector<const Candidate*> grown = {lib[to_fit[rank[static_cast<std::size_t>(start)]]].get()};
    SetFit grown_fit = fits[rank[static_cast<std::size_t>(start)]];
    double grown_bic = S.candidates[static_cast<std::size_t>(start)].bic;
    grow(grown, grown_fit, grown_bic);
    if (grown_bic < chosen_bic) {
      chosen = grown;
      chosen_fit = grown_fit;
      chosen_bic = grown_bic;
    }
  }

  // ---- findings ----
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    ScoredHypothesis h = scored(*chosen[k], chosen_fit, k, chosen_bic, options.si_units);
    h.delta_bic = bic0 - chosen_bic;
    S.findings.push_back(std::move(h));
  }
  S.after = chosen_fit.quality;

  // ---- verdict: decisive against the nominal model; ambiguous against a different explanation ----
  const ScoredHypothesis& best = S.candidates[0];
  std::vector<std::string> rivals;
  for (std::size_t k = 1; k < S.candidates.size(); ++k) {
    const ScoredHypothesis& h = S.candidates[k];
    if (!h.fitted || h.bic > best.bic + options.ambiguity) continue;
    const bool same = h.kind == best.kind || (!h.global && !best.global && near(model, h.site, best.site));
    if (!same) rivals.push_back(h.description + " (BIC +" + fmt_value(h.bic - best.bic, 2) + ")");
  }
  const bool recal_rival = S.recalibration.fitted && S.recalibration.bic <= best.bic + options.ambiguity;
  std::string found;
  for (const ScoredHypothesis& h : S.findings) found += (found.empty() ? "" : "; and ") + h.finding;
  const std::string fit_words = "max frequency error " + fmt_value(S.before.max_freq_error_pct, 3) + " % -> " +
                                fmt_value(S.after.max_freq_error_pct, 3) + " %, mean MAC " + fmt_value(S.before.mean_mac, 4) +
                                " -> " + fmt_value(S.after.mean_mac, 4);
  if (!rivals.empty() || recal_rival) {
    S.verdict = "inconclusive";
    S.explanation = "The model misses something (best: " + best.description + ", BIC improvement " + fmt_value(best.delta_bic, 3) +
                    "), but the data cannot tell it from ";
    if (recal_rival) rivals.push_back("recalibrating E and rho globally (BIC " + fmt_value(S.recalibration.bic - best.bic, 2) + ")");
    for (std::size_t k = 0; k < rivals.size(); ++k) S.explanation += (k ? ", " : "") + rivals[k];
    S.explanation += ". More modes, or sensors at the competing sites (rotations or strains there), would decide. "
                     "The best fit: " + found + " (" + fit_words + ").";
  } else {
    S.verdict = "missing_physics";
    S.explanation = "Missing physics: " + found + ". " + fit_words + "; BIC improvement " + fmt_value(S.findings.back().delta_bic, 3) +
                    " over the model as given and " + fmt_value(S.recalibration.bic - chosen_bic, 3) +
                    " over recalibrating E and rho globally" +
                    (S.candidates.size() > 1 ? ", " + fmt_value(S.candidates[1].bic - best.bic, 3) + " over the runner-up (" + S.candidates[1].description + ")" : std::string()) + ".";
  }
  S.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return S;
}

}  // namespace dynid
