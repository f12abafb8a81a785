// dynid/engine/virtual_test.hpp -- simulate a vibration test on a model: data whose true answer is known.
//
// The response is integrated by modal superposition, each mode exactly for an input that is linear between
// samples (first-order hold: the discrete state map of q'' + 2 zeta w q' + w^2 q = p is computed from the matrix
// exponential, so there is no integration error at the samples). Modes above the Nyquist frequency are left out,
// as an ideal anti-alias filter would. Rayleigh damping C = alpha M + beta K is diagonal in the mass-normalised
// modes, so it is exact too: zeta_j = alpha / (2 w_j) + beta w_j / 2.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dynid/engine/modal.hpp"
#include "dynid/engine/recording.hpp"

namespace dynid {

struct VirtualTestOptions {
  enum class Excitation {
    kImpact,   ///< a hammer-like half-sine pulse at each input DOF in turn; one record per impact; force recorded
    kRandom,   ///< band-limited Gaussian force at the input DOFs (all at once, independent); force recorded
    kAmbient   ///< unmeasured band-limited random forces at every free translation; outputs only
  };
  std::vector<MeasuredDof> sensors;       ///< response DOFs
  Quantity response = Quantity::kAcceleration;
  Excitation excitation = Excitation::kImpact;
  std::vector<MeasuredDof> inputs;        ///< excitation DOFs (impact, random)
  double sample_rate_hz = 0;              ///< required
  double duration_s = 0;                  ///< per record; required
  int impacts = 5;                        ///< impacts per input DOF (kImpact)
  double band_hz_lo = 0, band_hz_hi = 0;  ///< random/ambient force band; 0, 0 = up to 0.4 fs
  double pulse_s = 0;                     ///< impact pulse length; 0 = max(0.75 / band top, 4 samples)
  double pretrigger = 0.02;               ///< fraction of a record before the impact
  double force_rms = 1.0;                 ///< N (random, ambient); impact peak force for kImpact
  /// Damping: modal (every mode `damping_ratio`) or Rayleigh (alpha, beta).
  enum class Damping { kModal, kRayleigh };
  Damping damping = Damping::kModal;
  double damping_ratio = 0.01;
  double rayleigh_alpha = 0, rayleigh_beta = 0;
  /// Sensor noise: Gaussian, standard deviation = noise x the clean channel's RMS (per channel and record).
  double noise = 0.0;
  double force_noise = 0.0;  ///< same, on the force channels
  std::uint64_t seed = 1;
  bool IsValid(std::string* why) const;
};

struct VirtualTest {
  /// kImpact: one Recording per input DOF (its records are the impacts; channels = sensors, then the force);
  /// kRandom: one Recording (channels = sensors, then one force channel per input); kAmbient: one (sensors).
  std::vector<Recording> recordings;
  /// The truth: every mode below Nyquist that was simulated (frequency, the damping used, shapes at sensors).
  ModalData modes;
};

/// Simulates the test. `modes` must hold the model's modes up to (at least) the Nyquist frequency; modes
/// above it are ignored. Same options and seed, same data, whatever the thread count.
VirtualTest simulate_test(const Model& model, const ModalResult& modes, const VirtualTestOptions& options);

}  // namespace dynid
