#include "dynid/engine/frf.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "dynid/mesh/error.hpp"

namespace dynid {

namespace {

int order_of(Quantity q) {
  switch (q) {
    case Quantity::kDisplacement: return 0;
    case Quantity::kVelocity: return 1;
    case Quantity::kAcceleration: return 2;
    default: return -1;
  }
}

// Samples the hammer pulse occupies in a force record: from the start to where the force last exceeds 5 % of
// its peak, times 4 (at least 8 samples).
int pulse_window_length(const Eigen::VectorXd& f) {
  Eigen::Index peak;
  const double a = f.cwiseAbs().maxCoeff(&peak);
  Eigen::Index last = peak;
  for (Eigen::Index k = peak; k < f.size(); ++k)
    if (std::abs(f[k]) > 0.05 * a) last = k;
  return static_cast<int>(std::min<Eigen::Index>(f.size(), std::max<Eigen::Index>(8, 4 * (last + 1))));
}
}  // namespace

bool FrfOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (segment != 0 && segment < 8) return fail("segment must be 0 (whole records) or >= 8 samples");
  if (!(overlap >= 0 && overlap < 1)) return fail("overlap must be in [0, 1)");
  if (!(force_window >= 0 && force_window <= 1)) return fail("force window must be in [0, 1]");
  if (!(exponential_end >= 0 && exponential_end < 1)) return fail("exponential window end must be in [0, 1)");
  if (max_frequency_hz < 0) return fail("maximum frequency must be >= 0");
  return true;
}

FrfData estimate_frf(const std::vector<Recording>& recs, const FrfOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("FRF estimation: " + why);
  if (recs.empty()) throw InputError("FRF estimation: no recordings");
  FrfData out;
  const double fs = recs[0].sample_rate_hz;
  std::vector<int> outs0 = recs[0].output_channels();
  for (int c : outs0) out.outputs.push_back(recs[0].channels[c]);
  const Eigen::Index no = static_cast<Eigen::Index>(outs0.size());
  if (no == 0) throw InputError("FRF estimation: " + recs[0].source + " has no output channels");

  int n = o.segment;
  if (n == 0) {
    n = static_cast<int>(recs[0].records[0].rows());
    for (const Recording& r : recs)
      for (const Eigen::MatrixXd& x : r.records)
        if (x.rows() != n) throw InputError("FRF estimation: impact records must all have the same length (" + r.source + ")");
  }
  const int nf_all = n / 2 + 1;
  int nf = nf_all;
  if (o.max_frequency_hz > 0) nf = std::min(nf_all, static_cast<int>(std::floor(o.max_frequency_hz * n / fs)) + 1);
  out.frequency_hz = Eigen::VectorXd::LinSpaced(nf, 0.0, (nf - 1) * fs / n);
  std::vector<Eigen::VectorXcd> cols, cohs;
  double tau = 0;
  if (o.segment == 0 && o.exponential_end > 0) {
    tau = (n - 1) / fs / -std::log(o.exponential_end);
    out.window_decay = 1.0 / tau;
  }
  RealFft fft(n);
  Eigen::VectorXd seg(n);
  for (const Recording& r : recs) {
    r.validate("FRF estimation: " + r.source);
    if (r.sample_rate_hz != fs) throw InputError("FRF estimation: recordings have different sampling rates");
    const std::vector<int> ins = r.input_channels(), outs = r.output_channels();
    if (ins.empty()) throw InputError("FRF estimation: " + r.source + " has no input (force) channel; use output-only identification (SSI)");
    if (outs.size() != outs0.size()) throw InputError("FRF estimation: recordings have different output channels");
    for (std::size_t k = 0; k < outs.size(); ++k)
      if (!(r.channels[outs[k]].dof == out.outputs[k].dof))
        throw InputError("FRF estimation: output " + std::to_string(k + 1) + " of " + r.source + " is " + to_string(r.channels[outs[k]].dof) +
                         ", expected " + to_string(out.outputs[k].dof));
    const Eigen::Index ni = static_cast<Eigen::Index>(ins.size());
    if (o.estimator == FrfOptions::Estimator::kH2 && ni != 1) throw InputError("FRF estimation: H2 needs one input per recording");
    for (int c : ins) out.inputs.push_back(r.channels[c]);
    // Accumulated spectra: Gxx (ni x ni), Gyx (no x ni), Gyy (no), per line.
    std::vector<Eigen::MatrixXcd> Gxx(static_cast<std::size_t>(nf), Eigen::MatrixXcd::Zero(ni, ni)), Gyx(static_cast<std::size_t>(nf), Eigen::MatrixXcd::Zero(no, ni));
    Eigen::MatrixXd Gyy = Eigen::MatrixXd::Zero(nf, no);
    Eigen::MatrixXcd X(nf_all, ni), Y(nf_all, no);
    const int step = o.segment == 0 ? n : std::max(1, static_cast<int>(std::lround(n * (1 - o.overlap))));
    const Eigen::VectorXd w = o.segment == 0 ? Eigen::VectorXd::Ones(n) : make_window(o.window, n);
    Eigen::VectorXd ew = Eigen::VectorXd::Ones(n);
    if (tau > 0)
      for (int k = 0; k < n; ++k) ew[k] = std::exp(-k / fs / tau);
    int segments = 0;
    for (const Eigen::MatrixXd& x : r.records) {
      if (x.rows() < n) throw InputError("FRF estimation: a record of " + r.source + " is shorter than the segment");
      for (Eigen::Index s0 = 0; s0 + n <= x.rows(); s0 += step, ++segments) {
        for (Eigen::Index a = 0; a < ni; ++a) {
          seg = x.col(ins[a]).segment(s0, n).cwiseProduct(w).cwiseProduct(ew);
          if (o.segment == 0) {
            const int keep = o.force_window > 0 ? std::max(1, static_cast<int>(o.force_window * n)) : pulse_window_length(seg);
            seg.tail(n - keep).setZero();
          }
          fft.forward(seg.data(), reinterpret_cast<std::complex<double>*>(X.col(a).data()));
        }
        for (Eigen::Index b = 0; b < no; ++b) {
          seg = x.col(outs[b]).segment(s0, n).cwiseProduct(w).cwiseProduct(ew);
          fft.forward(seg.data(), reinterpret_cast<std::complex<double>*>(Y.col(b).data()));
        }
        for (int k = 0; k < nf; ++k) {
          Gxx[k].noalias() += X.row(k).adjoint() * X.row(k);
          Gyx[k].noalias() += Y.row(k).transpose() * X.row(k).conjugate();
          Gyy.row(k) += Y.row(k).cwiseAbs2();
        }
      }
    }
    if (segments == 0) throw InputError("FRF estimation: " + r.source + " is shorter than one segment");
    for (Eigen::Index a = 0; a < ni; ++a) {
      cols.insert(cols.end(), static_cast<std::size_t>(no), Eigen::VectorXcd(nf));
      cohs.insert(cohs.end(), static_cast<std::size_t>(no), Eigen::VectorXcd(nf));
    }
    const std::size_t base = cols.size() - static_cast<std::size_t>(no * ni);
    for (int k = 0; k < nf; ++k) {
      Eigen::MatrixXcd H(no, ni);
      Eigen::VectorXd coh(no);
      const Eigen::FullPivLU<Eigen::MatrixXcd> lu(Gxx[k]);
      const bool ok = lu.rank() == ni && Gxx[k].cwiseAbs().maxCoeff() > 0;
      if (ok) {
        H = Gyx[k] * lu.inverse();  // the explained power below is H Gxy = Gyx Gxx^-1 Gxy
        for (Eigen::Index b = 0; b < no; ++b) {
          const double explained = (H.row(b) * Gyx[k].row(b).adjoint())(0, 0).real();
          coh[b] = Gyy(k, b) > 0 ? std::min(1.0, explained / Gyy(k, b)) : 0.0;
        }
        if (o.estimator == FrfOptions::Estimator::kH2)
          for (Eigen::Index b = 0; b < no; ++b)
            H(b, 0) = std::abs(Gyx[k](b, 0)) > 0 ? Gyy(k, b) / std::conj(Gyx[k](b, 0)) : std::complex<double>(0);
      } else {
        H.setZero();
        coh.setZero();
      }
      for (Eigen::Index a = 0; a < ni; ++a)
        for (Eigen::Index b = 0; b < no; ++b) {
          cols[base + static_cast<std::size_t>(b + a * no)][k] = H(b, a);
          cohs[base + static_cast<std::size_t>(b + a * no)][k] = coh[b];
        }
    }
  }
  out.H.resize(nf, static_cast<Eigen::Index>(cols.size()));
  out.coherence.resize(nf, static_cast<Eigen::Index>(cols.size()));
  for (std::size_t c = 0; c < cols.size(); ++c) {
    out.H.col(static_cast<Eigen::Index>(c)) = cols[c];
    out.coherence.col(static_cast<Eigen::Index>(c)) = cohs[c].real();
  }
  out.source = recs.size() == 1 ? recs[0].source : std::to_string(recs.size()) + " recordings";
  return out;
}

FrfData convert_frf(const FrfData& frf, Quantity target) {
  const int to = order_of(target);
  if (to < 0) throw InputError("FRF conversion: target must be displacement, velocity or acceleration");
  FrfData out = frf;
  for (Channel& c : out.outputs) {
    if (order_of(c.quantity) < 0) throw InputError("FRF conversion: output " + c.name + " is not a motion quantity");
    if (order_of(c.quantity) != order_of(frf.outputs[0].quantity))
      throw InputError("FRF conversion: outputs measure different quantities");
    c.quantity = target;
  }
  const int k = to - order_of(frf.outputs[0].quantity);
  if (k == 0) return out;
  Eigen::Index first = 0;
  if (k < 0)
    while (first < frf.frequency_hz.size() && frf.frequency_hz[first] <= 0) ++first;
  const Eigen::Index nf = frf.frequency_hz.size() - first;
  out.frequency_hz = frf.frequency_hz.tail(nf);
  out.H = frf.H.bottomRows(nf);
  if (frf.coherence.size()) out.coherence = frf.coherence.bottomRows(nf);
  for (Eigen::Index r = 0; r < nf; ++r)
    out.H.row(r) *= std::pow(std::complex<double>(0, 2 * M_PI * out.frequency_hz[r]), k);
  return out;
}

}  // namespace dynid
