// dynid/engine/recording.hpp -- test data in memory: time recordings and frequency response functions.
//
// These are what readers (io/uff.hpp, io/test_data.hpp) produce and what the virtual test, FRF estimation and
// modal identification consume. Nothing here reads files.
#pragma once

#include <Eigen/Core>
#include <complex>
#include <string>
#include <vector>

#include "dynid/engine/modal_data.hpp"

namespace dynid {

/// What a channel measures.
enum class Quantity { kDisplacement, kVelocity, kAcceleration, kForce, kOther };
const char* to_string(Quantity q);  // "displacement", ...

/// One sensor (or the hammer / shaker force).
struct Channel {
  std::string name;            ///< free text (sensor id, UFF record id line)
  MeasuredDof dof;             ///< where and in which direction (node 0 if unknown)
  Quantity quantity = Quantity::kAcceleration;
  std::string unit;            ///< as given ("m/s^2", "g", "N"); informative only, values are used as they are
  bool input = false;          ///< an excitation (force) channel
};

/// Sampled time histories: one or more records (e.g. one per impact, or one long ambient run), each
/// samples x channels, all with the same channels and sampling rate.
struct Recording {
  double sample_rate_hz = 0;
  std::vector<Channel> channels;
  std::vector<Eigen::MatrixXd> records;
  std::string source;

  int num_channels() const { return static_cast<int>(channels.size()); }
  std::vector<int> input_channels() const;   ///< indices of channels with input = true
  std::vector<int> output_channels() const;  ///< the others
  /// Throws InputError naming `what` if the sampling rate is not > 0, records disagree with the channels, or
  /// a sample is NaN/Inf.
  void validate(const std::string& what) const;
};

/// Frequency response functions H(f) = output / input on a common frequency grid.
/// Column o + i * outputs.size() of `H` is output o over input i; `coherence` (optional) has the same layout
/// (for several simultaneous inputs, the multiple coherence of output o, repeated over those inputs).
struct FrfData {
  Eigen::VectorXd frequency_hz;
  std::vector<Channel> outputs;   ///< response DOFs and their quantity (receptance/mobility/accelerance)
  std::vector<Channel> inputs;    ///< excitation DOFs
  Eigen::MatrixXcd H;             ///< frequencies x (outputs * inputs)
  Eigen::MatrixXd coherence;      ///< empty, or the shape of H
  /// Decay rate 1/tau (1/s) of an exponential window applied to the time data before the FRF was formed: it
  /// adds 1/tau to every pole's decay rate, and identification takes it off again.
  double window_decay = 0;
  std::string source;

  int num_outputs() const { return static_cast<int>(outputs.size()); }
  int num_inputs() const { return static_cast<int>(inputs.size()); }
  std::complex<double> operator()(Eigen::Index k, int o, int i) const { return H(k, o + i * num_outputs()); }
  /// Throws InputError naming `what` on inconsistent sizes, non-increasing frequencies or NaN/Inf.
  void validate(const std::string& what) const;
};

}  // namespace dynid
