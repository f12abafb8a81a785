// The band and frequency resolution of an identification from the data's spectral peaks (see
// dynid/engine/identify.hpp, plan_identification).
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "dynid/engine/identify.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/signal.hpp"

namespace dynid {

namespace {

// A force record is a hammer blow when its energy sits in a tenth of the record.
bool impulsive_record(const Eigen::VectorXd& f) {
  const Eigen::Index n = f.size();
  if (n < 16) return false;
  const double total = f.squaredNorm();
  if (!(total > 0)) return false;
  Eigen::Index peak;
  f.cwiseAbs().maxCoeff(&peak);
  const Eigen::Index w = std::max<Eigen::Index>(1, n / 10);
  const Eigen::Index a = std::max<Eigen::Index>(0, std::min(peak - w / 4, n - w));
  return f.segment(a, w).squaredNorm() >= 0.9 * total;
}

// Sum of the outputs' (or the inputs') auto spectra (the trace of the spectral matrix), pooled over all records.
struct Spectrum {
  Eigen::VectorXd f, level;  // level: PSD sum (continuous) or energy spectral density sum (impacts)
  double df = 0;
};

Spectrum channel_spectrum(const std::vector<Recording>& recs, bool impulsive, int segment, bool inputs) {
  Spectrum sp;
  const double fs = recs[0].sample_rate_hz;
  for (const Recording& r : recs) {
    const std::vector<int> outs = inputs ? r.input_channels() : r.output_channels();
    for (const Eigen::MatrixXd& x : r.records) {
      const int n = impulsive ? static_cast<int>(x.rows()) : segment;
      if (n > x.rows() || n < 8) continue;
      const int nf = n / 2 + 1;
      if (sp.level.size() == 0) {
        sp.f = Eigen::VectorXd::LinSpaced(nf, 0.0, (nf - 1) * fs / n);
        sp.level = Eigen::VectorXd::Zero(nf);
        sp.df = fs / n;
      }
      if (sp.level.size() != nf) continue;  // records of another length (impacts of another test)
      RealFft fft(n);
      const Eigen::VectorXd win = impulsive ? Eigen::VectorXd::Ones(n) : make_window(Window::kHann, n);
      std::vector<std::complex<double>> X(static_cast<std::size_t>(nf));
      Eigen::VectorXd seg(n);
      const int step = impulsive ? n : n / 2;
      for (int c : outs) {
        const double mean = x.col(c).mean();
        for (Eigen::Index s0 = 0; s0 + n <= x.rows(); s0 += step) {
          seg = (x.col(c).segment(s0, n).array() - mean).matrix().cwiseProduct(win);
          fft.forward(seg.data(), X.data());
          for (int k = 0; k < nf; ++k) sp.level[k] += std::norm(X[static_cast<std::size_t>(k)]);
        }
      }
    }
  }
  return sp;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1))];
}

// -3 dB width of the peak nearest f (interpolated between lines), in Hz; 0 if it cannot be measured.
double half_power_width(const Spectrum& sp, double f) {
  const Eigen::Index n = sp.f.size();
  Eigen::Index k = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(std::lround(f / sp.df)), 1, n - 2);
  while (k > 1 && sp.level[k - 1] > sp.level[k]) --k;
  while (k < n - 2 && sp.level[k + 1] > sp.level[k]) ++k;
  const double half = 0.5 * sp.level[k];
  Eigen::Index a = k, b = k;
  while (a > 0 && sp.level[a] > half) --a;
  while (b < n - 1 && sp.level[b] > half) ++b;
  if (sp.level[a] > half || sp.level[b] > half) return 0;
  auto cross = [&](Eigen::Index i, Eigen::Index j) {  // between lines i (below half) and j (above)
    const double t = (half - sp.level[i]) / (sp.level[j] - sp.level[i]);
    return sp.f[i] + t * (sp.f[j] - sp.f[i]);
  };
  return cross(b, b - 1) - cross(a, a + 1);
}

// Peaks of a spectrum (power-like levels) that stand >= 10 dB above their surroundings and above the 10th
// percentile of the levels up to `top`, ascending. Impacts pass the outputs' own energy spectrum as `outputs`
// (q is then their |FRF|^2): a peak also counts where the outputs' energy stands 10 dB above its own 10th
// percentile (see plan_identification).
std::vector<double> band_peaks(const Spectrum& q, double top, std::vector<double>* widths,
                               const Spectrum* outputs = nullptr);

// The band rule (identify.hpp): [0.5 x lowest peak, min(1.25 x highest, top)].
void band_from_peaks(IdentificationPlan& p, double top) {
  if (p.peaks_hz.empty()) {
    p.band_lo_hz = 0;
    p.band_hi_hz = top;
    p.notes.push_back("no spectral peak stands 10 dB above its surroundings and the noise floor: the whole band up to " + std::to_string(top) + " Hz");
    return;
  }
  p.band_lo_hz = 0.5 * p.peaks_hz.front();
  p.band_hi_hz = std::min(1.25 * p.peaks_hz.back(), top);
  p.band_from_data = true;
  char b[200];
  std::snprintf(b, sizeof b, "band %.4g-%.4g Hz from %zu spectral peaks (%.4g to %.4g Hz): 0.5 x the lowest, 1.25 x the highest", p.band_lo_hz,
                p.band_hi_hz, p.peaks_hz.size(), p.peaks_hz.front(), p.peaks_hz.back());
  p.notes.push_back(b);
}

std::vector<double> band_peaks(const Spectrum& q, double top, std::vector<double>* widths, const Spectrum* outputs) {
  auto decibels = [](const Eigen::VectorXd& level) {
    Eigen::VectorXd db(level.size());
    for (Eigen::Index k = 0; k < db.size(); ++k) db[k] = 10 * std::log10(std::max(level[k], 1e-300));
    return db;
  };
  // The 10th percentile of a spectrum's levels (dB) up to top: its floor.
  auto floor_of = [&](const Spectrum& x, const Eigen::VectorXd& db) {
    std::vector<double> in_band;
    for (Eigen::Index k = 1; k < db.size(); ++k)
      if (x.f[k] <= top) in_band.push_back(db[k]);
    return percentile(in_band, 0.1);
  };
  const Eigen::VectorXd db = decibels(q.level);
  const double floor = floor_of(q, db);
  const bool own = outputs && outputs->level.size() == q.level.size();
  const Eigen::VectorXd out_db = own ? decibels(outputs->level) : Eigen::VectorXd();
  const double out_floor = own ? floor_of(*outputs, out_db) : 0;
  std::vector<double> out;
  for (const SpectrumPeak& pk : spectrum_peaks(q.f, db, q.f[0] + q.df * 0.5, top, 10.0)) {
    bool above = pk.level_db >= floor + 10;
    if (!above && own) {  // the outputs' energy on the lines either side of the peak
      const Eigen::Index k =
          std::clamp<Eigen::Index>(static_cast<Eigen::Index>(pk.frequency_hz / q.df), 0, out_db.size() - 2);
      above = std::max(out_db[k], out_db[k + 1]) >= out_floor + 10;
    }
    if (above) out.push_back(pk.frequency_hz);
  }
  std::sort(out.begin(), out.end());
  if (widths) {
    widths->clear();
    for (double f : out) widths->push_back(half_power_width(q, f));
  }
  return out;
}

// The highest frequency up to `top` where a force spectrum stands within 20 dB of its median level over
// (0, top]: the end of a broadband excitation. 0 when there is no spectrum.
double excitation_top(const Spectrum& q, double top) {
  std::vector<double> levels;
  for (Eigen::Index k = 1; k < q.level.size(); ++k)
    if (q.f[k] <= top) levels.push_back(q.level[k]);
  if (levels.empty()) return 0;
  const double floor = 0.01 * percentile(levels, 0.5);
  double edge = 0;
  for (Eigen::Index k = 1; k < q.level.size(); ++k)
    if (q.f[k] <= top && q.level[k] >= floor) edge = q.f[k];
  return edge;
}

// Output-only records: the highest frequency up to `top` where the outputs' spectrum, averaged over 5 lines,
// stands >= 10 dB above its floor (the 10th percentile of its levels up to `top`): where the response ends (the
// excitation's band, or the modes the sensors see above the noise). Highly damped modes' peaks stand less than
// 10 dB out, so the peaks' rule stops short of them.
double response_top(const Spectrum& q, double top) {
  std::vector<double> levels;
  for (Eigen::Index k = 1; k < q.level.size(); ++k)
    if (q.f[k] <= top) levels.push_back(q.level[k]);
  if (levels.size() < 8) return 0;
  const double floor = 10 * percentile(levels, 0.1);
  double edge = 0;
  for (Eigen::Index k = 3; k + 2 < q.level.size() && q.f[k] <= top; ++k)
    if (q.level.segment(k - 2, 5).mean() >= floor) edge = q.f[k];
  return edge;
}

int pow2_at_most(double n) {
  int p = 8;
  while (2.0 * p <= n) p *= 2;
  return p;
}

}  // namespace

IdentificationPlan plan_identification(const std::vector<Recording>& recs, const IdentificationOptions& o) {
  if (recs.empty()) throw InputError("identification plan: no recordings");
  IdentificationPlan p;
  p.band_lo_hz = o.band_lo_hz;
  p.band_hi_hz = o.band_hi_hz;
  const double fs = recs[0].sample_rate_hz;
  // Impacts: every force record a blow.
  bool any_input = false, all_pulses = true;
  Eigen::Index shortest = -1;
  for (const Recording& r : recs) {
    for (const Eigen::MatrixXd& x : r.records) shortest = shortest < 0 ? x.rows() : std::min(shortest, x.rows());
    for (int c : r.input_channels()) {
      any_input = true;
      for (const Eigen::MatrixXd& x : r.records) all_pulses = all_pulses && impulsive_record(x.col(c));
    }
  }
  p.impulsive = any_input && all_pulses;
  int segment = p.impulsive ? 0 : pow2_at_most(static_cast<double>(shortest) / 8);
  if (!p.impulsive && segment < 64) segment = pow2_at_most(static_cast<double>(shortest));
  Spectrum sp = channel_spectrum(recs, p.impulsive, segment, false);
  Spectrum hits;    // impacts: the hits' energy spectrum
  Spectrum energy;  // impacts: the outputs' own energy spectrum, before it is divided by the hits'
  if (p.impulsive) {
    energy = sp;
    // Impacts: the outputs' energy over the hits' (a sum of |FRF|^2): the peaks of every mode the hits excite,
    // not only of those below the hits' spectral roll-off.
    hits = channel_spectrum(recs, true, segment, true);
    const Spectrum& in = hits;
    if (in.level.size() == sp.level.size()) {
      const double tiny = std::max(1e-12 * in.level.maxCoeff(), 1e-300);  // lines the hits do not reach
      for (Eigen::Index k = 0; k < sp.level.size(); ++k) sp.level[k] /= std::max(in.level[k], tiny);
    }
  }
  if (sp.level.size() < 8) {
    p.notes.push_back("records too short for a spectrum: the band and resolution are left as given");
    p.segment = o.segment > 0 ? o.segment : 0;
    return p;
  }
  // Impacts: the |FRF|^2 of accelerations falls to nothing below the lowest mode and rises where the hits are
  // weak, so its 10th percentile can stand within 10 dB of a well-excited lowest mode; the outputs' energy, whose
  // floor is the sensors' noise, shows that mode (a simply supported beam hit near a support: its first mode 20 dB
  // above its surroundings and 27 dB above the outputs' floor, but 9.97 dB above the |FRF|^2's).
  auto peaks_of = [&](const Spectrum& q, std::vector<double>* widths) {
    return band_peaks(q, 0.45 * fs, widths, p.impulsive ? &energy : nullptr);
  };
  std::vector<double> widths;
  p.peaks_hz = peaks_of(sp, &widths);
  // Resolution: refine continuous records while the lowest peak's half-power width spans < 4 lines.
  if (!p.impulsive && !p.peaks_hz.empty()) {
    const int longest = pow2_at_most(static_cast<double>(shortest) / 4);
    while (segment < longest && !(widths[0] >= kResolvedLines * sp.df)) {
      segment *= 2;
      sp = channel_spectrum(recs, false, segment, false);
      const std::vector<double> again = peaks_of(sp, &widths);
      if (again.empty()) break;
      p.peaks_hz = again;
    }
  }
  if (!p.peaks_hz.empty()) {
    p.lowest_peak_hz = p.peaks_hz.front();
    p.lowest_peak_damping = widths.empty() ? 0 : widths.front() / (2 * p.lowest_peak_hz);
  }
  // Band from the peaks, unless given; a measured broadband force (or the hits) shows where the excitation ends,
  // and the top reaches it when the peaks' rule stops short of it (the highest modes' peaks stand less than 10 dB
  // out, or overlap).
  if (o.band_hi_hz <= 0) {
    band_from_peaks(p, 0.45 * fs);
    if (any_input && p.band_from_data) {
      const double edge = excitation_top(p.impulsive ? hits : channel_spectrum(recs, false, segment, true), 0.45 * fs);
      if (edge > p.band_hi_hz) {
        p.band_hi_hz = edge;
        char b[160];
        std::snprintf(b, sizeof b,
                      "band top %.4g Hz: where the measured force's spectrum ends (20 dB below its median)", edge);
        p.notes.push_back(b);
      }
    } else if (!p.impulsive && p.band_from_data) {
      const double edge = response_top(sp, 0.45 * fs);
      if (edge > p.band_hi_hz) {
        p.band_hi_hz = edge;
        char b[160];
        std::snprintf(b, sizeof b, "band top %.4g Hz: where the outputs' spectrum ends (10 dB above its floor)", edge);
        p.notes.push_back(b);
      }
    }
  }
  // Segment for continuous records: the lowest peak's half-power bandwidth over 4 lines.
  if (o.segment >= 0) {
    p.segment = o.segment;
  } else if (p.impulsive) {
    p.segment = 0;
  } else {
    const int longest = pow2_at_most(static_cast<double>(shortest) / 4);
    double need = static_cast<double>(longest);
    if (p.lowest_peak_hz > 0 && p.lowest_peak_damping > 0)
      need = fs / (2 * p.lowest_peak_damping * p.lowest_peak_hz / kResolvedLines);
    int seg = 64;
    while (seg < need && seg < longest) seg *= 2;
    p.segment = std::min(seg, longest);
    if (seg > longest || need > longest) {
      char b[200];
      std::snprintf(b, sizeof b, "the records allow %.4g Hz lines (%d samples per segment, 7 averages); the lowest peak's bandwidth asks for %.4g Hz",
                    fs / p.segment, p.segment, fs / need);
      p.notes.push_back(b);
    }
  }
  p.resolution_hz = p.segment > 0 ? fs / p.segment : (shortest > 0 ? fs / static_cast<double>(shortest) : 0);
  return p;
}

IdentificationPlan plan_identification(const FrfData& frf, const IdentificationOptions& o) {
  IdentificationPlan p;
  p.band_lo_hz = o.band_lo_hz;
  p.band_hi_hz = o.band_hi_hz;
  const Eigen::Index n = frf.frequency_hz.size();
  if (n < 8) return p;
  p.resolution_hz = (frf.frequency_hz[n - 1] - frf.frequency_hz[0]) / static_cast<double>(n - 1);
  if (o.band_hi_hz > 0) return p;
  // Evenly spaced lines are needed by the peak widths; FRFs on an uneven grid keep their whole range.
  Spectrum sp;
  sp.f = frf.frequency_hz;
  sp.df = p.resolution_hz;
  for (Eigen::Index k = 1; k < n; ++k)
    if (std::abs(frf.frequency_hz[k] - frf.frequency_hz[k - 1] - sp.df) > 0.02 * sp.df) return p;
  sp.level.resize(n);
  const int no = frf.num_outputs(), ni = frf.num_inputs();
  for (Eigen::Index k = 0; k < n; ++k) {
    Eigen::MatrixXcd Hk(no, ni);
    for (int i = 0; i < ni; ++i)
      for (int q = 0; q < no; ++q) Hk(q, i) = frf.H(k, q + i * no);
    const double s1 = ni == 1 ? Hk.norm() : Eigen::JacobiSVD<Eigen::MatrixXcd>(Hk).singularValues()[0];
    sp.level[k] = s1 * s1;
  }
  std::vector<double> widths;
  p.peaks_hz = band_peaks(sp, frf.frequency_hz[n - 1], &widths);
  if (!p.peaks_hz.empty()) {
    p.lowest_peak_hz = p.peaks_hz.front();
    p.lowest_peak_damping = widths.front() / (2 * p.lowest_peak_hz);
  }
  band_from_peaks(p, frf.frequency_hz[n - 1]);
  return p;
}

}  // namespace dynid
