// dynid/engine/model_fit.hpp -- fitting a ParametricModel to measured modal data with Ceres Solver
// (Levenberg-Marquardt or dogleg trust region, bounds, analytic Jacobians, covariance).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/parametric.hpp"

namespace dynid {

/// Residuals, per measured mode k paired (by MAC) with model mode i at the current parameters:
///  kFrequency     (lambda_i - lambda_k) / s_k                          s_k = 2 frequency_noise lambda_k
///  kFrequencyMac  (lambda_i - lambda_k) / (s_k MAC_ik)                 the paper's f1 (eq. 2) as least squares
///  kCombined      kFrequency plus (c phi_i - u_k) / shape_noise at the measured DOFs, u_k the measured shape
///                 scaled to a largest entry of 1, c the least-squares scale
///  kSerep         the paper's f2: (K~ - lambda_k M~) u_k on the model reduced by SEREP to the measured DOFs
///                 (K~, M~ from the model's modes at the current parameters), scaled per mode
/// Frequency and shape noise are standard deviations (relative); with them the residuals are whitened and the
/// parameter covariance is meaningful.
enum class FitObjective { kFrequency, kFrequencyMac, kCombined, kSerep };
std::string_view fit_objective_name(FitObjective o);  // "frequency", "f1", "combined", "f2"

struct FitOptions {
  FitObjective objective = FitObjective::kCombined;
  double frequency_noise = 1e-3;  ///< relative std of measured frequencies
  double shape_noise = 1e-2;      ///< std of shape entries relative to each mode's largest entry
  /// Per measured mode, when given (one value per mode): they replace frequency_noise and shape_noise for that
  /// mode (measured uncertainties differ from mode to mode).
  Eigen::VectorXd frequency_noise_modes, shape_noise_modes;
  /// Per shape entry, when given (measured DOFs x modes): the std of each entry relative to its mode's largest
  /// entry; replaces the per-mode shape noise in `combined` (f2 uses each mode's RMS). An entry of 0 is exact
  /// (the entry the mode was normalised by): the model shape is scaled to match the exact entries, which carry
  /// no residual.
  Eigen::MatrixXd shape_noise_entries;
  /// Per measured mode, when given (one matrix per mode: measured DOFs x any number of columns, none allowed):
  /// directions along which the mode's shape is uncertain beyond the noise above, in the same units (relative to
  /// the mode's largest entry). In `combined` the shape residual's covariance is then diag(std^2) + F F^T and
  /// the residuals are whitened by its inverse square root: a misfit along F's columns weighs as little as their
  /// size says. Discovery gives the neighbours of closely spaced modes (docs/method.md, "Closely spaced modes").
  std::vector<Eigen::MatrixXd> shape_covariance_factors;
  double regularization = 0.0;    ///< Tikhonov weight w: residuals sqrt(w) (theta_p - nominal_p) / scale_p
  enum class Loss { kNone, kHuber, kCauchy };
  Loss loss = Loss::kNone;        ///< robust loss on each mode's frequency residual and, separately, its shape
                                  ///< residuals (whitened)
  double loss_scale = 3.0;        ///< in units of the noise std
  bool dogleg = false;            ///< trust-region dogleg instead of Levenberg-Marquardt
  int max_iterations = 100;
  /// Ceres stopping tests: relative cost change (1e-8: far below a significant chi-square change when the data
  /// are noisy), relative step (exact data converge here) and gradient.
  double function_tolerance = 1e-8, parameter_tolerance = 1e-10, gradient_tolerance = 1e-14;
  double min_mac = 0.5;           ///< pairing threshold
  /// Pairing plausibility: partners further apart in frequency than this factor are not paired (0 = no bound).
  double max_frequency_ratio = 0;
  /// Model modes the sensors cannot see are not pairing partners: those whose mean square at the measured DOFs
  /// is below this share of their mean square over all translational DOFs (axial or out-of-plane modes under
  /// transverse or in-plane sensors), whose MAC with any measurement is noise.
  double min_visibility = kMinPairingVisibility;
  int extra_modes = 10;           ///< model modes computed beyond the measured ones (pairing, expansion)
  /// Models up to this many DOFs are solved densely with every mode (exact shape derivatives); larger ones by
  /// shift-invert Lanczos for the modes needed, shape derivatives with a static correction. With hundreds of
  /// parameters (discovery's screening) the sparse path is the cheaper one well below 400 DOFs.
  int dense_max_dofs = 400;
  bool covariance = true;
  /// Reduced-basis fit (large models): each outer step solves the full model once (modes, Jacobian), projects it
  /// on its modes and one block of shift-invert Krylov vectors (V^T K(theta) V, V^T M(theta) V, linear in the
  /// parameters about that point), corrects the projection to the full residuals and Jacobian there (first-order
  /// consistent), and minimises that surrogate within a trust region; the full model then accepts or rejects the
  /// step. Same minimum as the direct fit, far fewer eigen-solves. kAuto: on for sparse models of at least
  /// reduced_basis_min_dofs DOFs. Not applied (a warning says so) to the f2 objective, to models solved densely
  /// and to free-free models.
  enum class ReducedBasis { kOff, kAuto, kOn };
  ReducedBasis reduced_basis = ReducedBasis::kOff;
  int reduced_basis_min_dofs = 20000;
  /// Tied parameters: theta[p] = ratio * theta[q] for each (p, (q, ratio)); q must be free, p is not.
  std::vector<std::pair<int, std::pair<int, double>>> ties;
  bool IsValid(std::string* why) const;
};

struct FitSummary {
  Eigen::VectorXd theta;        ///< all parameters (fixed ones unchanged)
  Eigen::VectorXd stddev;       ///< from the Ceres covariance; NaN where not estimable (or fixed)
  bool covariance_ok = false;
  int covariance_rank = 0;      ///< rank of J^T J over the free parameters
  int free_parameters = 0;
  std::vector<double> cost_history;  ///< Ceres cost (1/2 sum r^2) per iteration, starting with the initial
  int iterations = 0;                ///< Ceres iterations, or the reduced-basis fit's outer steps taken
  int rejected_steps = 0;            ///< reduced-basis fit: outer steps the full model rejected
  int surrogate_iterations = 0;      ///< reduced-basis fit: Ceres iterations on the surrogates (no eigen-solve)
  bool reduced_basis = false;        ///< the fit ran on reduced-basis surrogates
  int evaluations = 0;          ///< model evaluations (eigen-solves)
  double time_eigen = 0;        ///< seconds in eigen-solves
  double time_sensitivity = 0;  ///< seconds in sensitivities (Jacobians)
  double time_surrogate = 0;    ///< reduced-basis fit: seconds building and minimising the surrogates
  double time_total = 0;        ///< seconds in fit_parameters
  std::string termination;      ///< Ceres termination: CONVERGENCE, NO_CONVERGENCE, FAILURE, ...
  bool converged = false;
  double initial_cost = 0, final_cost = 0;
  Eigen::VectorXd measured_hz, initial_hz, final_hz;  ///< per measured mode (paired model modes)
  Eigen::VectorXd initial_mac, final_mac;
  /// sqrt(chi2 / (data - free parameters)) at the solution: 1 when the stated noise is right. `stddev` assumes
  /// the stated noise; stddev * residual_scale is the a-posteriori estimate when the noise is not known.
  double residual_scale = std::numeric_limits<double>::quiet_NaN();
  /// J^T J of the whitened residuals over the free parameters at the solution (without regularization): the
  /// inverse posterior covariance at the stated noise (Laplace approximations of the evidence).
  Eigen::MatrixXd information;
  Eigen::MatrixXd information_frequency;  ///< the frequency residuals' part of `information`
  double final_chi2_frequency = 0;  ///< the frequency residuals' part of 2 final_cost
  Eigen::VectorXd final_residuals;  ///< the whitened residuals at the solution, mode by mode (as linearize())
  std::vector<char> final_forced;   ///< per measured mode: paired below min_mac (or the ratio bound) at the solution
  std::vector<int> at_bound;    ///< parameters that ended on a bound
  std::vector<std::string> warnings;
  std::string report;           ///< Ceres FullReport()
};

/// The noise a fit should weight by when the measured data carry their own standard deviations: `options` with
/// frequency_noise_modes from ModalData::frequency_std_hz (relative), and shape_noise_entries from
/// shape_entry_std (relative to each mode's largest entry) or shape_noise_modes from shape_std. What the data do
/// not carry stays at the stated levels, and a warning says so.
struct MeasuredNoise {
  FitOptions options;
  bool frequency = false, shape = false;  ///< taken from the data
  std::vector<std::string> warnings;
};
MeasuredNoise measured_noise(const ModalData& measured, const FitOptions& options);

/// Fits the parameters marked free (all if `free` is empty) starting from theta0. Throws InputError on
/// invalid options or data that does not match the model.
FitSummary fit_parameters(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta0,
                          const std::vector<char>& free, const FitOptions& options);

/// The whitened residuals r(theta) (stacked mode by mode, as fit_parameters builds them) and the Jacobian
/// J = dr/dtheta for every parameter, from one model evaluation: for screening many candidate parameter subsets
/// (e.g. one element at a time) at the cost of one eigen-solve.
struct Linearization {
  Eigen::VectorXd r;
  Eigen::MatrixXd J;               ///< rows of r x all parameters
  std::vector<int> block_start;    ///< first row of each measured mode's block
  Eigen::VectorXd model_hz, mac;   ///< paired model frequencies and MAC per measured mode
  std::vector<char> forced;        ///< mode paired below min_mac
};
Linearization linearize(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta,
                        const FitOptions& options);

/// The fit's residual vector and cost as functions of the parameters, for other optimisers (the genetic
/// algorithm baseline in bench/) and for scans. Keeps the eigen-solver's symbolic analysis between calls.
class FitProblem {
 public:
  FitProblem(const ParametricModel& pm, const ModalData& measured, const FitOptions& options);
  ~FitProblem();
  /// Whitened residuals at theta (all parameters); false if the model cannot be evaluated there.
  bool residuals(const Eigen::VectorXd& theta, Eigen::VectorXd* r);
  /// 1/2 ||r||^2, or +inf where the model cannot be evaluated.
  double cost(const Eigen::VectorXd& theta);
  int evaluations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One evaluation of the model against measured data (no fitting): frequencies and MAC of the paired modes.
struct Correlation {
  Eigen::VectorXd measured_hz, model_hz, mac;
  std::vector<int> model_mode;  ///< paired elastic model mode (0-based, rigid modes not counted), -1 if none
};
/// The pairing follows `options` (min_mac, max_frequency_ratio, min_visibility); a measured mode without a plausible
/// partner has model_mode -1 and, in model_hz and mac, the values of the mode it would be forced to.
Correlation correlate(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta,
                      const FitOptions& options);

/// The measured modes a fit should use: those with a plausible partner in the model at theta (correlate(): MAC >=
/// min_mac with a model mode the sensors see, within max_frequency_ratio and never beyond kMaxPairingRatio), and
/// the others (a spurious mode, or one the model does not have), which are left out rather than forced onto another
/// model mode, where one bad mode could carry the fit. Updating applies it at the initial values, as discovery does
/// at the model as given.
struct PlausibleModes {
  std::vector<int> paired;    ///< measured modes (0-based) with a plausible partner, ascending
  std::vector<int> unpaired;  ///< the others, ascending
  Correlation
      correlation;  ///< every measured mode at theta (model_hz and mac of an unpaired one: the forced partner's)
};
PlausibleModes plausible_modes(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta,
                               const FitOptions& options);

}  // namespace dynid
