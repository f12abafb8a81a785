// dynid run CASE [--out DIR] [--report]: the whole pipeline of a case (modal analysis, then the detect, update and
// discover sections it has), each step's JSON and figure in DIR, a manifest (run.json) and optionally the report.
// dynid report DIR [-o FILE]: the self-contained HTML report of such a folder.
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/output.hpp"
#include "dynid/io/report.hpp"
#include "dynid/mesh/error.hpp"

namespace fs = std::filesystem;

namespace dynid::cli {

namespace {

struct RunArgs {
  std::string case_path, out;
  bool report = false, force = false;
};

std::string report_path(const std::string& dir) { return (fs::path(dir) / "report.html").string(); }

int write_report(const std::string& dir, const std::string& file, bool force, const GlobalOptions& g) {
  write_file_atomic(file, html_report(dir), force);
  if (!g.quiet) fmt::print("dynid report: wrote {}\n", file);
  return 0;
}

int run_case(const RunArgs& a, const GlobalOptions& g) {
  const Case c = load_case(a.case_path, g.limits);  // errors in the case file stop here, before anything is written
  const std::string dir = a.out.empty() ? c.name + "-results" : a.out;
  using Step = int (*)(const std::string&, const std::string&, const std::string&, bool, const GlobalOptions&);
  std::vector<std::pair<std::string, Step>> steps = {{"modal", modal_step}};
  if (c.detect) steps.emplace_back("detect", detect_step);
  if (c.update) steps.emplace_back("update", update_step);
  if (c.discover) steps.emplace_back("discover", discover_step);
  if (c.test)  // simulate-test + identify; the recordings go to DIR/test*.uff
    steps.emplace_back("identify", [](const std::string& cp, const std::string& json, const std::string&, bool force,
                                      const GlobalOptions& g) { return test_step(cp, fs::path(json).parent_path().string(), force, g); });
  std::vector<std::string> outputs = {(fs::path(dir) / kRunManifest).string()};
  for (const auto& [name, f] : steps) {
    outputs.push_back((fs::path(dir) / (name + ".json")).string());
    outputs.push_back((fs::path(dir) / (name + ".png")).string());
  }
  outputs.push_back((fs::path(dir) / "modal-view.json").string());  // the report's 3D mode shapes (modal_step)
  if (a.report) outputs.push_back(report_path(dir));
  refuse_existing(outputs, a.force);  // nothing is written if anything would be lost
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the results folder (" + ec.message() + ")");

  nlohmann::json run = {{"case", c.name}, {"description", c.description}, {"case_path", c.path},
                        {"dynid", std::string("dynid ") + DYNID_VERSION}, {"steps", nlohmann::json::array()}};
  int worst = 0;
  for (const auto& [name, step] : steps) {
    if (!g.quiet) fmt::print("== dynid run: {} ({})\n", name, c.name);
    const auto t0 = std::chrono::steady_clock::now();
    const int rc = run_guarded(name, [&, s = step, n = name] {
      return s(a.case_path, (fs::path(dir) / (n + ".json")).string(), (fs::path(dir) / (n + ".png")).string(), a.force, g);
    });
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    nlohmann::json entry = {{"name", name}, {"json", name + ".json"}, {"plot", name + ".png"}, {"exit_code", rc}, {"seconds", secs}};
    std::error_code vec;
    if (name == "modal" && fs::is_regular_file(fs::path(dir) / "modal-view.json", vec)) entry["view"] = "modal-view.json";
    run["steps"].push_back(entry);
    if (rc != 0 && worst == 0) worst = rc;
  }
  write_file_atomic(outputs[0], run.dump(1) + "\n", a.force);
  if (!g.quiet) fmt::print("dynid run: results in {}\n", dir);
  if (a.report) write_report(dir, report_path(dir), a.force, g);
  return worst;
}

}  // namespace

void register_run(CLI::App& app, GlobalOptions& g) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand("run", "Run a case's whole pipeline: modal analysis, then its detect, update and "
                                            "discover sections (and simulate-test + identify for a test: section); "
                                            "results, figures and run.json in one folder");
  cmd->add_option("CASE", a->case_path, "Case file or folder (with case.yaml)")->required();
  cmd->add_option("--out,-o", a->out, "Results folder (default: <case name>-results)");
  cmd->add_flag("--report", a->report, "Also write the HTML report (DIR/report.html)");
  cmd->add_flag("--force", a->force, "Overwrite existing results");
  cmd->callback([a, &g]() { g.exit_code = run_guarded("run", [&] { return run_case(*a, g); }); });

  struct ReportArgs {
    std::string dir, file;
    bool force = false;
  };
  auto r = std::make_shared<ReportArgs>();
  CLI::App* rep = app.add_subcommand("report", "Write one self-contained HTML page with the tables and figures of a "
                                               "results folder made by `dynid run`");
  rep->add_option("RESULTS", r->dir, "Results folder (with run.json)")->required();
  rep->add_option("-o,--output", r->file, "HTML file (default: RESULTS/report.html)");
  rep->add_flag("--force", r->force, "Overwrite an existing report");
  rep->callback([r, &g]() {
    g.exit_code = run_guarded("report", [&] {
      return write_report(r->dir, r->file.empty() ? report_path(r->dir) : r->file, r->force, g);
    });
  });
}

}  // namespace dynid::cli
