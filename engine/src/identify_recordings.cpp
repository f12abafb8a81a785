// Identification of recordings as a whole (used by discovery and by host codes): FRFs + LSCF, or SSI-cov.
#include <algorithm>

#include "dynid/engine/frf.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid {

/// Merges FRF sets with the same outputs and frequency grid: their inputs side by side.
FrfData merge_frfs(std::vector<FrfData> sets) {
  FrfData out = std::move(sets[0]);
  for (std::size_t k = 1; k < sets.size(); ++k) {
    const FrfData& s = sets[k];
    if (s.frequency_hz.size() != out.frequency_hz.size() || !s.frequency_hz.isApprox(out.frequency_hz))
      throw InputError(s.source + ": its frequency lines differ from " + out.source + "'s; FRFs identified together must share them");
    if (s.outputs.size() != out.outputs.size()) throw InputError(s.source + ": its outputs differ from " + out.source + "'s");
    for (std::size_t o = 0; o < s.outputs.size(); ++o)
      if (!(s.outputs[o].dof == out.outputs[o].dof)) throw InputError(s.source + ": its outputs differ from " + out.source + "'s");
    Eigen::MatrixXcd H(out.H.rows(), out.H.cols() + s.H.cols());
    H << out.H, s.H;
    out.H = H;
    out.inputs.insert(out.inputs.end(), s.inputs.begin(), s.inputs.end());
    if (out.coherence.size() && s.coherence.size()) {
      Eigen::MatrixXd C(out.coherence.rows(), out.coherence.cols() + s.coherence.cols());
      C << out.coherence, s.coherence;
      out.coherence = C;
    } else {
      out.coherence.resize(0, 0);
    }
  }
  out.validate("identify");
  return out;
}

IdentificationSummary identify_recordings(std::vector<Recording> recs, const std::string& method_in,
                                          const IdentificationOptions& io) {
  if (recs.empty()) throw InputError("identify: no recordings");
  bool has_inputs = false;
  for (const Recording& r : recs) has_inputs = has_inputs || !r.input_channels().empty();
  const std::string method = method_in.empty() ? (has_inputs ? "lscf" : "ssi") : method_in;
  if (method == "lscf") {
    if (!has_inputs) throw InputError("identify: LSCF needs recordings with a force channel; these are output-only: use ssi");
    FrfOptions fo;
    if (io.band_hi_hz > 0) fo.max_frequency_hz = std::min(1.25 * io.band_hi_hz, recs[0].sample_rate_hz / 2);
    return identify_lscf(estimate_frf(recs, fo), io);
  }
  if (method != "ssi") throw InputError("identify: unknown method '" + method + "' (lscf or ssi)");
  for (std::size_t k = 1; k < recs.size(); ++k) {
    if (recs[k].sample_rate_hz != recs[0].sample_rate_hz || recs[k].num_channels() != recs[0].num_channels())
      throw InputError("identify: recordings identified together need the same channels and sampling rate (" + recs[k].source + ")");
    recs[0].records.insert(recs[0].records.end(), recs[k].records.begin(), recs[k].records.end());
  }
  return identify_ssi(recs[0], io);
}

}  // namespace dynid
