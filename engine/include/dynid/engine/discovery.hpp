// dynid/engine/discovery.hpp -- missing-physics discovery: where a model and measured modes disagree, which
// physics the model left out, its fitted parameters, and the fit before and after.
//
// Four steps (docs/method.md, "Discovery"):
//  1. Locate: residual forces of the measured modes on the model reduced by SEREP to the measured DOFs, summarised
//     per node and direction (localized or spread; stiffness-like or mass-like), and a linearised screening of
//     every local hypothesis (one eigen-solve for all of them).
//  2. Hypothesize: a library of candidate augmentations (class Candidate: a small parametric dK(theta), dM(theta)
//     with bounds and a physical meaning), placed at the screened sites or applied globally.
//  3. Fit and select: every plausible candidate fitted with Ceres (fit_parameters), scored by BIC on the whitened
//     frequency and shape residuals; further effects added greedily while the score improves decisively; the
//     classic alternative (recalibrate E and rho globally) is scored too.
//  4. Report: the verdict, the findings with uncertainties, the ranking, and the fit before and after.
// The engine reads no files and prints nothing.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/parametric.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

/// Where a candidate acts (user ids).
struct Site {
  std::vector<int> nodes, elements;
};

/// One parameter of a candidate, in the candidate's own dimensionless units (well scaled for the optimiser).
struct CandidateParameter {
  std::string name;
  double nominal = 0, lower = 0, upper = 1;
};

/// A parameter in physical units (what the report states).
struct PhysicalValue {
  std::string name, unit;
  double value = 0, std = 0;
};

/// A model augmentation hypothesis. A new kind of missing physics is one small class: its parameters with bounds,
/// its dK(theta), dM(theta) and their derivatives (as CustomTerms on the model), and its physical meaning.
class Candidate {
 public:
  virtual ~Candidate() = default;
  virtual std::string kind() const = 0;           ///< "semi_rigid_joint", "lumped_mass", ...
  virtual std::string description() const = 0;    ///< one line: "rotational spring between element 12 and node 5"
  virtual Site site() const = 0;
  virtual bool global() const { return false; }   ///< acts on the whole structure (or a group)
  virtual std::vector<CandidateParameter> parameters() const = 0;
  /// dK, dM as custom terms on `model`, on this candidate's parameters numbered from `first` in the
  /// ParametricModel (the caller adds the parameters, then these terms).
  virtual std::vector<CustomTerm> terms(const Model& model, int first) const = 0;
  /// The fitted parameters in physical units (theta, std: this candidate's, dimensionless).
  virtual std::vector<PhysicalValue> physical(const Eigen::VectorXd& theta, const Eigen::VectorXd& std) const = 0;
  /// What was left out, in words, with the values ("the base at node 1 is not fixed: rotational spring ...").
  virtual std::string finding(const std::vector<PhysicalValue>& values) const = 0;
};

struct DiscoveryOptions {
  FitOptions fit;                  ///< objective (combined), noise levels, pairing; see FitOptions
  /// Noise levels used to whiten the residuals: measured frequencies (relative std) and shape entries (std
  /// relative to each mode's largest entry). Identified data give their own frequency spread; these are floors.
  double frequency_noise = 1e-3, shape_noise = 5e-2;
  int screen_fit = 16;             ///< local candidates fitted in full after the linear screening
  int max_effects = 3;             ///< greedy: at most this many effects combined (and at most one fitted
                                   ///< parameter per two measured modes)
  /// Decisive evidence (BIC difference; 10 = "very strong" on the Kass-Raftery scale) for a finding and for each
  /// further effect; an alternative within `ambiguity` of the best makes the verdict inconclusive.
  double decisive = 10.0, ambiguity = 6.0;
  /// The nominal model must misfit the data by more than this before any finding is made (chi-square per datum,
  /// whitened by the noise levels above, of the frequencies or of the shape entries, whichever is larger; the
  /// few frequencies are not diluted by the many shape entries): below it the model is consistent with the data.
  double min_misfit = 2.0;
  /// A further effect's parameters must differ from nominal by this many standard deviations (a posteriori).
  double min_significance = 3.0;
  std::vector<std::string> kinds;  ///< candidate kinds to consider (empty = all)
  std::vector<int> sensor_nodes;   ///< nodes carrying sensors (sensor mass loading); empty = the measured nodes
  std::vector<int> suspension_nodes;  ///< free-free tests: suspension points (empty = the two farthest nodes)
  bool si_units = true;            ///< label reported values in SI (kg, N, m); false: "(model units)"
  bool IsValid(std::string* why) const;
};

/// Step 1: where the data disagree with the model.
struct Localization {
  std::vector<MeasuredDof> dofs;   ///< measured DOFs (rows of the residuals)
  Eigen::MatrixXd residuals;       ///< SEREP-reduced residual force per measured mode (dofs x modes)
  Eigen::VectorXd pseudo;          ///< per DOF: geometric mean over modes of |R| / ||R||
  struct NodeShare {
    int node = 0;                  ///< user id
    double share = 0;              ///< share of the residual force (sum over the node's DOFs of pseudo^2)
    double x = 0, y = 0, z = 0;    ///< shares per direction
  };
  std::vector<NodeShare> nodes;    ///< sorted by share, largest first
  double concentration = 0;        ///< share of the largest 20 % of nodes (1 = all in one spot)
  bool localized = false;
  Eigen::Vector3d direction_share = Eigen::Vector3d::Zero();  ///< x, y, z shares of the residual
  double mass_alignment = 0;       ///< mean over modes of cos(R_k, lambda_k M~ u_k): ~ +-1 mass-like, ~0 stiffness-like
  double mean_frequency_error_pct = 0;  ///< mean (model - measured) / measured
  std::string nature;              ///< "stiffness" or "mass" (dominant), from the screening and the alignment
  std::string words;               ///< the summary in one or two sentences
};

/// One scored hypothesis (a candidate, a combination, the nominal model or the recalibration).
struct ScoredHypothesis {
  std::string kind, description;
  Site site;
  bool global = false;
  double screening = 0;            ///< linearised chi-square drop of the screening (local candidates)
  bool fitted = false;
  double chi2 = 0;                 ///< whitened residual sum of squares after the fit
  int parameters = 0;
  double bic = 0, delta_bic = 0;   ///< score (lower is better) and its improvement over the nominal model
  std::vector<PhysicalValue> values;
  std::string finding;
  double max_freq_error_pct = 0, mean_mac = 0;
  bool at_bound = false;           ///< a parameter ended on a bound (the hypothesis strains to fit)
};

struct FitQuality {
  Eigen::VectorXd measured_hz, model_hz, mac;
  double max_freq_error_pct = 0;  ///< over the modes that pair (MAC >= 0.5)
  int unpaired = 0;                ///< measured modes with no model mode of MAC >= 0.5
  double mean_mac = 0, chi2 = 0;
};

struct DiscoverySummary {
  std::string verdict;             ///< "missing_physics", "consistent" or "inconclusive"
  std::string explanation;         ///< why, in words, with the evidence
  Localization localization;
  std::vector<ScoredHypothesis> findings;    ///< the accepted effects, in the order they were added
  std::vector<ScoredHypothesis> candidates;  ///< every hypothesis scored, best first (single effects)
  ScoredHypothesis recalibration;            ///< E and rho recalibrated globally
  FitQuality before, after;
  int data = 0;                    ///< whitened residuals (frequencies + shape entries)
  double chi2_per_datum_before = 0;     ///< max of the frequency and the shape parts (see min_misfit)
  double chi2_frequency_before = 0, chi2_shape_before = 0;  ///< per datum
  int eigen_solves = 0;
  double seconds = 0;
  std::vector<std::string> warnings;
};

/// The candidate library placed on a model: every local candidate at every admissible site and the global ones
/// (filtered by options.kinds). Exposed so host codes can inspect or extend it.
std::vector<std::unique_ptr<Candidate>> candidate_library(const Model& model, const ModalData& measured,
                                                          const DiscoveryOptions& options);

/// Adds the candidates' parameters (kCustom, with their bounds) and terms to `pm`, in order; returns the index of
/// each candidate's first parameter. For host codes that fit or evaluate candidates themselves.
std::vector<int> install_candidates(ParametricModel* pm, const std::vector<const Candidate*>& set);

/// Runs the four steps. `extra` candidates (a host code's own) are considered with the library's.
/// Throws InputError for data that does not fit the model or invalid options.
DiscoverySummary discover(const Model& model, const ModalData& measured, const DiscoveryOptions& options,
                          std::vector<std::unique_ptr<Candidate>> extra = {});

}  // namespace dynid
