// The stages of discover() (internal): each a function of the Problem, tested on its own (tests/test_discovery.cpp).
#pragma once

#include <algorithm>
#include <exception>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/discovery.hpp"
#include "dynid/engine/model_fit.hpp"
#include "internal/parallel.hpp"

namespace dynid::internal {

/// What every stage shares: the model, the data discovery uses, the noise model, the candidates. Filled in place by
/// prepare() (the candidate context points into it).
struct Problem {
  Problem() = default;
  Problem(const Problem&) = delete;
  Problem& operator=(const Problem&) = delete;
  const Model* model = nullptr;
  DiscoveryOptions options;
  ModalData data;                  ///< the measured modes used (set-aside ones removed)
  std::vector<int> data_modes;     ///< their indices in the measured data
  /// The measured modes without a partner in the model as given (a local mode of what is missing, or a spurious
  /// identification), and per mode the most a hypothesis pairing it can gain in -2 ln L: the log ratio of the noise's
  /// normal density to the vague density an unpaired mode has (prepare.cpp); it earns that less its chi-square.
  ModalData unpartnered;
  Eigen::VectorXd unpartnered_edge;
  NoiseModel noise;
  FitOptions fit;                  ///< combined frequency and shape residuals at the noise model's levels
  /// The fit's options for other measured modes than `data`'s (the typical noise level instead of per mode).
  FitOptions fit_for_other_modes() const {
    FitOptions f = fit;
    f.frequency_noise_modes.resize(0);
    f.shape_noise_modes.resize(0);
    f.shape_covariance_factors.clear();
    return f;
  }
  CandidateContext context;
  std::vector<std::unique_ptr<Candidate>> library;
  std::unique_ptr<Candidate> recalibration;
  /// Candidates in the library per Candidate::physics() (the evidence's prior over physics and sites).
  std::map<std::string, int> sites_per_physics;
  int n = 0;                       ///< whitened residuals
  int modes = 0;                   ///< measured modes used
  double chi2_0 = 0;               ///< the model as given: whitened residual sum of squares
  double chi2_0_frequency = 0;     ///< its frequency part
};

/// A set of candidates fitted together.
struct SetFit {
  bool ok = false;
  std::vector<const Candidate*> set;
  std::vector<Eigen::VectorXd> theta;  ///< per candidate, its own parameters
  double chi2 = 0;                 ///< whitened residual sum of squares at the solution
  double chi2_frequency = 0;       ///< its frequency part
  Eigen::VectorXd residuals;       ///< the whitened residuals at the solution (what the set predicts, less the data)
  Eigen::MatrixXd information;     ///< J^T J over the set's parameters (whitened at the stated noise)
  Eigen::MatrixXd information_frequency;  ///< its frequency rows' part
  FitQuality quality;
  /// Sum over the unpartnered modes this set pairs of (log-density gain, prepare.cpp): evidence from modes the
  /// model as given lacks.
  double unpartnered_gain = 0;
  /// A magnitude (first) parameter ended on a bound, or a candidate's values are not plausible
  /// (Candidate::plausible): either way no explanation.
  bool at_bound = false;
  int evaluations = 0;
  int parameters() const;
};

// ---- prepare ----
/// The noise model (stated, the data's own, or the conservative default with a warning).
NoiseModel noise_model(const ModalData& data, const DiscoveryOptions& o, std::vector<std::string>* warnings);
/// Identified modes whose shapes are complex (MPC < 1) are mixtures: a close neighbour, or a neighbour's tail, is
/// in them. The out-of-phase part of a shape shows how much (its energy c = B/A of the in-phase part's, from MPC =
/// ((A - B)/(A + B))^2): the frequency's relative std gains the damping ratio times sqrt(c) (a mixture's pole moves
/// within the half-power band), in quadrature. The shapes keep their noise: widening each entry's std by sqrt(c)
/// times the rms entry took the weight off the higher modes that place an attached mass (bundled
/// frame-two-effects, seed 15: MPC 0.89 and 0.97, mass named at the wrong node). Data without MPC: unchanged.
void add_contamination(const ModalData& data, NoiseModel* nm);
/// Free-free models: measured modes that are rigid-body motions on the test's suspension (below the first elastic
/// model frequency, shaped like the model's rigid-body motions at the sensors).
std::vector<SetAside> rigid_body_modes(const Model& model, const ModalData& data);
/// Fills the problem: data without the set-aside modes, noise, candidates (throws InputError on bad options).
void prepare(const Model& model, const ModalData& measured, const DiscoveryOptions& o,
             std::vector<std::unique_ptr<Candidate>> extra, Problem* p, DiscoverySummary* S);

// ---- locate ----
Localization locate(const Problem& p);

// ---- screen ----
/// The linearised chi-square drop of every candidate (0 for those not screened: global ones), one eigen-solve.
struct Screening {
  std::vector<double> drop;        ///< per library candidate
  /// The linearisation's Jacobian of the whitened residuals at the model as given (all candidates' parameters),
  /// and each candidate's magnitude column in it.
  Eigen::MatrixXd J;
  std::vector<Eigen::Index> column;
  Eigen::VectorXd model_hz, mac;   ///< the model as given, per measured mode
  std::vector<char> paired;        ///< per measured mode: a plausible partner in the model as given
  double chi2 = 0, chi2_frequency = 0;
};
Screening screen(const Problem& p);
/// The local candidates to fit in full: the best screened, those at the nodes with most residual force, and
/// every global one (library indices).
std::vector<int> shortlist(const Problem& p, const Screening& s, const Localization& L);

// ---- fit and score ----
SetFit fit_set(const Problem& p, const std::vector<const Candidate*>& set, const std::vector<Eigen::VectorXd>& start = {});
/// The evidence the unpartnered modes give a model with parameters theta (see SetFit::unpartnered_gain).
double unpartnered_gain(const Problem& p, const ParametricModel& pm, const Eigen::VectorXd& theta);
FitQuality quality_of(const Problem& p, const Eigen::VectorXd& model_hz, const Eigen::VectorXd& mac, double chi2,
                      const std::vector<char>& nominal_paired);
/// The prediction-error level of each data type under a fitted set, in units of the noise model's (>= 1): the most
/// likely level given the set's misfit and a half-normal prior on the model-form error (scale
/// DiscoveryOptions::form_error_frequency / form_error_shape). A hypothesis that approximates the real physics
/// misfits the frequencies beyond their measurement noise; it is scored at that level, not at the measurement's
/// (Beck & Yuen 2004: the prediction-error variance belongs to the model class).
struct ErrorScale {
  double frequency = 1, shape = 1;
};
ErrorScale error_scale(const Problem& p, double chi2, double chi2_frequency);
inline ErrorScale error_scale(const Problem& p, const SetFit& f) { return error_scale(p, f.chi2, f.chi2_frequency); }
/// Sum of squares of whitened residuals (mode by mode: the frequency, then the shape entries) at the levels `s`.
double scaled_norm2(const Problem& p, const Eigen::VectorXd& r, const ErrorScale& s);
/// ln Bayes factor of a fitted set against the model as given (Problem::chi2_0), each with its own prediction-error
/// levels (error_scale), with a Laplace approximation of the parameters' posterior.
double log_evidence(const Problem& p, const SetFit& f);
/// Posterior standard deviations of a set's parameters (all candidates in order) at the levels `s`.
Eigen::VectorXd posterior_stddev(const SetFit& f, const ErrorScale& s);
/// Share of the model's misfit (Problem::chi2_0) a fitted set removes, relative to the lowest chi-square any explored
/// set reached (chi2_best); 0 for a set that could not be fitted.
double explained_share(const Problem& p, const SetFit& f, double chi2_best);
/// Smallest |theta - nominal| / std over the set's parameters of candidate k (at the set's levels); 0 on a bound.
double significance(const Problem& p, const SetFit& f, std::size_t k);
/// One candidate of a fitted set as reported: its values with their standard deviations.
ScoredHypothesis scored(const Problem& p, const SetFit& f, std::size_t k);
/// Whether two candidates tell the same story: the same global kind, or local ones of compatible nature (mass
/// with mass, stiffness with stiffness; "both" with either) at sites that share a node.
bool same_story(const Model& m, const Candidate& a, const Candidate& b);

// ---- select ----
/// The explanation: the smallest admissible set of effects that explains the misfit, grown from the best single
/// candidates and pruned after every addition.
struct Selection {
  SetFit fit;                      ///< the chosen set (empty: nothing admissible)
  std::vector<double> importance;  ///< per effect of `fit`: the evidence lost without it
  std::vector<SelectionStep> steps;
  std::vector<SetFit> alternatives;  ///< the other starts' complete explanations (rival candidates)
  double chi2_best = 0;            ///< the lowest chi-square any explored set reached
  int eigen_solves = 0;
};
Selection select(const Problem& p, const std::vector<SetFit>& singles, const FitQuality& before);
/// The findings' probability among the explanations scored (equal prior odds over them; the model as given is
/// one of them at ln evidence 0): each other explanation, by its relation to the findings and its ln evidence.
struct StoryOdds {
  enum class Relation {
    kSameStory,  ///< the findings' story at an equivalent site, or by a kind of the same physics: counts for them
    kSameKinds,  ///< the findings' kinds elsewhere
    kOther,      ///< another physics (`kinds`), or no physics (empty `kinds`: the recalibration of E and rho)
  };
  struct Entry {
    Relation relation = Relation::kOther;
    double log_evidence = 0;
    std::vector<std::string> kinds;
  };
  double probability = 0;        ///< the findings, with their equivalent sites
  double kind_probability = 0;   ///< their kinds anywhere (= probability when another site of them is more probable)
  int other = -1;                ///< entry of the best explanation of the most probable other physics (-1: none)
  double other_probability = 0;  ///< that physics' probability, summed over its sites and explanations
};
/// `best`: the findings' ln evidence.
StoryOdds story_odds(double best, const std::vector<StoryOdds::Entry>& entries);

/// A set of candidates in a canonical order (by address): the same set, however reached, has the same key.
std::vector<const Candidate*> set_key(std::vector<const Candidate*> s);

/// Whether a fitted set may stand as an explanation (select.cpp: inside its bounds, no worse than the model as
/// given, every effect significant, at most one parameter per two measured modes).
bool admissible(const Problem& p, const SetFit& f, const FitQuality& before);
/// One step of the selection for the record: the set `f` after `what` was added, removed or started from, scored
/// (its evidence, the share of the misfit it removes against chi2_best).
SelectionStep selection_step(const Problem& p, SelectionStep::Action a, const std::string& what, const SetFit& f,
                             double chi2_best);

}  // namespace dynid::internal
