// dynid detect CASE [--json FILE] [--plot FILE] [--study]: locate and quantify changes by residual forces.
#include <fmt/core.h>

#include <cmath>
#include <filesystem>

#include "commands.hpp"
#include "dynid/engine/detect.hpp"
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

struct DetectArgs {
  std::string case_path, json, plot;
  bool study = false, force = false;
};

int run_detect(const DetectArgs& a, const GlobalOptions& g) {
  set_threads(g.threads);
  const Case c = load_case(a.case_path, g.limits);
  require_section(c, c.detect.has_value(), "detect");
  const DetectSpec& d = *c.detect;
  const Model& model = c.model;
  Progress progress(!g.quiet);

  if (a.study) {
    if (!d.has_study) throw InputError(c.path + ": --study needs a study: section under detect:");
    const Model changed = changed_model(model, d.changes);
    progress.update("noise study", -1);
    const auto rows = noise_study(model, changed, d.changes[0].first, d.study);
    progress.done();
    const int id = d.changes[0].first;
    fmt::print("dynid detect --study: {} (element {}, dk {:+.1f} %, dm {:+.1f} %), {} trials per level, {} modes at {} DOFs, "
               "frequency noise {:.2g} %, seed {}\n",
               c.name, id, 100 * d.changes[0].second.first, 100 * d.changes[0].second.second, d.study.trials,
               d.study.modes, d.study.dofs.size(), 100 * d.study.frequency_noise, d.study.seed);
    fmt::print("| shape noise | paper pseudo residual: 1st | top 3 | dynid: 1st | top 3 | in 95 % set | mean set size | "
               "twin ranked 1st | twin called |\n|---|---|---|---|---|---|---|---|---|\n");
    nlohmann::json out = nlohmann::json::array();
    for (const auto& r : rows) {
      auto pct = [&](int k) { return 100.0 * k / r.trials; };
      fmt::print("| {:.0f} % | {:.1f} % | {:.1f} % | {:.1f} % | {:.1f} % | {:.1f} % | {:.2f} | {:.1f} % | {:.1f} % |\n",
                 100 * r.shape_noise, pct(r.pseudo_first), pct(r.pseudo_top3), pct(r.dynid_first), pct(r.dynid_top3),
                 pct(r.in_confidence_set), r.mean_set_size, pct(r.twin_first), pct(r.twin_called));
      out.push_back({{"shape_noise", r.shape_noise}, {"trials", r.trials}, {"pseudo_first", r.pseudo_first},
                     {"pseudo_top3", r.pseudo_top3}, {"dynid_first", r.dynid_first}, {"dynid_top3", r.dynid_top3},
                     {"twin_first", r.twin_first}, {"twin_called", r.twin_called},
                     {"in_confidence_set", r.in_confidence_set}, {"mean_set_size", r.mean_set_size}});
    }
    if (!a.json.empty()) write_file_atomic(a.json, nlohmann::json{{"case", c.name}, {"element", id}, {"study", out}}.dump(1) + "\n", a.force);
    return 0;
  }

  // The changed state (a simulation of the modified model, or measured data), then detection.
  progress.update("detect", -1);
  const DetectSummary S = detect_case(c);
  progress.done();

  if (!g.quiet) {
    fmt::print("dynid detect: {} ({} modes, {} DOFs{})\n", c.name, S.used_modes.size(), S.dofs.size(),
               S.full_dofs ? ", every model DOF" : ", SEREP-reduced");
    fmt::print("  localization: {}\n  rule: {}\n", S.method, S.threshold_rule);
    fmt::print("  rank  element  score       pseudo(paper)  flagged\n");
    for (std::size_t k = 0; k < S.elements.size() && k < 8; ++k) {
      const ElementScore& e = S.elements[k];
      std::string tw;
      for (int t : e.twins) tw += (tw.empty() ? " twin of " : ", ") + std::to_string(t);
      fmt::print("  {:4d}  {:7d}  {:<10.4g}  {:<13.4g}  {}{}\n", e.rank, e.element, e.probability, e.pseudo,
                 e.flagged ? "yes" : "", tw);
    }
    if (!S.amounts.empty()) {
      fmt::print("  quantification (fractions; -0.15 = 15 % loss):\n  element  dk          dm          dk 1st order  dm 1st order\n");
      for (const ElementAmount& am : S.amounts)
        fmt::print("  {:7d}  {:<+10.5f}  {:<+10.5f}  {:<+12.5f}  {:<+12.5f}\n", am.element, am.dk, am.dm,
                   am.dk_first_order, am.dm_first_order);
    } else {
      fmt::print("  no element flagged\n");
    }
    for (const std::string& w : S.warnings) fmt::print(stderr, "dynid detect: warning: {}\n", w);
  }
  if (!a.json.empty()) {
    write_file_atomic(a.json, detect_json(c.name, S).dump(1) + "\n", a.force);
    const std::string png = a.plot.empty() ? std::filesystem::path(a.json).replace_extension(".png").string() : a.plot;
    plot::save(plot::detect_figure(c, S), png, a.force);
  } else if (!a.plot.empty()) {
    plot::save(plot::detect_figure(c, S), a.plot, a.force);
  }
  return 0;
}

}  // namespace

int detect_step(const std::string& case_path, const std::string& json, const std::string& plot, bool force, const GlobalOptions& g) {
  return run_detect(DetectArgs{case_path, json, plot, false, force}, g);
}

void register_detect(CLI::App& app, GlobalOptions& g) {
  auto a = std::make_shared<DetectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "detect", "Locate and quantify changes (damage, added mass) by residual forces (the paper's NDT method)");
  cmd->add_option("CASE", a->case_path, "Case file or folder with a detect: section")->required();
  cmd->add_option("--json", a->json, "Write the results as JSON to FILE (and the plot beside it, FILE.png)");
  cmd->add_option("--plot", a->plot, "Write the plot (pseudo residual per DOF and per element) to FILE (.png or .svg)");
  cmd->add_flag("--study", a->study, "Run the case's noise study (detect: study:) instead of a single detection");
  cmd->add_flag("--force", a->force, "Overwrite existing output files");
  cmd->callback([a, &g]() { g.exit_code = run_guarded("detect", [&] { return run_detect(*a, g); }); });
}

}  // namespace dynid::cli
