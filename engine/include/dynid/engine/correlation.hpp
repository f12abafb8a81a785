// dynid/engine/correlation.hpp -- test/analysis correlation: MAC, mode pairing, COMAC, frequency errors.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace dynid {

/// MAC(i, j) = (a_i . b_j)^2 / ((a_i . a_i)(b_j . b_j)) for the columns of A (dofs x ma) and B (dofs x mb).
/// 1 = same shape up to scale and sign, 0 = orthogonal. A zero column gives MAC 0.
Eigen::MatrixXd mac_matrix(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B);

struct ModePair {
  int a = 0;              ///< column in A (e.g. the measured mode)
  int b = 0;              ///< column in B (e.g. the model mode)
  double mac = 0;
  double freq_error = 0;  ///< (f_b - f_a) / f_a
};

struct Pairing {
  std::vector<ModePair> pairs;  ///< sorted by a
  std::vector<int> unpaired_a;  ///< columns of A with no partner of MAC >= min_mac
  std::vector<int> unpaired_b;
  /// Pair of column a, or nullptr.
  const ModePair* of_a(int a) const;
};

/// Partners further apart in frequency than this factor are never paired (issue 16): a spatial alias (few
/// sensors: a high mode can look like a low one at the measured DOFs) or a spurious mode, not a partner.
constexpr double kMaxPairingRatio = 2.0;

/// Weight of the relative frequency gap against the MAC in pairing: one per cent of frequency weighs like 0.01 of
/// MAC. Both are a few per cent for a true pair (shape noise; the model's form error), so neither decides alone:
/// with few sensors two model modes can look alike at the measured DOFs (MAC 0.96 to each other at 7 sensors on a
/// frame), and then a measured MAC of 0.92 against 0.90 says nothing, while 15 % against 2.5 % in frequency does.
constexpr double kPairingFrequencyWeight = 1.0;

/// One-to-one pairing: repeatedly takes the pair with the highest score MAC - kPairingFrequencyWeight
/// min(1, |f_b - f_a|/f_a) (the twin modes of symmetric structures, equal in MAC, go by frequency), among pairs
/// with MAC >= min_mac within a frequency ratio of kMaxPairingRatio (or max_ratio, when > 0 and tighter); a mode
/// without one is left unpaired. fa, fb may be empty (MAC alone, no ratio bound).
Pairing pair_modes(const Eigen::MatrixXd& mac, const Eigen::VectorXd& fa, const Eigen::VectorXd& fb,
                   double min_mac = 0.5, double max_ratio = 0);

/// Repeated eigenvalues (symmetric structures: the two bending modes of a square tower): groups of the columns
/// of B whose frequencies fb lie within rel_tol (relative) of their neighbour's, in order; a single mode is a
/// group of one. Within a group of two or more, any basis of the subspace is an equally valid set of modes, so
/// the solver's choice is arbitrary and only the subspace can be compared with a measurement.
std::vector<std::vector<int>> repeated_groups(const Eigen::VectorXd& fb, double rel_tol);

/// mac_matrix(A, B) with, for each column of B in a group of repeated modes, the MAC of a's column with the
/// group's subspace instead: ||P a||^2 / ||a||^2, P the orthogonal projector onto the group's columns of B. It is
/// the best MAC any mode of the repeated eigenvalue reaches, the same for every basis of the subspace.
Eigen::MatrixXd subspace_mac_matrix(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                                    const std::vector<std::vector<int>>& groups);

/// The unit coefficients c (|c| = 1) of a group of B's columns whose combination sum_k c_k B.col(group[k]) best
/// matches a (the normalised least-squares fit). With mass-normalised modes of a repeated eigenvalue the
/// combination is again a mass-normalised mode: the member of the subspace the measurement a shows.
Eigen::VectorXd subspace_coefficients(const Eigen::VectorXd& a, const Eigen::MatrixXd& B, const std::vector<int>& group);
/// That member itself: sum_k c_k B.col(group[k]) with c = subspace_coefficients(a, B, group).
Eigen::VectorXd subspace_member(const Eigen::VectorXd& a, const Eigen::MatrixXd& B, const std::vector<int>& group);

/// COMAC per DOF over the paired modes: (sum_k |a_ik b_ik|)^2 / (sum_k a_ik^2 sum_k b_ik^2), shapes scaled to
/// their MAC-consistent sign. 1 = the DOF agrees in every pair.
Eigen::VectorXd comac(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Pairing& p);

/// Scale factor s minimising ||a - s b|| (modal scale factor, MSF).
double modal_scale_factor(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

}  // namespace dynid
