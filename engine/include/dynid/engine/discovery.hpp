// dynid/engine/discovery.hpp -- missing-physics discovery: where a model and measured modes disagree, which
// physics the model left out, its fitted parameters, and the fit before and after.
//
// discover() is a short driver over named stages (docs/method.md, "Discovery"):
//  1. prepare:  the noise model (stated, carried by the data, or a conservative default with a warning) and the
//               measured modes set aside (rigid-body modes of a free-free test on its suspension);
//  2. locate:   residual forces (eq. 6-8, residual_force.hpp) of the measured modes on the model reduced by SEREP to
//               the measured DOFs, summarised per node and direction;
//  3. screen:   one linearisation of the whitened frequency and shape residuals ranks every local candidate;
//  4. fit:      the screened candidates, every global one and the recalibration of E and rho fitted (Ceres), each
//               scored by its Laplace-approximated evidence with physical priors;
//  5. select:   effects added while each is decisive, explains a real share of the misfit left and keeps every
//               mode's fit (no finding may worsen the largest frequency error or the mean MAC); after every
//               addition each chosen effect must still earn its place (backward elimination);
//  6. decide:   the verdict and why, as data (the words are io's: discover_io.hpp).
// The engine reads no files and prints nothing.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/candidate.hpp"
#include "dynid/engine/modal_data.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

struct DiscoveryOptions {
  /// Noise of the measured data: relative std of the frequencies, and std of shape entries relative to each mode's
  /// largest entry. NaN = not stated: the data's own estimates (ModalData::frequency_std_hz, shape_std) where it
  /// carries them, else the conservative defaults below, with a warning (a silent optimistic default would call
  /// every mismatch of noisy data missing physics).
  double frequency_noise = std::numeric_limits<double>::quiet_NaN();
  double shape_noise = std::numeric_limits<double>::quiet_NaN();
  double default_frequency_noise = 0.01, default_shape_noise = 0.05;
  /// Floors of noise levels taken from the data (an identification's split-data or pole-scatter estimates): those
  /// see the random error only, not the bias every identification carries (leakage, out-of-band modes, a fitted
  /// pole model), and on a null case an estimate of 0.15 % made the model's own shapes look decisively wrong.
  double min_data_frequency_noise = 1e-4, min_data_shape_noise = 0.03;
  /// The model is consistent with the data when the chi-square of its whitened residuals stays below the quantile
  /// 1 - consistency_level of the chi-square distribution (frequencies and shapes tested separately, each at
  /// half this level).
  double consistency_level = 1e-3;
  int screen_fit = 16;             ///< local candidates fitted in full after the linear screening
  int max_effects = 3;             ///< at most this many effects combined (and one parameter per two measured modes)
  /// Evidence thresholds, natural log of the Bayes factor: `decisive` for a finding and for each further effect
  /// (5 = 150:1, "very strong" on the Kass-Raftery scale); explanations of another story within `ambiguity` of the
  /// findings are reported as rivals.
  double decisive = 5.0, ambiguity = 3.0;
  /// The findings are named (verdict missing_physics) when their posterior probability among the explanations
  /// scored (theirs, every explored explanation of another story, the recalibration, the model as given; equal
  /// prior odds) is at least this: more probable than all the others together. Below it the verdict is
  /// inconclusive (reason rivals).
  double min_probability = 0.5;
  /// A further effect must remove `further` of the misfit its predecessors leave (beyond what the best set
  /// explored leaves): a real second effect removes nearly all of it, a stand-in that absorbs the first effect's
  /// approximation of the real physics only part. An explanation that removes less than `partial` of the misfit
  /// beyond the noise leaves the verdict inconclusive (an effect outside the library, or several at once).
  double further = 0.8, partial = 0.5;
  /// ... and at least `min_share` of the misfit the model as given has beyond the best set's: a candidate that
  /// approximates the real physics (equal masses for unequal ones, a spring for a soft stub) leaves a misfit in
  /// proportion to the effect it models, which a second candidate will always reduce; a real second effect
  /// carries a share of its own.
  double min_share = 0.01;
  /// Model-form uncertainty of a finding's values: a candidate approximates the real physics (a spring for a soft
  /// stub, a point mass for a block), so its reported standard deviation has this share of its change from
  /// nominal added in quadrature (docs/method.md).
  double model_form = 0.05;
  /// The form error a hypothesis of the right physics still has in the frequencies (relative) and in the shape
  /// entries (relative to each mode's largest): the scale of the half-normal prior on each data type's model-form
  /// error, which every hypothesis, the model as given included, is scored with at its most likely level.
  double form_error_frequency = 0.0025, form_error_shape = 0.02;
  /// A further effect's parameters must differ from nominal by this many standard deviations.
  double min_significance = 3.0;
  int max_iterations = 100;        ///< Ceres iterations per fit
  double min_mac = 0.5;            ///< pairing: a measured mode pairs with a model mode of at least this MAC ...
  double max_frequency_ratio = 1.5;  ///< ... within this frequency ratio, else it is unpaired (never forced)
  std::vector<std::string> kinds;  ///< candidate kinds to consider (empty = all); unknown names are an error
  std::vector<CandidateKind> extra_kinds;  ///< a host code's own kinds, considered with dynid's
  std::vector<int> sensor_nodes;   ///< nodes carrying sensors (sensor mass loading); empty = the measured nodes
  std::vector<int> suspension_nodes;  ///< free-free tests: suspension points (empty = the two farthest nodes)
  /// Gravity's direction (self_weight). Zero: -y for plane models; -z for space ones, or -y when the structure
  /// stands on its lowest y (every support there and not every one at its lowest z: a frame drawn with y up).
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  /// The acceleration of gravity in the model's units (self_weight's loads); 0 = 9.81 m/s^2 in the length unit
  /// the model's materials imply (mesh/units.hpp: metres or millimetres; metres when they do not say, with a
  /// warning in the summary when the library holds a self_weight candidate).
  double gravity_acceleration = 0;
  bool si_units = true;            ///< label reported values in SI (kg, N, m); false: "(model units)"
  bool IsValid(std::string* why) const;
};

/// Step 2: where the data disagree with the model.
struct Localization {
  std::vector<MeasuredDof> dofs;   ///< measured DOFs (rows of the residuals)
  Eigen::MatrixXd residuals;       ///< eq. (6) on the SEREP-reduced model, per measured mode (dofs x modes)
  Eigen::VectorXd pseudo;          ///< eqs. (7)-(8) per DOF
  struct NodeShare {
    int node = 0;                  ///< user id
    double share = 0;              ///< share of the residual force (sum over the node's DOFs of pseudo^2)
    double x = 0, y = 0, z = 0;    ///< shares per direction
  };
  std::vector<NodeShare> nodes;    ///< sorted by share, largest first
  double concentration = 0;        ///< share of the largest 20 % of nodes (1 = all in one spot)
  bool localized = false;          ///< three or more measured nodes and over half the share in the top fifth
  Eigen::Vector3d direction_share = Eigen::Vector3d::Zero();  ///< x, y, z shares of the residual
  /// Mean over modes of |cos(R_k, lambda_k M~ u_k)|: 1 when the model is off in proportion everywhere (a uniform
  /// change of E or of rho: the residual is then the inertia force itself), small for a local change of either
  /// nature. It does not tell mass from stiffness; `nature` does.
  double mass_alignment = 0;
  double mean_frequency_error_pct = 0;  ///< mean (model - measured) / measured
  Nature nature = Nature::kStiffness;   ///< the nature of the candidates that explain most in the screening
};

/// One scored hypothesis: a candidate, or a set of them.
struct ScoredHypothesis {
  std::string kind;                ///< the candidate's kind ("+"-joined for a set)
  Nature nature = Nature::kStiffness;
  std::string description;
  Site site;
  bool global = false;
  double screening = 0;            ///< linearised chi-square drop of the screening (local candidates)
  bool fitted = false;
  double chi2 = 0;                 ///< whitened residual sum of squares after the fit
  int parameters = 0;
  /// ln of the Bayes factor against the model as given (Laplace approximation, physical priors, the noise scaled
  /// to the misfit nothing explains): > `decisive` is a decisive improvement.
  double log_evidence = -std::numeric_limits<double>::infinity();
  double explained = 0;            ///< share of the model's misfit beyond the noise that the hypothesis removes
  double significance = 0;         ///< smallest |theta - nominal| / std over its parameters
  std::vector<PhysicalValue> values;
  std::string finding;             ///< the candidate's own sentence (Candidate::finding)
  /// Findings: the same kind at other sites the data cannot tell from this one (a local finding's `site` holds
  /// theirs too, after its own; a global one keeps its own).
  std::vector<std::string> equivalent;
  /// Each equivalent site's own values (and standard deviations), fitted alone, in the order of `equivalent`: a
  /// spring or a mass at another site needs another value to predict the same data, so `values` belong to the
  /// first site only.
  std::vector<std::vector<PhysicalValue>> equivalent_values;
  double max_freq_error_pct = 0, mean_mac = 0;
  bool at_bound = false;           ///< a parameter ended on a bound (the hypothesis strains to fit)
};

struct FitQuality {
  Eigen::VectorXd measured_hz, model_hz, mac;
  std::vector<char> paired;        ///< per measured mode: a plausible partner (MAC, frequency ratio)
  /// Largest |model - measured| / measured over the modes the model as given pairs (the same modes before and
  /// after, so that the two numbers compare).
  double max_freq_error_pct = 0;
  int unpaired = 0;                ///< measured modes without a plausible model partner
  double mean_mac = 0, chi2 = 0;   ///< mean MAC over the measured modes (0 for unpaired ones)
};

/// What the noise levels are and where they come from.
struct NoiseModel {
  enum class Source { kStated, kData, kDefault };
  double frequency = 0, shape = 0;  ///< relative std (frequencies; shape entries relative to each mode's largest)
  Source frequency_source = Source::kStated, shape_source = Source::kStated;
  /// From the data: per measured mode (used), each at least the typical (median) mode's - a mode identified
  /// unusually well is not trusted beyond the others, one identified poorly weighs less. Empty when stated.
  Eigen::VectorXd frequency_modes, shape_modes;
  /// The model's own discretisation error per measured mode used (relative frequency, discretization_error()),
  /// added in quadrature to the frequency noise: a mesh too coarse to resolve a mode is no missing physics.
  Eigen::VectorXd discretization;
  /// Closely spaced modes, per measured mode used: the largest share s = min(1, r / delta) by which another
  /// model mode mixes into its shape (docs/method.md; r the frequency's std, or the damping ratio for a neighbour
  /// without a measured partner); 1 when the model has a mode within that resolution. Empty when the frequency
  /// noise is not the identification's.
  Eigen::VectorXd neighbour_mixing;
  /// Per measured mode used: the relative frequency std added (in quadrature, inside frequency_modes) for model
  /// modes the sensors see, without a measured partner, that the identification may have merged with it (the
  /// pull s^2 delta toward each, s = min(1, zeta / delta), zeta the identified damping ratio). Empty like
  /// neighbour_mixing.
  Eigen::VectorXd unresolved;
};

/// A measured mode discovery does not use, and why.
struct SetAside {
  int mode = 0;                    ///< 0-based index in the measured data
  double frequency_hz = 0;
  /// kRigidBody: a free-free test's rigid-body motion on its suspension (below the first elastic mode, shaped
  /// like the model's rigid-body motions). kNoPartner: the model as given has no mode of that shape within the
  /// plausible frequency ratio (a local mode of what is missing, or a spurious identification); after discovery,
  /// `paired_after` tells whether the findings predict it (kRigidBody: whether the findings include the suspension
  /// and their values were refitted with this mode, which they then predict at `model_hz_after`).
  enum class Reason { kRigidBody, kNoPartner } reason = Reason::kRigidBody;
  double mac = 0;                  ///< kRigidBody: MAC with the rigid-body motions; kNoPartner: best MAC
  bool paired_after = false;
  double model_hz_after = 0, mac_after = 0;
};

enum class Verdict { kConsistent, kMissingPhysics, kInconclusive };
const char* to_string(Verdict v);  // "consistent", "missing_physics", "inconclusive"

/// Why the verdict is what it is.
enum class VerdictReason {
  kWithinNoise,      ///< consistent: the model fits the data within the noise
  kExplained,        ///< missing physics: the findings are decisive and explain the misfit
  kNothingDecisive,  ///< inconclusive: a misfit no candidate explains decisively
  kPartlyExplained,  ///< inconclusive: the best explanation leaves most of the misfit
  kRivals,           ///< inconclusive: a different explanation fits about as well
  kSiteUncertain,    ///< missing physics of the findings' kinds, but where is uncertain (kind_probability)
};
const char* to_string(VerdictReason r);  // "within_noise", ...

/// One step of the selection, for the record: an effect added or removed, and the score after it.
struct SelectionStep {
  enum class Action { kStart, kAdd, kRemove } action = Action::kAdd;
  std::string description;         ///< the effect
  double log_evidence = 0, explained = 0, max_freq_error_pct = 0, mean_mac = 0;
};

struct DiscoverySummary {
  Verdict verdict = Verdict::kConsistent;
  VerdictReason reason = VerdictReason::kWithinNoise;
  NoiseModel noise;
  std::vector<SetAside> set_aside;
  Localization localization;
  /// The explanation: the accepted effects, most important first (by the evidence lost without each). Each
  /// carries the values fitted in the combination; `combined` scores the set as a whole.
  std::vector<ScoredHypothesis> findings;
  ScoredHypothesis combined;
  std::vector<SelectionStep> steps;          ///< how the explanation was reached
  std::vector<ScoredHypothesis> candidates;  ///< every single candidate fitted, best first
  std::vector<ScoredHypothesis> rivals;      ///< explanations of another kind or place within `ambiguity`
  /// The findings' posterior probability among the explanations scored (DiscoveryOptions::min_probability); 1 when
  /// nothing else comes near, 0 when nothing was found.
  double probability = 0;
  /// The probability that the missing physics is of the findings' kinds, wherever it sits: the findings and the
  /// explanations of the same kinds at other sites, against every other explanation scored (>= probability).
  /// Below min_probability for the findings but above it for their kinds, the verdict is missing physics with the
  /// reason site_uncertain: the kind is clear, the place is not.
  double kind_probability = 0;
  ScoredHypothesis recalibration;            ///< E and rho recalibrated globally (always scored)
  FitQuality before, after;
  /// Share of the model's misfit beyond the noise (chi-square above its expectation at the noise model's
  /// levels) that the findings remove.
  double explained = 0;
  int data = 0;                    ///< whitened residuals (frequencies + shape entries)
  double chi2_frequency_before = 0, chi2_shape_before = 0;  ///< per datum, at the noise model's levels
  /// The explanation's prediction-error levels, in units of the noise model's (>= 1): its misfit per frequency
  /// and per shape entry where larger than the noise (the model as given's when nothing is found). Each hypothesis
  /// is scored at its own levels (DiscoveryOptions: the evidence).
  double noise_scale_frequency = 1, noise_scale_shape = 1;
  int eigen_solves = 0;
  double seconds = 0;
  std::vector<std::string> warnings;
};

/// The candidate library placed on a model: every candidate of the kinds in options.kinds (all if empty) among
/// dynid's and options.extra_kinds, exactly as discover() places it (its units come from the model's modes paired
/// with `measured`). Exposed so host codes can inspect it. Throws as discover() does on invalid options or data.
std::vector<std::unique_ptr<Candidate>> candidate_library(const Model& model, const ModalData& measured,
                                                          const DiscoveryOptions& options);

/// Runs the stages. `extra` candidates (a host code's own, already placed) are considered with the library's.
/// Throws InputError for invalid options or data that does not fit the model, NumericalError when the model
/// itself cannot be solved.
DiscoverySummary discover(const Model& model, const ModalData& measured, const DiscoveryOptions& options,
                          std::vector<std::unique_ptr<Candidate>> extra = {});

}  // namespace dynid
