// dynid/io/results_json.hpp -- what `dynid detect` and `dynid update` compute for a case, and their results JSON
// (docs/results-json.md). One home for each, so that the command line and the Python module (python/) give the
// same numbers in the same structure.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "dynid/engine/detect.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/parametric.hpp"
#include "dynid/engine/regularization.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/discover_io.hpp"

namespace dynid {

/// `dynid detect` on a case: the changed state (simulated from detect: changes, or read from measured:), the
/// reference-state data when the case names one, then detect(). Throws InputError when the case has no detect:.
DetectSummary detect_case(const Case& c);

/// The detect results JSON: {"case", "method", "threshold_rule", "full_dofs", "modes", "localization",
/// "quantification", "first_order_condition", "serep", "warnings"}.
nlohmann::json detect_json(const std::string& case_name, const DetectSummary& s);

/// `dynid update` on a case: the measured data, the parametric model of the case's parameters, the fit.
/// `pm` refers to c.model: keep the case alive while the run is used.
struct UpdateRun {
  ModalData measured;
  std::unique_ptr<ParametricModel> pm;
  FitSummary fit;                        ///< the fit (with multistart: the best start's)
  std::optional<MultiStartSummary> search;  ///< the global search, when the case asks for it
  std::optional<LCurveSummary> lcurve;      ///< the L-curve that chose the regularization weight, when asked for
};
/// `measured`, when given, replaces the case's measured data (a host's own modes; the first update: modes used).
UpdateRun update_case(const Case& c, const ModalData* measured = nullptr);

/// The update results JSON: {"case", "parameters", "frequencies_hz", "mac", "objective", "iterations",
/// "model_evaluations", "cost", "termination", "converged", "covariance", "warnings"}. `u` gives the initial
/// values, which parameters are free, the ties and the objective. With `search` (multistart), also "multistart":
/// {"starts", "seed", "continuation", "same_minimum", "failed", "best_start", "distinct_minima", "minima" (lowest
/// cost first: cost, starts, parameters, frequencies_hz, mac, max_frequency_error, mean_mac, at_bound, converged),
/// "start_costs", "start_iterations", "start_evaluations", "start_seconds", "time_wall_s", "time_cpu_s"}. With a
/// regularization weight or `lcurve`, also "regularization": {"rule" (fixed | l-curve), "weight", and for the
/// L-curve "corner" and "points" (weight, misfit, size, curvature, converged; smallest weight first)}.
nlohmann::json update_json(const std::string& case_name, const ParametricModel& pm, const UpdateSpec& u,
                           const FitSummary& f, const MultiStartSummary* search = nullptr,
                           const LCurveSummary* lcurve = nullptr);

/// The measured modes of a discover: case given in memory instead of the case's measured: / recordings: (host
/// codes, Python): modal data, kept as discovery_data() keeps a file's (min_mpc, modes), or recordings,
/// identified as the case's recordings are (its identify: options; without a band, the band the model implies
/// for the sensors). `source` names the data in the results.
DiscoveryData discovery_data(const Case& c, ModalData measured, const std::string& source);
DiscoveryData discovery_data(const Case& c, std::vector<Recording> recordings, const std::string& source);

}  // namespace dynid
