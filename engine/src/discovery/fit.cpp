// Discovery, stage 4: fitting sets of candidates and scoring them by their evidence.
#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <set>

#include "discovery/stages.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid::internal {

int SetFit::parameters() const {
  int n = 0;
  for (const Eigen::VectorXd& t : theta) n += static_cast<int>(t.size());
  return n;
}

FitQuality quality_of(const Problem& p, const Eigen::VectorXd& model_hz, const Eigen::VectorXd& mac, double chi2,
                      const std::vector<char>& forced) {
  FitQuality q;
  q.measured_hz = p.data.frequencies_hz;
  q.model_hz = model_hz;
  q.mac = mac;
  q.chi2 = chi2;
  q.paired.assign(static_cast<std::size_t>(mac.size()), 1);
  // Every mode used pairs plausibly with the model as given (prepare() set the others aside), so the largest
  // frequency error is over the same modes before and after; a mode that loses its partner counts at the one
  // it is forced to (a hypothesis that breaks a pairing shows as a worse fit, never as a better one).
  for (Eigen::Index k = 0; k < mac.size(); ++k) {
    if (static_cast<std::size_t>(k) < forced.size() && forced[static_cast<std::size_t>(k)]) {
      q.paired[static_cast<std::size_t>(k)] = 0;
      ++q.unpaired;
    }
    const double f = p.data.frequencies_hz[k];
    q.max_freq_error_pct = std::max(q.max_freq_error_pct, 100.0 * std::abs(model_hz[k] - f) / f);
  }
  q.mean_mac = mac.size() ? mac.mean() : 0.0;
  return q;
}

namespace {

// A single candidate's start: its magnitude parameter scanned over 1/64 to 16 times its prior scale (both ways
// within the bounds), each point scored by its chi-square less the evidence of the unpartnered modes it pairs.
// A local gradient method started at the nominal value finds the basin nearest the model as given; a mass that
// creates a local mode, or a release that reorders modes, lies in another one.
Eigen::VectorXd scanned_start(const Problem& p, const ParametricModel& pm, const Candidate& c, int* evaluations) {
  Eigen::VectorXd best = pm.nominal();
  const CandidateParameter q = c.parameters()[0];
  const double scale = q.prior_scale > 0 ? q.prior_scale : 0.1 * (q.upper - q.lower);
  try {
    FitProblem fp(pm, p.data, p.fit);
    auto score = [&](const Eigen::VectorXd& th) {
      Eigen::VectorXd r;
      if (!fp.residuals(th, &r)) return std::numeric_limits<double>::infinity();
      return r.squaredNorm() - unpartnered_gain(p, pm, th);
    };
    double best_score = score(best);
    for (double sign : {1.0, -1.0})
      for (double m : {1.0 / 64, 1.0 / 16, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0}) {
        Eigen::VectorXd th = pm.nominal();
        th[0] = q.nominal + sign * m * scale;
        if (th[0] < q.lower || th[0] > q.upper) continue;
        const double v = score(th);
        if (v < best_score) best_score = v, best = th;
      }
    *evaluations += fp.evaluations();
  } catch (const NumericalError&) {
  }
  return best;
}

}  // namespace

SetFit fit_set(const Problem& p, const std::vector<const Candidate*>& set, const std::vector<Eigen::VectorXd>& start) {
  SetFit out;
  out.set = set;
  ParametricModel pm(*p.model);
  const std::vector<int> first = install_candidates(&pm, set);
  Eigen::VectorXd theta0 = pm.nominal();
  for (std::size_t k = 0; k < start.size() && k < set.size(); ++k)
    if (start[k].size()) theta0.segment(first[k], start[k].size()) = start[k];
  if (set.size() == 1 && start.empty()) theta0 = scanned_start(p, pm, *set[0], &out.evaluations);
  FitSummary s;
  try {
    s = fit_parameters(pm, p.data, theta0, {}, p.fit);
  } catch (const NumericalError&) {
    return out;  // the model cannot be solved there (e.g. a release that leaves a mechanism)
  }
  out.evaluations += s.evaluations;
  if (!std::isfinite(s.final_cost)) return out;
  out.chi2 = 2.0 * s.final_cost;
  out.residuals = s.final_residuals;
  out.chi2_frequency = s.final_chi2_frequency;
  out.information = s.information;
  out.information_frequency = s.information_frequency;
  out.quality = quality_of(p, s.final_hz, s.final_mac, out.chi2, s.final_forced);
  for (std::size_t k = 0; k < set.size(); ++k) {
    const std::vector<CandidateParameter> ps = set[k]->parameters();
    const Eigen::Index np = static_cast<Eigen::Index>(ps.size());
    out.theta.push_back(s.theta.segment(first[k], np));
    const double th = s.theta[first[k]], tol = 1e-6 * (ps[0].upper - ps[0].lower);
    if (std::abs(th - ps[0].lower) < tol && ps[0].lower != ps[0].nominal) out.at_bound = true;
    if (std::abs(th - ps[0].upper) < tol && ps[0].upper != ps[0].nominal) out.at_bound = true;
    if (!set[k]->plausible(out.theta.back())) out.at_bound = true;
  }
  out.ok = true;
  out.unpartnered_gain = unpartnered_gain(p, pm, s.theta);
  return out;
}

double unpartnered_gain(const Problem& p, const ParametricModel& pm, const Eigen::VectorXd& theta) {
  if (p.unpartnered.num_modes() == 0) return 0;
  const FitOptions fo = p.fit_for_other_modes();
  double gain = 0;
  try {
    // The whitened residuals of the unpartnered modes at theta, mode by mode (a paired mode's block: its
    // frequency and shape entries; fit_parameters' residual layout).
    FitProblem fp(pm, p.unpartnered, fo);
    Eigen::VectorXd r;
    if (!fp.residuals(theta, &r)) return 0;
    const Correlation c = correlate(pm, p.unpartnered, theta, fo);
    const Eigen::Index block = 1 + static_cast<Eigen::Index>(p.unpartnered.dofs.size());
    for (int k = 0; k < p.unpartnered.num_modes(); ++k) {
      if (c.model_mode[static_cast<std::size_t>(k)] < 0) continue;
      const double chi2 = r.segment(k * block, block).squaredNorm();
      gain += std::max(0.0, p.unpartnered_edge[k] - chi2);
    }
  } catch (const NumericalError&) {
    return 0;
  }
  return gain;
}

namespace {

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// ln of the prior density of one parameter at theta, and its precision (the Laplace approximation's prior term),
// truncated to the bounds (candidate.hpp). Normal: precision 1 / tau^2. Heavy-tailed: the density's local width
// at theta, t + |theta - nominal| (its curvature is negative away from the nominal, but a parameter the data do
// not see must not earn a posterior wider than its prior: the Occam factor stays at most about 1). Uniform:
// precision that of a normal of equal variance (12 / width^2), so that an undetermined parameter stays bounded.
void prior(const CandidateParameter& q, double theta, double* log_density, double* precision) {
  const double w = q.upper - q.lower;
  if (!(q.prior_scale > 0)) {
    *log_density = -std::log(w);
    *precision = 12.0 / (w * w);
    return;
  }
  const double t = q.prior_scale;
  if (q.prior == CandidateParameter::Prior::kHeavyTailed) {
    // Density (1/t) / (1 + |x - x0| / t)^2 on each side of x0 (half the mass each), truncated: the mass on
    // [x0, x0 + d] is (1/2) (1 - 1 / (1 + d / t)).
    auto side = [&](double d) { return d > 0 ? 0.5 * (1.0 - 1.0 / (1.0 + d / t)) : 0.0; };
    const double mass = side(q.upper - q.nominal) + side(q.nominal - q.lower);
    const double z = std::abs(theta - q.nominal) / t;
    *log_density = std::log(0.5 / t) - 2.0 * std::log1p(z) - std::log(std::max(mass, 1e-300));
    *precision = 1.0 / ((t + std::abs(theta - q.nominal)) * (t + std::abs(theta - q.nominal)));
    return;
  }
  const double mass = normal_cdf((q.upper - q.nominal) / t) - normal_cdf((q.lower - q.nominal) / t);
  const double z = (theta - q.nominal) / t;
  *log_density = -0.5 * z * z - std::log(t * std::sqrt(2 * M_PI)) - std::log(std::max(mass, 1e-300));
  *precision = 1.0 / (t * t);
}

}  // namespace

namespace {

// One data type's prediction-error level, as the variance factor u >= 1 over the noise model's (u = 1 + t^2, t the
// model-form error in noise units), and the log likelihood at it. Gaussian errors of variance u (n whitened
// residuals, sum of squares chi2 at u = 1) and a half-normal prior on the model-form error of scale `a` noise units
// (the form error a hypothesis of the right physics still has): ln L(u) = -(n/2) ln u - chi2/(2u) - (u - 1)/(2a^2),
// maximized in closed form (u^2 + n a^2 u - chi2 a^2 = 0). Constants common to all hypotheses dropped.
struct Level {
  double u = 1, log_likelihood = 0;
};
Level level(double chi2, int n, double a) {
  n = std::max(1, n);
  const double a2 = a * a;
  double u = 0.5 * (-n * a2 + std::sqrt(n * a2 * n * a2 + 4 * chi2 * a2));
  if (!(u > 1)) u = 1;
  return {u, -0.5 * n * std::log(u) - 0.5 * chi2 / u - 0.5 * (u - 1) / a2};
}

double form_scale(double form, double noise) { return form / std::max(noise, 1e-12); }

Level frequency_level(const Problem& p, double chi2_frequency) {
  return level(chi2_frequency, p.modes, form_scale(p.options.form_error_frequency, p.noise.frequency));
}
Level shape_level(const Problem& p, double chi2_shape) {
  return level(chi2_shape, p.n - p.modes, form_scale(p.options.form_error_shape, p.noise.shape));
}

// ln of the likelihood of the data at a hypothesis's own prediction-error levels.
double log_likelihood(const Problem& p, double chi2, double chi2_frequency) {
  return frequency_level(p, chi2_frequency).log_likelihood + shape_level(p, chi2 - chi2_frequency).log_likelihood;
}

}  // namespace

ErrorScale error_scale(const Problem& p, double chi2, double chi2_frequency) {
  return {std::sqrt(frequency_level(p, chi2_frequency).u), std::sqrt(shape_level(p, chi2 - chi2_frequency).u)};
}

double scaled_norm2(const Problem& p, const Eigen::VectorXd& r, const ErrorScale& s) {
  const Eigen::Index block = 1 + static_cast<Eigen::Index>(p.data.dofs.size());
  double sum = 0;
  for (Eigen::Index i = 0; i < r.size(); ++i) sum += r[i] * r[i] / (i % block == 0 ? s.frequency * s.frequency : s.shape * s.shape);
  return sum;
}

namespace {

// The inverse posterior covariance from the data at the levels `s` (the prior's precision not included).
Eigen::MatrixXd data_precision(const SetFit& f, const ErrorScale& s) {
  const Eigen::MatrixXd& If = f.information_frequency;
  const Eigen::MatrixXd Is = f.information - If;
  return If / (s.frequency * s.frequency) + Is / (s.shape * s.shape);
}

}  // namespace

double log_evidence(const Problem& p, const SetFit& f) {
  if (!f.ok) return -std::numeric_limits<double>::infinity();
  const ErrorScale s = error_scale(p, f);
  const int k = f.parameters();
  Eigen::MatrixXd H = data_precision(f, s);
  double occam = 0;
  int i = 0;
  for (std::size_t c = 0; c < f.set.size(); ++c) {
    const std::vector<CandidateParameter> ps = f.set[c]->parameters();
    for (std::size_t q = 0; q < ps.size(); ++q, ++i) {
      double lp = 0, prec = 0;
      prior(ps[q], f.theta[c][static_cast<Eigen::Index>(q)], &lp, &prec);
      occam += lp;
      H(i, i) += prec;
    }
    // A uniform prior over the physics (Candidate::physics: the kinds that model one effect at different
    // discretisations share it) and over all the sites of that physics, whichever kind models them.
    const auto it = p.sites_per_physics.find(f.set[c]->physics());
    occam -= std::log(static_cast<double>(std::max<std::size_t>(1, p.sites_per_physics.size()))) +
             std::log(static_cast<double>(it == p.sites_per_physics.end() ? 1 : it->second));
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  double logdet = 0;
  for (Eigen::Index j = 0; j < k; ++j) logdet += std::log(std::max(ldlt.vectorD()[j], 1e-300));
  occam += 0.5 * k * std::log(2 * M_PI) - 0.5 * logdet;
  // The model as given is scored at the noise alone: its form error is what is in question.
  const double fit = log_likelihood(p, f.chi2, f.chi2_frequency) + 0.5 * p.chi2_0;
  return fit + f.unpartnered_gain / (2 * s.frequency * s.frequency) + occam;
}

Eigen::VectorXd posterior_stddev(const SetFit& f, const ErrorScale& s) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(data_precision(f, s));
  const Eigen::VectorXd& ev = es.eigenvalues();
  const double tol = 1e-12 * std::max(1e-300, ev.size() ? ev.maxCoeff() : 0.0);
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(ev.size());
  for (Eigen::Index i = 0; i < ev.size(); ++i)
    inv[i] = ev[i] > tol ? 1.0 / ev[i] : std::numeric_limits<double>::infinity();
  Eigen::VectorXd sd(ev.size());
  for (Eigen::Index j = 0; j < ev.size(); ++j) {
    double v = 0;
    for (Eigen::Index i = 0; i < ev.size(); ++i) {
      const double w = es.eigenvectors()(j, i);
      if (w != 0) v += w * w * inv[i];
    }
    sd[j] = std::sqrt(v);
  }
  return sd;
}

namespace {

Eigen::Index offset_of(const SetFit& f, std::size_t k) {
  Eigen::Index o = 0;
  for (std::size_t c = 0; c < k; ++c) o += f.theta[c].size();
  return o;
}

}  // namespace

double explained_share(const Problem& p, const SetFit& f, double chi2_best) {
  const double span = p.chi2_0 - chi2_best;
  return f.ok && span > 0 ? std::clamp((p.chi2_0 - f.chi2) / span, 0.0, 1.0) : 0.0;
}

double significance(const Problem& p, const SetFit& f, std::size_t k) {
  if (!f.ok) return 0;
  // The magnitude parameter (the first: a mass, a stiffness, a fraction) against its nominal.
  const CandidateParameter q = f.set[k]->parameters()[0];
  const double th = f.theta[k][0], sd = posterior_stddev(f, error_scale(p, f))[offset_of(f, k)];
  const double tol = 1e-6 * (q.upper - q.lower);
  if ((std::abs(th - q.lower) < tol && q.lower != q.nominal) || (std::abs(th - q.upper) < tol && q.upper != q.nominal))
    return 0.0;  // on a bound: the hypothesis strains to fit
  return std::isfinite(sd) && sd > 0 ? std::abs(th - q.nominal) / sd : 0.0;
}

ScoredHypothesis scored(const Problem& p, const SetFit& f, std::size_t k) {
  const Candidate& c = *f.set[k];
  ScoredHypothesis h;
  h.kind = c.kind();
  h.nature = c.nature();
  h.description = c.description();
  h.site = c.site();
  h.global = c.global();
  h.parameters = static_cast<int>(c.parameters().size());
  h.fitted = f.ok;
  if (!f.ok) return h;
  h.chi2 = f.chi2;
  // Reported standard deviations: the posterior's at the set's error levels, the frequencies' counted over the
  // degrees of freedom the fit leaves them (the values rest on the frequencies), with the candidate's model-form
  // uncertainty, `model_form` of its change from nominal, in quadrature.
  ErrorScale s = error_scale(p, f);
  s.frequency = std::max(s.frequency, std::sqrt(std::max(1.0, f.chi2_frequency / std::max(1, p.modes - f.parameters()))));
  const std::vector<CandidateParameter> ps = c.parameters();
  Eigen::VectorXd sd = posterior_stddev(f, s).segment(offset_of(f, k), f.theta[k].size());
  for (Eigen::Index q = 0; q < sd.size(); ++q)
    sd[q] = std::hypot(sd[q], p.options.model_form * std::abs(f.theta[k][q] - ps[static_cast<std::size_t>(q)].nominal));
  h.values = c.physical(f.theta[k], sd);
  if (!p.options.si_units)
    for (PhysicalValue& v : h.values)
      if (!v.unit.empty() && v.unit != "%") v.unit = "(model units)";
  h.finding = c.finding(h.values);
  h.max_freq_error_pct = f.quality.max_freq_error_pct;
  h.mean_mac = f.quality.mean_mac;
  h.at_bound = f.at_bound;
  return h;
}

bool same_story(const Model& m, const Candidate& a, const Candidate& b) {
  if (a.global() || b.global()) return a.kind() == b.kind();
  if (a.nature() != b.nature() && a.nature() != Nature::kBoth && b.nature() != Nature::kBoth) return false;
  auto nodes = [&](const Candidate& c) {
    const Site site = c.site();
    std::set<int> n(site.nodes.begin(), site.nodes.end());
    for (int id : site.elements) {
      const int e = m.element_index(id);
      for (int k = 0; k < m.elements()[e].num_nodes; ++k) n.insert(m.nodes()[m.element_nodes(e)[k]].id);
    }
    return n;
  };
  const std::set<int> na = nodes(a), nb = nodes(b);
  for (int n : na)
    if (nb.count(n)) return true;
  return false;
}

}  // namespace dynid::internal
