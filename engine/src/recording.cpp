#include "dynid/engine/recording.hpp"

#include <cmath>

#include "dynid/mesh/error.hpp"

namespace dynid {

const char* to_string(Quantity q) {
  switch (q) {
    case Quantity::kDisplacement: return "displacement";
    case Quantity::kVelocity: return "velocity";
    case Quantity::kAcceleration: return "acceleration";
    case Quantity::kForce: return "force";
    case Quantity::kOther: return "other";
  }
  return "other";
}

std::vector<int> Recording::input_channels() const {
  std::vector<int> out;
  for (int c = 0; c < num_channels(); ++c)
    if (channels[c].input) out.push_back(c);
  return out;
}

std::vector<int> Recording::output_channels() const {
  std::vector<int> out;
  for (int c = 0; c < num_channels(); ++c)
    if (!channels[c].input) out.push_back(c);
  return out;
}

void Recording::validate(const std::string& what) const {
  if (!(sample_rate_hz > 0) || !std::isfinite(sample_rate_hz))
    throw InputError(what + ": the sampling rate must be a finite number > 0 (got " + std::to_string(sample_rate_hz) + ")");
  if (channels.empty()) throw InputError(what + ": no channels");
  if (records.empty()) throw InputError(what + ": no records");
  for (std::size_t r = 0; r < records.size(); ++r) {
    const std::string rec = what + ": record " + std::to_string(r + 1);
    if (records[r].cols() != num_channels())
      throw InputError(rec + " has " + std::to_string(records[r].cols()) + " channels, expected " + std::to_string(num_channels()));
    if (records[r].rows() < 2) throw InputError(rec + " has fewer than 2 samples");
    for (Eigen::Index c = 0; c < records[r].cols(); ++c)
      if (!records[r].col(c).allFinite())
        throw InputError(rec + ", channel " + std::to_string(c + 1) + " (" + channels[c].name + ") holds NaN or Inf samples");
  }
}

void FrfData::validate(const std::string& what) const {
  const Eigen::Index nf = frequency_hz.size();
  if (nf < 2) throw InputError(what + ": fewer than 2 frequency lines");
  if (outputs.empty() || inputs.empty()) throw InputError(what + ": no outputs or no inputs");
  if (H.rows() != nf || H.cols() != static_cast<Eigen::Index>(outputs.size() * inputs.size()))
    throw InputError(what + ": FRF matrix is " + std::to_string(H.rows()) + " x " + std::to_string(H.cols()) + ", expected " +
                     std::to_string(nf) + " x " + std::to_string(outputs.size() * inputs.size()));
  for (Eigen::Index k = 1; k < nf; ++k)
    if (!(frequency_hz[k] > frequency_hz[k - 1]))
      throw InputError(what + ": frequencies must increase (line " + std::to_string(k + 1) + ": " + std::to_string(frequency_hz[k]) + " Hz)");
  if (!frequency_hz.allFinite() || frequency_hz[0] < 0) throw InputError(what + ": frequencies must be finite and >= 0");
  for (Eigen::Index c = 0; c < H.cols(); ++c)
    if (!H.col(c).allFinite()) throw InputError(what + ": FRF " + std::to_string(c + 1) + " holds NaN or Inf values");
  if (coherence.size() != 0 && (coherence.rows() != nf || coherence.cols() != H.cols()))
    throw InputError(what + ": coherence must have the shape of the FRF matrix");
  if (!(window_decay >= 0)) throw InputError(what + ": window decay must be >= 0");
}

}  // namespace dynid
