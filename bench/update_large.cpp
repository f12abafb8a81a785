// dynid_update_large -- model updating at scale: a generated 3D frame of 135,408 DOF, 224 stiffness factors (14
// stories x 4x4 plan zones), target = seeded random factors in [0.85, 1.15], 20 modes measured at the x and y
// translations of 5 column lines on every floor (140 DOFs) with 0.1 % frequency and 1 % shape noise. Objective:
// frequencies + shapes, with a weak prior toward nominal (std 0.2). Prints Ceres' iterations, the time per
// iteration against one eigen-solve of the model, and the recovered factors' error.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "blas_kernels.hpp"
#include "dynid/engine/model_fit.hpp"

using Clock = std::chrono::steady_clock;
static double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

int main(int argc, char** argv) {
  dynid::cli::ensure_blas_kernels(argv);
  // --direct: Ceres on the full model at every step (FitOptions::ReducedBasis::kOff); default: the reduced-basis fit.
  bool direct = false;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--direct") {
      direct = true;
      for (int j = i; j + 1 < argc; ++j) argv[j] = argv[j + 1];
      --argc;
      break;
    }
  dynid::Frame3DSpec f;
  f.bays_x = f.bays_y = argc > 1 ? std::atoi(argv[1]) : 12;
  f.stories = argc > 2 ? std::atoi(argv[2]) : 14;
  f.divisions = argc > 3 ? std::atoi(argv[3]) : 4;
  f.span_x = f.span_y = 6;
  f.height = 3.5;
  f.material = dynid::bench::Steel();
  f.column = dynid::bench::Column();
  f.beam = dynid::bench::Beam();
  const dynid::Model model = dynid::make_frame3d(f);
  // Parameter of each element: story (by midpoint height) x plan zone (4 x 4 zones of 18 m).
  const int zones = 4, P = f.stories * zones * zones;
  std::vector<std::vector<int>> members(P);
  for (int e = 0; e < model.num_elements(); ++e) {
    const auto& en = model.element_nodes(e);
    const Eigen::Vector3d c = 0.5 * (model.nodes()[en[0]].x + model.nodes()[en[1]].x);
    const int story = std::min(f.stories - 1, static_cast<int>(std::floor((c.z() - 1e-6) / f.height)));
    const int zx = std::min(zones - 1, static_cast<int>(c.x() / (f.bays_x * f.span_x / zones)));
    const int zy = std::min(zones - 1, static_cast<int>(c.y() / (f.bays_y * f.span_y / zones)));
    members[(story * zones + zy) * zones + zx].push_back(e);
  }
  dynid::ParametricModel pm(model);
  for (int p = 0; p < P; ++p) {
    dynid::Parameter q;
    q.name = "E:" + std::to_string(p);
    q.kind = dynid::ParameterKind::kStiffness;
    q.elements = members[p];
    q.lower = 0.3;
    q.upper = 3.0;
    q.scale = 0.2;
    pm.add(q);
  }
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.85, 1.15);
  Eigen::VectorXd truth(P);
  for (int p = 0; p < P; ++p) truth[p] = U(rng);
  // Target data: exact modes of K(truth), then noise.
  std::vector<dynid::MeasuredDof> dofs;
  const int nx = f.bays_x + 1;
  const int b = f.bays_x;
  const std::vector<std::pair<int, int>> lines = {{0, 0}, {b, 0}, {0, b}, {b, b}, {b / 2, b / 2}};
  for (int k = 1; k <= f.stories; ++k)
    for (const auto& [i, j] : lines)
      for (dynid::Dof d : {dynid::Dof::UX, dynid::Dof::UY}) dofs.push_back({1 + (k * nx + j) * nx + i, d});
  dynid::SparseMatrix K, M;
  pm.matrices(truth, &K, &M);
  dynid::EigenOptions eo;
  eo.num_modes = 60;
  auto t0 = Clock::now();
  const dynid::EigenSolution target = dynid::solve_eigen(K, M, eo);
  const double t_eig = since(t0);
  const std::vector<int> rows = dynid::measured_equations(model, dofs);
  // A test identifies the modes its sensors see: keep the first 20 whose largest amplitude at the sensors is at
  // least 30 % of their largest translation anywhere (local member modes are invisible to floor sensors).
  std::vector<int> seen;
  for (Eigen::Index k = 0; k < target.eigenvalues.size() && seen.size() < 20; ++k) {
    double at_sensors = 0, anywhere = 0;
    for (int r : rows) at_sensors = std::max(at_sensors, std::abs(target.modes(r, k)));
    for (int i = 0; i < model.num_dofs(); ++i)
      if (static_cast<int>(model.dof_map().type_of(i)) < 3) anywhere = std::max(anywhere, std::abs(target.modes(i, k)));
    if (at_sensors >= 0.3 * anywhere) seen.push_back(static_cast<int>(k));
  }
  dynid::ModalData meas;
  meas.dofs = dofs;
  meas.frequencies_hz.resize(static_cast<Eigen::Index>(seen.size()));
  meas.shapes.resize(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(seen.size()));
  std::normal_distribution<double> N(0, 1);
  for (int k = 0; k < static_cast<int>(seen.size()); ++k) {
    meas.frequencies_hz[k] = std::sqrt(target.eigenvalues[seen[k]]) / (2 * M_PI) * (1 + 1e-3 * N(rng));
    for (std::size_t r = 0; r < rows.size(); ++r) meas.shapes(static_cast<Eigen::Index>(r), k) = target.modes(rows[r], seen[k]);
    const double big = meas.shapes.col(k).cwiseAbs().maxCoeff();
    for (std::size_t r = 0; r < rows.size(); ++r) meas.shapes(static_cast<Eigen::Index>(r), k) += 1e-2 * big * N(rng);
  }
  dynid::FitOptions o;
  o.objective = dynid::FitObjective::kCombined;
  o.regularization = 1.0;
  o.max_iterations = 100;
  o.reduced_basis = direct ? dynid::FitOptions::ReducedBasis::kOff : dynid::FitOptions::ReducedBasis::kOn;
  if (const char* e = std::getenv("DYNID_EXTRA_MODES")) o.extra_modes = std::atoi(e);
  // One fresh eigen-solve of the modes the fit solves (new solver: ordering, factorization, Lanczos from a random
  // start) at the nominal parameters: 20 + extra modes, grown as the fit grows them until 1.1 x the highest
  // measured frequency is passed. Median of 3.
  double t_fresh = 0;
  int fresh_modes = static_cast<int>(seen.size()) + o.extra_modes;
  {
    pm.matrices(pm.nominal(), &K, &M);
    const double need = std::pow(2 * M_PI * 1.1 * meas.frequencies_hz.maxCoeff(), 2);
    std::vector<double> times;
    for (int rep = 0; rep < 3; ++rep) {
      dynid::EigenOptions fo;
      fo.num_modes = fresh_modes;
      dynid::EigenSolution fs = dynid::solve_eigen(K, M, fo);
      while (fs.summary.ok() && fs.eigenvalues.maxCoeff() < need) {
        fresh_modes = fresh_modes * 3 / 2 + 10;
        fo.num_modes = fresh_modes;
        fs = dynid::solve_eigen(K, M, fo);
      }
      const auto tf = Clock::now();
      fs = dynid::solve_eigen(K, M, fo);
      times.push_back(since(tf));
    }
    std::sort(times.begin(), times.end());
    t_fresh = times[1];
  }
  t0 = Clock::now();
  const dynid::FitSummary s = dynid::fit_parameters(pm, meas, pm.nominal(), {}, o);
  const double t_fit = since(t0);
  const double rms0 = std::sqrt((truth.array() - 1.0).square().mean());
  const double rms1 = std::sqrt((s.theta - truth).array().square().mean());
  int within2sd = 0, with_sd = 0;
  for (int p = 0; p < P; ++p)
    if (!std::isnan(s.stddev[p])) {
      ++with_sd;
      within2sd += std::abs(s.theta[p] - truth[p]) <= 2 * s.stddev[p];
    }
  std::printf("3D frame %d DOF, %d parameters, %zu modes (of the lowest %d; the ones the sensors see) at %zu DOFs "
              "(0.1 %% / 1 %% noise)\n\n", model.num_dofs(), P, seen.size(), seen.empty() ? 0 : seen.back() + 1, dofs.size());
  std::printf("| quantity | value |\n|---|---|\n");
  std::printf("| Ceres termination | %s (%d iterations, %d model evaluations) |\n", s.termination.c_str(), s.iterations, s.evaluations);
  std::printf("| cost | %.4g -> %.4g (chi2/dof %.3f) |\n", s.initial_cost, s.final_cost, s.residual_scale * s.residual_scale);
  std::printf("| one eigen-solve of the model (60 modes, for the target) | %.2f s |\n", t_eig);
  const double per_solve = s.time_eigen / s.evaluations;
  std::printf("| the fit's eigen-solves (modes up to 1.1 x the highest measured frequency) | %d, %.2f s each |\n",
              s.evaluations, per_solve);
  // Full Jacobians: the direct fit computes one per accepted step (Ceres' iterations less its rejected steps,
  // whose count is evaluations - iterations - 1, the start included); the reduced-basis fit one at the start and
  // one per step taken.
  const int jacobians =
      s.reduced_basis ? s.iterations + 1 : std::max(1, s.iterations - (s.evaluations - s.iterations - 1));
  std::printf("| sensitivities (eigenvalue and shape derivatives, all parameters) | %d, %.2f s each |\n", jacobians,
              s.time_sensitivity / jacobians);
  if (s.reduced_basis)
    std::printf(
        "| reduced-basis surrogates (projection, corrections, minimisation) | %.2f s in all, %d steps taken, %d "
        "rejected, %d surrogate iterations |\n",
        s.time_surrogate, s.iterations, s.rejected_steps, s.surrogate_iterations);
  std::printf("| the fit's wall time | %.2f s |\n", t_fit);
  std::printf("| one fresh eigen-solve of the fit's %d modes (median of 3) | %.2f s |\n", fresh_modes, t_fresh);
  std::printf("| wall time per iteration | %.2f s (%.2fx one of the fit's eigen-solves, %.2fx a fresh one) |\n",
              t_fit / std::max(1, s.iterations), t_fit / std::max(1, s.iterations) / per_solve,
              t_fit / std::max(1, s.iterations) / t_fresh);
  std::printf("| RMS factor error: nominal -> updated | %.4f -> %.4f |\n", rms0, rms1);
  std::printf("| updated factors within 2 std of the truth | %d of %d |\n", within2sd, with_sd);
  if (std::getenv("DYNID_VERBOSE")) std::printf("%s\n", s.report.c_str());
  return s.converged ? 0 : 1;
}
