// Identification of recordings as a whole (used by dynid identify, discovery and host codes): the plan (band and
// resolution from the data), FRFs + LSCF or SSI-cov, and the split-data uncertainty.
#include <algorithm>
#include <cmath>
#include <limits>

#include "dynid/engine/frf.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/identify_select.hpp"

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

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

// The half of a mode in a half-data identification: within max(5 %, 3 zeta) in frequency, the best MAC >= 0.8.
const IdentifiedMode* partner(const IdentifiedMode& m, const IdentificationSummary& half) {
  const IdentifiedMode* best = nullptr;
  double best_mac = 0.8;
  const Eigen::VectorXcd a = m.real_shape.cast<std::complex<double>>();
  for (const IdentifiedMode& h : half.modes) {
    if (std::abs(h.frequency_hz - m.frequency_hz) > std::max(0.05, 3 * m.damping_ratio) * m.frequency_hz) continue;
    const double mac = internal::complex_mac(a, h.real_shape.cast<std::complex<double>>());
    if (mac >= best_mac) best_mac = mac, best = &h;
  }
  return best;
}

// The share of the spread over orders that the frequency's std keeps beside the halves' spread (identify.hpp,
// header comment): the error the halves have in common.
constexpr double kOrderShare = 0.25;

// Split-data uncertainty (identify.hpp, header comment) from the identifications of the two halves.
void split_uncertainty(IdentificationSummary& s, const IdentificationSummary& A, const IdentificationSummary& B) {
  const std::size_t n = s.modes.size();
  std::vector<double> ef(n, -1), ez(n, -1), es(n, -1);
  std::vector<double> pf, pz, ps;
  for (std::size_t k = 0; k < n; ++k) {
    const IdentifiedMode& m = s.modes[k];
    const IdentifiedMode* a = partner(m, A);
    const IdentifiedMode* b = partner(m, B);
    if (!a || !b) continue;
    const double zeta = std::max(m.damping_ratio, 1e-4);
    ef[k] = std::abs(a->frequency_hz - b->frequency_hz) / (2 * m.frequency_hz * zeta);
    ez[k] = std::abs(a->damping_ratio - b->damping_ratio) / (2 * zeta);
    Eigen::VectorXd ua = a->real_shape, ub = b->real_shape;  // max |.| = 1 each
    if (ua.dot(ub) < 0) ub = -ub;
    es[k] = std::sqrt((ua - ub).squaredNorm() / static_cast<double>(ua.size())) / 2;
    pf.push_back(ef[k]), pz.push_back(ez[k]), ps.push_back(es[k]);
  }
  if (pf.empty()) {
    s.notes.push_back("split-data uncertainty: no mode was found in both halves of the data; the spread over model orders is reported");
    return;
  }
  const double kMad = 0.6745;  // median of |N(0, 1)|
  const double pool_f = median(pf) / kMad, pool_z = median(pz) / kMad, pool_s = median(ps) / kMad;
  s.uncertainty_halves = 2;
  s.pooled_frequency_std = pool_f;
  s.pooled_shape_std = pool_s;
  int own = 0;
  for (std::size_t k = 0; k < n; ++k) {
    IdentifiedMode& m = s.modes[k];
    const double zeta = std::max(m.damping_ratio, 1e-4);
    m.frequency_std_hz =
        std::hypot(m.frequency_hz * zeta * std::max(ef[k], pool_f), kOrderShare * m.order_frequency_std_hz);
    m.damping_std = zeta * std::max(ez[k], pool_z);
    m.shape_std = std::max(es[k], pool_s);
    own += ef[k] >= 0;
  }
  s.notes.push_back(
      fmt("split-data uncertainty: %.0f of %.0f modes found in both halves of the data; ", own,
          static_cast<double>(n)) +
      fmt("pooled sigma_f = %.3g x f zeta (with %.2g of the spread over orders), shape std %.3g of the largest entry",
          pool_f, kOrderShare, pool_s));
}

// The overlap of each mode with its nearest neighbour among the identified modes: their mean half-power
// half-bandwidth (zeta_k f_k + zeta_j f_j) / 2 over their distance |f_k - f_j|, the largest over j.
std::vector<double> modal_overlap(const std::vector<IdentifiedMode>& modes) {
  std::vector<double> o(modes.size(), 0.0);
  for (std::size_t k = 0; k < modes.size(); ++k)
    for (std::size_t j = 0; j < modes.size(); ++j) {
      if (j == k) continue;
      const double d = std::abs(modes[k].frequency_hz - modes[j].frequency_hz);
      const double w =
          0.5 * (modes[k].damping_ratio * modes[k].frequency_hz + modes[j].damping_ratio * modes[j].frequency_hz);
      o[k] = std::max(o[k], d > 0 ? w / d : std::numeric_limits<double>::infinity());
    }
  return o;
}

// Stationary-response uncertainty (identify.hpp, header comment): continuous records of total length T give
// sigma_f / f = sqrt(zeta / (pi f T)) sqrt(1 + (o / kOverlapScale)^2), o the mode's overlap with its nearest
// neighbour, combined with kOrderShare of the spread over orders, and sigma_zeta / zeta = sqrt(1 / (pi zeta f T)).
void stationary_response_uncertainty(IdentificationSummary& s, const std::vector<Recording>& recs) {
  constexpr double kOverlapScale = 0.3;
  double T = 0;
  for (const Recording& r : recs)
    for (const Eigen::MatrixXd& x : r.records) T += static_cast<double>(x.rows()) / r.sample_rate_hz;
  const std::vector<double> overlap = modal_overlap(s.modes);
  for (std::size_t k = 0; k < s.modes.size(); ++k) {
    IdentifiedMode& m = s.modes[k];
    const double zeta = std::max(m.damping_ratio, 1e-4), f = m.frequency_hz, o = overlap[k] / kOverlapScale;
    m.frequency_std_hz =
        std::hypot(f * std::sqrt(zeta / (M_PI * f * T)) * std::sqrt(1 + o * o), kOrderShare * m.order_frequency_std_hz);
    m.damping_std = zeta * std::sqrt(1.0 / (M_PI * zeta * f * T));
  }
  s.stationary_record_s = T;
  s.notes.push_back(fmt(
      "frequency and damping std from the stationary response (%.4g s of records): sigma_f / f = "
      "sqrt(zeta / (pi f T)), widened where a neighbour overlaps, with %.2g of the spread over orders; the split-data "
      "spread sets the shapes' std only",
      T, kOrderShare));
}

// The two halves of the data: alternate records of every recording when each has two or more, else the two
// halves in time of each record (continuous data). Empty when the data cannot be split (one impact).
bool halves_of(const std::vector<Recording>& recs, bool impulsive, std::vector<Recording>* A, std::vector<Recording>* B, std::string* how) {
  bool by_records = true;
  for (const Recording& r : recs) by_records = by_records && r.records.size() >= 2;
  if (!by_records && impulsive) return false;
  for (const Recording& r : recs) {
    Recording a = r, b = r;
    a.records.clear(), b.records.clear();
    for (std::size_t k = 0; k < r.records.size(); ++k) {
      if (by_records) {
        (k % 2 ? b : a).records.push_back(r.records[k]);
      } else {
        const Eigen::Index h = r.records[k].rows() / 2;
        a.records.push_back(r.records[k].topRows(h));
        b.records.push_back(r.records[k].middleRows(h, h));
      }
    }
    A->push_back(std::move(a));
    B->push_back(std::move(b));
  }
  *how = by_records ? "alternate records" : "the two halves in time";
  return true;
}

IdentificationSummary identify_once(const std::vector<Recording>& recs, const std::string& method, const IdentificationOptions& io,
                                    const IdentificationPlan& plan) {
  if (method == "lscf") {
    FrfOptions fo;
    fo.estimator = io.estimator;
    fo.exponential_end = plan.impulsive ? io.exponential_end : 0;
    fo.segment = plan.impulsive ? 0 : plan.segment;
    fo.max_frequency_hz = std::min(1.25 * io.band_hi_hz, recs[0].sample_rate_hz / 2);
    IdentificationOptions o = io;
    // Impacts only: on Welch FRFs of continuous records it lost more lowest modes than it found (docs/method.md).
    if (plan.impulsive && o.lscf_fit_below == 0) o.lscf_fit_below = 0.5;
    return identify_lscf(estimate_frf(recs, fo), o);
  }
  Recording all = recs[0];
  for (std::size_t k = 1; k < recs.size(); ++k) {
    if (recs[k].sample_rate_hz != recs[0].sample_rate_hz || recs[k].num_channels() != recs[0].num_channels())
      throw InputError("identify: recordings identified together need the same channels and sampling rate (" + recs[k].source + ")");
    all.records.insert(all.records.end(), recs[k].records.begin(), recs[k].records.end());
  }
  return identify_ssi(all, io);
}

// Options for LSCF beside an SSI run: automatic orders (SSI's are no LSCF orders), up to 60 poles whatever the
// options' budget: on Welch FRFs with a few lines per half-power bandwidth, orders to 60 with two shakers biased
// two dev modes of the identification benchmark's random-force tests beyond 0.5 % (bench/README.md).
IdentificationOptions lscf_options(IdentificationOptions io) {
  io.min_order = io.max_order = io.order_step = 0;
  io.lscf_pole_budget = 60;
  return io;
}

// A random-force test identified by SSI (its selection: no leakage bias at the lowest modes of a wide band)
// takes each mode's frequency and damping from LSCF on the H1 FRFs of the same records where LSCF has the same
// mode (MAC >= 0.9, within the mode's half-power half-bandwidth, at least 0.5 %): the measured force removes the
// coloured-input bias SSI's output-only model leaves at some modes (bench/README.md, identification accuracy:
// dev random-force tests' median damping error 5.3 -> 3.1 %, modes found unchanged; bench/discovery/README.md:
// dev random-force cases named right 43 -> 55 of 70; test 37 of 55 before and after, parameters within 10 % more
// often). Returns, per mode, which of LSCF's values it took.
enum class Refined : char { kNone, kFrequencyAndDamping, kFrequency };
std::vector<Refined> refine_with_lscf(IdentificationSummary& s, const std::vector<Recording>& recs,
                                      const IdentificationOptions& io, const IdentificationPlan& plan) {
  std::vector<Refined> refined_mode(s.modes.size(), Refined::kNone);
  IdentificationSummary L;
  try {
    L = identify_once(recs, "lscf", lscf_options(io), plan);
  } catch (const InputError& e) {
    s.notes.push_back(std::string("LSCF refinement of the random-force test not done (") + e.what() + ")");
    return refined_mode;
  }
  int refined = 0, unresolved = 0;
  for (std::size_t k = 0; k < s.modes.size(); ++k) {
    IdentifiedMode& m = s.modes[k];
    const IdentifiedMode* best = nullptr;
    double best_d = std::max(m.damping_ratio, 0.005);
    for (const IdentifiedMode& l : L.modes) {
      if (l.real_shape.size() != m.real_shape.size() || m.real_shape.size() == 0) continue;
      const double d = std::abs(l.frequency_hz - m.frequency_hz) / m.frequency_hz;
      const double mac =
          internal::complex_mac(m.real_shape.cast<std::complex<double>>(), l.real_shape.cast<std::complex<double>>());
      if (mac >= 0.9 && d <= best_d) best_d = d, best = &l;
    }
    if (!best) continue;
    m.frequency_hz = best->frequency_hz;
    // LSCF's damping only where the Welch lines resolve the peak: its half-power bandwidth spans >= kResolvedLines
    // (the plan's resolution rule). Below that LSCF's damping is biased high (paper frame, 300 s random force: 1.2-2.6
    // lines gave 1.21-1.43 % for 1.0 %, the frequencies within 0.1 %), and SSI's, which needs no lines, stays.
    const bool resolved =
        !(L.resolution_hz > 0 && 2 * best->damping_ratio * best->frequency_hz < kResolvedLines * L.resolution_hz);
    if (resolved)
      m.damping_ratio = best->damping_ratio;
    else
      ++unresolved;
    m.order_frequency_std_hz = best->order_frequency_std_hz;
    refined_mode[k] = resolved ? Refined::kFrequencyAndDamping : Refined::kFrequency;
    ++refined;
  }
  s.notes.push_back(
      fmt("random-force test: frequency and damping of %.0f of %.0f SSI modes from LSCF on the H1 FRFs "
          "(same mode: MAC >= 0.9, within its half-power half-bandwidth)",
          refined, static_cast<double>(s.modes.size())));
  if (unresolved > 0)
    s.notes.push_back(
        fmt("%.0f of the refined modes keep SSI's damping: their half-power bandwidth spans fewer "
            "than %.0f of the FRFs' %.4g Hz lines",
            unresolved, kResolvedLines, L.resolution_hz));
  return refined_mode;
}

// The refined modes' frequency and damping std: LSCF's own scatter, from the halves of the data identified by
// LSCF (split_uncertainty), in place of the stationary response's (which describes SSI's output-only estimates:
// with the force measured, LSCF's errors on the paper frame's random-force tests are 0.47 times that value).
void lscf_split_uncertainty(IdentificationSummary& s, const std::vector<Refined>& refined,
                            const std::vector<Recording>& A, const std::vector<Recording>& B,
                            const IdentificationOptions& io, const IdentificationPlan& plan) {
  IdentificationSummary t;  // the modes alone: split_uncertainty reads nothing else
  t.modes = s.modes;
  try {
    const IdentificationOptions lo = lscf_options(io);
    split_uncertainty(t, identify_once(A, "lscf", lo, plan), identify_once(B, "lscf", lo, plan));
  } catch (const InputError& e) {
    s.notes.push_back(std::string("LSCF on the halves failed (") + e.what() +
                      "); the refined modes keep the stationary response's std");
    return;
  }
  if (!t.uncertainty_halves) return;
  for (std::size_t k = 0; k < s.modes.size(); ++k)
    if (refined[k] != Refined::kNone) {
      s.modes[k].frequency_std_hz = t.modes[k].frequency_std_hz;
      if (refined[k] == Refined::kFrequencyAndDamping) s.modes[k].damping_std = t.modes[k].damping_std;
    }
  s.notes.push_back("the LSCF-refined modes' frequency and damping std from LSCF on the same halves: " +
                    t.notes.back());
}

}  // namespace

IdentificationSummary identify_frfs(const FrfData& frf, const IdentificationOptions& io_in, const std::vector<FrfData>& halves) {
  const IdentificationPlan plan = plan_identification(frf, io_in);
  IdentificationOptions io = io_in;
  io.band_lo_hz = plan.band_lo_hz;
  io.band_hi_hz = plan.band_hi_hz;
  IdentificationSummary s = identify_lscf(frf, io);
  s.band_from_data = plan.band_from_data;
  s.notes.insert(s.notes.begin(), plan.notes.begin(), plan.notes.end());
  if (io.split_uncertainty && halves.size() == 2 && !s.modes.empty()) {
    IdentificationOptions h = io;
    h.band_lo_hz = s.band_lo_hz, h.band_hi_hz = s.band_hi_hz;
    split_uncertainty(s, identify_lscf(halves[0], h), identify_lscf(halves[1], h));
  }
  return s;
}

IdentificationSummary identify_recordings(std::vector<Recording> recs, const std::string& method_in, const IdentificationOptions& io_in) {
  if (recs.empty()) throw InputError("identify: no recordings");
  std::string why;
  if (!io_in.IsValid(&why)) throw InputError("identify: " + why);
  for (const Recording& r : recs) r.validate("identify: " + r.source);
  bool has_inputs = false;
  for (const Recording& r : recs) has_inputs = has_inputs || !r.input_channels().empty();
  // The plan: band and resolution from the data where the options leave them open.
  const IdentificationPlan plan = plan_identification(recs, io_in);
  // No method given: LSCF on the FRFs of impacts; SSI-cov on continuous records (output-only, or a random force:
  // broadband, so the outputs alone identify the modes, without the leakage bias of Welch FRFs at the lowest
  // modes of a wide band).
  const std::string method = method_in.empty() ? (has_inputs && plan.impulsive ? "lscf" : "ssi") : method_in;
  if (method == "lscf" && !has_inputs) throw InputError("identify: LSCF needs recordings with a force channel; these are output-only: use ssi");
  if (method != "lscf" && method != "ssi") throw InputError("identify: unknown method '" + method + "' (lscf or ssi)");
  IdentificationOptions io = io_in;
  io.band_lo_hz = plan.band_lo_hz;
  io.band_hi_hz = plan.band_hi_hz;
  if (method == "ssi" && io.segment < 0 && plan.segment > 0) io.segment = plan.segment;
  IdentificationSummary s = identify_once(recs, method, io, plan);
  std::vector<Refined> refined;
  if (method_in.empty() && has_inputs && method == "ssi" && !s.modes.empty())
    refined = refine_with_lscf(s, recs, io, plan);
  s.band_from_data = plan.band_from_data;
  s.notes.insert(s.notes.begin(), plan.notes.begin(), plan.notes.end());
  if (io.split_uncertainty && !s.modes.empty()) {
    std::vector<Recording> A, B;
    std::string how;
    if (!halves_of(recs, plan.impulsive, &A, &B, &how)) {
      s.notes.push_back("split-data uncertainty: one impact cannot be split; the spread over model orders is reported");
    } else {
      IdentificationOptions h = io;
      h.split_uncertainty = false;
      IdentificationPlan hp = plan;
      if (!plan.impulsive && how != "alternate records") hp.segment = std::max(8, plan.segment / 2);
      try {
        const IdentificationSummary a = identify_once(A, method, h, hp), b = identify_once(B, method, h, hp);
        split_uncertainty(s, a, b);
        if (s.uncertainty_halves) s.notes.back() += " (halves: " + how + ")";
        if (!plan.impulsive) stationary_response_uncertainty(s, recs);
        if (std::any_of(refined.begin(), refined.end(), [](Refined r) { return r != Refined::kNone; }))
          lscf_split_uncertainty(s, refined, A, B, h, plan);
      } catch (const InputError& e) {
        s.notes.push_back(std::string("split-data uncertainty: the halves could not be identified (") + e.what() + "); the spread over model orders is reported");
      }
    }
  }
  return s;
}

}  // namespace dynid
