// dynid/engine/identify.hpp -- modal identification: poly-reference LSCF + LSFD (input-output, from FRFs) and
// covariance-driven stochastic subspace identification (output-only, from time data).
//
// Both run over a range of model orders, build a stabilization diagram (each pole marked stable in frequency,
// damping and vector against the previous order), and select modes automatically: physical poles stable in
// frequency and vector (and within cluster_damping in damping) are clustered across orders (a window of +-cluster_tolerance around the densest pole, one
// pole per order), and a cluster becomes a mode when it holds a pole in at least `min_cluster_fraction` of the
// orders. The mode's frequency and damping are the cluster medians; their standard deviations across the cluster
// are reported as the uncertainty (the spread over model orders).
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "dynid/engine/recording.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

struct IdentificationOptions {
  double band_lo_hz = 0, band_hi_hz = 0;  ///< analysis band (0, 0 = everything above 0 Hz the data holds)
  int min_order = 0, max_order = 0;       ///< model orders (0 = automatic: LSCF 2..40 per input; SSI 2..80)
  int order_step = 0;                     ///< 0 = 1 (LSCF), 2 (SSI)
  // Stabilization criteria against the previous order.
  double stable_frequency = 0.01;   ///< relative frequency change
  double stable_damping = 0.05;     ///< relative damping change
  double cluster_damping = 0.25;    ///< relative damping change allowed for poles that join clusters
  double stable_mac = 0.98;         ///< MAC of the pole's vector (participation for LSCF, shape for SSI)
  double max_damping = 0.2;         ///< poles with zeta outside (0, max_damping) are not physical
  double min_cluster_fraction = 0.45; ///< of the orders, for a cluster to count as a mode
  double cluster_tolerance = 0.01;    ///< half-width of a cluster's window (relative frequency)
  // SSI-cov.
  int block_rows = 0;  ///< i (0 = automatic from the band's lowest frequency and the maximum order)
  int decimate = 0;    ///< 0 = automatic (to about 2.5x the band's top), 1 = none
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
  bool stable() const { return stable_frequency && stable_damping && stable_vector; }
};

struct IdentifiedMode {
  double frequency_hz = 0, damping_ratio = 0;
  double frequency_std_hz = 0, damping_std = 0;  ///< spread over the model orders of its cluster
  int poles = 0;                                 ///< poles in its cluster (orders that found it)
  Eigen::VectorXcd shape;                        ///< complex shape at the outputs (LSFD residues / SSI C psi)
  Eigen::VectorXd real_shape;                    ///< real-normalized (best real rotation), max |.| = 1
  double mpc = 0;                                ///< modal phase collinearity (1 = a real, normal mode)
  double contribution = 0;  ///< peak FRF amplitude of the mode relative to the strongest one (LSCF), else 0
  /// Index of a stronger mode with the same shape (MAC >= 0.95) within 15 % in frequency, or -1: a split pair
  /// (e.g. the two bending planes of a nearly axisymmetric part seen by one sensor direction) or a duplicate.
  int twin_of = -1;
  double twin_mac = 0;
};

struct IdentificationSummary {
  std::string method;                   ///< "lscf" or "ssi"
  std::vector<MeasuredDof> dofs;        ///< outputs (rows of the shapes)
  std::vector<IdentifiedMode> modes;    ///< ascending frequency
  std::vector<StabilizationPole> poles; ///< every pole of every order (the diagram)
  int min_order = 0, max_order = 0;
  // Background of the diagram: sum over the FRFs of |H| (LSCF) or the first singular value of the output
  // cross-spectral matrix (SSI), on `frequency_hz`.
  Eigen::VectorXd frequency_hz, background;
  std::string background_label;
  double window_decay_removed = 0;  ///< exponential-window decay taken off the poles (1/s)
  double seconds = 0;
  /// The modes as ModalData (real-normalized shapes, damping, MPC, standard deviations).
  ModalData modal_data(const std::string& source) const;
};

/// LSCF (poly-reference when the FRFs have several inputs) on FRFs; shapes by LSFD with lower and upper
/// residuals at the selected poles. Any response quantity works (poles do not depend on it); shapes are
/// residues of the receptance.
IdentificationSummary identify_lscf(const FrfData& frf, const IdentificationOptions& options);

/// SSI-cov on the output channels of a recording (all outputs are references; records are concatenated into
/// the correlation estimate, each record's mean removed).
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
};
ModelBand band_from_model(const Model& model, const std::vector<MeasuredDof>& sensors, double nyquist_hz, int modes = 8);

/// Recordings identified as a whole: "lscf" on H1 FRFs (recordings with force channels; a roving hammer gives one
/// recording per hit location) or "ssi" (output-only; records of all recordings concatenated); "" picks by the
/// data.
IdentificationSummary identify_recordings(std::vector<Recording> recordings, const std::string& method,
                                          const IdentificationOptions& options);

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
