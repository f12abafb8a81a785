// dynid_update_bridge -- the global search of cases/gt-pedestrian-bridge timed in its parts: the real SAP2000
// bridge (946 DOFs, 474 massless, 17 stiffness groups, 5 modes measured at 58 channels with their standard
// deviations). Prints the model's sizes, the time of one model evaluation (eigen-solve) and of one Jacobian, one
// local fit from the initial values, and the whole multistart search (wall and process CPU time, getrusage), with
// its distinct minima.
//
//   dynid_update_bridge [--starts N] [--threads T] [--no-search] [--start K] [--l-curve] [--case DIR]
#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "blas_kernels.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/multistart.hpp"
#include "dynid/engine/regularization.hpp"
#include "dynid/io/case_file.hpp"

using Clock = std::chrono::steady_clock;
static double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
static double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int main(int argc, char** argv) {
  dynid::cli::ensure_blas_kernels(argv);
  std::string dir = std::string(DYNID_CASES_DIR) + "/gt-pedestrian-bridge";
  int starts = 0, threads = 0, only = -1;
  bool search = true, lcurve = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--starts" && i + 1 < argc)
      starts = std::atoi(argv[++i]);
    else if (a == "--threads" && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else if (a == "--case" && i + 1 < argc)
      dir = argv[++i];
    else if (a == "--no-search")
      search = false;
    else if (a == "--start" && i + 1 < argc)
      only = std::atoi(argv[++i]);
    else if (a == "--l-curve")
      lcurve = true;
    else {
      std::fprintf(
          stderr,
          "usage: dynid_update_bridge [--starts N] [--threads T] [--no-search] [--start K] [--l-curve] [--case DIR]\n");
      return 2;
    }
  }
  if (threads > 0) omp_set_num_threads(threads);
  dynid::cli::set_blas_threads(1);  // as `dynid update` does for a global search: the threads run the starts

  auto t0 = Clock::now();
  const dynid::Case c = dynid::load_case(dir);
  const dynid::UpdateSpec& u = *c.update;
  const dynid::ModalData measured = dynid::update_measured_data(c);
  const double t_load = since(t0);
  dynid::ParametricModel pm(c.model);
  for (const dynid::Parameter& p : u.parameters) pm.add(p);
  const dynid::MeasuredNoise noise = dynid::measured_noise(measured, u.options);
  const dynid::FitOptions& o = noise.options;
  std::printf("model: %d DOFs, nnz(K) %lld, %d parameters; %d measured modes at %zu DOFs; case read in %.2f s\n",
              c.model.num_dofs(), static_cast<long long>(pm.K0().nonZeros()), pm.num_parameters(), measured.num_modes(),
              measured.dofs.size(), t_load);

  for (int e = 0; e < c.model.num_elements(); ++e) {  // the group matrices: DOFs touched, nonzero entries
    const dynid::Element& el = c.model.elements()[e];
    if (!el.matrix) continue;
    const Eigen::MatrixXd& K = el.matrix->K;
    const Eigen::MatrixXd& M = el.matrix->M;
    std::printf("  group %-8s %4ld DOFs, %7ld nonzero K entries, %6ld nonzero M entries (%ld off the diagonal)\n",
                el.group.c_str(), static_cast<long>(K.rows()), static_cast<long>((K.array() != 0).count()),
                static_cast<long>((M.array() != 0).count()),
                static_cast<long>((M.array() != 0).count() - (M.diagonal().array() != 0).count()));
  }
  // One model evaluation (eigen-solve and residuals), and one with the Jacobian, each the median of 5.
  dynid::FitProblem prob(pm, measured, o);
  auto median5 = [](auto&& f) {
    double t[5];
    for (double& x : t) {
      const auto s = Clock::now();
      f();
      x = since(s);
    }
    std::sort(t, t + 5);
    return t[2];
  };
  Eigen::VectorXd r;
  Eigen::VectorXd theta = u.initial;
  const double t_eval = median5([&] {
    theta[0] = theta[0] == u.initial[0] ? 0.95 : u.initial[0];  // a new point each time (no cache)
    prob.residuals(theta, &r);
  });
  const double t_lin = median5([&] { dynid::linearize(pm, measured, u.initial, o); });
  std::printf(
      "one evaluation (eigen-solve + residuals): %.4f s; one linearization (solve + Jacobian, new evaluator): %.4f s\n",
      t_eval, t_lin);

  t0 = Clock::now();
  double c0 = cpu_seconds();
  const dynid::FitSummary f = dynid::fit_parameters(pm, measured, u.initial, u.free, o);
  std::printf(
      "one local fit from the initial values: %.2f s wall, %.2f s CPU; %d iterations, %d evaluations, "
      "eigen %.2f s, sensitivities %.2f s; cost %.4g; max freq. error %.3f %%, mean MAC %.4f\n",
      since(t0), cpu_seconds() - c0, f.iterations, f.evaluations, f.time_eigen, f.time_sensitivity, f.final_cost,
      100 * (f.final_hz.array() / f.measured_hz.array() - 1).abs().maxCoeff(), f.final_mac.mean());
  dynid::MultiStartOptions ms = u.search;
  if (starts > 0) ms.starts = starts;
  if (only >= 0) {  // one start of the search alone: its point's lowest modes, and its local fit
    const Eigen::VectorXd x = dynid::multistart_points(pm, u.initial, u.free, o, ms).at(static_cast<std::size_t>(only));
    dynid::SparseMatrix K, M;
    pm.matrices(x, &K, &M);
    dynid::EigenOptions eo;
    eo.num_modes = 15;
    const dynid::EigenSolution es = dynid::solve_eigen(K, M, eo);
    std::printf("start %d: lowest modes (Hz):", only);
    for (Eigen::Index k = 0; k < es.eigenvalues.size(); ++k)
      std::printf(" %.3g", std::sqrt(std::max(0.0, es.eigenvalues[k])) / (2 * M_PI));
    std::printf(" (%s)\n", es.summary.FullReport().c_str());
    t0 = Clock::now();
    c0 = cpu_seconds();
    const dynid::FitSummary g = dynid::fit_parameters(pm, measured, x, u.free, o);
    std::printf("its local fit: %.2f s wall, %.2f s CPU; %d iterations, %d evaluations, eigen %.2f s; cost %.5g\n",
                since(t0), cpu_seconds() - c0, g.iterations, g.evaluations, g.time_eigen, g.final_cost);
    return 0;
  }
  if (lcurve) {  // the L-curve path, then an unregularized fit from each of its points
    t0 = Clock::now();
    c0 = cpu_seconds();
    const dynid::LCurveSummary l = dynid::l_curve(pm, measured, u.initial, u.free, o);
    std::printf("L-curve: %zu weights, %d evaluations, %.2f s wall, %.2f s CPU; corner %d (weight %.3g)\n",
                l.points.size(), l.evaluations, since(t0), cpu_seconds() - c0, l.corner, l.weight);
    std::printf("  weight      misfit    size     curvature  | unregularized from here: cost  max err %%  mean MAC\n");
    for (const dynid::LCurvePoint& p : l.points) {
      const dynid::FitSummary g = dynid::fit_parameters(pm, measured, p.theta, u.free, o);
      std::printf("  %-10.3g  %-8.4g  %-7.4g  %9.3f  | %10.5g  %9.3f  %8.4f\n", p.weight, p.misfit, p.size, p.curvature,
                  g.final_cost, 100 * (g.final_hz.array() / g.measured_hz.array() - 1).abs().maxCoeff(),
                  g.final_mac.mean());
    }
  }
  if (!search) return 0;

  t0 = Clock::now();
  c0 = cpu_seconds();
  const dynid::MultiStartSummary s = dynid::fit_multistart(pm, measured, u.initial, u.free, o, ms);
  const double wall = since(t0), cpu = cpu_seconds() - c0;
  double own = 0;
  for (double t : s.start_time) own += t;
  std::printf(
      "global search: %zu starts on %d threads, %d failed, %zu distinct minima: %.2f s wall, %.2f s CPU "
      "(getrusage; the search's own count %.2f s); sum of the starts' wall times %.2f s\n",
      s.start_points.size(), omp_get_max_threads(), s.failed, s.minima.size(), wall, cpu, s.time_cpu, own);
  std::printf("  start  iterations  evaluations  converged  seconds  cost\n");
  for (std::size_t k = 0; k < s.start_points.size(); ++k)
    std::printf("  %5zu  %10d  %11d  %9s  %7.2f  %.5g\n", k, s.start_iterations[k], s.start_evaluations[k],
                s.start_converged[k] ? "yes" : "no", s.start_time[k], s.start_cost[k]);
  std::printf("  minimum  cost        starts  max freq err %%  mean MAC  on bounds\n");
  for (std::size_t m = 0; m < s.minima.size(); ++m) {
    const dynid::LocalMinimum& lm = s.minima[m];
    std::printf("  %7zu  %-10.5g  %6zu  %14.3f  %8.4f  %9d\n", m + 1, lm.cost, lm.starts.size(),
                100 * lm.max_frequency_error, lm.mean_mac, lm.at_bound);
  }
  std::printf("best: start %d, cost %.5g\n", s.best_start, s.best.final_cost);
  return 0;
}
