// What `dynid detect` and `dynid update` compute for a case, and their results JSON (dynid/io/results_json.hpp).
#include "dynid/io/results_json.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/io/point_map.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/json_util.hpp"
#include "internal/text_util.hpp"

namespace dynid {

using internal::format_number;
using internal::vec;

namespace {
nlohmann::json num(double v) { return std::isnan(v) ? nlohmann::json() : nlohmann::json(v); }
}  // namespace

DetectSummary detect_case(const Case& c) {
  require_section(c, c.detect.has_value(), "detect");
  const DetectSpec& d = *c.detect;
  Model changed_m;
  DetectOptions opt = d.options;
  const ModalData changed = detect_changed_data(c, &changed_m);
  if (!d.changes.empty()) opt.simulated_changed = &changed_m;
  ModalData refmeas;
  if (!d.reference_measured_file.empty())
    refmeas = read_measured_modal_data(d.reference_measured_file, d.geometry, c.model, nullptr, {}, c.limits);
  return detect(c.model, changed, opt, d.reference_measured_file.empty() ? nullptr : &refmeas);
}

nlohmann::json detect_json(const std::string& case_name, const DetectSummary& S) {
  nlohmann::json j;
  j["case"] = case_name;
  j["method"] = S.method;
  j["threshold_rule"] = S.threshold_rule;
  j["full_dofs"] = S.full_dofs;
  j["modes"] = {{"used", S.used_modes}, {"model_hz", vec(S.model_hz)}, {"changed_hz", vec(S.changed_hz)}, {"mac", vec(S.mac)}};
  nlohmann::json els = nlohmann::json::array();
  for (const ElementScore& e : S.elements)
    els.push_back({{"id", e.element},
                   {"score", e.probability},
                   {"flagged", e.flagged},
                   {"rank", e.rank},
                   {"pseudo", num(e.pseudo)},
                   {"pseudo_rank", e.pseudo_rank},
                   {"chi2", e.chi2},
                   {"twins", e.twins}});
  nlohmann::json dofs = nlohmann::json::array();
  for (std::size_t r = 0; r < S.dofs.size(); ++r)
    dofs.push_back({{"dof", to_string(S.dofs[r])}, {"pseudo", S.pseudo[r]}, {"reference", S.pseudo_reference[r]},
                    {"delta", S.delta_pseudo[r]}});
  j["localization"] = {{"elements", els},
                       {"dofs", dofs},
                       {"score", S.full_dofs ? "fraction of the residual-force energy the element alone explains"
                                             : "posterior probability that this element alone changed"},
                       {"chi2_unchanged", S.chi2_unchanged},
                       {"chi2_final", S.chi2_final}};
  nlohmann::json q = nlohmann::json::array();
  for (const ElementAmount& a : S.amounts)
    q.push_back({{"element", a.element}, {"dk", a.dk}, {"dm", a.dm}, {"dk_first_order", a.dk_first_order},
                 {"dm_first_order", a.dm_first_order}, {"dk_std", num(a.dk_std)}, {"dm_std", num(a.dm_std)}});
  j["quantification"] = q;
  j["first_order_condition"] = S.first_order_condition;
  j["serep"] = {{"modes", S.serep_modes}, {"rank", S.serep_rank}};
  j["localization"]["confidence_set"] = S.confidence_set;
  j["warnings"] = S.warnings;
  return j;
}

UpdateRun update_case(const Case& c, const ModalData* measured) {
  require_section(c, c.update.has_value(), "update");
  const UpdateSpec& u = *c.update;
  UpdateRun run;
  run.measured = measured ? first_modes(*measured, u.modes) : update_measured_data(c);
  run.pm = std::make_unique<ParametricModel>(c.model);
  for (const Parameter& p : u.parameters) run.pm->add(p);
  // Measured modes without a plausible partner at the initial values are set aside, never forced onto a model
  // mode (the pairing of detect and discover: MAC >= min_mac with a mode the sensors see, within a factor 2).
  const PlausibleModes pl = plausible_modes(*run.pm, run.measured, u.initial, u.options);
  if (pl.paired.empty())
    throw InputError("update: no measured mode pairs with a model mode the sensors see (MAC >= " +
                     format_number(u.options.min_mac, 3) + ", within a factor " + format_number(kMaxPairingRatio, 2) +
                     " in frequency); check the DOF labels and directions");
  std::vector<std::string> aside;
  for (int k : pl.unpaired)
    aside.push_back("measured mode " + std::to_string(k + 1) + " (" + format_number(run.measured.frequencies_hz[k], 5) +
                    " Hz) has no plausible partner in the model at the initial values (the best remaining is " +
                    format_number(pl.correlation.model_hz[k], 5) + " Hz at MAC " +
                    format_number(pl.correlation.mac[k], 3) + "): set aside, not fitted");
  if (!pl.unpaired.empty()) run.measured = modes_subset(run.measured, pl.paired);
  const MeasuredNoise noise = measured_noise(run.measured, u.options);
  FitOptions o = noise.options;
  if (u.lcurve) {  // the weight by the L-curve rule, traced from the initial values; then the fit or search with it
    run.lcurve = l_curve(*run.pm, run.measured, u.initial, u.free, o, u.lcurve_options);
    o.regularization = run.lcurve->weight;
  }
  if (u.multistart) {
    run.search = fit_multistart(*run.pm, run.measured, u.initial, u.free, o, u.search);
    run.fit = run.search->best;
    run.fit.warnings.insert(run.fit.warnings.begin(), run.search->warnings.begin(), run.search->warnings.end());
  } else {
    run.fit = fit_parameters(*run.pm, run.measured, u.initial, u.free, o);
  }
  if (run.lcurve)
    run.fit.warnings.insert(run.fit.warnings.begin(), run.lcurve->warnings.begin(), run.lcurve->warnings.end());
  run.fit.warnings.insert(run.fit.warnings.begin(), noise.warnings.begin(), noise.warnings.end());
  run.fit.warnings.insert(run.fit.warnings.begin(), aside.begin(), aside.end());
  return run;
}

nlohmann::json update_json(const std::string& case_name, const ParametricModel& pm, const UpdateSpec& u,
                           const FitSummary& f, const MultiStartSummary* search, const LCurveSummary* lcurve) {
  nlohmann::json params = nlohmann::json::array();
  for (int p = 0; p < pm.num_parameters(); ++p) {
    const Parameter& q = pm.parameter(p);
    std::string status = u.free.empty() || u.free[p] ? "free" : "fixed";
    for (const auto& t : u.ties)
      if (t.first == p) status = "tied to " + pm.parameter(t.second.first).name;
    params.push_back({{"name", q.name},
                      {"kind", std::string(parameter_kind_name(q.kind))},
                      {"initial", u.initial[p]},
                      {"value", f.theta[p]},
                      {"std", num(f.stddev[p])},
                      {"std_aposteriori", num(f.stddev[p] * f.residual_scale)},
                      {"status", status},
                      {"at_bound", std::find(f.at_bound.begin(), f.at_bound.end(), p) != f.at_bound.end()}});
  }
  nlohmann::json j;
  j["case"] = case_name;
  j["parameters"] = params;
  j["frequencies_hz"] = {{"initial", vec(f.initial_hz)}, {"updated", vec(f.final_hz)}, {"measured", vec(f.measured_hz)}};
  j["mac"] = {{"initial", vec(f.initial_mac)}, {"updated", vec(f.final_mac)}};
  j["objective"] = std::string(fit_objective_name(u.options.objective));
  j["iterations"] = f.iterations;
  j["model_evaluations"] = f.evaluations;
  if (f.reduced_basis)
    j["reduced_basis"] = {{"steps_rejected", f.rejected_steps},
                          {"surrogate_iterations", f.surrogate_iterations},
                          {"seconds_in_surrogates", f.time_surrogate}};
  j["cost"] = {{"initial", f.initial_cost}, {"final", f.final_cost}, {"history", f.cost_history}};
  j["termination"] = f.termination;
  j["converged"] = f.converged;
  j["covariance"] = {{"rank", f.covariance_rank}, {"free_parameters", f.free_parameters}, {"full_rank", f.covariance_ok},
                     {"residual_scale", num(f.residual_scale)}};
  if (search) {
    const MultiStartSummary& s = *search;
    nlohmann::json minima = nlohmann::json::array();
    for (const LocalMinimum& m : s.minima) {
      nlohmann::json th = nlohmann::json::object();
      for (int p = 0; p < pm.num_parameters(); ++p) th[pm.parameter(p).name] = m.theta[p];
      minima.push_back({{"cost", m.cost}, {"starts", m.starts}, {"parameters", th}, {"frequencies_hz", vec(m.final_hz)},
                        {"mac", vec(m.final_mac)}, {"max_frequency_error", m.max_frequency_error}, {"mean_mac", m.mean_mac},
                        {"at_bound", m.at_bound}, {"converged", m.converged}});
    }
    nlohmann::json costs = nlohmann::json::array();
    for (double c : s.start_cost) costs.push_back(num(std::isfinite(c) ? c : std::nan("")));
    j["multistart"] = {{"starts", s.start_points.size()},
                       {"seed", u.search.seed},
                       {"continuation", u.search.continuation},
                       {"same_minimum", u.search.same_minimum},
                       {"failed", s.failed},
                       {"best_start", s.best_start},
                       {"distinct_minima", s.minima.size()},
                       {"minima", minima},
                       {"start_costs", costs},
                       {"start_iterations", s.start_iterations},
                       {"start_evaluations", s.start_evaluations},
                       {"start_seconds", s.start_time},
                       {"time_wall_s", s.time_wall},
                       {"time_cpu_s", s.time_cpu}};
  }
  if (lcurve) {
    nlohmann::json pts = nlohmann::json::array();
    for (const LCurvePoint& p : lcurve->points)
      pts.push_back({{"weight", p.weight},
                     {"misfit", p.misfit},
                     {"size", p.size},
                     {"curvature", p.curvature},
                     {"converged", p.converged}});
    j["regularization"] = {
        {"rule", "l-curve"}, {"weight", lcurve->weight}, {"corner", lcurve->corner}, {"points", pts}};
  } else if (u.options.regularization > 0) {
    j["regularization"] = {{"rule", "fixed"}, {"weight", u.options.regularization}};
  }
  j["warnings"] = f.warnings;
  return j;
}

}  // namespace dynid
