#include "dynid/engine/virtual_test.hpp"

#include <unsupported/Eigen/MatrixFunctions>

#include <cmath>
#include <random>

#include "dynid/mesh/error.hpp"
#include "dynid/solvers/signal.hpp"

namespace dynid {

namespace {
using Excitation = VirtualTestOptions::Excitation;

// Deterministic per-stream generator: the same (seed, record, stream) always gives the same numbers.
std::mt19937_64 stream_rng(std::uint64_t seed, std::uint64_t record, std::uint64_t stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(record), static_cast<std::uint32_t>(stream)};
  return std::mt19937_64(seq);
}

// Gaussian noise band-limited to [lo, hi] Hz by zeroing FFT lines outside, scaled to `rms`.
Eigen::VectorXd band_noise(int n, double fs, double lo, double hi, double rms, std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = g(rng);
  RealFft fft(n);
  std::vector<std::complex<double>> X(static_cast<std::size_t>(n / 2 + 1));
  fft.forward(x.data(), X.data());
  for (int k = 0; k <= n / 2; ++k) {
    const double f = k * fs / n;
    if (f < lo || f > hi) X[static_cast<std::size_t>(k)] = 0;
  }
  fft.inverse(X.data(), x.data());
  const double r = std::sqrt(x.squaredNorm() / n);
  if (r > 0) x *= rms / r;
  return x;
}

void add_noise(Eigen::Ref<Eigen::VectorXd> y, double level, std::mt19937_64& rng) {
  if (level <= 0) return;
  const double sd = level * std::sqrt(y.squaredNorm() / static_cast<double>(y.size()));
  std::normal_distribution<double> g(0.0, sd);
  for (Eigen::Index i = 0; i < y.size(); ++i) y[i] += g(rng);
}

// Exact first-order-hold map of one mode: x_{k+1} = Phi x_k + G0 u_k + G1 u_{k+1}, x = (q, q').
struct ModeMap {
  Eigen::Matrix2d Phi;
  Eigen::Vector2d G0, G1;
  double w2 = 0, c = 0;  // q'' = u - c q' - w2 q
};

ModeMap mode_map(double w2, double c, double h) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
  M(0, 1) = 1;
  M(1, 0) = -w2;
  M(1, 1) = -c;
  M(1, 2) = 1;  // B = (0, 1)
  M(2, 3) = 1;
  const Eigen::Matrix4d E = (M * h).exp();
  ModeMap m;
  m.Phi = E.topLeftCorner<2, 2>();
  const Eigen::Vector2d F12 = E.block<2, 1>(0, 2), F13 = E.block<2, 1>(0, 3);
  m.G1 = F13 / h;
  m.G0 = F12 - m.G1;
  m.w2 = w2;
  m.c = c;
  return m;
}
}  // namespace

bool VirtualTestOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (sensors.empty()) return fail("no sensors");
  if (!(sample_rate_hz > 0)) return fail("the sampling rate must be > 0");
  if (!(duration_s > 0)) return fail("the duration must be > 0");
  if (sample_rate_hz * duration_s < 16) return fail("fewer than 16 samples per record");
  if (sample_rate_hz * duration_s > 2e8) return fail("more than 2e8 samples per record");
  if (excitation != Excitation::kAmbient && inputs.empty()) return fail("impact and random tests need input DOFs");
  if (excitation == Excitation::kImpact && impacts < 1) return fail("impacts must be >= 1");
  if (response == Quantity::kForce || response == Quantity::kOther) return fail("sensors measure displacement, velocity or acceleration");
  if (band_hz_lo < 0 || band_hz_hi < 0 || (band_hz_hi > 0 && band_hz_hi <= band_hz_lo)) return fail("the band must satisfy 0 <= lo < hi");
  if (band_hz_hi > sample_rate_hz / 2) return fail("the band's top is above the Nyquist frequency");
  if (pulse_s < 0 || !(pretrigger >= 0 && pretrigger < 0.5)) return fail("pulse must be >= 0 and pretrigger in [0, 0.5)");
  if (!(force_rms > 0)) return fail("the force level must be > 0");
  if (damping == Damping::kModal && !(damping_ratio >= 0 && damping_ratio < 1)) return fail("the damping ratio must be in [0, 1)");
  if (damping == Damping::kRayleigh && (rayleigh_alpha < 0 || rayleigh_beta < 0)) return fail("Rayleigh coefficients must be >= 0");
  if (noise < 0 || force_noise < 0) return fail("noise levels must be >= 0");
  return true;
}

namespace {

// The modal model of a virtual test: the modes kept, their exact step maps, and the sensor and force rows.
struct ModalSimulator {
  explicit ModalSimulator(const VirtualTestOptions& options) : o(options) {}
  const VirtualTestOptions& o;
  double fs = 0, h = 0;
  int n = 0;                  // samples per record
  std::vector<int> kept;      // modes simulated (indices into the modal result)
  std::vector<ModeMap> maps;  // their step maps
  Eigen::VectorXd zeta;       // their damping ratios
  Eigen::MatrixXd Ps, Pf;     // sensors x modes, force DOFs x modes
  std::vector<MeasuredDof> force_dofs;
  Eigen::Index ns = 0;  // sensors

  // Response of every sensor to forces F (samples x force DOFs).
  Eigen::MatrixXd respond(const Eigen::MatrixXd& F) const {
    const int m = static_cast<int>(kept.size());
    const Eigen::MatrixXd p = F * Pf;  // modal forces, samples x modes
    Eigen::MatrixXd q(n, m);
#pragma omp parallel for schedule(static)
    for (int a = 0; a < m; ++a) {
      const ModeMap& mm = maps[a];
      Eigen::Vector2d x = Eigen::Vector2d::Zero();
      for (int k = 0; k < n; ++k) {
        double out = x[0];
        if (o.response == Quantity::kVelocity) out = x[1];
        if (o.response == Quantity::kAcceleration) out = p(k, a) - mm.c * x[1] - mm.w2 * x[0];
        q(k, a) = out;
        if (k + 1 < n) x = mm.Phi * x + mm.G0 * p(k, a) + mm.G1 * p(k + 1, a);
      }
    }
    return Eigen::MatrixXd(q * Ps.transpose());
  }

  // The sensors' channels, then one force channel per DOF of `forces`.
  std::vector<Channel> channels(const std::vector<MeasuredDof>& forces) const {
    std::vector<Channel> ch;
    const char* unit = o.response == Quantity::kAcceleration ? "m/s^2" : o.response == Quantity::kVelocity ? "m/s" : "m";
    for (const MeasuredDof& d : o.sensors) ch.push_back({to_string(d), d, o.response, unit, false});
    for (const MeasuredDof& d : forces) ch.push_back({to_string(d) + " force", d, Quantity::kForce, "N", true});
    return ch;
  }

  // Measurement noise on every channel of a record (sensors: o.noise, forces: o.force_noise).
  void finish_record(Eigen::MatrixXd& Y, std::uint64_t record) const {
    for (Eigen::Index c = 0; c < Y.cols(); ++c) {
      std::mt19937_64 rng = stream_rng(o.seed, record, 1000000 + static_cast<std::uint64_t>(c));
      add_noise(Y.col(c), c < ns ? o.noise : o.force_noise, rng);
    }
  }
};

// Modes kept: below Nyquist (an ideal anti-alias filter), with their step maps and the rows of the sensors and forces.
ModalSimulator modal_simulator(const Model& model, const ModalResult& modal, const VirtualTestOptions& o) {
  ModalSimulator sim(o);
  sim.fs = o.sample_rate_hz;
  sim.h = 1.0 / sim.fs;
  sim.n = static_cast<int>(std::llround(o.duration_s * sim.fs));
  const double nyquist = sim.fs / 2;
  // The caller must have computed past the Nyquist frequency.
  std::vector<int>& kept = sim.kept;
  for (int j = 0; j < modal.modes.cols(); ++j)
    if (modal.frequencies_hz[j] < nyquist) kept.push_back(j);
  if (kept.empty())
    throw InputError("virtual test: no mode below the Nyquist frequency " + std::to_string(nyquist) + " Hz");
  if (static_cast<int>(kept.size()) == modal.modes.cols() &&
      modal.frequencies_hz[modal.modes.cols() - 1] < 0.8 * nyquist)
    throw InputError("virtual test: the modal basis stops at " +
                     std::to_string(modal.frequencies_hz[modal.modes.cols() - 1]) +
                     " Hz, below the Nyquist frequency " + std::to_string(nyquist) + " Hz; compute more modes");
  const int m = static_cast<int>(kept.size());
  sim.maps.resize(static_cast<std::size_t>(m));
  sim.zeta.resize(m);
  for (int a = 0; a < m; ++a) {
    const double lam = modal.rigid_body[kept[a]] ? 0.0 : std::max(0.0, modal.eigenvalues[kept[a]]);
    const double w = std::sqrt(lam);
    const double c = o.damping == VirtualTestOptions::Damping::kModal ? 2 * o.damping_ratio * w
                                                                      : o.rayleigh_alpha + o.rayleigh_beta * lam;
    sim.zeta[a] = w > 0 ? c / (2 * w) : 0;
    sim.maps[a] = mode_map(lam, c, sim.h);
  }
  auto rows_of = [&](const std::vector<MeasuredDof>& dofs) {
    const std::vector<int> eq = measured_equations(model, dofs);
    Eigen::MatrixXd P(static_cast<Eigen::Index>(dofs.size()), m);
    for (std::size_t r = 0; r < dofs.size(); ++r)
      for (int a = 0; a < m; ++a) P(static_cast<Eigen::Index>(r), a) = modal.modes(eq[r], kept[a]);
    return P;
  };
  sim.Ps = rows_of(o.sensors);
  sim.force_dofs = o.inputs;
  if (o.excitation == Excitation::kAmbient) {
    sim.force_dofs.clear();
    for (const MeasuredDof& d : all_dofs(model))
      if (d.dof == Dof::UX || d.dof == Dof::UY || d.dof == Dof::UZ) sim.force_dofs.push_back(d);
  }
  sim.Pf = rows_of(sim.force_dofs);
  sim.ns = static_cast<Eigen::Index>(o.sensors.size());
  return sim;
}

// Impact test: one recording per input DOF, o.impacts records each (a half-sine pulse of random amplitude).
void impact_recordings(const ModalSimulator& sim, double band_hi, const std::string& src, VirtualTest* out) {
  const VirtualTestOptions& o = sim.o;
  const int n = sim.n;
  const double fs = sim.fs;
  const double tp = o.pulse_s > 0 ? o.pulse_s : std::max(0.75 / band_hi, 4.0 / fs);
  if (tp * fs < 3)
    throw InputError("virtual test: the impact pulse (" + std::to_string(tp) +
                     " s) spans fewer than 3 samples; raise the sampling rate");
  const double t0 = o.pretrigger * o.duration_s;
  std::uint64_t record = 0;
  for (std::size_t i = 0; i < o.inputs.size(); ++i) {
    Recording r;
    r.sample_rate_hz = fs;
    r.channels = sim.channels({o.inputs[i]});
    r.source = src + " (impact at " + to_string(o.inputs[i]) + ")";
    for (int hit = 0; hit < o.impacts; ++hit, ++record) {
      std::mt19937_64 rng = stream_rng(o.seed, record, 0);
      const double amp = o.force_rms * std::uniform_real_distribution<double>(0.8, 1.2)(rng);
      Eigen::MatrixXd F = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(o.inputs.size()));
      for (int k = 0; k < n; ++k) {
        const double t = k * sim.h - t0;
        if (t > 0 && t < tp) F(k, static_cast<Eigen::Index>(i)) = amp * std::sin(M_PI * t / tp);
      }
      Eigen::MatrixXd Y(n, sim.ns + 1);
      Y.leftCols(sim.ns) = sim.respond(F);
      Y.col(sim.ns) = F.col(static_cast<Eigen::Index>(i));
      sim.finish_record(Y, record);
      r.records.push_back(std::move(Y));
    }
    out->recordings.push_back(std::move(r));
  }
}

// Random-force or ambient test: one record, band-limited noise at every force DOF.
void random_recording(const ModalSimulator& sim, double band_lo, double band_hi, const std::string& src,
                      VirtualTest* out) {
  const VirtualTestOptions& o = sim.o;
  const int n = sim.n;
  const Eigen::Index nf = static_cast<Eigen::Index>(sim.force_dofs.size());
  Eigen::MatrixXd F(n, nf);
  for (Eigen::Index c = 0; c < nf; ++c) {
    std::mt19937_64 rng = stream_rng(o.seed, 0, static_cast<std::uint64_t>(c));
    F.col(c) = band_noise(n, sim.fs, band_lo, band_hi, o.force_rms, rng);
  }
  Recording r;
  r.sample_rate_hz = sim.fs;
  const bool ambient = o.excitation == Excitation::kAmbient;
  r.channels = sim.channels(ambient ? std::vector<MeasuredDof>{} : sim.force_dofs);
  r.source = src + (ambient ? " (ambient)" : " (random force)");
  Eigen::MatrixXd Y(n, sim.ns + (ambient ? 0 : nf));
  Y.leftCols(sim.ns) = sim.respond(F);
  if (!ambient) Y.rightCols(nf) = F;
  sim.finish_record(Y, 0);
  r.records.push_back(std::move(Y));
  out->recordings.push_back(std::move(r));
}

// The truth: the simulated elastic modes at the sensors.
ModalData simulated_modes(const ModalSimulator& sim, const ModalResult& modal) {
  ModalData t;
  t.dofs = sim.o.sensors;
  t.source = "simulated modes";
  const std::vector<int>& kept = sim.kept;
  std::vector<int> el;
  for (int a = 0; a < static_cast<int>(kept.size()); ++a)
    if (!modal.rigid_body[kept[a]] && modal.frequencies_hz[kept[a]] > 0) el.push_back(a);
  t.frequencies_hz.resize(static_cast<Eigen::Index>(el.size()));
  t.damping_ratios.resize(static_cast<Eigen::Index>(el.size()));
  t.shapes.resize(sim.ns, static_cast<Eigen::Index>(el.size()));
  for (std::size_t b = 0; b < el.size(); ++b) {
    t.frequencies_hz[static_cast<Eigen::Index>(b)] = modal.frequencies_hz[kept[el[b]]];
    t.damping_ratios[static_cast<Eigen::Index>(b)] = sim.zeta[el[b]];
    t.shapes.col(static_cast<Eigen::Index>(b)) = sim.Ps.col(el[b]);
  }
  return t;
}

}  // namespace

VirtualTest simulate_test(const Model& model, const ModalResult& modal, const VirtualTestOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("virtual test: " + why);
  const double band_lo = o.band_hz_lo, band_hi = o.band_hz_hi > 0 ? o.band_hz_hi : 0.4 * o.sample_rate_hz;
  const ModalSimulator sim = modal_simulator(model, modal, o);
  VirtualTest out;
  const std::string src = "virtual test";
  if (o.excitation == Excitation::kImpact)
    impact_recordings(sim, band_hi, src, &out);
  else
    random_recording(sim, band_lo, band_hi, src, &out);
  out.modes = simulated_modes(sim, modal);
  return out;
}

}  // namespace dynid
