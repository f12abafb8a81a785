// dynid modal CASE [--modes N] [--json FILE]: modal analysis of a case's model.
// dynid export-matrices CASE DIR: the case's model as matrices (docs/matrix-input.md).
#include <fmt/core.h>

#include <filesystem>

#include "commands.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/matrix_model.hpp"
#include "dynid/io/model_plots.hpp"
#include "dynid/io/model_view.hpp"
#include "dynid/io/output.hpp"
#include "progress.hpp"

namespace dynid::cli {

namespace {
struct ModalArgs {
  std::string case_path;
  int modes = 0;
  std::string json, plot;
  bool force = false;
  std::string view;  ///< the report's 3D mode-shape data (dynid run: modal-view.json)
};

int run_modal(const ModalArgs& a, const GlobalOptions& g) {
  set_threads(g.threads);
  Case c = load_case(a.case_path, g.limits);
  for (const std::string& w : c.model.warnings())
    if (!g.quiet) fmt::print(stderr, "dynid modal: warning: {}: {}\n", c.path, w);
  for (const std::string& n : c.notes)
    if (!g.quiet) fmt::print(stderr, "dynid modal: note: {}\n", n);
  EigenOptions opt = c.analysis.eigen_options();
  if (a.modes > 0) {
    opt.num_modes = a.modes;
    opt.band_lo = opt.band_hi = std::numeric_limits<double>::quiet_NaN();
  }
  if (g.distributed) opt.backend = EigenOptions::Backend::kDistributed;
  Progress progress(!g.quiet);
  opt.progress = [&](std::string_view stage, double f) { progress.update(stage, f); };
  const ModalResult r = modal_analysis(c.model, opt);
  progress.done();
  if (!g.quiet) {
    fmt::print("dynid modal: {} ({} DOFs, {} nonzeros)\n", c.name, r.dofs, r.nonzeros);
    fmt::print("  mode  frequency [Hz]   kind\n");
    int elastic = 0, rigid = 0;
    for (Eigen::Index k = 0; k < r.eigenvalues.size(); ++k) {
      std::string kind;
      if (r.rigid_body[k]) {
        kind = "rigid body";
        if (rigid < static_cast<int>(r.rigid_body_descriptions.size()))
          kind += " (" + r.rigid_body_descriptions[rigid] + ")";
        ++rigid;
      } else {
        kind = fmt::format("elastic {}", ++elastic);
      }
      fmt::print("  {:4d}  {:14.6g}   {}\n", k + 1, r.frequencies_hz[k], kind);
    }
    if (g.verbose) fmt::print("{}", r.summary.FullReport());
  }
  if (!g.root) return r.ok() ? 0 : 1;  // distributed: rank 0 writes the files and reports
  if (!a.plot.empty()) refuse_existing({a.plot}, a.force);
  if (!a.view.empty()) refuse_existing({a.view}, a.force);
  if (!a.json.empty()) write_file_atomic(a.json, modal_json(c, r).dump(1) + "\n", a.force);
  if (!a.view.empty() && r.ok()) write_file_atomic(a.view, model_view_json(c.model, r).dump() + "\n", a.force);
  if (!a.plot.empty()) plot::save(plot::mode_shape_figure(c.model, r, 6, "dynid modal: " + c.name + " - mode shapes"), a.plot, a.force);
  if (!r.ok()) {
    fmt::print(stderr, "dynid modal: {}\n", r.summary.BriefReport());
    return 1;
  }
  return 0;
}
}  // namespace

int modal_step(const std::string& case_path, const std::string& json, const std::string& plot, bool force, const GlobalOptions& g) {
  const std::filesystem::path j(json);
  return run_modal(ModalArgs{case_path, 0, json, plot, force, (j.parent_path() / (j.stem().string() + "-view.json")).string()}, g);
}

void register_modal(CLI::App& app, GlobalOptions& g) {
  auto a = std::make_shared<ModalArgs>();
  CLI::App* cmd = app.add_subcommand("modal", "Modal analysis: the lowest modes (or a band) of a case's model");
  cmd->add_option("CASE", a->case_path, "Case file or folder (with case.yaml)")->required();
  cmd->add_option("--modes", a->modes, "Number of lowest modes, rigid-body modes included (overrides the case)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--json", a->json, "Write the results as JSON to FILE");
  cmd->add_option("--plot", a->plot, "Draw the first six elastic mode shapes on the structure to FILE (.png or .svg)");
  cmd->add_flag("--force", a->force, "Overwrite existing output files");
  cmd->callback([a, &g]() { g.exit_code = run_guarded("modal", [&] { return run_modal(*a, g); }); });

  struct ExportArgs {
    std::string case_path, dir;
    bool force = false;
  };
  auto x = std::make_shared<ExportArgs>();
  CLI::App* ex = app.add_subcommand(
      "export-matrices", "Write a case's model as matrices: K.mtx, M.mtx, the DOF and node tables, element matrices "
                         "and the model section that reads them back (docs/matrix-input.md)");
  ex->add_option("CASE", x->case_path, "Case file or folder (with case.yaml)")->required();
  ex->add_option("DIR", x->dir, "Folder to write into (created if missing)")->required();
  ex->add_flag("--force", x->force, "Overwrite existing files");
  ex->callback([x, &g]() {
    g.exit_code = run_guarded("export-matrices", [&] {
      const Case c = load_case(x->case_path, g.limits);
      const auto paths = write_matrix_model(c.model, x->dir, x->force);
      if (!g.quiet) {
        fmt::print("dynid export-matrices: {} ({} DOFs, {} elements) -> {}\n", c.name, c.model.num_dofs(),
                   c.model.num_elements(), x->dir);
        for (const std::string& p : paths) fmt::print("  {}\n", p);
      }
      return 0;
    });
  });
}

}  // namespace dynid::cli
