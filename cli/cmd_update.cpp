// dynid update CASE [--json FILE] [--plot FILE]: FE model updating with Ceres.
#include <fmt/core.h>

#include <cmath>
#include <filesystem>

#include "blas_kernels.hpp"
#include "commands.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/figures.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/output.hpp"
#include "dynid/io/plot.hpp"
#include "dynid/io/results_json.hpp"
#include "dynid/mesh/error.hpp"
#include "progress.hpp"

namespace dynid::cli {

namespace {

struct UpdateArgs {
  std::string case_path, json, plot;
  bool force = false;
};

int run_update(const UpdateArgs& a, const GlobalOptions& g) {
  set_threads(g.threads);
  const Case c = load_case(a.case_path, g.limits);
  require_section(c, c.update.has_value(), "update");
  const UpdateSpec& u = *c.update;
  // OpenBLAS on one thread where the threads work on independent tasks (the starts of a global search), whose
  // solves would otherwise oversubscribe the cores.
  if (u.multistart) set_blas_threads(1);
  Progress progress(!g.quiet);
  progress.update("updating", -1);
  const UpdateRun run = update_case(c);
  const ModalData& measured = run.measured;
  const ParametricModel& pm = *run.pm;
  const FitSummary& f = run.fit;
  progress.done();
  if (!g.quiet) {
    fmt::print("dynid update: {} — {} parameters ({} free), {} measured modes at {} DOFs, objective {}\n", c.name,
               pm.num_parameters(), f.free_parameters, measured.num_modes(), measured.dofs.size(),
               fit_objective_name(u.options.objective));
    if (run.lcurve) {
      const LCurveSummary& l = *run.lcurve;
      const LCurvePoint& q = l.points[static_cast<std::size_t>(l.corner)];
      fmt::print(
          "  regularization by the L-curve: {} weights from {:.3g} to {:.3g} ({} model evaluations); the corner, "
          "weight {:.3g}: misfit {:.4g}, change from nominal {:.4g}\n",
          l.points.size(), l.points.front().weight, l.points.back().weight, l.evaluations, l.weight, q.misfit, q.size);
    }
    if (run.search) {
      const MultiStartSummary& s = *run.search;
      fmt::print("  global search: {} starts (start 0: the initial values; the others a Latin hypercube within the bounds, "
                 "seed {}{}), {} failed, {} distinct minima; {:.1f} s wall, {:.1f} s CPU\n", s.start_points.size(), u.search.seed,
                 u.search.continuation ? ", frequency-only first" : "", s.failed, s.minima.size(), s.time_wall, s.time_cpu);
      fmt::print("  minimum  cost        starts  max freq err %  mean MAC  on bounds\n");
      for (std::size_t m = 0; m < s.minima.size(); ++m) {
        const LocalMinimum& lm = s.minima[m];
        fmt::print("  {:7d}  {:<10.5g}  {:6d}  {:14.3f}  {:8.4f}  {:9d}{}\n", m + 1, lm.cost, lm.starts.size(),
                   100 * lm.max_frequency_error, lm.mean_mac, lm.at_bound, lm.converged ? "" : "  (not converged)");
      }
      fmt::print("  the best minimum (start {}):\n", s.best_start);
    }
    fmt::print("  Ceres: {} iterations, {} model evaluations, cost {:.4g} -> {:.4g}, {}\n", f.iterations, f.evaluations,
               f.initial_cost, f.final_cost, f.termination);
    fmt::print("  parameter            initial      updated      std (stated noise)  std (a posteriori, x{:.3g})\n",
               f.residual_scale);
    for (int p = 0; p < pm.num_parameters(); ++p)
      fmt::print("  {:<18}  {:<11.6g}  {:<11.6g}  {:<18}  {}\n", pm.parameter(p).name, u.initial[p], f.theta[p],
                 std::isnan(f.stddev[p]) ? std::string("-") : fmt::format("{:.3g}", f.stddev[p]),
                 std::isnan(f.stddev[p] * f.residual_scale) ? std::string("-")
                                                            : fmt::format("{:.3g}", f.stddev[p] * f.residual_scale));
    fmt::print("  mode  measured Hz  initial Hz (err %)    updated Hz (err %)    MAC initial  MAC updated\n");
    for (Eigen::Index k = 0; k < f.measured_hz.size(); ++k)
      fmt::print("  {:4d}  {:<11.6g}  {:<10.6g} ({:+7.3f})  {:<10.6g} ({:+7.3f})  {:<11.4f}  {:.4f}\n", k + 1,
                 f.measured_hz[k], f.initial_hz[k], 100 * (f.initial_hz[k] / f.measured_hz[k] - 1), f.final_hz[k],
                 100 * (f.final_hz[k] / f.measured_hz[k] - 1), f.initial_mac[k], f.final_mac[k]);
    for (const std::string& w : f.warnings) fmt::print(stderr, "dynid update: warning: {}\n", w);
  }
  if (!a.json.empty()) {
    write_file_atomic(
        a.json,
        update_json(c.name, pm, u, f, run.search ? &*run.search : nullptr, run.lcurve ? &*run.lcurve : nullptr)
                .dump(1) +
            "\n",
        a.force);
    const std::string png = a.plot.empty() ? std::filesystem::path(a.json).replace_extension(".png").string() : a.plot;
    plot::save(plot::update_figure(c, pm, u, f), png, a.force);
  } else if (!a.plot.empty()) {
    plot::save(plot::update_figure(c, pm, u, f), a.plot, a.force);
  }
  return f.converged ? 0 : 1;
}

}  // namespace

int update_step(const std::string& case_path, const std::string& json, const std::string& plot, bool force, const GlobalOptions& g) {
  return run_update(UpdateArgs{case_path, json, plot, force}, g);
}

void register_update(CLI::App& app, GlobalOptions& g) {
  auto a = std::make_shared<UpdateArgs>();
  CLI::App* cmd = app.add_subcommand("update", "FE model updating: fit physical parameters to measured modes (Ceres)");
  cmd->add_option("CASE", a->case_path, "Case file or folder with an update: section")->required();
  cmd->add_option("--json", a->json, "Write the results as JSON to FILE (and the plot beside it, FILE.png)");
  cmd->add_option("--plot", a->plot, "Write the plot (frequency errors, MAC, parameters) to FILE (.png or .svg)");
  cmd->add_flag("--force", a->force, "Overwrite existing output files");
  cmd->callback([a, &g]() { g.exit_code = run_guarded("update", [&] { return run_update(*a, g); }); });
}

}  // namespace dynid::cli
