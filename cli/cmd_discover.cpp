// dynid discover: missing-physics discovery on a case's discover: section.
#include <fmt/core.h>

#include <cmath>
#include <memory>

#include "commands.hpp"
#include "dynid/io/discover_io.hpp"
#include "dynid/io/output.hpp"
#include "dynid/mesh/error.hpp"
#include "progress.hpp"


namespace dynid::cli {

namespace {

struct DiscoverArgs {
  std::string case_path, json, plot;
  int seeds = 0;  // 0 = the case's
  bool force = false;
  bool exact = false;  // diagnosis: the truth model's exact modes instead of the identified ones
};

void print_candidates(const Case& c, const DiscoverySummary& s) {
  fmt::print("  2-3. candidates (ln Bayes factor over the model as given; > {:.0f} is decisive):\n", c.discover->options.decisive);
  fmt::print("       {:>4}  {:<22} {:<28} {:>9} {:>9} {:>8}\n", "rank", "kind", "where", "evidence", "max df %", "MAC");
  const int show = std::min<int>(12, static_cast<int>(s.candidates.size()));
  for (int k = 0; k < show; ++k) {
    const ScoredHypothesis& h = s.candidates[k];
    std::string where = h.global ? "global" : site_label(h.site, ",");
    if (where.size() > 28) where = where.substr(0, 25) + "...";
    fmt::print("       {:>4}  {:<22} {:<28} {:>9.1f} {:>9.3f} {:>8.5f}{}\n", k + 1, h.kind, where, h.log_evidence, h.max_freq_error_pct, h.mean_mac,
               h.at_bound ? "  (at a bound)" : "");
  }
  const ScoredHypothesis& r = s.recalibration;
  fmt::print("       {:>4}  {:<22} {:<28} {:>9.1f} {:>9.3f} {:>8.5f}\n", "-", "global_recalibration", "global (E, rho)", r.log_evidence,
             r.max_freq_error_pct, r.mean_mac);
}

void print_summary(const Case& c, const DiscoveryData& d, const DiscoverySummary& s) {
  fmt::print("dynid discover: {} — {} measured mode{} at {} DOFs ({})\n", c.name, d.measured.num_modes(),
             d.measured.num_modes() == 1 ? "" : "s", d.measured.dofs.size(), d.source);
  for (const std::string& n : d.notes) fmt::print("  note: {}\n", n);
  for (const std::string& n : set_aside_words(s)) fmt::print("  note: {}\n", n);
  for (const std::string& w : s.warnings) fmt::print("  warning: {}\n", w);
  fmt::print("  1. where:  {}\n", localization_words(s));
  if (candidates_fitted(s))
    print_candidates(c, s);
  else
    fmt::print("  2-3. candidates: none fitted\n");
  if (s.steps.size() > 1) {
    fmt::print("  selection:\n");
    for (const SelectionStep& st : s.steps)
      fmt::print("       {:<6} {:<60} ln B {:>8.1f}  explains {:>3.0f} %\n",
                 st.action == SelectionStep::Action::kStart ? "start" : st.action == SelectionStep::Action::kAdd ? "add" : "remove",
                 st.description.substr(0, 60), st.log_evidence, 100 * st.explained);
  }
  fmt::print("  4. verdict: {}\n     {}\n", to_string(s.verdict), discovery_explanation(s));
  fmt::print("     fit: max frequency error {:.3f} % -> {:.3f} %, mean MAC {:.5f} -> {:.5f}{} ({} eigen-solves, {:.1f} s)\n",
             s.before.max_freq_error_pct, s.after.max_freq_error_pct, s.before.mean_mac, s.after.mean_mac,
             s.before.unpaired || s.after.unpaired ? fmt::format(", measured modes without a partner {} -> {}", s.before.unpaired, s.after.unpaired) : std::string(),
             s.eigen_solves, s.seconds);
}

int run_discover(const DiscoverArgs& a, const GlobalOptions& g) {
  set_threads(g.threads);
  const Case c = load_case(a.case_path, g.limits);
  require_section(c, c.discover.has_value(), "discover");
  const DiscoverSpec& spec = *c.discover;
  const int seeds = a.seeds > 0 ? a.seeds : spec.seeds;
  if (seeds > 1 && !spec.truth) throw InputError("discover: --seeds needs a case with a truth: model (a concealed-data study)");
  const std::string json = a.json.empty() ? c.name + "-discover.json" : a.json;
  const std::string png = a.plot.empty() ? c.name + "-discover.png" : a.plot;
  refuse_existing({json, png}, a.force);
  Progress progress(!g.quiet);
  progress.update(spec.truth ? "virtual test of the truth model and identification" : "measured data", -1);
  DiscoveryData d = discovery_data(c, 0);
  if (a.exact) {
    if (!spec.truth) throw InputError("discover: --exact needs a case with a truth: model");
    // The truth's modes at the sensors that the identification found (paired by frequency within 5 %).
    ModalData e = d.measured;
    for (Eigen::Index k = 0; k < e.frequencies_hz.size(); ++k) {
      Eigen::Index best = 0;
      (d.truth_modes.frequencies_hz.array() - e.frequencies_hz[k]).abs().minCoeff(&best);
      e.frequencies_hz[k] = d.truth_modes.frequencies_hz[best];
      e.shapes.col(k) = d.truth_modes.shapes.col(best);
    }
    e.frequency_std_hz.resize(0);
    e.source = "exact modes of the truth model";
    d.measured = e;
    d.source = e.source;
  }
  progress.update("discovery", -1);
  const DiscoverySummary s = discover(c.model, d.measured, spec.options);
  std::unique_ptr<ExpectCheck> check;
  if (spec.expect) check = std::make_unique<ExpectCheck>(check_expectation(*spec.expect, s, c.model));
  nlohmann::ordered_json j = discovery_json(c, d, s, check.get());

  // Robustness: the same case over further noise seeds of the truth test (seed offset 0 is the run above).
  if (seeds > 1) {
    int named = 0, consistent = 0;
    double worst = 0;
    nlohmann::ordered_json runs = nlohmann::ordered_json::array();
    auto record = [&](int k, const DiscoverySummary& sk) {
      bool ok = false;
      if (spec.expect) {
        const ExpectCheck ck = check_expectation(*spec.expect, sk, c.model);
        ok = ck.ok();
        if (std::isfinite(ck.parameter_error)) worst = std::max(worst, ck.parameter_error);
      }
      named += ok;
      consistent += sk.verdict == Verdict::kConsistent;
      runs.push_back({{"seed_offset", k}, {"verdict", to_string(sk.verdict)}, {"first", sk.findings.empty() ? "" : sk.findings[0].kind}, {"ok", ok}});
    };
    record(0, s);
    for (int k = 1; k < seeds; ++k) {
      progress.update("robustness: seed " + std::to_string(k + 1) + " of " + std::to_string(seeds), -1);
      record(k, discover(c.model, discovery_data(c, k).measured, spec.options));
    }
    j["robustness"] = {{"seeds", seeds}, {"as_expected", named}, {"rate", static_cast<double>(named) / seeds},
                       {"consistent", consistent}, {"worst_parameter_error", worst}, {"runs", runs}};
  }
  progress.done();
  write_file_atomic(json, j.dump(1) + "\n", a.force);
  plot::save(discovery_figure(c, s), png, a.force);
  if (!g.quiet) {
    print_summary(c, d, s);
    if (check) fmt::print("  expected: {}\n", check->words);
    if (seeds > 1)
      fmt::print("  robustness: {} of {} seeds as expected ({:.0f} %)\n", j["robustness"]["as_expected"].get<int>(), seeds,
                 100.0 * j["robustness"]["rate"].get<double>());
    fmt::print("  wrote {}, {}\n", json, png);
  }
  // Exit code 4: the case states what the answer should be (expect:) and this is not it (test suites).
  return check && !check->ok() ? 4 : 0;
}

}  // namespace

int discover_step(const std::string& case_path, const std::string& json, const std::string& plot, bool force, const GlobalOptions& g) {
  return run_discover(DiscoverArgs{case_path, json, plot, 0, force}, g);
}

void register_discover(CLI::App& app, GlobalOptions& g) {
  auto a = std::make_shared<DiscoverArgs>();
  CLI::App* cmd = app.add_subcommand("discover", "Find what physics the model leaves out: locate the mismatch, fit candidate effects, report");
  cmd->add_option("CASE", a->case_path, "Case file or folder with a discover: section")->required();
  cmd->add_option("--json", a->json, "Results JSON (default: <case>-discover.json)");
  cmd->add_option("--plot", a->plot, "Report figure, .png or .svg (default: <case>-discover.png)");
  cmd->add_option("--seeds", a->seeds, "Robustness study: repeat the truth test over this many noise seeds")->check(CLI::Range(1, 1000));
  cmd->add_flag("--force", a->force, "Overwrite existing output files");
  cmd->add_flag("--exact", a->exact, "Diagnosis: use the truth model's exact modes (the ones identified) instead of the identified values");
  cmd->callback([a, &g]() { g.exit_code = run_guarded("discover", [&] { return run_discover(*a, g); }); });
}

}  // namespace dynid::cli
