// dynid/engine/frf.hpp -- frequency response functions from recordings (H1, H2, coherence).
#pragma once

#include "dynid/engine/recording.hpp"
#include "dynid/solvers/signal.hpp"

namespace dynid {

struct FrfOptions {
  enum class Estimator { kH1, kH2 };
  /// H1 = Gyx Gxx^-1 (noise on the outputs; the default); H2 = Gyy / Gxy (noise on the input; one input per
  /// recording).
  Estimator estimator = Estimator::kH1;
  /// Samples per segment. 0 = each record is one segment (impact testing: one record per hit).
  int segment = 0;
  double overlap = 0.5;
  /// Window on every channel when segment > 0 (Welch averaging of continuous data).
  Window window = Window::kHann;
  /// Impact windows (segment = 0): force window on input channels keeping `force_window` of the record
  /// (0 = automatic: 4x the detected pulse), and an exponential window on all channels ending at
  /// `exponential_end` of its start value (0 = none). The exponential window's decay is recorded in
  /// FrfData::window_decay so identification can remove the damping it adds.
  double force_window = 0;
  double exponential_end = 0;
  /// Keep lines up to this frequency (0 = Nyquist).
  double max_frequency_hz = 0;
  bool IsValid(std::string* why) const;
};

/// FRFs of the output channels over the input channels of each recording. Recordings must share the output
/// channels (same DOFs in the same order); their inputs are put side by side (a roving hammer gives one
/// recording per hit location). Throws InputError if a recording has no input channel.
FrfData estimate_frf(const std::vector<Recording>& recordings, const FrfOptions& options);

/// Converts FRFs to another response quantity by the factor (i w)^k (e.g. accelerance to receptance: k = -2).
/// Lines at 0 Hz are dropped when dividing.
FrfData convert_frf(const FrfData& frf, Quantity target);

}  // namespace dynid
