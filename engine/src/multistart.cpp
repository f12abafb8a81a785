#include "dynid/engine/multistart.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <numeric>

#include "dynid/mesh/error.hpp"
#include "internal/free_parameters.hpp"
#include "internal/parallel.hpp"

namespace dynid {

bool MultiStartOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (starts < 0) return fail("starts must be >= 0 (0 = the rule)");
  if (!(same_minimum > 0 && same_minimum < 1)) return fail("same_minimum must be in (0, 1)");
  return true;
}

int starts_for(int free_parameters) { return std::clamp(2 * free_parameters, 8, 32); }

namespace {

// A small deterministic generator (splitmix64): the same points on every platform and standard library.
struct Rng {
  std::uint64_t s;
  std::uint64_t next() {
    std::uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

}  // namespace

std::vector<Eigen::VectorXd> multistart_points(const ParametricModel& pm, const Eigen::VectorXd& theta0,
                                               const std::vector<char>& is_free, const FitOptions& o,
                                               const MultiStartOptions& ms) {
  std::string why;
  if (!ms.IsValid(&why)) throw InputError("multistart options: " + why);
  if (theta0.size() != pm.num_parameters())
    throw InputError("multistart: " + std::to_string(theta0.size()) + " start values for " + std::to_string(pm.num_parameters()) + " parameters");
  const std::vector<int> free = internal::free_parameters(pm, is_free, o);
  for (int p : free)
    if (!std::isfinite(pm.parameter(p).lower) || !std::isfinite(pm.parameter(p).upper))
      throw InputError("multistart: parameter '" + pm.parameter(p).name +
                       "' has no finite bounds; the starts fill the bounds: give it bounds: [low, high]");
  const int n = ms.starts > 0 ? ms.starts : starts_for(static_cast<int>(free.size()));

  // Start 0: the user's values; starts 1..n-1: a Latin hypercube (one point per stratum in every parameter).
  std::vector<Eigen::VectorXd> points(static_cast<std::size_t>(n), theta0);
  Rng rng{ms.seed};
  const int m = n - 1;
  for (int p : free) {
    std::vector<int> perm(static_cast<std::size_t>(m));
    std::iota(perm.begin(), perm.end(), 0);
    for (int i = m - 1; i > 0; --i) std::swap(perm[static_cast<std::size_t>(i)], perm[rng.next() % static_cast<std::uint64_t>(i + 1)]);
    const Parameter& q = pm.parameter(p);
    const bool log = q.lower > 0 && q.upper >= 10 * q.lower;
    for (int i = 0; i < m; ++i) {
      const double u = (perm[static_cast<std::size_t>(i)] + rng.uniform()) / m;
      const double v = log ? q.lower * std::pow(q.upper / q.lower, u) : q.lower + u * (q.upper - q.lower);
      points[static_cast<std::size_t>(i + 1)][p] = std::min(std::max(v, q.lower), q.upper);
    }
  }
  for (const auto& [p, t] : o.ties)  // tied parameters follow their free partner, as in the fit
    for (Eigen::VectorXd& x : points) {
      const Parameter& q = pm.parameter(p);
      x[p] = std::min(std::max(t.second * x[t.first], q.lower), q.upper);
    }
  return points;
}

MultiStartSummary fit_multistart(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta0,
                                 const std::vector<char>& is_free, const FitOptions& o, const MultiStartOptions& ms) {
  MultiStartSummary out;
  out.start_points = multistart_points(pm, theta0, is_free, o, ms);
  const std::vector<int> free = internal::free_parameters(pm, is_free, o);
  const int n = static_cast<int>(out.start_points.size());

  pm.nominal();  // the parametric model's terms are built once here, not concurrently
  {
    SparseMatrix K, M;
    pm.matrices(theta0, &K, &M);
  }
  std::vector<FitSummary> fits(static_cast<std::size_t>(n));
  out.start_cost.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  out.start_error.assign(static_cast<std::size_t>(n), "");
  out.start_iterations.assign(static_cast<std::size_t>(n), 0);
  out.start_evaluations.assign(static_cast<std::size_t>(n), 0);
  out.start_converged.assign(static_cast<std::size_t>(n), 0);
  out.start_time.assign(static_cast<std::size_t>(n), 0.0);
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t clock0 = std::clock();
  internal::parallel_for(n, [&](int s) {
    const std::size_t k = static_cast<std::size_t>(s);
    const auto ts = std::chrono::steady_clock::now();
    try {
      Eigen::VectorXd x = out.start_points[k];
      if (ms.continuation && o.objective != FitObjective::kFrequency) {
        FitOptions fo = o;
        fo.objective = FitObjective::kFrequency;
        fo.covariance = false;
        const FitSummary first = fit_parameters(pm, measured, x, is_free, fo);
        x = first.theta;
        out.start_iterations[k] += first.iterations;
        out.start_evaluations[k] += first.evaluations;
      }
      fits[k] = fit_parameters(pm, measured, x, is_free, o);
      out.start_cost[k] = fits[k].final_cost;
      out.start_iterations[k] += fits[k].iterations;
      out.start_evaluations[k] += fits[k].evaluations;
      out.start_converged[k] = fits[k].converged;
    } catch (const NumericalError& e) {
      out.start_error[k] = e.what();
    }
    out.start_time[k] = std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count();
  });
  out.time_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.time_cpu = static_cast<double>(std::clock() - clock0) / CLOCKS_PER_SEC;
  out.failed = static_cast<int>(std::count_if(out.start_error.begin(), out.start_error.end(), [](const std::string& e) { return !e.empty(); }));
  if (out.failed == n) throw NumericalError("multistart: every start failed; the first: " + out.start_error[0]);

  // Distinct minima: ends by cost; each joins the first minimum it agrees with in every free parameter.
  std::vector<int> order;
  for (int s = 0; s < n; ++s)
    if (out.start_error[static_cast<std::size_t>(s)].empty()) order.push_back(s);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return out.start_cost[static_cast<std::size_t>(a)] < out.start_cost[static_cast<std::size_t>(b)]; });
  for (int s : order) {
    const FitSummary& f = fits[static_cast<std::size_t>(s)];
    bool joined = false;
    for (LocalMinimum& lm : out.minima) {
      bool same = true;
      for (int p : free) {
        const Parameter& q = pm.parameter(p);
        same = same && std::abs(f.theta[p] - lm.theta[p]) <= ms.same_minimum * (q.upper - q.lower);
      }
      if (same) {
        lm.starts.push_back(s);
        joined = true;
        break;
      }
    }
    if (joined) continue;
    LocalMinimum lm;
    lm.theta = f.theta;
    lm.cost = f.final_cost;
    lm.starts = {s};
    lm.final_hz = f.final_hz;
    lm.final_mac = f.final_mac;
    lm.max_frequency_error = (f.final_hz.array() / f.measured_hz.array() - 1.0).abs().maxCoeff();
    lm.mean_mac = f.final_mac.mean();
    lm.at_bound = static_cast<int>(f.at_bound.size());
    lm.converged = f.converged;
    out.minima.push_back(std::move(lm));
  }
  out.best_start = order.front();
  out.best = std::move(fits[static_cast<std::size_t>(out.best_start)]);
  // "initial" means the user's values, not the best start's point.
  const Correlation c0 = correlate(pm, measured, theta0, o);
  out.best.initial_hz = c0.model_hz;
  out.best.initial_mac = c0.mac;
  if (out.failed > 0)
    out.warnings.push_back(std::to_string(out.failed) + " of " + std::to_string(n) + " starts failed (the model could not be "
                           "evaluated there): " + out.start_error[static_cast<std::size_t>(
                               std::find_if(out.start_error.begin(), out.start_error.end(), [](const std::string& e) { return !e.empty(); }) -
                               out.start_error.begin())]);
  return out;
}

}  // namespace dynid
