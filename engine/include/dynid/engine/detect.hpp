// dynid/engine/detect.hpp -- locating and quantifying changes (damage, added mass) from modal data, by residual
// forces (the paper's NDT method) and by a noise-robust sensitivity fit.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "dynid/engine/correlation.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/modal_data.hpp"

namespace dynid {

struct DetectOptions {
  int modes = 0;                 ///< p: changed-state modes used (0 = every mode that pairs)
  int serep_modes = 0;           ///< modes in the SEREP basis (0 = as many as master DOFs)
  double min_mac = 0.5;          ///< pairing threshold
  double frequency_noise = 1e-3; ///< relative std of the measured frequencies (weights of the sensitivity fit)
  double shape_noise = 1e-2;     ///< std of shape entries relative to each mode's largest entry
  /// Flagging: an element is flagged when adding it to the changed set lowers the chi-square of the fit by
  /// more than the chi-square(2) quantile at this level (likelihood-ratio test, 2 parameters per element).
  double significance = 1e-3;
  int max_changed = 3;           ///< at most this many elements flagged
  bool refine = true;            ///< Ceres refinement of the amounts (re-solving the eigenproblem)
  bool localize_only = false;    ///< ranking only: no flagging fits, no quantification (noise studies)
  std::vector<int> candidates;   ///< element ids that may have changed (empty = every beam and frame element)
  /// Simulation studies: the changed model whose exact modes are the data. With full-DOF data its eigenpairs
  /// are refined by mixed-precision Newton iterations and the residual forces formed in extended precision,
  /// so that DOFs outside the changed elements sit at ~1e-12 instead of double rounding (~1e-9 of ||K||).
  /// Used for models of up to 3000 DOFs; ignored otherwise.
  const Model* simulated_changed = nullptr;
};

struct ElementScore {
  int element = 0;          ///< user id
  double pseudo = 0;        ///< the paper's pseudo residual force mapped to the element (geometric mean of its
                            ///< nodes' largest DOF entries); NaN if none of its nodes is observed
  int pseudo_rank = 0;      ///< rank by `pseudo` (1 = largest)
  double chi2 = 0;          ///< sensitivity fit: chi-square of "only this element changed"
  double probability = 0;   ///< posterior probability of that hypothesis (uniform prior over elements)
  int rank = 0;             ///< dynid's rank (1 = most likely)
  bool flagged = false;
  std::vector<int> twins;   ///< mirror-image elements the data cannot tell apart from this one
};

struct ElementAmount {
  int element = 0;
  double dk = 0, dm = 0;                          ///< refined (fractions: -0.15 = 15 % loss)
  double dk_first_order = 0, dm_first_order = 0;  ///< the paper's eq. (14)-(21)
  double dk_std = 0, dm_std = 0;                  ///< from the refinement's covariance (NaN if not estimable)
};

struct DetectSummary {
  bool full_dofs = false;               ///< residuals on every model DOF (simulation), else SEREP-reduced
  std::vector<MeasuredDof> dofs;        ///< DOFs of the residual vectors
  Eigen::MatrixXd residuals;            ///< R_i per used mode (dofs x p), eq. (6)
  Eigen::VectorXd pseudo;               ///< changed state's pseudo residual force, eq. (7)-(8)
  Eigen::VectorXd pseudo_reference;     ///< reference state's (zero when the reference is the model)
  Eigen::VectorXd delta_pseudo;         ///< pseudo - pseudo_reference
  std::vector<ElementScore> elements;   ///< every candidate, sorted by rank
  /// Elements the data cannot rule out as the single changed one: chi-square within the 95 % quantile
  /// (2 dof: 5.99) of the best (measured DOFs), or explaining as much residual force as the best (full DOFs).
  std::vector<int> confidence_set;
  std::vector<ElementAmount> amounts;   ///< quantification of the flagged elements
  std::vector<int> used_modes;          ///< changed-state modes used (0-based)
  Eigen::VectorXd model_hz, changed_hz, mac;  ///< paired frequencies and MAC of the used modes
  int serep_modes = 0, serep_rank = 0;
  double chi2_unchanged = 0;            ///< chi-square of "nothing changed"
  double chi2_final = 0;                ///< after the flagged set was fitted
  std::string threshold_rule;           ///< the flagging rule, in words
  std::vector<std::string> warnings;
  std::string method;                   ///< which localizer decided the flags
  double first_order_condition = 0;     ///< cond(L) of eq. (18)
  int refine_iterations = 0;
  double time_modal = 0, time_localization = 0, time_quantification = 0;  ///< seconds
};

/// Locates and quantifies the change between a reference model and a changed state known by its modal data
/// (measured, or simulated and sampled). With data at every DOF of the model, residual forces are exact and
/// the changed elements are those whose element matrices explain them (greedy least squares on R); with data
/// at some DOFs, residual forces are computed on the model reduced by SEREP and elements are ranked by a
/// whitened fit of frequencies and shapes to each single-element hypothesis. `reference_measured` (optional)
/// is the reference state's own modal data (for the delta pseudo residual force of experiments).
/// Throws InputError on data that does not fit the model (unknown DOFs, no pairing modes).
DetectSummary detect(const Model& reference, const ModalData& changed, const DetectOptions& options,
                     const ModalData* reference_measured = nullptr);

/// Noise study: the changed model's exact modes at `dofs`, perturbed `trials` times (seeded) with Gaussian noise,
/// frequencies by frequency_noise (relative std), every shape entry by shape_noise times its mode's largest
/// entry; each trial is localised by the paper's pseudo residual force and by dynid's sensitivity fit (which
/// is told the noise levels). Counts how often the changed element comes first / in the top 3.
struct NoiseStudyOptions {
  int trials = 200;
  int modes = 6;
  double frequency_noise = 1e-3;
  std::vector<double> shape_noise = {0.01, 0.03};
  std::uint64_t seed = 1;
  std::vector<MeasuredDof> dofs;  ///< measured DOFs
};
struct NoiseStudyRow {
  double shape_noise = 0;
  int trials = 0;
  int pseudo_first = 0, pseudo_top3 = 0;  ///< paper's pseudo residual force
  int dynid_first = 0, dynid_top3 = 0;    ///< dynid's sensitivity fit
  int twin_first = 0;                     ///< dynid ranked a mirror twin of the changed element first
  int twin_called = 0;                    ///< dynid named the changed element and its twin as indistinguishable
  int in_confidence_set = 0;              ///< the changed element was in dynid's 95 % confidence set
  double mean_set_size = 0;               ///< average size of that set
};
std::vector<NoiseStudyRow> noise_study(const Model& reference, const Model& changed, int element_id,
                                       const NoiseStudyOptions& options);

/// Applies relative changes to a copy of a model (for simulation studies): element id -> (dk, dm).
Model changed_model(const Model& reference, const std::vector<std::pair<int, std::pair<double, double>>>& changes);

}  // namespace dynid
