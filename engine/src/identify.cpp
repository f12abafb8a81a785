#include "dynid/engine/identify.hpp"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <random>

#include "dynid/engine/frf.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/signal.hpp"
#include "internal/identify_select.hpp"

namespace dynid {

using internal::complex_mac;

namespace {
using Clock = std::chrono::steady_clock;

// Marks modes whose shape repeats a stronger one's nearby (split pairs / duplicates).
void mark_twins(std::vector<IdentifiedMode>& modes, bool by_contribution) {
  for (std::size_t a = 0; a < modes.size(); ++a)
    for (std::size_t b = 0; b < modes.size(); ++b) {
      if (a == b || modes[a].real_shape.size() < 3) continue;
      const double mac = complex_mac(modes[a].real_shape.cast<std::complex<double>>(), modes[b].real_shape.cast<std::complex<double>>());
      const bool weaker = by_contribution ? modes[a].contribution < modes[b].contribution : modes[a].poles < modes[b].poles;
      if (mac >= 0.95 && weaker && std::abs(modes[a].frequency_hz / modes[b].frequency_hz - 1) <= 0.15 &&
          (modes[a].twin_of < 0 || mac > modes[a].twin_mac))
        modes[a].twin_of = static_cast<int>(b), modes[a].twin_mac = mac;
    }
}

void finish_shape(IdentifiedMode& m) {
  m.mpc = modal_phase_collinearity(m.shape);
  m.real_shape = real_normalize(m.shape);
}

// LSFD: residues of every FRF column at fixed poles, with lower (mass-line) and upper (constant) residuals, on
// receptance data. Returns one row per mode, columns = FRF columns.
Eigen::MatrixXcd lsfd(const Eigen::VectorXd& w, const Eigen::MatrixXcd& H, const std::vector<std::complex<double>>& poles) {
  const Eigen::Index nf = w.size(), nm = static_cast<Eigen::Index>(poles.size()), np = 2 * nm + 2;
  Eigen::MatrixXcd B(nf, np);
  const std::complex<double> I(0, 1);
  for (Eigen::Index k = 0; k < nf; ++k) {
    const std::complex<double> s = I * w[k];
    for (Eigen::Index r = 0; r < nm; ++r) {
      const std::complex<double> a = 1.0 / (s - poles[r]), b = 1.0 / (s - std::conj(poles[r]));
      B(k, 2 * r) = a + b;
      B(k, 2 * r + 1) = I * a - I * b;
    }
    B(k, np - 2) = -1.0 / (w[k] * w[k]);
    B(k, np - 1) = 1.0;
  }
  Eigen::MatrixXd A(2 * nf, np), rhs(2 * nf, H.cols());
  A << B.real(), B.imag();
  rhs << H.real(), H.imag();
  const Eigen::VectorXd scale = A.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd x = (A * scale.asDiagonal()).colPivHouseholderQr().solve(rhs);
  Eigen::MatrixXcd R(nm, H.cols());
  for (Eigen::Index r = 0; r < nm; ++r)
    for (Eigen::Index c = 0; c < H.cols(); ++c)
      R(r, c) = {scale[2 * r] * x(2 * r, c), scale[2 * r + 1] * x(2 * r + 1, c)};
  return R;
}

// Residues of every FRF column at a pole from the lines around it (a local LSFD: the pole's pair, the pairs of
// the `others` poles, and a complex constant plus slope for everything else). For judging a cluster: fitted with
// its neighbours' poles, the two modes of a closely spaced pair each get their own residue (alone, each takes up
// both); near-duplicate poles of one mode share its residue with parallel vectors (the split check merges them).
// Returns the first pole's residue per column.
Eigen::VectorXcd local_residues(const Eigen::VectorXd& w, const Eigen::MatrixXcd& H, std::complex<double> pole,
                                const std::vector<std::complex<double>>& others, double half_width) {
  const Eigen::Index nf = w.size();
  const double wr = pole.imag();
  const Eigen::Index np = 1 + static_cast<Eigen::Index>(others.size()), nu = 2 * np + 4;
  Eigen::Index a = std::lower_bound(w.data(), w.data() + nf, wr - half_width) - w.data();
  Eigen::Index b = std::upper_bound(w.data(), w.data() + nf, wr + half_width) - w.data();
  while (b - a < std::max<Eigen::Index>(8, nu) && (a > 0 || b < nf)) {
    if (a > 0) --a;
    if (b < nf) ++b;
  }
  const Eigen::Index n = b - a;
  const std::complex<double> I(0, 1);
  Eigen::MatrixXcd B(n, nu);
  for (Eigen::Index k = 0; k < n; ++k) {
    const std::complex<double> sk = I * w[a + k];
    for (Eigen::Index r = 0; r < np; ++r) {
      const std::complex<double> pr = r == 0 ? pole : others[static_cast<std::size_t>(r - 1)];
      const std::complex<double> p = 1.0 / (sk - pr), q = 1.0 / (sk - std::conj(pr));
      B(k, 2 * r) = p + q;
      B(k, 2 * r + 1) = I * p - I * q;
    }
    const double x = (w[a + k] - wr) / std::max(half_width, 1e-300);
    B.row(k).tail(4) << 1.0, I, x, I * x;
  }
  Eigen::MatrixXd A(2 * n, nu), rhs(2 * n, H.cols());
  A << B.real(), B.imag();
  rhs << H.middleRows(a, n).real(), H.middleRows(a, n).imag();
  const Eigen::VectorXd scale = A.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd x = (A * scale.asDiagonal()).colPivHouseholderQr().solve(rhs);
  Eigen::VectorXcd R(H.cols());
  for (Eigen::Index c = 0; c < H.cols(); ++c) R[c] = {scale[0] * x(0, c), scale[1] * x(1, c)};
  return R;
}

// The k leading left singular vectors and values of a square matrix. Large matrices: randomized range finder
// with a fixed seed and 4 subspace (power) iterations, then an exact SVD of the small projected matrix; the
// signal subspace of a correlation Toeplitz matrix is separated by a wide gap, which this resolves to working
// precision. Small ones: a full SVD.
void leading_svd(const Eigen::MatrixXd& T, int k, Eigen::MatrixXd* U, Eigen::VectorXd* sv) {
  const Eigen::Index n = T.rows(), q = std::min<Eigen::Index>(n, k + 30);
  if (n <= 3 * q) {
    Eigen::BDCSVD<Eigen::MatrixXd> svd(T, Eigen::ComputeThinU);
    *U = svd.matrixU();
    *sv = svd.singularValues();
    return;
  }
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> g;
  Eigen::MatrixXd Om(n, q);
  for (Eigen::Index j = 0; j < q; ++j)
    for (Eigen::Index i = 0; i < n; ++i) Om(i, j) = g(rng);
  Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(T * Om).householderQ() * Eigen::MatrixXd::Identity(n, q);
  for (int it = 0; it < 4; ++it) {
    const Eigen::MatrixXd W = Eigen::HouseholderQR<Eigen::MatrixXd>(T.transpose() * Q).householderQ() * Eigen::MatrixXd::Identity(n, q);
    Q = Eigen::HouseholderQR<Eigen::MatrixXd>(T * W).householderQ() * Eigen::MatrixXd::Identity(n, q);
  }
  Eigen::BDCSVD<Eigen::MatrixXd> svd(Q.transpose() * T, Eigen::ComputeThinU);
  *U = Q * svd.matrixU();
  *sv = svd.singularValues();
}

// The checks every identification starts with (the options, then the data); the clock starts after them.
template <class Data>
Clock::time_point checked_start(const IdentificationOptions& o, const Data& data, const std::string& what) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("identification: " + why);
  data.validate(what + data.source);
  return Clock::now();
}
}  // namespace

bool IdentificationOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (band_lo_hz < 0 || band_hi_hz < 0 || (band_hi_hz > 0 && band_hi_hz <= band_lo_hz)) return fail("the band must satisfy 0 <= lo < hi");
  if (min_order < 0 || max_order < 0 || (max_order > 0 && max_order < std::max(min_order, 2))) return fail("orders must satisfy 2 <= min <= max");
  if (max_order > 400) return fail("the maximum order is limited to 400");
  if (order_step < 0) return fail("the order step must be >= 0");
  if (lscf_pole_budget < 0 || lscf_pole_budget > 400) return fail("the LSCF pole budget must be in [0, 400]");
  if (!(stable_frequency > 0 && stable_damping > 0 && stable_mac > 0 && stable_mac <= 1)) return fail("stability tolerances must be > 0 (MAC <= 1)");
  if (!(max_damping > 0 && max_damping < 1)) return fail("the damping limit must be in (0, 1)");
  if (!(cluster_damping > 0)) return fail("the cluster damping tolerance must be > 0");
  if (!(min_cluster_fraction > 0 && min_cluster_fraction <= 1)) return fail("the cluster fraction must be in (0, 1]");
  if (!(cluster_tolerance > 0 && cluster_tolerance < 0.5)) return fail("the cluster tolerance must be in (0, 0.5)");
  if (!(cluster_mac > 0 && cluster_mac < 1)) return fail("the cluster MAC must be in (0, 1)");
  if (block_rows < 0 || decimate < 0) return fail("block rows and decimation must be >= 0");
  if (!(min_mpc >= 0 && min_mpc <= 1)) return fail("the MPC limit must be in [0, 1]");
  if (!std::isfinite(min_peak_db) || !(max_edge_db > 0)) return fail("the indicator peak limit must be finite and the edge limit > 0 dB");
  if (!(merge_tolerance >= 0 && merge_tolerance < 0.5) || !(merge_span >= 0 && merge_span < 0.5) ||
      !(merge_mac > 0 && merge_mac <= 1))
    return fail("the merge tolerance and span must be in [0, 0.5) and the merge MAC in (0, 1]");
  if (!(expected_fraction > 0) || !(expected_mac > 0 && expected_mac <= 1) || !(expected_ratio >= 1))
    return fail("the expected-mode fraction must be > 0, its MAC in (0, 1] and its frequency ratio >= 1");
  for (const ExpectedMode& e : expected_modes)
    if (!(e.frequency_hz > 0) || e.shape.size() != static_cast<Eigen::Index>(e.dofs.size()))
      return fail("an expected mode needs a frequency > 0 and one shape entry per DOF");
  if (segment < -1 || (segment > 0 && segment < 8)) return fail("the segment must be -1 (automatic), 0 (whole records) or >= 8 samples");
  if (!(exponential_end >= 0 && exponential_end < 1)) return fail("the exponential window end must be in [0, 1)");
  return true;
}

const char* to_string(Rejection r) {
  switch (r) {
    case Rejection::kFewOrders: return "few orders";
    case Rejection::kComplexShape: return "complex shape";
    case Rejection::kIndicatorTrough: return "no indicator peak";
    case Rejection::kSpectralEdge: return "spectral edge";
    case Rejection::kSplit: return "split";
  }
  return "?";
}

std::vector<SpectrumPeak> spectrum_peaks(const Eigen::VectorXd& f, const Eigen::VectorXd& db, double lo, double hi, double min_prom) {
  if (f.size() != db.size() || f.size() < 3) throw InputError("spectrum peaks: frequency and level must have the same length (>= 3)");
  std::vector<Eigen::Index> idx;
  for (Eigen::Index k = 0; k < f.size(); ++k)
    if (f[k] >= lo && (hi <= 0 || f[k] <= hi)) idx.push_back(k);
  std::vector<SpectrumPeak> out;
  const Eigen::Index n = static_cast<Eigen::Index>(idx.size());
  for (Eigen::Index j = 1; j + 1 < n; ++j) {
    const Eigen::Index k = idx[j];
    if (!(db[k] > db[idx[j - 1]] && db[k] >= db[idx[j + 1]])) continue;
    // Prominence: walk each way to a higher line (or the band edge), tracking the minimum.
    double left = db[k], right = db[k];
    Eigen::Index a = j - 1;
    for (; a >= 0 && db[idx[a]] <= db[k]; --a) left = std::min(left, db[idx[a]]);
    Eigen::Index b = j + 1;
    for (; b < n && db[idx[b]] <= db[k]; ++b) right = std::min(right, db[idx[b]]);
    const double prom = db[k] - std::max(left, right);
    if (prom < min_prom) continue;
    // Parabola through the three lines around the maximum.
    const double y0 = db[idx[j - 1]], y1 = db[k], y2 = db[idx[j + 1]], den = y0 - 2 * y1 + y2;
    const double d = den != 0 ? 0.5 * (y0 - y2) / den : 0.0;
    const double step = f[idx[j + 1]] - f[k];
    out.push_back({f[k] + d * step, y1 - 0.25 * (y0 - y2) * d, prom});
  }
  std::sort(out.begin(), out.end(), [](const SpectrumPeak& x, const SpectrumPeak& y) { return x.prominence_db > y.prominence_db; });
  return out;
}

double modal_phase_collinearity(const Eigen::VectorXcd& v) {
  const double sxx = v.real().squaredNorm(), syy = v.imag().squaredNorm(), sxy = v.real().dot(v.imag());
  const double tr = sxx + syy, det = sxx * syy - sxy * sxy;
  if (tr <= 0) return 0;
  const double disc = std::sqrt(std::max(0.0, tr * tr / 4 - det));
  const double e1 = tr / 2 + disc, e2 = tr / 2 - disc;
  return std::pow((e1 - e2) / (e1 + e2), 2);
}

Eigen::VectorXd real_normalize(const Eigen::VectorXcd& v) {
  // Principal direction of the points (Re v_i, Im v_i): the angle maximizing ||Re(e^{-i theta} v)||.
  const double sxx = v.real().squaredNorm(), syy = v.imag().squaredNorm(), sxy = v.real().dot(v.imag());
  const double theta = 0.5 * std::atan2(2 * sxy, sxx - syy);
  Eigen::VectorXd r = (v * std::exp(std::complex<double>(0, -theta))).real();
  Eigen::Index i;
  const double m = r.cwiseAbs().maxCoeff(&i);
  if (m > 0) r /= (r[i] > 0 ? m : -m);
  return r;
}

ModalData IdentificationSummary::modal_data(const std::string& source) const {
  ModalData d;
  d.dofs = dofs;
  d.source = source;
  const Eigen::Index n = static_cast<Eigen::Index>(modes.size());
  d.frequencies_hz.resize(n);
  d.damping_ratios.resize(n);
  d.mpc.resize(n);
  d.frequency_std_hz.resize(n);
  d.damping_std.resize(n);
  if (uncertainty_halves > 0) d.shape_std.resize(n);
  d.shapes.resize(static_cast<Eigen::Index>(dofs.size()), n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const IdentifiedMode& m = modes[static_cast<std::size_t>(k)];
    d.frequencies_hz[k] = m.frequency_hz;
    d.damping_ratios[k] = m.damping_ratio;
    d.mpc[k] = m.mpc;
    d.frequency_std_hz[k] = m.frequency_std_hz;
    d.damping_std[k] = m.damping_std;
    // A mode reported on the model's word (IdentificationOptions::expected_modes) keeps its frequency, the data's
    // own, but its shape cannot also be evidence for or against that model: std of the largest entry (where the
    // data carry shape std at all: not a single impact's modes).
    if (uncertainty_halves > 0) d.shape_std[k] = m.expected_hz > 0 ? std::max(m.shape_std, 1.0) : m.shape_std;
    d.shapes.col(k) = m.real_shape;
  }
  return d;
}

namespace {

// ---- LSCF stages ----------------------------------------------------------------------------------------------

// The FRFs in the band as LSCF fits them (receptance when every output is a motion: shapes are residues of the
// receptance, poles do not depend on the quantity), and the model orders.
struct LscfInput {
  FrfData frf;
  Eigen::VectorXd w;               // rad/s of the lines in the band
  Eigen::MatrixXcd H;              // FRFs at those lines
  double lo = 0, hi = 0, top = 0;  // band; frequency of the highest line in it
  int ni = 0, no = 0, pmin = 0, pmax = 0, step = 1;
};

LscfInput lscf_input(const FrfData& frf_in, const IdentificationOptions& o) {
  LscfInput in;
  bool motion = true;
  for (const Channel& c : frf_in.outputs)
    motion = motion && (c.quantity == Quantity::kDisplacement || c.quantity == Quantity::kVelocity || c.quantity == Quantity::kAcceleration) &&
             c.quantity == frf_in.outputs[0].quantity;
  in.frf = motion ? convert_frf(frf_in, Quantity::kDisplacement) : frf_in;
  const FrfData& frf = in.frf;
  in.lo = std::max(o.band_lo_hz, 0.0);
  in.hi = o.band_hi_hz > 0 ? o.band_hi_hz : frf.frequency_hz[frf.frequency_hz.size() - 1];
  std::vector<Eigen::Index> lines;
  for (Eigen::Index k = 0; k < frf.frequency_hz.size(); ++k)
    if (frf.frequency_hz[k] > 0 && frf.frequency_hz[k] >= in.lo && frf.frequency_hz[k] <= in.hi) lines.push_back(k);
  const Eigen::Index nf = static_cast<Eigen::Index>(lines.size());
  in.ni = frf.num_inputs(), in.no = frf.num_outputs();
  // Orders not given: up to max(10, budget / inputs), the budget kLscfOrders unless lscf_pole_budget gives one
  // (the poles per order grow with the inputs), but no more than the band's lines support (a narrow band of a short
  // record); orders given are kept or refused. Orders to 60 whatever the inputs (1cb0c07, reverted) found more
  // modes of two-hammer tests (identification benchmark, dev impacts: 137 -> 140 of 157) but cost discovery: the
  // bundled frame-null called missing physics in 3 of 40 seeds (a 96 Hz mode 0.6 % off), frame-damage missed 1,
  // and on the discovery benchmark's test recordings it gained 1 case and lost 2 (bench/discovery/README.md).
  in.pmax =
      o.max_order > 0 ? o.max_order : std::max(10, (o.lscf_pole_budget > 0 ? o.lscf_pole_budget : kLscfOrders) / in.ni);
  in.pmin = o.min_order > 0 ? o.min_order : 2;
  if (o.max_order == 0) in.pmax = std::min(in.pmax, static_cast<int>(nf / 2) - 1);
  in.step = o.order_step > 0 ? o.order_step : 1;
  if (nf < 2 * (in.pmax + 1) || in.pmax < std::max(in.pmin + 2, 6))
    throw InputError("LSCF: " + std::to_string(nf) + " frequency lines in the band are too few for order " +
                     std::to_string(std::max(in.pmax, 6)) +
                     ": widen the band or use longer records (finer frequency lines)");
  in.w.resize(nf);
  in.H.resize(nf, frf.H.cols());
  for (Eigen::Index k = 0; k < nf; ++k) {
    in.w[k] = 2 * M_PI * frf.frequency_hz[lines[k]];
    in.H.row(k) = frf.H.row(lines[k]);
  }
  in.top = frf.frequency_hz[lines.back()];
  return in;
}

// Column c = o + i * no of an FRF row (or of a residue row) as the outputs x inputs matrix.
Eigen::MatrixXcd outputs_by_inputs(const Eigen::Ref<const Eigen::RowVectorXcd>& row, int no, int ni) {
  Eigen::MatrixXcd M(no, ni);
  for (int i = 0; i < ni; ++i)
    for (int oo = 0; oo < no; ++oo) M(oo, i) = row[oo + i * no];
  return M;
}

// CMIF: the first singular value of the outputs x inputs FRF matrix at every line.
Eigen::VectorXd cmif(const FrfData& frf) {
  const int ni = frf.num_inputs(), no = frf.num_outputs();
  Eigen::VectorXd out(frf.frequency_hz.size());
  for (Eigen::Index k = 0; k < frf.frequency_hz.size(); ++k) {
    const Eigen::MatrixXcd Hk = outputs_by_inputs(frf.H.row(k), no, ni);
    out[k] = ni == 1 ? Hk.norm() : Eigen::JacobiSVD<Eigen::MatrixXcd>(Hk).singularValues()[0];
  }
  return out;
}

// The reduced normal equations of LSCF at the largest order. Basis z^r on the unit circle, dt = 1 / (2 f_top).
// The blocks are Toeplitz in the degree:
//   R[r, s] = Re c(s - r),  S_o[r, (s, j)] = -Re h_oj(s - r),  T_o[(r, i), (s, j)] = Re g_oij(s - r),
// with c(d) = sum_k z_k^d, h_oj(d) = sum_k H_oj z_k^d, g_oij(d) = sum_k conj(H_oi) H_oj z_k^d, so only their
// 2P - 1 diagonals are summed over the frequency lines (O(nf P) per block instead of O(nf P^2)).
struct LscfNormal {
  double dt = 0;
  Eigen::MatrixXd R;
  std::vector<Eigen::MatrixXd> S, T;
};

LscfNormal lscf_normal_equations(const LscfInput& in) {
  const Eigen::Index nf = in.w.size();
  const int ni = in.ni, no = in.no;
  LscfNormal ne;
  ne.dt = 1.0 / (2 * in.top);
  const int P = in.pmax + 1, D = 2 * P - 1;
  Eigen::MatrixXcd Z(D, nf);  // Z(d + P - 1, k) = z_k^d
  for (Eigen::Index k = 0; k < nf; ++k)
    for (int d = -(P - 1); d <= P - 1; ++d) Z(d + P - 1, k) = std::exp(std::complex<double>(0, in.w[k] * ne.dt * d));
  Eigen::MatrixXcd sums(nf, 1 + no * (ni + ni * ni));  // columns: 1, then per output H_oj and conj(H_oi) H_oj
  sums.col(0).setOnes();
  for (int oo = 0; oo < no; ++oo) {
    // Output o's row of H, weighted by 1 / its RMS so every output counts alike.
    Eigen::MatrixXcd Ho(nf, ni);
    for (int i = 0; i < ni; ++i) Ho.col(i) = in.H.col(oo + i * no);
    const double rms = std::sqrt(Ho.squaredNorm() / static_cast<double>(Ho.size()));
    if (rms > 0) Ho /= rms;
    const int base = 1 + oo * (ni + ni * ni);
    for (int j = 0; j < ni; ++j) sums.col(base + j) = Ho.col(j);
    for (int i = 0; i < ni; ++i)
      for (int j = 0; j < ni; ++j) sums.col(base + ni + i * ni + j) = Ho.col(i).conjugate().cwiseProduct(Ho.col(j));
  }
  const Eigen::MatrixXd diag = (Z * sums).real();  // D x columns
  auto at = [&](int col, int d) { return diag(d + P - 1, col); };
  ne.R.resize(P, P);
  for (int r = 0; r < P; ++r)
    for (int c = 0; c < P; ++c) ne.R(r, c) = at(0, c - r);
  ne.S.assign(static_cast<std::size_t>(no), Eigen::MatrixXd(P, P * ni));
  ne.T.assign(static_cast<std::size_t>(no), Eigen::MatrixXd(P * ni, P * ni));
  for (int oo = 0; oo < no; ++oo) {
    const int base = 1 + oo * (ni + ni * ni);
    for (int r = 0; r < P; ++r)
      for (int c = 0; c < P; ++c)
        for (int j = 0; j < ni; ++j) {
          ne.S[oo](r, c * ni + j) = -at(base + j, c - r);
          for (int i = 0; i < ni; ++i) ne.T[oo](r * ni + i, c * ni + j) = at(base + ni + i * ni + j, c - r);
        }
  }
  return ne;
}

// The poles of every order: the denominator alpha (alpha_p = I) from the reduced normal equations, its
// companion matrix (left eigenvectors of the right fraction: participation vectors), the window's decay removed.
internal::OrderPoles lscf_poles(const LscfInput& in, const LscfNormal& ne, double window_decay) {
  const int ni = in.ni;
  internal::OrderPoles out;
  for (int p = in.pmin; p <= in.pmax; p += in.step) {
    const int q = (p + 1) * ni;
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(q, q);
    const Eigen::LDLT<Eigen::MatrixXd> Rl(ne.R.topLeftCorner(p + 1, p + 1));
    for (int oo = 0; oo < in.no; ++oo) {
      const Eigen::MatrixXd Sp = ne.S[oo].topLeftCorner(p + 1, q);
      M += ne.T[oo].topLeftCorner(q, q) - Sp.transpose() * Rl.solve(Sp);
    }
    const int a = p * ni;
    const Eigen::MatrixXd alpha = -M.topLeftCorner(a, a).ldlt().solve(M.topRightCorner(a, ni));
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(a, a);
    for (int r = 0; r < p; ++r) C.block(0, (p - 1 - r) * ni, ni, ni) = -alpha.block(r * ni, 0, ni, ni).transpose();
    if (p > 1) C.bottomLeftCorner(a - ni, a - ni).setIdentity();
    Eigen::MatrixXd participation = Eigen::MatrixXd::Zero(ni, a);
    participation.rightCols(ni).setIdentity();
    out.poles.push_back(internal::discrete_poles(C, ne.dt, window_decay, participation));
    out.order.push_back(p);
  }
  return out;
}

Eigen::VectorXcd principal(const Eigen::MatrixXcd& Rr) {
  Eigen::JacobiSVD<Eigen::MatrixXcd> svd(Rr, Eigen::ComputeThinU);
  return svd.matrixU().col(0) * svd.singularValues()[0];
}

// A cluster's shape for the evidence checks: the principal vector of its residues from the lines around it,
// fitted together with the poles of the other clusters that get a shape (internal::kShapedShare) in that window.
// When that joint fit leaves the shape complex (MPC below min_mpc) and the fit of its pole alone does not, the
// alone fit's shape: two poles within one peak's width share its lines, and the joint fit can split one mode's
// residue between them at random phase (a close pair the data cannot separate is then judged as a split).
internal::ClusterShape lscf_cluster_shape(const LscfInput& in, const std::vector<internal::PoleCluster>& clusters,
                                          std::size_t c, double window_decay, double resolution_hz, double min_share,
                                          double min_mpc) {
  auto windowed = [&](const internal::PoleCluster& q) {
    return internal::pole_of(q.frequency_hz, q.damping_ratio) - window_decay;
  };
  const internal::PoleCluster& me = clusters[c];
  const double zw = me.damping_ratio + window_decay / (2 * M_PI * me.frequency_hz);
  const std::complex<double> pw = windowed(me);
  const double half_width = std::max(3 * zw * std::abs(pw), 5 * 2 * M_PI * resolution_hz);
  std::vector<std::complex<double>> others;
  for (std::size_t q = 0; q < clusters.size(); ++q)
    if (q != c && clusters[q].support >= min_share &&
        std::abs(2 * M_PI * clusters[q].frequency_hz - pw.imag()) <= half_width)
      others.push_back(windowed(clusters[q]));
  auto shape = [&](const std::vector<std::complex<double>>& with) {
    return principal(outputs_by_inputs(local_residues(in.w, in.H, pw, with, half_width).transpose(), in.no, in.ni));
  };
  internal::ClusterShape cs;
  cs.shape = shape(others);
  if (!others.empty() && modal_phase_collinearity(cs.shape) < min_mpc) {
    const Eigen::VectorXcd alone = shape({});
    if (modal_phase_collinearity(alone) >= min_mpc) cs.shape = alone;
  }
  cs.strength = cs.shape.norm() / std::abs(pw.real());
  return cs;
}

// The FRFs seen through a shape u: |u^H H|^2 / |u|^2 summed over the inputs, at every line.
Eigen::VectorXd projected_frf_power(const FrfData& frf, const Eigen::VectorXcd& u) {
  const int ni = frf.num_inputs(), no = frf.num_outputs();
  const double uu = std::max(u.squaredNorm(), 1e-300);
  Eigen::VectorXd out = Eigen::VectorXd::Zero(frf.frequency_hz.size());
  for (int i = 0; i < ni; ++i) out += (frf.H.middleCols(i * no, no) * u.conjugate()).cwiseAbs2();
  return out / uu;
}

// LSFD at the modes' poles of the windowed data (the window's decay put back): shapes and contributions. The
// poles of rejected clusters stable over the orders (support >= min_support; not splits, whose mode is reported)
// join the fit unreported, each more than a half-power bandwidth from every reported mode and from each other: a
// mode the selection did not report (at a spectral edge, complex, without its own indicator peak) still responds,
// and left out of the fit its response is taken up by the reported poles near it, whose shapes it makes complex.
void lscf_mode_shapes(const LscfInput& in, double window_decay, double min_support, IdentificationSummary& s) {
  if (s.modes.empty()) return;
  std::vector<std::complex<double>> poles;
  std::vector<std::pair<double, double>> taken;  // (frequency, damping) of the poles in the fit
  for (const IdentifiedMode& m : s.modes) {
    poles.push_back(internal::pole_of(m.frequency_hz, m.damping_ratio) - window_decay);
    taken.emplace_back(m.frequency_hz, m.damping_ratio);
  }
  for (const RejectedCluster& r : s.rejected) {
    if (r.reason == Rejection::kSplit || r.reason == Rejection::kFewOrders || r.support < min_support) continue;
    bool apart = true;
    for (const auto& [f, z] : taken)
      apart = apart && std::abs(r.frequency_hz - f) > 2 * std::max(z, r.damping_ratio) * f;
    if (!apart) continue;
    poles.push_back(internal::pole_of(r.frequency_hz, r.damping_ratio) - window_decay);
    taken.emplace_back(r.frequency_hz, r.damping_ratio);
  }
  const Eigen::MatrixXcd res = lsfd(in.w, in.H, poles);
  double top = 0;
  for (std::size_t r = 0; r < s.modes.size(); ++r) {
    const Eigen::MatrixXcd Rr = outputs_by_inputs(res.row(static_cast<Eigen::Index>(r)), in.no, in.ni);
    s.modes[r].shape = principal(Rr);
    finish_shape(s.modes[r]);
    s.modes[r].contribution = Rr.norm() / std::abs(poles[r].real());
    top = std::max(top, s.modes[r].contribution);
  }
  for (IdentifiedMode& m : s.modes) m.contribution = top > 0 ? m.contribution / top : 0;
  mark_twins(s.modes, true);
}

// Removes the modes marked in `drop` from s.modes, listing each in s.rejected with its reason (kSplit: merged
// into `into`), and renumbers the diagram poles' and rejected splits' modes.
void reject_modes(IdentificationSummary& s, const std::vector<Rejection>& why, const std::vector<char>& drop,
                  const std::vector<double>& value, const std::vector<double>& limit, const std::vector<int>& into) {
  std::vector<int> index(s.modes.size(), -1);
  std::vector<IdentifiedMode> kept;
  for (std::size_t k = 0; k < s.modes.size(); ++k)
    if (!drop[k]) index[k] = static_cast<int>(kept.size()), kept.push_back(s.modes[k]);
  for (RejectedCluster& r : s.rejected)
    if (r.merged_into >= 0) r.merged_into = index[static_cast<std::size_t>(r.merged_into)];
  for (std::size_t k = 0; k < s.modes.size(); ++k) {
    if (!drop[k]) continue;
    const IdentifiedMode& m = s.modes[k];
    RejectedCluster rc;
    rc.frequency_hz = m.frequency_hz;
    rc.damping_ratio = m.damping_ratio;
    rc.poles = m.poles;
    rc.support = m.support;
    rc.reason = why[k];
    rc.value = value[k];
    rc.limit = limit[k];
    rc.merged_into = into[k] >= 0 ? index[static_cast<std::size_t>(into[k])] : -1;
    s.rejected.push_back(rc);
  }
  for (StabilizationPole& p : s.poles)
    if (p.cluster >= 0) p.cluster = index[static_cast<std::size_t>(p.cluster)];
  std::stable_sort(s.rejected.begin(), s.rejected.end(),
                   [](const RejectedCluster& a, const RejectedCluster& b) { return a.frequency_hz < b.frequency_hz; });
  s.modes = std::move(kept);
}

// The modes' final shapes (LSFD at all of them together) judged as the clusters' were: a mode whose shape is not
// a normal mode's (MPC below min_mpc) or repeats a stronger mode's (a split, by the rule of the selection, the
// stronger by contribution) is rejected and the others are fitted again without it. The clusters' shapes were
// local; the joint fit may hand a pole that only fits a neighbour's residual error that neighbour's shape.
void lscf_final_modes(const LscfInput& in, const FrfData& frf_in, double window_decay, const IdentificationOptions& o,
                      IdentificationSummary& s) {
  // A mode whose cluster's shape matched a mode the model predicts keeps that shape (and counts as that mode) when
  // the joint fit leaves its shape complex: the cluster's pole is the mode's, the joint residues are not.
  std::vector<double> pre_hz = internal::expected_frequencies(o, s);
  std::vector<Eigen::VectorXcd> pre_shape(s.modes.size());
  for (std::size_t k = 0; k < s.modes.size(); ++k) {
    if (s.modes[k].expected_hz > 0) pre_hz[k] = s.modes[k].expected_hz;
    pre_shape[k] = s.modes[k].shape;
  }
  auto shapes = [&]() {
    lscf_mode_shapes(in, window_decay, o.min_cluster_fraction, s);
    for (std::size_t k = 0; k < s.modes.size(); ++k) {
      IdentifiedMode& m = s.modes[k];
      if (!(pre_hz[k] > 0) || m.mpc >= o.min_mpc) continue;
      if (!(m.expected_hz > 0)) m.expected_hz = pre_hz[k], m.expected_because = Rejection::kComplexShape;
      m.shape = pre_shape[k];
      finish_shape(m);
    }
  };
  for (int pass = 0; pass < 4; ++pass) {
    shapes();
    const std::size_t n = s.modes.size();
    std::vector<char> drop(n, 0);
    std::vector<Rejection> why(n, Rejection::kComplexShape);
    std::vector<double> value(n, 0), limit(n, 0);
    std::vector<int> into(n, -1);
    for (std::size_t k = 0; k < n; ++k)
      if (s.modes[k].mpc < o.min_mpc) drop[k] = 1, value[k] = s.modes[k].mpc, limit[k] = o.min_mpc;
    std::vector<std::size_t> order;
    for (std::size_t k = 0; k < n; ++k)
      if (!drop[k]) order.push_back(k);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return s.modes[a].contribution > s.modes[b].contribution; });
    auto side = [&](std::size_t k) {
      return internal::SplitSide{s.modes[k].frequency_hz, s.modes[k].damping_ratio,
                                 s.modes[k].real_shape.cast<std::complex<double>>()};
    };
    for (std::size_t a = 1; a < order.size(); ++a)
      for (std::size_t b = 0; b < a && !drop[order[a]]; ++b) {
        const std::size_t c = order[a], h = order[b];
        if (drop[h]) continue;
        const Eigen::VectorXd ind = projected_frf_power(frf_in, s.modes[h].shape);
        const double zw = s.modes[h].damping_ratio + window_decay / (2 * M_PI * s.modes[h].frequency_hz);
        const double peak = internal::indicator_evidence(s.frequency_hz, ind, s.modes[h].frequency_hz, zw).peak_db;
        if (internal::is_split(side(c), side(h), peak, s.frequency_hz, ind, o)) {
          drop[c] = 1, why[c] = Rejection::kSplit, into[c] = static_cast<int>(h);
          value[c] = complex_mac(side(c).shape, side(h).shape), limit[c] = o.merge_mac;
        }
      }
    if (std::find(drop.begin(), drop.end(), 1) == drop.end()) return;
    reject_modes(s, why, drop, value, limit, into);
    std::size_t j = 0;
    for (std::size_t k = 0; k < n; ++k)
      if (!drop[k]) pre_hz[j] = pre_hz[k], pre_shape[j] = pre_shape[k], ++j;
    pre_hz.resize(j), pre_shape.resize(j);
  }
  shapes();
}

// ---- SSI-cov stages -------------------------------------------------------------------------------------------

struct SsiSetup {
  std::vector<int> outs;
  int l = 0, dec = 1, nmin = 2, nmax = 80, step = 2, i = 0;  // outputs, decimation, orders, block rows
  double fs = 0, lo = 0, hi = 0, flow = 0;                   // decimated rate, band, lowest frequency of interest
};

SsiSetup ssi_setup(const Recording& rec, const IdentificationOptions& o) {
  SsiSetup u;
  u.outs = rec.output_channels();
  u.l = static_cast<int>(u.outs.size());
  if (u.l < 1) throw InputError("SSI: " + rec.source + " has no output channels");
  const double fs0 = rec.sample_rate_hz;
  u.hi = o.band_hi_hz > 0 ? o.band_hi_hz : 0.4 * fs0;
  if (u.hi > fs0 / 2)
    throw InputError("SSI: the band's top is above the Nyquist frequency " + std::to_string(fs0 / 2) + " Hz");
  u.dec = o.decimate > 0 ? o.decimate : std::max(1, static_cast<int>(std::floor(fs0 / (2.5 * u.hi))));
  u.fs = fs0 / u.dec;
  u.lo = o.band_lo_hz;
  u.nmax = o.max_order > 0 ? o.max_order : 80;
  u.nmin = o.min_order > 0 ? o.min_order : 2;
  u.step = o.order_step > 0 ? o.order_step : 2;
  u.flow = u.lo > 0 ? u.lo : u.fs / 100;
  const int l = u.l;
  u.i =
      o.block_rows > 0 ? o.block_rows : std::max((u.nmax + l - 1) / l + 2, static_cast<int>(std::ceil(u.fs / u.flow)));
  u.i = std::min(u.i, std::max((u.nmax + l - 1) / l + 2, 1500 / l));
  if ((u.i - 1) * l < u.nmax)
    throw InputError("SSI: (block rows - 1) x outputs (" + std::to_string((u.i - 1) * l) +
                     ") must reach the maximum order " + std::to_string(u.nmax) +
                     "; raise the block rows or lower the order");
  return u;
}

// The output channels of every record, each demeaned and decimated.
std::vector<Eigen::MatrixXd> ssi_records(const Recording& rec, const SsiSetup& u) {
  std::vector<Eigen::MatrixXd> out;
  for (const Eigen::MatrixXd& x : rec.records) {
    Eigen::MatrixXd y(x.rows(), u.l);
    for (int c = 0; c < u.l; ++c) y.col(c) = x.col(u.outs[c]).array() - x.col(u.outs[c]).mean();
    y = decimate(y, u.dec);
    if (y.rows() <= 4 * u.i)
      throw InputError("SSI: a record of " + rec.source + " has too few samples (" + std::to_string(y.rows()) +
                       " after decimation) for " + std::to_string(u.i) + " block rows");
    out.push_back(std::move(y));
  }
  return out;
}

// Correlations R_k = E[y_{t+k} y_t^T], k = 0..2i, pooled over records; the block Toeplitz T(a, b) = R_{i + a - b}.
Eigen::MatrixXd ssi_toeplitz(const std::vector<Eigen::MatrixXd>& records, const SsiSetup& u) {
  const int i = u.i, l = u.l;
  std::vector<Eigen::MatrixXd> Rk(static_cast<std::size_t>(2 * i + 1), Eigen::MatrixXd::Zero(l, l));
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(2 * i + 1);
  for (const Eigen::MatrixXd& y : records) {
    const std::vector<Eigen::MatrixXd> r = correlations(y, 2 * i);
    for (int k = 0; k <= 2 * i; ++k) {
      const double n = static_cast<double>(y.rows() - k);
      Rk[k] += n * r[k];
      weight[k] += n;
    }
  }
  for (int k = 0; k <= 2 * i; ++k) Rk[k] /= weight[k];
  Eigen::MatrixXd Tm(i * l, i * l);
  for (int a = 0; a < i; ++a)
    for (int b = 0; b < i; ++b) Tm.block(a * l, b * l, l, l) = Rk[i + a - b];
  return Tm;
}

// The poles of every order: A_n = pinv(O_up) O_down with O = U_n S_n^(1/2); from the leading n x n blocks of
// G = U_up^T U_up and F = U_up^T U_down (computed once at the largest order), A_n = S^-1/2 G_n^-1 F_n S^1/2; the
// shapes C psi with C the first block row of O.
internal::OrderPoles ssi_poles(const Eigen::MatrixXd& Tm, const SsiSetup& u) {
  const int i = u.i, l = u.l;
  Eigen::MatrixXd U;
  Eigen::VectorXd sv;
  leading_svd(Tm, u.nmax, &U, &sv);
  const Eigen::MatrixXd Uq = U.leftCols(u.nmax);
  const Eigen::MatrixXd Gm = Uq.topRows((i - 1) * l).transpose() * Uq.topRows((i - 1) * l);
  const Eigen::MatrixXd Fm = Uq.topRows((i - 1) * l).transpose() * Uq.bottomRows((i - 1) * l);
  internal::OrderPoles out;
  for (int n = u.nmin; n <= u.nmax; n += u.step) {
    const Eigen::VectorXd sq = sv.head(n).cwiseSqrt();
    const Eigen::MatrixXd A = sq.cwiseInverse().asDiagonal() * Gm.topLeftCorner(n, n).ldlt().solve(Fm.topLeftCorner(n, n)) * sq.asDiagonal();
    const Eigen::MatrixXd C = Uq.topRows(l).leftCols(n) * sq.asDiagonal();
    out.poles.push_back(internal::discrete_poles(A, 1.0 / u.fs, 0.0, C));
    out.order.push_back(n);
  }
  return out;
}

// Background and mode indicator: the first singular value of the output cross-spectral matrix (Welch, the
// plan's resolution when given, else segments of 8 periods of the lowest frequency of interest).
CrossSpectra output_spectrum_indicator(const std::vector<Eigen::MatrixXd>& records, const SsiSetup& u,
                                       const IdentificationOptions& o, IdentificationSummary& s) {
  WelchOptions wo;
  int seg = 8;
  const Eigen::Index shortest = std::min_element(records.begin(), records.end(), [](const auto& a, const auto& b) {
                                  return a.rows() < b.rows();
                                })->rows();
  if (o.segment > 0) {  // the plan's resolution, in decimated samples
    while (seg * 2 <= shortest && seg * 2 <= o.segment / u.dec) seg *= 2;
  } else {
    while (seg * 2 <= shortest && seg < 8 * u.fs / u.flow && seg < (1 << 16)) seg *= 2;
  }
  wo.segment = seg;
  const CrossSpectra G = welch(records, u.fs, wo);
  s.frequency_hz = G.frequency;
  s.resolution_hz = u.fs / seg;
  s.background.resize(G.frequency.size());
  for (Eigen::Index k = 0; k < G.frequency.size(); ++k)
    s.background[k] = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXcd>(G.G[k], Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  s.background_label = "first singular value of the output spectral matrix";
  return G;
}

// The output spectral matrix seen through a shape u: u^H G u / |u|^2 at every line.
Eigen::VectorXd projected_spectrum(const CrossSpectra& G, const Eigen::VectorXcd& u) {
  const double uu = std::max(u.squaredNorm(), 1e-300);
  Eigen::VectorXd out(G.frequency.size());
  for (Eigen::Index k = 0; k < G.frequency.size(); ++k)
    out[k] = std::max(u.dot(G.G[static_cast<std::size_t>(k)] * u).real(), 0.0) / uu;
  return out;
}

// A cluster's shape: the weighted mean of its poles' shapes, each turned to the strongest member's phase.
Eigen::VectorXcd ssi_cluster_shape(const internal::OrderPoles& op, const internal::PoleCluster& pc) {
  const std::size_t top = static_cast<std::size_t>(std::max_element(pc.member_weight.begin(), pc.member_weight.end()) -
                                                   pc.member_weight.begin());
  const Eigen::VectorXcd ref = op.poles[pc.members[top].first][pc.members[top].second].vec.normalized();
  Eigen::VectorXcd sum = Eigen::VectorXcd::Zero(ref.size());
  for (std::size_t m = 0; m < pc.members.size(); ++m) {
    Eigen::VectorXcd v = op.poles[pc.members[m].first][pc.members[m].second].vec.normalized();
    const std::complex<double> d = ref.dot(v);  // conj(ref) . v
    if (std::abs(d) > 0) v *= std::conj(d) / std::abs(d);
    sum += pc.member_weight[m] * v;
  }
  return sum;
}

// Sub-bands of a wide band (identify.hpp, identify_lscf / identify_ssi): from the top down, each [hi / kSubBandSpan,
// hi], owning [hi / 8, hi / 2] (the top one everything above hi / 8, the lowest everything below), the next one's top a
// quarter of this one's; the lowest reaches down to `flow`.
constexpr double kSubBandSpan = 16;
struct SubBand {
  double lo = 0, hi = 0, own_lo = 0, own_hi = 0;
};
std::vector<SubBand> sub_bands(double flow, double hi) {
  std::vector<SubBand> out;
  if (hi / flow <= kSubBandSpan) return {{flow, hi, 0, 1e300}};
  for (double top = hi;; top /= 4) {
    SubBand b{top / kSubBandSpan, top, top / 8, out.empty() ? 1e300 : top / 2};
    if (b.lo <= 2 * flow) {
      b.lo = std::min(b.lo, flow);
      b.own_lo = 0;
      out.push_back(b);
      break;
    }
    out.push_back(b);
  }
  return out;
}

// Adds the modes, rejected clusters and diagram poles of a sub-band's summary t in [a, b) to s.
void merge_sub_band(IdentificationSummary& s, const IdentificationSummary& t, double a, double b) {
  std::vector<int> index(t.modes.size(), -1);
  for (std::size_t k = 0; k < t.modes.size(); ++k)
    if (t.modes[k].frequency_hz >= a && t.modes[k].frequency_hz < b) {
      index[k] = static_cast<int>(s.modes.size());
      s.modes.push_back(t.modes[k]);
    }
  for (const RejectedCluster& r : t.rejected)
    if (r.frequency_hz >= a && r.frequency_hz < b) {
      s.rejected.push_back(r);
      if (r.merged_into >= 0) s.rejected.back().merged_into = index[static_cast<std::size_t>(r.merged_into)];
    }
  for (const StabilizationPole& p : t.poles)
    if (p.frequency_hz >= a && p.frequency_hz < b) {
      s.poles.push_back(p);
      if (p.cluster >= 0) s.poles.back().cluster = index[static_cast<std::size_t>(p.cluster)];
    }
}

// The merged modes in ascending frequency (the rejected splits' and the diagram poles' mode indices renumbered),
// the rejected clusters too, and a note of the sub-bands.
void sort_merged(IdentificationSummary& s, std::size_t bands, double flow, double hi, const char* label,
                 const char* how) {
  auto by_f = [](const auto& x, const auto& y) { return x.frequency_hz < y.frequency_hz; };
  std::vector<std::size_t> order(s.modes.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return by_f(s.modes[x], s.modes[y]); });
  std::vector<int> rank(order.size());
  std::vector<IdentifiedMode> modes;
  for (std::size_t k = 0; k < order.size(); ++k)
    rank[order[k]] = static_cast<int>(k), modes.push_back(s.modes[order[k]]);
  s.modes = std::move(modes);
  for (RejectedCluster& r : s.rejected)
    if (r.merged_into >= 0) r.merged_into = rank[static_cast<std::size_t>(r.merged_into)];
  for (StabilizationPole& p : s.poles)
    if (p.cluster >= 0) p.cluster = rank[static_cast<std::size_t>(p.cluster)];
  std::stable_sort(s.rejected.begin(), s.rejected.end(), by_f);
  if (bands < 2) return;
  char b[200];
  std::snprintf(b, sizeof b, "%s in %zu sub-bands (each 1:%g%s): the band %.4g-%.4g Hz spans 1:%.0f", label, bands,
                kSubBandSpan, how, flow, hi, hi / flow);
  s.notes.push_back(b);
}

// The summary's fields for LSCF over in's band; `background` is the CMIF of all the data (cmif(frf_in)), computed
// once for the whole band and its sub-bands.
IdentificationSummary lscf_head(const FrfData& frf_in, const LscfInput& in, const Eigen::VectorXd& background) {
  IdentificationSummary s;
  s.method = "lscf";
  for (const Channel& c : in.frf.outputs) s.dofs.push_back(c.dof);
  s.min_order = in.pmin;
  s.max_order = in.pmax;
  s.window_decay_removed = in.frf.window_decay;
  s.band_lo_hz = in.lo;
  s.band_hi_hz = in.hi;
  const Eigen::Index nl = frf_in.frequency_hz.size();
  s.resolution_hz = nl > 1 ? (frf_in.frequency_hz[nl - 1] - frf_in.frequency_hz[0]) / static_cast<double>(nl - 1) : 0;
  s.frequency_hz = frf_in.frequency_hz;
  s.background = background;
  s.background_label = "CMIF (first singular value of the FRFs)";
  return s;
}

// The poles of in's band and their selection on the CMIF's power (the windowed data's peaks are wider by the
// window's decay); the modes' shapes are the clusters' until lscf_final_modes.
void lscf_select(const FrfData& frf_in, const LscfInput& in, const IdentificationOptions& o, IdentificationSummary& s) {
  const double decay = in.frf.window_decay;
  const internal::OrderPoles poles = lscf_poles(in, lscf_normal_equations(in), decay);
  internal::select_modes(
      poles, in.lo, in.hi, o, s.background.cwiseAbs2(), decay,
      [&](const std::vector<internal::PoleCluster>& all, std::size_t c) {
        return lscf_cluster_shape(in, all, c, decay, s.resolution_hz, internal::kShapedShare * o.min_cluster_fraction,
                                  o.min_mpc);
      },
      [&](const Eigen::VectorXcd& u) { return projected_frf_power(frf_in, u); }, s);
}

// The FRFs without the references that excite nothing: an input whose FRF power is below kDeadPower of the
// strongest input's (-120 dB, beyond any acquisition's dynamic range) carries no information, and its numerically zero
// columns leave LSCF's poly-reference normal equations rank-deficient (the denominator's block for that input
// undetermined, no pole stable over the orders). One note per reference left out. (An output channel that sees nothing
// keeps its unit-RMS weight: on the identification benchmark's dev seeds, weighting such channels 0 changed one
// marginal mode, found -> missed.) None when every reference is live (the caller keeps the FRFs it has).
constexpr double kDeadPower = 1e-12;

std::optional<FrfData> live_references(const FrfData& frf, std::vector<std::string>& notes) {
  const int ni = frf.num_inputs(), no = frf.num_outputs();
  Eigen::VectorXd power(ni);
  for (int i = 0; i < ni; ++i) power[i] = frf.H.middleCols(i * no, no).squaredNorm();
  const double top = ni > 0 ? power.maxCoeff() : 0;
  std::vector<int> keep;
  for (int i = 0; i < ni; ++i) {
    if (!(top > 0) || power[i] >= kDeadPower * top) {
      keep.push_back(i);
      continue;
    }
    char b[240];
    std::snprintf(b, sizeof b,
                  "reference %s left out: its FRFs are %.0f dB below the strongest reference's (it excites nothing "
                  "the sensors record, e.g. a hit on a support)",
                  to_string(frf.inputs[static_cast<std::size_t>(i)].dof).c_str(),
                  power[i] > 0 ? 10 * std::log10(top / power[i]) : 300.0);
    notes.push_back(b);
  }
  if (static_cast<int>(keep.size()) == ni) return std::nullopt;
  FrfData live;
  live.frequency_hz = frf.frequency_hz;
  live.outputs = frf.outputs;
  live.window_decay = frf.window_decay;
  live.source = frf.source;
  live.H.resize(frf.H.rows(), no * static_cast<Eigen::Index>(keep.size()));
  if (frf.coherence.size() > 0) live.coherence.resize(frf.coherence.rows(), live.H.cols());
  for (std::size_t j = 0; j < keep.size(); ++j) {
    const Eigen::Index from = keep[j] * no, to = static_cast<Eigen::Index>(j) * no;
    live.inputs.push_back(frf.inputs[static_cast<std::size_t>(keep[j])]);
    live.H.middleCols(to, no) = frf.H.middleCols(from, no);
    if (frf.coherence.size() > 0) live.coherence.middleCols(to, no) = frf.coherence.middleCols(from, no);
  }
  return live;
}

}  // namespace

IdentificationSummary identify_lscf(const FrfData& frf_all, const IdentificationOptions& o) {
  const auto t0 = checked_start(o, frf_all, "LSCF: ");
  std::vector<std::string> dropped;
  const std::optional<FrfData> live = live_references(frf_all, dropped);
  const FrfData& frf_in = live ? *live : frf_all;
  const LscfInput in = lscf_input(frf_in, o);
  const Eigen::VectorXd background = cmif(frf_in);
  IdentificationSummary s = lscf_head(frf_in, in, background);
  // A wide band with automatic orders: poles and selection per sub-band (the lowest modes of a wide band need
  // orders the strongest ones take), every sub-band giving the modes it owns; then LSFD over the whole band at
  // all of them. A sub-band too narrow for its orders (too few lines) leaves the whole band to one fit.
  // Lines below the band (lscf_fit_below) fix its lowest modes; the lowest sub-band then owns them from in.lo up.
  const bool automatic = o.max_order == 0 && in.lo > 0;
  const double below = automatic && o.lscf_fit_below > 0 ? std::clamp(o.lscf_fit_below, 0.1, 1.0) : 1.0;
  std::vector<SubBand> bands =
      automatic ? sub_bands(below * in.lo, in.hi) : std::vector<SubBand>{{in.lo, in.hi, 0, 1e300}};
  if (below < 1) bands.back().own_lo = in.lo;
  bool whole = bands.size() == 1 && below == 1;
  if (!whole) {
    try {
      for (const SubBand& b : bands) {
        IdentificationOptions ob = o;
        ob.band_lo_hz = b.lo;
        ob.band_hi_hz = b.hi;
        const LscfInput ib = lscf_input(frf_in, ob);
        IdentificationSummary t = lscf_head(frf_in, ib, background);
        lscf_select(frf_in, ib, ob, t);
        merge_sub_band(s, t, b.own_lo, b.own_hi);
      }
      sort_merged(s, bands.size(), in.lo, in.hi, "LSCF", "");
      if (below < 1) {
        char b[200];
        std::snprintf(b, sizeof b,
                      "LSCF fitted from %.4g Hz, at most %.2g of the band's bottom (its lowest modes need lines below "
                      "them); modes reported from %.4g Hz",
                      bands.back().lo, below, in.lo);
        s.notes.push_back(b);
      }
    } catch (const InputError&) {
      s = lscf_head(frf_in, in, background);
      whole = true;
    }
  }
  if (whole) lscf_select(frf_in, in, o, s);
  lscf_final_modes(in, frf_in, in.frf.window_decay, o, s);
  s.notes.insert(s.notes.begin(), dropped.begin(), dropped.end());
  s.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return s;
}

namespace {

// SSI-cov over one band (the options' band; decimation and block rows from it).
IdentificationSummary identify_ssi_band(const Recording& rec, const IdentificationOptions& o) {
  const SsiSetup u = ssi_setup(rec, o);
  IdentificationSummary s;
  s.method = "ssi";
  for (int c : u.outs) s.dofs.push_back(rec.channels[c].dof);
  s.min_order = u.nmin;
  s.max_order = u.nmax;
  s.band_lo_hz = u.lo;
  s.band_hi_hz = u.hi;
  const std::vector<Eigen::MatrixXd> records = ssi_records(rec, u);
  const internal::OrderPoles poles = ssi_poles(ssi_toeplitz(records, u), u);
  const CrossSpectra G = output_spectrum_indicator(records, u, o, s);
  internal::select_modes(
      poles, u.lo, u.hi, o, s.background, 0.0,
      [&](const std::vector<internal::PoleCluster>& all, std::size_t c) {
        return internal::ClusterShape{ssi_cluster_shape(poles, all[c]), -1.0};
      },
      [&](const Eigen::VectorXcd& shape) { return projected_spectrum(G, shape); }, s);
  for (IdentifiedMode& m : s.modes) finish_shape(m);
  return s;
}

}  // namespace

IdentificationSummary identify_ssi(const Recording& rec, const IdentificationOptions& o) {
  const auto t0 = checked_start(o, rec, "SSI: ");
  const SsiSetup u = ssi_setup(rec, o);
  const std::vector<SubBand> bands =
      o.decimate == 0 && o.block_rows == 0 ? sub_bands(u.flow, u.hi) : std::vector<SubBand>{{u.lo, u.hi, 0, 1e300}};
  IdentificationSummary s;
  if (bands.size() == 1) {
    s = identify_ssi_band(rec, o);
  } else {
    // The top sub-band's summary carries the background; every sub-band gives the modes it owns.
    for (std::size_t k = 0; k < bands.size(); ++k) {
      IdentificationOptions ok = o;
      ok.band_lo_hz = bands[k].lo;
      ok.band_hi_hz = bands[k].hi;
      IdentificationSummary t = identify_ssi_band(rec, ok);
      if (k == 0) {
        s = t;
        s.modes.clear(), s.rejected.clear(), s.poles.clear();
        s.band_lo_hz = u.lo;
      }
      merge_sub_band(s, t, bands[k].own_lo, bands[k].own_hi);
    }
    sort_merged(s, bands.size(), u.flow, u.hi, "SSI", ", decimated to its top");
  }
  mark_twins(s.modes, false);
  s.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return s;
}

}  // namespace dynid
