// Automatic mode selection shared by LSCF and SSI (see dynid/engine/identify.hpp, header comment): stability
// weights, mean-shift clusters, and the evidence checks. Internal to the engine.
#pragma once

#include <complex>
#include <functional>
#include <vector>

#include "dynid/engine/identify.hpp"

namespace dynid::internal {

/// A pole of one model order with the vector the stability check compares (participation or shape).
struct RawPole {
  std::complex<double> lambda;  ///< continuous time, rad/s, Im > 0
  Eigen::VectorXcd vec;
};

/// The poles of every model order, as the stabilization diagram takes them.
struct OrderPoles {
  std::vector<std::vector<RawPole>> poles;  ///< per order, its poles
  std::vector<int> order;                   ///< the model order of each
};

/// Pole extraction (LSCF and SSI alike): the eigenvalues mu of a discrete-time state (or companion) matrix A
/// with Im mu > 0 become continuous-time poles ln(mu) / dt + decay (rad/s; `decay` takes off an exponential
/// window's damping), each with the vector `output` * (its eigenvector) (LSCF: the participation rows; SSI: C).
/// Empty when the eigen-solve fails.
std::vector<RawPole> discrete_poles(const Eigen::MatrixXd& A, double dt, double decay, const Eigen::MatrixXd& output);

double pole_hz(std::complex<double> l);
double pole_zeta(std::complex<double> l);
double complex_mac(const Eigen::VectorXcd& a, const Eigen::VectorXcd& b);
/// The continuous-time pole of a frequency and damping ratio.
std::complex<double> pole_of(double frequency_hz, double zeta);

/// A cluster of poles across orders (step 2).
struct PoleCluster {
  double frequency_hz = 0, damping_ratio = 0, frequency_std_hz = 0, damping_std = 0;
  double support = 0;                    ///< weighted share of the orders
  int poles = 0;                         ///< orders with a supporting pole
  std::vector<std::pair<int, int>> members;  ///< (order index, pole index) of each order's best pole
  std::vector<double> member_weight;     ///< their weights (stability x window)
  std::vector<int> diagram_index;        ///< their index in IdentificationSummary::poles
};

/// Steps 1-2: fills s.poles (the diagram with stability flags and weights) and returns every cluster of >= 2
/// poles, ascending in frequency.
std::vector<PoleCluster> stabilize_and_cluster(const std::vector<std::vector<RawPole>>& orders, const std::vector<int>& order_of, double lo,
                                               double hi, const IdentificationOptions& o, IdentificationSummary& s);

/// The mode indicator around a pole (f, zeta), with w = max(2 zeta f, 2 df) (df the line spacing):
///   peak_db  how far (dB) it stands above (+) or below (-) the straight line, in dB, between its values at
///            f -+ w; at a band edge, against the one side it has;
///   edge_db  how much further it falls on its steeper side, from f to f -+ w, than the pole's own resonance
///            can: 10 log10(1 + (w / (zeta f))^2) (> 0: a spectral edge, e.g. where the excitation or an
///            anti-alias filter stops, not a resonance).
struct IndicatorEvidence {
  double peak_db = 0, edge_db = 0;
};
IndicatorEvidence indicator_evidence(const Eigen::VectorXd& frequency_hz, const Eigen::VectorXd& indicator, double f, double zeta);
/// How far (dB) the indicator falls between fa and fb below the lower of its levels at fa and fb (0 when it never
/// falls below them, or no line lies between): two peaks, or the flank of one. Levels are the dB values averaged
/// over +- smooth_hz (half a half-power half-bandwidth: finer lines of short averages scatter by dB).
double indicator_dip_db(const Eigen::VectorXd& frequency_hz, const Eigen::VectorXd& indicator, double fa, double fb,
                        double smooth_hz);

/// The split rule (identify.hpp, step 3): a weaker mode c is a split of a stronger one h when their shapes
/// (real-normalised) have a MAC >= merge_mac, within max(merge_tolerance, zeta) in frequency, or within merge_span
/// with h's indicator peak standing (h_peak_db >= min_peak_db), and h's indicator nowhere dips min_peak_db between
/// them. Damping ratios as the indicator sees them (an exponential window's decay included).
struct SplitSide {
  double frequency_hz = 0, damping_ratio = 0;
  Eigen::VectorXcd shape;
};
bool is_split(const SplitSide& c, const SplitSide& h, double h_peak_db, const Eigen::VectorXd& frequency_hz,
              const Eigen::VectorXd& h_indicator, const IdentificationOptions& o);

/// A cluster with its shape, for the evidence checks.
struct Candidate {
  PoleCluster cluster;
  Eigen::VectorXcd shape;
  double strength = 0;  ///< which of two splits is the stronger (ClusterShape::strength, else support)
};

/// Per mode of s (its frequency and complex shape at s.dofs): the frequency of the model's mode
/// (IdentificationOptions::expected_modes) it matches (within expected_ratio, MAC >= expected_mac over at least 3
/// shared outputs, the best), 0 for none.
std::vector<double> expected_frequencies(const IdentificationOptions& o, const IdentificationSummary& s);

/// Step 3: the checks, on candidates with shapes (those without one, below the shaping limit, are rejected for
/// their support). Splits are merged first (a weaker cluster with the same shape joins the stronger when within
/// the merge window, or within merge_span with no indicator dip of min_peak_db between them), then each group is
/// checked: joint support, MPC and mode indicator of its strongest cluster.
/// Returns the accepted modes, ascending in frequency, each as its strongest candidate followed by the splits
/// merged into it; appends every rejected candidate to s.rejected. `evidence` gives each candidate's
/// indicator_evidence on its own mode indicator `indicators` (on s.frequency_hz; the dip between two clusters is
/// read on the stronger one's); `n_orders` the number of model orders.
std::vector<std::vector<std::size_t>> check_evidence(const std::vector<Candidate>& candidates,
                                                     const std::vector<IndicatorEvidence>& evidence,
                                                     const std::vector<Eigen::VectorXd>& indicators,
                                                     const IdentificationOptions& o, std::size_t n_orders,
                                                     IdentificationSummary& s);

/// The accepted modes as IdentifiedModes (frequency, damping, spreads and shape of the strongest cluster, the
/// joint support of all; a mode short of support: the expected mode it was reported as), and the diagram's poles
/// marked with their mode.
void make_modes(const std::vector<Candidate>& candidates, const std::vector<IndicatorEvidence>& evidence,
                const std::vector<std::vector<std::size_t>>& accepted, std::size_t n_orders,
                const IdentificationOptions& options, IdentificationSummary& s);

/// A cluster's shape (complex, at the outputs), given every cluster (LSCF fits it with its neighbours' poles),
/// and its strength when the method measures one (< 0: its support): of two clusters of one mode (a split), the
/// stronger one is the mode. LSCF: the peak amplitude of its residues, |R| / (zeta w) (a pole fitting a stronger
/// neighbour's residual error has a small residue, however stable it is).
struct ClusterShape {
  Eigen::VectorXcd shape;
  double strength = -1;
};
using ShapeOf = std::function<ClusterShape(const std::vector<PoleCluster>& clusters, std::size_t c)>;
/// The mode indicator seen through a shape u, power-like on s.frequency_hz: the output spectral matrix's
/// u^H G u / |u|^2 (SSI) or the FRFs' |u^H H|^2 / |u|^2 summed over the inputs (LSCF). A mode whose shape differs
/// from its neighbours' (the other mode of a closely spaced pair) shows its own peak there, where the first
/// singular value shows the stronger mode's flank.
using IndicatorOf = std::function<Eigen::VectorXd(const Eigen::VectorXcd& u)>;

/// Steps 1-3 on the poles of every order: the diagram and clusters in [lo, hi], a shape from `shape_of` for the
/// clusters with enough support to be checked and their mode indicator through it (`indicator_of`; `indicator`,
/// power-like on s.frequency_hz, for the others), each cluster's indicator evidence (the cluster's damping widened
/// by an exponential window's `decay`), the checks, and s.modes (shapes as given, before any final
/// re-estimation).
void select_modes(const OrderPoles& poles, double lo, double hi, const IdentificationOptions& o,
                  const Eigen::VectorXd& indicator, double decay, const ShapeOf& shape_of,
                  const IndicatorOf& indicator_of, IdentificationSummary& s);

/// Clusters with at least this share of min_cluster_fraction get a shape and the evidence checks (weaker ones
/// are rejected for their support without one).
constexpr double kShapedShare = 1.0 / 3.0;

}  // namespace dynid::internal
