// dynid/engine/multistart.hpp -- global search for model updating: many local fits (fit_parameters) from
// space-filling starting points within the bounds, run in parallel, grouped into the distinct local minima.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "dynid/engine/model_fit.hpp"

namespace dynid {

/// One rule for every structure (docs/method.md, "Global search"):
///  - starts: the user's initial values, then a Latin hypercube over the free parameters' bounds (log-uniform
///    where 0 < lower and upper >= 10 lower); starts_for() gives their number when `starts` is 0;
///  - each start is a local fit (with `continuation`: a frequency-only fit first, then the objective from its end);
///  - two ends are the same minimum when every free parameter agrees within `same_minimum` of its bound range;
///  - the best is the minimum with the lowest cost.
/// Starts are independent and their points drawn before any runs: the result is the same for any thread count.
struct MultiStartOptions {
  int starts = 0;                ///< 0 = starts_for(free parameters)
  std::uint64_t seed = 19;
  double same_minimum = 0.01;    ///< share of each parameter's bound range
  bool continuation = false;
  bool IsValid(std::string* why) const;
};
/// The rule's number of starts: 2 per free parameter, at least 8, at most 32.
int starts_for(int free_parameters);

struct LocalMinimum {
  Eigen::VectorXd theta;         ///< all parameters (of the lowest-cost start that reached it)
  double cost = 0;               ///< Ceres cost (1/2 sum r^2) there
  std::vector<int> starts;       ///< the starts that ended here (0 = the user's initial values)
  Eigen::VectorXd final_hz, final_mac;
  double max_frequency_error = 0;  ///< largest |f_model / f_measured - 1|
  double mean_mac = 0;
  int at_bound = 0;              ///< parameters on a bound
  bool converged = false;        ///< the representative start converged
};

struct MultiStartSummary {
  FitSummary best;               ///< the full fit of the start with the lowest cost (initial_hz, initial_mac:
                                 ///< at the user's initial values, as for a single fit)
  int best_start = -1;
  std::vector<LocalMinimum> minima;          ///< distinct minima, lowest cost first
  std::vector<Eigen::VectorXd> start_points; ///< every start (all parameters)
  std::vector<double> start_cost;            ///< final cost of every start (+inf: it failed)
  std::vector<std::string> start_error;      ///< why a start failed ("" = it did not)
  std::vector<int> start_iterations, start_evaluations;  ///< Ceres iterations and model evaluations of every start
  std::vector<char> start_converged;                     ///< every start: Ceres reported CONVERGENCE
  std::vector<double> start_time;                        ///< seconds of every start (its own wall time)
  int failed = 0;
  double time_wall = 0;          ///< seconds for all starts
  double time_cpu = 0;           ///< processor time of the process during the search (all threads; std::clock)
  std::vector<std::string> warnings;
};

/// The starting points of the search (all parameters): the user's values, then the Latin hypercube. Throws
/// InputError for invalid options, or a free parameter without finite bounds.
std::vector<Eigen::VectorXd> multistart_points(const ParametricModel& pm, const Eigen::VectorXd& theta0,
                                               const std::vector<char>& free, const FitOptions& options,
                                               const MultiStartOptions& ms);

/// Runs the global search. Parameters that are free must have finite bounds (InputError otherwise); fixed and
/// tied ones behave as in fit_parameters. Throws NumericalError when every start fails.
MultiStartSummary fit_multistart(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta0,
                                 const std::vector<char>& free, const FitOptions& options, const MultiStartOptions& ms);

}  // namespace dynid
