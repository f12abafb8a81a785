// dynid/engine/identify.hpp -- modal identification: poly-reference LSCF + LSFD (input-output, from FRFs) and
// covariance-driven stochastic subspace identification (output-only, from time data).
//
// Both run over a range of model orders, build a stabilization diagram (each pole marked stable in frequency,
// damping and vector against the nearest pole of the previous order), and select modes automatically:
//   1. Each physical pole gets a stability weight in [0, 1]: 1 while its frequency, damping and vector changes
//      against the pole of the previous order it continues are within the tolerances below, falling linearly to
//      0 at twice them (the weight is the largest over the previous order's poles: of a closely spaced pair, the
//      nearest pole in frequency may be the other mode's). The weight is continuous in the poles, so rounding
//      (another thread count, another BLAS) moves it by rounding, never from 0 to 1: no selection decision below
//      hinges on one pole crossing a threshold.
//   2. Clusters: the pole frequencies are grouped around the maxima of their weighted density (mean shift with
//      a window of +-cluster_tolerance, relative); within a window, poles whose vectors differ (MAC below
//      cluster_mac; a share of their weight down to 2 cluster_mac - 1) form separate clusters: the two modes of a
//      closely spaced pair, both present over the orders. A cluster's support is the sum over the orders of the
//      weight of the order's best pole (the window's edge weighs 0), divided by the number of orders.
//      Its frequency and damping are the support-weighted means of those poles; their weighted standard
//      deviations are the spread over orders.
//   3. Evidence, each a reason to reject a cluster (listed in IdentificationSummary::rejected). Each cluster's
//      shape is judged as estimated beside its neighbours (LSCF: residues from the lines around it, fitted with
//      the poles of the clusters near it, so that each of a close pair gets its own; its pole alone when that joint
//      fit leaves the shape complex and the alone fit does not), and its mode indicator is
//      seen through that shape (the FRFs' |u^H H|^2, the output spectra's u^H G u), where the weaker mode of a
//      close pair has its own peak:
//        support below min_cluster_fraction (not stable over enough orders);
//        shape: MPC below min_mpc (not a normal mode: noise or a mathematical pole);
//        mode indicator less than min_peak_db above the straight line (in dB) between its values one half-power
//          bandwidth either side (w = max(2 zeta f, 2 line spacings)): no peak of its own there (a mode the
//          sensors barely see, whose shape is noise, or a pole in a trough or on the flank of another mode);
//        a spectral edge: the indicator falls from f to f -+ w more than max_edge_db further than the pole's own
//          resonance can (10 log10(1 + (w / zeta f)^2)): the spectrum stops there (the excitation's band, an
//          anti-alias filter) and the pole models the edge, not a resonance;
//        a split: a shape MAC >= merge_mac with a stronger cluster within max(merge_tolerance, zeta) in
//          frequency (one half-power half-bandwidth), or within merge_span on the flank of the stronger one's
//          indicator peak (it has one), and one peak of the indicator between them (nowhere min_peak_db below
//          the lower of their levels; a dip means two modes, whose local shapes may look alike): one physical
//          mode whose poles drifted over orders, or a second report of it. Splits
//          are merged before the other checks: the group's support counts, per order, its best pole; its
//          frequency, damping and shape are the strongest cluster's (LSCF: the largest peak amplitude of its
//          residues, a pole fitting a neighbour's residual error has a small one; SSI: the best support).
// Uncertainty: the spread over orders understates the scatter of a mode from one data set to the next. With
// recordings (identify_recordings), the two halves of the data (records, or the two halves in time of one
// record) are identified again with the same settings; halves' modes are paired with the full data's by MAC;
// per mode, sigma_f = |f_A - f_B| / 2 and sigma_shape = rms(u_A - u_B) / 2 (shapes scaled to a largest entry
// of 1, signs aligned) estimate the standard deviation of the full data's estimates (each half has twice the
// variance of the whole, their difference four times). One pair is a one-degree-of-freedom estimate, so the
// relative values |f_A - f_B| / (2 f zeta) (frequency scatter scales with the half-power bandwidth) and the
// shape values are pooled over the modes by their median (scaled by 1 / 0.6745, the median of |N(0, 1)|), and
// each mode reports the larger of its own and the pooled value (a mode with no partner in a half gets the
// pooled value). frequency_std_hz is that estimate (or the spread over orders when there is none).
// Continuous records (random force or ambient; not impacts): the frequency and damping std are instead those of a
// stationary response of total length T, sigma_f / f = sqrt(zeta / (pi f T)) and sigma_zeta / zeta =
// sqrt(1 / (pi zeta f T)): sqrt(2) times the Cramer-Rao bound of one mode's frequency and damping from a
// white-noise-driven response (its Fisher information over T: T E[x'^2] / q and T E[x^2] / q for 2 zeta omega
// and omega^2, E[x^2] = q / (4 zeta omega^3), E[x'^2] = q / (4 zeta omega), q the force's spectral intensity;
// SSI-cov is not efficient). The halves' one-degree-of-freedom spread ranged from 0.46 to 2.7 times this per
// mode on the dev split's records (up to 6.6); this value is within its spread (median |z| of the dev split's
// random and ambient modes 0.67-0.69 against 0.674 for a normal error) and tests/test_identify.cpp checks it by
// Monte Carlo. A mode overlapped by a neighbour is biased by its tail: sigma_f is widened by sqrt(1 + (o / 0.3)^2),
// o the mean half-power half-bandwidth of the mode and its nearest identified neighbour over their distance (on
// the dev split's records, median |z| by the truth's overlap: 0.61 below 0.05, 0.86 at 0.1-0.2, 1.05 at 0.4-0.8,
// 4.2 above 0.8 before; 0.61-0.78 up to 0.8 after). The shapes keep the split-data std. A random-force test's
// modes refined by LSCF (identify_recordings) take instead the split-data value of LSCF on the same halves, as
// impacts do: with the force measured, their error is about half the stationary value (the paper frame's
// random-force tests: rms z 0.47 with it, 0.88 with LSCF's halves; tests/test_identify.cpp).
// Both statistical values are combined in quadrature with a quarter of the mode's spread over the model orders
// (order_frequency_std_hz): what the halves have in common (an impact record's truncation, the fitted model's
// order, a neighbour's tail) moves the pole with the order, not between the halves. The halves' spread alone
// understated the error of impact tests (the discovery benchmark's dev split, 390 modes of 71 impact tests:
// median |z| 1.82, 46 % beyond 2 sigma, 33 % beyond 3), the spread over orders alone overstated it (median |z|
// 0.25); with the quarter: median |z| 0.73, 8 % beyond 2 sigma, 4 % beyond 3. On continuous records the
// stationary value dominates (random / ambient: median |z| 0.62 / 0.65 unchanged; beyond 3 sigma 3 / 2 % before,
// 1.3 / 1.2 % after), and tests/test_identify.cpp checks both against the error over realisations.
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "dynid/engine/frf.hpp"
#include "dynid/engine/recording.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

/// LSCF's pole budget when the options leave the orders open: orders up to max(10, kLscfOrders / inputs).
constexpr int kLscfOrders = 60;

/// A mode a model predicts for the test: its frequency and its shape at measured DOFs (IdentificationOptions::
/// expected_modes).
struct ExpectedMode {
  double frequency_hz = 0;
  std::vector<MeasuredDof> dofs;
  Eigen::VectorXd shape;  ///< at `dofs`
};

struct IdentificationOptions {
  /// Analysis band. 0, 0 = identify_lscf / identify_ssi: everything the data holds above 0 Hz;
  /// identify_recordings: from the data's spectral peaks (plan_identification).
  double band_lo_hz = 0, band_hi_hz = 0;
  int min_order = 0, max_order = 0;       ///< model orders (0 = automatic: LSCF 2..max(10, 60 / inputs); SSI 2..80)
  int order_step = 0;                     ///< 0 = 1 (LSCF), 2 (SSI)
  int lscf_pole_budget = 0;               ///< > 0: automatic LSCF orders up to max(10, this / inputs) (0: kLscfOrders)
  /// Automatic LSCF orders: poles and selection from lines down to this fraction of the band's bottom (lower where
  /// the lowest sub-band reaches lower), modes still reported from the bottom up (1 = the band itself). 0 = the
  /// default: 0.5 for impacts in identify_recordings (a mode within about twice the bottom of the fitted lines is
  /// poorly fixed; docs/method.md, "LSCF's lowest lines"), 1 otherwise.
  double lscf_fit_below = 0;
  // Stability against the previous order (full weight within these, none beyond twice them).
  double stable_frequency = 0.01;   ///< relative frequency change
  double stable_damping = 0.05;     ///< relative damping change (the diagram's "stable in damping" mark)
  double cluster_damping = 0.25;    ///< relative damping change of the poles that support clusters
  double stable_mac = 0.98;         ///< MAC of the pole's vector (participation for LSCF, shape for SSI)
  double max_damping = 0.2;         ///< poles with zeta outside (0, max_damping) are not physical
  double min_cluster_fraction = 0.45; ///< support a cluster needs (weighted share of the orders)
  double cluster_tolerance = 0.01;    ///< half-width of a cluster's window (relative frequency)
  double cluster_mac = 0.9;           ///< poles support one cluster only with vectors this alike (MAC)
  // Evidence a cluster needs to be reported as a mode (see the header comment).
  double min_mpc = 0.5;             ///< modal phase collinearity of its shape
  double min_peak_db = 3;           ///< how far above its surroundings the mode indicator must stand
  double max_edge_db = 10;          ///< how much steeper than its resonance the indicator may fall beside it
  double merge_tolerance = 0.03;    ///< clusters this close (relative, or zeta if wider) ...
  double merge_mac = 0.9;           ///< ... with shapes this alike are one mode
  double merge_span = 0.15;         ///< so are those this close on the flank of the stronger's peak
  /// The modes a model predicts (empty = none; discover fills them from the analysis model when it takes the band
  /// from it: band_from_model). A cluster stable over fewer than min_cluster_fraction of the orders, but over at
  /// least expected_fraction, is still a mode (with every other piece of evidence: MPC, the mode indicator) when
  /// its shape matches one of these, at expected_mac or better over at least 3 of its outputs, within
  /// expected_ratio in frequency, and no mode already reported matches that one: a weak mode the model says is
  /// there, shaped as the model says, is not noise. Its frequency and damping stay the data's own; it carries
  /// IdentifiedMode::expected_hz, and its shape no weight in IdentificationSummary::modal_data (docs/method.md).
  /// So does a mode whose cluster passed every check alone shaped like one of these when LSCF's joint LSFD of
  /// all modes leaves its shape complex (MPC below min_mpc): it keeps its cluster's shape instead of being dropped.
  std::vector<ExpectedMode> expected_modes;
  double expected_fraction = 0.2, expected_mac = 0.9, expected_ratio = 1.15;
  // SSI-cov.
  int block_rows = 0;  ///< i (0 = automatic from the band's lowest frequency and the maximum order)
  int decimate = 0;    ///< 0 = automatic (to about 2.5x the band's top), 1 = none
  // From recordings (identify_recordings).
  /// Samples per FRF segment for continuous records (random excitation): -1 = from the plan (the lowest peak's
  /// half-power bandwidth spans 4 lines, within the record), 0 = whole records (impacts: always whole records).
  int segment = -1;
  FrfOptions::Estimator estimator = FrfOptions::Estimator::kH1;
  double exponential_end = 0;       ///< exponential window on impact records (FrfOptions::exponential_end)
  bool split_uncertainty = true;    ///< the split-data estimate of the frequency and shape uncertainty
  bool IsValid(std::string* why) const;
};

/// A pole at one model order, as drawn in the stabilization diagram.
struct StabilizationPole {
  int order = 0;
  double frequency_hz = 0, damping_ratio = 0;
  bool physical = false;  ///< in the band with 0 < zeta < max_damping
  bool stable_frequency = false, stable_damping = false, stable_vector = false;
  int cluster = -1;       ///< index of the selected mode it supports, or -1
  double damping_change = 1;  ///< |zeta - zeta_previous| / zeta against the nearest pole of the previous order
  double weight = 0;      ///< stability weight in [0, 1] (header comment, step 1)
  bool stable() const { return stable_frequency && stable_damping && stable_vector; }
};

/// Why a cluster of poles was not reported as a mode.
enum class Rejection {
  kFewOrders,        ///< support below min_cluster_fraction
  kComplexShape,     ///< MPC below min_mpc
  kIndicatorTrough,  ///< the mode indicator has no peak there (below min_peak_db)
  kSpectralEdge,     ///< the mode indicator falls beside it faster than a resonance can (an excitation edge)
  kSplit             ///< a split of a stronger cluster with the same shape (merged into it)
};
const char* to_string(Rejection r);  // "few orders", "complex shape", "no indicator peak", "spectral edge", "split"

struct IdentifiedMode {
  double frequency_hz = 0, damping_ratio = 0;
  /// Standard deviations: the split-data estimate when there is one (header comment), else the spread over
  /// the model orders of its cluster.
  double frequency_std_hz = 0, damping_std = 0;
  double order_frequency_std_hz = 0;             ///< spread of the frequency over the model orders
  double shape_std = 0;  ///< std of the shape entries relative to the largest (split data; 0 = not estimated)
  int poles = 0;                                 ///< poles in its cluster (orders that found it)
  double support = 0;                            ///< weighted share of the orders (header comment, step 2)
  /// The model's mode (IdentificationOptions::expected_modes) this one was reported as, short of the evidence a
  /// mode needs on its own; 0 = reported on its own evidence.
  double expected_hz = 0;
  /// What it was short of: support (kFewOrders: its cluster stable over fewer than min_cluster_fraction of the
  /// orders), or a normal mode's shape in the joint LSFD of all modes (kComplexShape: its cluster passed every
  /// check alone, shaped like the model's mode; it keeps that shape, as its own pole's fit gave it).
  Rejection expected_because = Rejection::kFewOrders;
  double indicator_db = 0;  ///< mode indicator above (+) or below (-) the line between its surroundings, dB
  Eigen::VectorXcd shape;                        ///< complex shape at the outputs (LSFD residues / SSI C psi)
  Eigen::VectorXd real_shape;                    ///< real-normalized (best real rotation), max |.| = 1
  double mpc = 0;                                ///< modal phase collinearity (1 = a real, normal mode)
  double contribution = 0;  ///< peak FRF amplitude of the mode relative to the strongest one (LSCF), else 0
  /// Index of a stronger mode with the same shape (MAC >= 0.95) within 15 % in frequency, or -1: a split pair
  /// (e.g. the two bending planes of a nearly axisymmetric part seen by one sensor direction) or a duplicate.
  int twin_of = -1;
  double twin_mac = 0;
};

struct RejectedCluster {
  double frequency_hz = 0, damping_ratio = 0;
  int poles = 0;
  double support = 0;
  Rejection reason = Rejection::kFewOrders;
  double value = 0, limit = 0;  ///< the measured quantity and its limit (support, MPC, dB, or MAC for a split)
  int merged_into = -1;         ///< kSplit: index of the mode it was merged into
};

struct IdentificationSummary {
  std::string method;                   ///< "lscf" or "ssi"
  std::vector<MeasuredDof> dofs;        ///< outputs (rows of the shapes)
  std::vector<IdentifiedMode> modes;    ///< ascending frequency
  std::vector<RejectedCluster> rejected;  ///< every cluster of >= 2 poles not reported, ascending frequency
  std::vector<StabilizationPole> poles; ///< every pole of every order (the diagram)
  int min_order = 0, max_order = 0;
  double band_lo_hz = 0, band_hi_hz = 0;  ///< the band analysed
  bool band_from_data = false;            ///< the band came from the spectral peaks (plan_identification)
  double resolution_hz = 0;               ///< frequency line spacing of the FRFs / spectra (0 = not from a transform)
  // Background of the diagram and the mode indicator: CMIF, the first singular value of the FRF matrix (LSCF),
  // or the first singular value of the output cross-spectral matrix (SSI), on `frequency_hz`.
  Eigen::VectorXd frequency_hz, background;
  std::string background_label;
  double window_decay_removed = 0;  ///< exponential-window decay taken off the poles (1/s)
  // Split-data uncertainty (identify_recordings): 0 = not estimated.
  int uncertainty_halves = 0;          ///< 2 when estimated
  double pooled_frequency_std = 0;     ///< pooled sigma_f / (f zeta) (header comment)
  double pooled_shape_std = 0;         ///< pooled shape std relative to the largest entry
  /// Continuous records: their total length T (s), from which the modes' frequency and damping std come (header
  /// comment); 0 when those come from the halves (impacts) or the spread over orders.
  double stationary_record_s = 0;
  std::vector<std::string> notes;      ///< what the plan and the uncertainty estimate did, in words
  double seconds = 0;
  /// The modes as ModalData (real-normalized shapes, damping, MPC, standard deviations, shape_std).
  ModalData modal_data(const std::string& source) const;
};

/// Lines of a spectrum that a mode's half-power bandwidth 2 zeta f must span for the spectrum to resolve it: the
/// plan's resolution rule (below), and where identify_recordings takes LSCF's damping of a random-force test.
constexpr double kResolvedLines = 4;

/// The band and frequency resolution for recordings when the options leave them open: from the peaks of the
/// summed output spectra (Welch segments of an eighth of the record), for impacts of the summed output energy
/// spectra over the summed hit energy spectra (whole records: a sum of |FRF|^2, so that the modes above the
/// hits' spectral roll-off show their peaks too).
///   band: [0.5 x lowest peak, min(1.25 x highest peak, 0.45 x sampling rate)], over the peaks that stand
///         >= 10 dB above their surroundings (prominence) and >= 10 dB above the spectrum's 10th-percentile
///         level (the noise floor; impacts: or the outputs' own energy >= 10 dB above its 10th percentile, since
///         the |FRF|^2 of accelerations has no such floor: it falls to nothing below the first mode and rises
///         where the hits are weak); the whole range below 0.45 fs when there is none. Records with a measured
///         force (continuous or hits): the top reaches where the force's spectrum ends (the highest line within
///         20 dB of its median level: a mode where the force puts a hundredth of its median power still stands
///         out of the |FRF|^2), when the peaks' rule stops below it (the highest modes' peaks stand out less, or
///         overlap).
///   resolution (continuous records): the lowest peak's half-power bandwidth 2 zeta f (zeta from the -3 dB
///         width, refined with longer segments while the width spans fewer than kResolvedLines = 4 lines) spans
///         4 lines: segment = fs / (zeta f / 2), a power of two, at most a quarter of the shortest record (>= 7
///         averages with half overlap).
struct IdentificationPlan {
  double band_lo_hz = 0, band_hi_hz = 0;
  bool band_from_data = false;
  bool impulsive = false;      ///< records are impacts (one per hit): transforms over whole records
  int segment = 0;             ///< samples per FRF / Welch segment (0 = whole records)
  double resolution_hz = 0;
  double lowest_peak_hz = 0, lowest_peak_damping = 0;  ///< 0 = no peak found
  std::vector<double> peaks_hz;  ///< the peaks the band rule used, ascending
  std::vector<std::string> notes;
};
IdentificationPlan plan_identification(const std::vector<Recording>& recordings, const IdentificationOptions& options);
/// The band of FRFs by the same rule, from the peaks of their CMIF (first singular value at every line); the
/// resolution is the FRFs' own.
IdentificationPlan plan_identification(const FrfData& frf, const IdentificationOptions& options);

/// LSCF (poly-reference when the FRFs have several inputs) on FRFs; shapes by LSFD with lower and upper
/// residuals at the selected poles. Any response quantity works (poles do not depend on it); shapes are
/// residues of the receptance. The LSFD also fits, unreported, the poles of rejected clusters stable over the
/// orders (support >= min_cluster_fraction, not splits), each more than a half-power bandwidth from the others: a
/// mode the selection left out still responds, and its response would otherwise make its neighbours complex.
/// A band wider than 1:16 with automatic orders is analysed in sub-bands as SSI's (identify_ssi): poles and
/// selection per sub-band, each giving the modes it owns, then one LSFD over the whole band at all of them; the
/// lowest modes of a wide band otherwise appear only at the orders the strongest modes leave them (on the
/// discovery benchmark's dev impact tests, 71: named right 44 -> 47, within 10 % 37 -> 41, nulls 7 -> 8 of 8;
/// the identification benchmark's dev seeds 0-59 unchanged, found 231 of 266). A sub-band with too few lines
/// for its orders leaves the whole band to one fit. A reference whose FRFs are 120 dB below the strongest
/// reference's (it excites nothing the sensors record) is left out with a note: its numerically zero columns
/// would leave the poly-reference fit rank-deficient.
IdentificationSummary identify_lscf(const FrfData& frf, const IdentificationOptions& options);

/// SSI-cov on the output channels of a recording (all outputs are references; records are concatenated into
/// the correlation estimate, each record's mean removed). A band wider than 1:16 (automatic decimation and block
/// rows) is analysed in sub-bands from the top down, each [top / 16, top] decimated to its top and owning
/// [top / 8, top / 2] (the top one everything above, the lowest everything below), the next top a quarter of this
/// one's.
IdentificationSummary identify_ssi(const Recording& recording, const IdentificationOptions& options);

/// FRF sets with the same outputs and frequency lines merged: their inputs side by side. Throws InputError if
/// they do not match.
FrfData merge_frfs(std::vector<FrfData> sets);

/// The identification band a model implies for a test (the one rule dynid uses whenever a model is given and
/// the band is not): the model's elastic modes the sensors can see (mean square at the sensor DOFs at least 5 %
/// of the mode's mean square over all translations), the lowest `modes` of them (at most one per sensor DOF),
/// band [0.6 f_first, 1.25 f_last], capped at 0.8 times the Nyquist frequency `nyquist_hz` (0 = no cap), and
/// only modes 20 % below the cap (a mode at the band's edge is identified poorly). The margins leave room for a
/// structure that differs from its model by tens of per cent. Throws InputError when the sensors see no mode
/// of the model below the cap.
struct ModelBand {
  double lo_hz = 0, hi_hz = 0;
  std::vector<double> visible_hz;  ///< the visible model modes the band covers
  std::vector<ExpectedMode> expected;  ///< the same modes, with their shapes at the sensors on the model's free DOFs
};
ModelBand band_from_model(const Model& model, const std::vector<MeasuredDof>& sensors, double nyquist_hz, int modes = 8);

/// Recordings identified as a whole: "lscf" on FRFs (recordings with force channels; a roving hammer gives one
/// recording per hit location) or "ssi" (the output channels; records of all recordings concatenated); "" picks
/// by the data: lscf for impacts (every force record a blow), ssi for continuous records, output-only or with a
/// random force (broadband: the outputs alone select the modes, free of the leakage bias Welch FRFs have at
/// the lowest modes of a wide band). With a random force, each SSI mode then takes its frequency and damping
/// from LSCF on the H1 FRFs of the same records where LSCF has the same mode (MAC >= 0.9, within the mode's
/// half-power half-bandwidth or 0.5 %): the measured force removes the bias SSI's output-only model leaves at
/// some modes, and those modes' std is LSCF's split-data scatter (header comment); where the mode's half-power
/// bandwidth spans fewer than 4 of the FRFs' lines, LSCF's damping is biased high and SSI's damping and damping
/// std are kept (LSCF's frequency is still taken). The band and resolution come
/// from plan_identification where the options leave them open; then the split-data uncertainty (header
/// comment) when options.split_uncertainty.
IdentificationSummary identify_recordings(std::vector<Recording> recordings, const std::string& method,
                                          const IdentificationOptions& options);
/// FRFs identified with LSCF (the band from plan_identification where the options leave it open), with the
/// split-data uncertainty when `halves` holds the FRFs of the two halves of the data (e.g. of alternate hits).
IdentificationSummary identify_frfs(const FrfData& frf, const IdentificationOptions& options, const std::vector<FrfData>& halves = {});

/// Peaks of a magnitude spectrum (e.g. a dB spectrum without phase): local maxima in [lo, hi] standing at
/// least `min_prominence_db` above the higher of the two minima that separate them from higher peaks (or the
/// band edges), located by parabolic interpolation of the dB values around the maximum line. Strongest first.
struct SpectrumPeak {
  double frequency_hz = 0, level_db = 0, prominence_db = 0;
};
std::vector<SpectrumPeak> spectrum_peaks(const Eigen::VectorXd& frequency_hz, const Eigen::VectorXd& level_db, double lo, double hi,
                                         double min_prominence_db);

/// Modal phase collinearity of a complex vector: ((e1 - e2) / (e1 + e2))^2 with e1 >= e2 the eigenvalues of the
/// 2 x 2 covariance of its real and imaginary parts.
double modal_phase_collinearity(const Eigen::VectorXcd& v);
/// The real vector closest to v up to a complex scale: Re(e^{-i theta} v) for the best theta, max |.| = 1,
/// largest entry positive.
Eigen::VectorXd real_normalize(const Eigen::VectorXcd& v);

}  // namespace dynid
