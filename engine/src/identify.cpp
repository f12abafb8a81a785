#include "dynid/engine/identify.hpp"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>

#include "dynid/engine/frf.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/signal.hpp"
#include "internal/identify_select.hpp"

namespace dynid {

using internal::complex_mac;
using internal::Candidate;
using internal::PoleCluster;
using internal::RawPole;

namespace {
constexpr double kPi = 3.14159265358979323846;
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

// Residues of every FRF column at one pole from the lines around it alone (a local LSFD: the pole's pair and a
// complex constant plus slope for everything else). For judging a cluster: near-duplicate poles of one mode do
// not share (and scramble) one residue as they would in a joint fit. Returns one residue per column.
Eigen::VectorXcd local_residues(const Eigen::VectorXd& w, const Eigen::MatrixXcd& H, std::complex<double> pole, double half_width) {
  const Eigen::Index nf = w.size();
  const double wr = pole.imag();
  Eigen::Index a = std::lower_bound(w.data(), w.data() + nf, wr - half_width) - w.data();
  Eigen::Index b = std::upper_bound(w.data(), w.data() + nf, wr + half_width) - w.data();
  while (b - a < 8 && (a > 0 || b < nf)) {
    if (a > 0) --a;
    if (b < nf) ++b;
  }
  const Eigen::Index n = b - a;
  const std::complex<double> I(0, 1);
  Eigen::MatrixXcd B(n, 6);
  for (Eigen::Index k = 0; k < n; ++k) {
    const std::complex<double> sk = I * w[a + k], p = 1.0 / (sk - pole), q = 1.0 / (sk - std::conj(pole));
    const double x = (w[a + k] - wr) / std::max(half_width, 1e-300);
    B.row(k) << p + q, I * p - I * q, 1.0, I, x, I * x;
  }
  Eigen::MatrixXd A(2 * n, 6), rhs(2 * n, H.cols());
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

void check_band(const IdentificationOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("identification: " + why);
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
  if (!(stable_frequency > 0 && stable_damping > 0 && stable_mac > 0 && stable_mac <= 1)) return fail("stability tolerances must be > 0 (MAC <= 1)");
  if (!(max_damping > 0 && max_damping < 1)) return fail("the damping limit must be in (0, 1)");
  if (!(cluster_damping > 0)) return fail("the cluster damping tolerance must be > 0");
  if (!(min_cluster_fraction > 0 && min_cluster_fraction <= 1)) return fail("the cluster fraction must be in (0, 1]");
  if (!(cluster_tolerance > 0 && cluster_tolerance < 0.5)) return fail("the cluster tolerance must be in (0, 0.5)");
  if (block_rows < 0 || decimate < 0) return fail("block rows and decimation must be >= 0");
  if (!(min_mpc >= 0 && min_mpc <= 1)) return fail("the MPC limit must be in [0, 1]");
  if (!std::isfinite(min_peak_db) || !(max_edge_db > 0)) return fail("the indicator peak limit must be finite and the edge limit > 0 dB");
  if (!(merge_tolerance >= 0 && merge_tolerance < 0.5) || !(merge_mac > 0 && merge_mac <= 1))
    return fail("the merge tolerance must be in [0, 0.5) and the merge MAC in (0, 1]");
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
    if (uncertainty_halves > 0) d.shape_std[k] = m.shape_std;
    d.shapes.col(k) = m.real_shape;
  }
  return d;
}

IdentificationSummary identify_lscf(const FrfData& frf_in, const IdentificationOptions& o) {
  check_band(o);
  const auto t0 = Clock::now();
  frf_in.validate("LSCF: " + frf_in.source);
  // Shapes are residues of the receptance; poles do not depend on the quantity.
  bool motion = true;
  for (const Channel& c : frf_in.outputs)
    motion = motion && (c.quantity == Quantity::kDisplacement || c.quantity == Quantity::kVelocity || c.quantity == Quantity::kAcceleration) &&
             c.quantity == frf_in.outputs[0].quantity;
  const FrfData frf = motion ? convert_frf(frf_in, Quantity::kDisplacement) : frf_in;
  const double lo = std::max(o.band_lo_hz, 0.0), hi = o.band_hi_hz > 0 ? o.band_hi_hz : frf.frequency_hz[frf.frequency_hz.size() - 1];
  std::vector<Eigen::Index> lines;
  for (Eigen::Index k = 0; k < frf.frequency_hz.size(); ++k)
    if (frf.frequency_hz[k] > 0 && frf.frequency_hz[k] >= lo && frf.frequency_hz[k] <= hi) lines.push_back(k);
  const Eigen::Index nf = static_cast<Eigen::Index>(lines.size());
  const int ni = frf.num_inputs(), no = frf.num_outputs();
  // Orders not given: up to 60 / inputs, but no more than the band's lines support (a narrow band of a short
  // record); orders given are kept or refused.
  int pmax = o.max_order > 0 ? o.max_order : std::max(10, 60 / ni);
  const int pmin = o.min_order > 0 ? o.min_order : 2;
  if (o.max_order == 0) pmax = std::min(pmax, static_cast<int>(nf / 2) - 1);
  const int step = o.order_step > 0 ? o.order_step : 1;
  if (nf < 2 * (pmax + 1) || pmax < std::max(pmin + 2, 6))
    throw InputError("LSCF: " + std::to_string(nf) + " frequency lines in the band are too few for order " + std::to_string(std::max(pmax, 6)) +
                     ": widen the band or use longer records (finer frequency lines)");

  IdentificationSummary s;
  s.method = "lscf";
  for (const Channel& c : frf.outputs) s.dofs.push_back(c.dof);
  s.min_order = pmin;
  s.max_order = pmax;
  s.window_decay_removed = frf.window_decay;
  Eigen::VectorXd w(nf);
  Eigen::MatrixXcd H(nf, frf.H.cols());
  for (Eigen::Index k = 0; k < nf; ++k) {
    w[k] = 2 * kPi * frf.frequency_hz[lines[k]];
    H.row(k) = frf.H.row(lines[k]);
  }
  s.band_lo_hz = lo;
  s.band_hi_hz = hi;
  s.resolution_hz = frf_in.frequency_hz.size() > 1 ? (frf_in.frequency_hz[frf_in.frequency_hz.size() - 1] - frf_in.frequency_hz[0]) / static_cast<double>(frf_in.frequency_hz.size() - 1) : 0;
  // CMIF: the first singular value of the outputs x inputs FRF matrix at every line.
  s.frequency_hz = frf_in.frequency_hz;
  s.background.resize(frf_in.frequency_hz.size());
  for (Eigen::Index k = 0; k < frf_in.frequency_hz.size(); ++k) {
    Eigen::MatrixXcd Hk(no, ni);
    for (int i = 0; i < ni; ++i)
      for (int oo = 0; oo < no; ++oo) Hk(oo, i) = frf_in.H(k, oo + i * no);
    s.background[k] = ni == 1 ? Hk.norm() : Eigen::JacobiSVD<Eigen::MatrixXcd>(Hk).singularValues()[0];
  }
  s.background_label = "CMIF (first singular value of the FRFs)";

  // Basis z^r on the unit circle, dt = 1 / (2 f_top). The normal-equation blocks are Toeplitz in the degree:
  //   R[r, s] = Re c(s - r),  S_o[r, (s, j)] = -Re h_oj(s - r),  T_o[(r, i), (s, j)] = Re g_oij(s - r),
  // with c(d) = sum_k z_k^d, h_oj(d) = sum_k H_oj z_k^d, g_oij(d) = sum_k conj(H_oi) H_oj z_k^d, so only their
  // 2P - 1 diagonals are summed over the frequency lines (O(nf P) per block instead of O(nf P^2)).
  const double dt = 1.0 / (2 * frf.frequency_hz[lines.back()]);
  const int P = pmax + 1, D = 2 * P - 1;
  Eigen::MatrixXcd Z(D, nf);  // Z(d + P - 1, k) = z_k^d
  for (Eigen::Index k = 0; k < nf; ++k)
    for (int d = -(P - 1); d <= P - 1; ++d) Z(d + P - 1, k) = std::exp(std::complex<double>(0, w[k] * dt * d));
  Eigen::MatrixXcd sums(nf, 1 + no * (ni + ni * ni));  // columns: 1, then per output H_oj and conj(H_oi) H_oj
  sums.col(0).setOnes();
  for (int oo = 0; oo < no; ++oo) {
    // Output o's row of H, weighted by 1 / its RMS so every output counts alike.
    Eigen::MatrixXcd Ho(nf, ni);
    for (int i = 0; i < ni; ++i) Ho.col(i) = H.col(oo + i * no);
    const double rms = std::sqrt(Ho.squaredNorm() / static_cast<double>(Ho.size()));
    if (rms > 0) Ho /= rms;
    const int base = 1 + oo * (ni + ni * ni);
    for (int j = 0; j < ni; ++j) sums.col(base + j) = Ho.col(j);
    for (int i = 0; i < ni; ++i)
      for (int j = 0; j < ni; ++j) sums.col(base + ni + i * ni + j) = Ho.col(i).conjugate().cwiseProduct(Ho.col(j));
  }
  const Eigen::MatrixXd diag = (Z * sums).real();  // D x columns
  auto at = [&](int col, int d) { return diag(d + P - 1, col); };
  Eigen::MatrixXd R(P, P);
  for (int r = 0; r < P; ++r)
    for (int c = 0; c < P; ++c) R(r, c) = at(0, c - r);
  std::vector<Eigen::MatrixXd> S(static_cast<std::size_t>(no), Eigen::MatrixXd(P, P * ni)), T(static_cast<std::size_t>(no), Eigen::MatrixXd(P * ni, P * ni));
  for (int oo = 0; oo < no; ++oo) {
    const int base = 1 + oo * (ni + ni * ni);
    for (int r = 0; r < P; ++r)
      for (int c = 0; c < P; ++c)
        for (int j = 0; j < ni; ++j) {
          S[oo](r, c * ni + j) = -at(base + j, c - r);
          for (int i = 0; i < ni; ++i) T[oo](r * ni + i, c * ni + j) = at(base + ni + i * ni + j, c - r);
        }
  }
  std::vector<std::vector<RawPole>> orders;
  std::vector<int> order_of;
  for (int p = pmin; p <= pmax; p += step) {
    const int q = (p + 1) * ni;
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(q, q);
    const Eigen::LDLT<Eigen::MatrixXd> Rl(R.topLeftCorner(p + 1, p + 1));
    for (int oo = 0; oo < no; ++oo) {
      const Eigen::MatrixXd Sp = S[oo].topLeftCorner(p + 1, q);
      M += T[oo].topLeftCorner(q, q) - Sp.transpose() * Rl.solve(Sp);
    }
    // alpha_p = I: alpha_{0..p-1} = -Maa^-1 Mab.
    const int a = p * ni;
    const Eigen::MatrixXd alpha = -M.topLeftCorner(a, a).ldlt().solve(M.topRightCorner(a, ni));
    // Companion matrix of sum_r alpha_r^T z^r (left eigenvectors of the right fraction: participation).
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(a, a);
    for (int r = 0; r < p; ++r) C.block(0, (p - 1 - r) * ni, ni, ni) = -alpha.block(r * ni, 0, ni, ni).transpose();
    if (p > 1) C.bottomLeftCorner(a - ni, a - ni).setIdentity();
    Eigen::EigenSolver<Eigen::MatrixXd> es(C);
    std::vector<RawPole> poles;
    if (es.info() == Eigen::Success)
      for (int k = 0; k < a; ++k) {
        const std::complex<double> z = es.eigenvalues()[k];
        if (z.imag() <= 0 || std::abs(z) == 0) continue;
        RawPole rp;
        rp.lambda = std::log(z) / dt + frf.window_decay;
        rp.vec = es.eigenvectors().col(k).tail(ni);
        poles.push_back(rp);
      }
    orders.push_back(std::move(poles));
    order_of.push_back(p);
  }
  // Selection: clusters, shapes of those with support (LSFD at all of them), evidence, then LSFD at the modes.
  const std::vector<PoleCluster> clusters = internal::stabilize_and_cluster(orders, order_of, lo, hi, o, s);
  auto residues = [&](const std::vector<std::complex<double>>& poles) {
    // Per pole, the outputs x inputs residue matrix of the receptance.
    std::vector<Eigen::MatrixXcd> out;
    if (poles.empty()) return out;
    const Eigen::MatrixXcd res = lsfd(w, H, poles);
    for (std::size_t r = 0; r < poles.size(); ++r) {
      Eigen::MatrixXcd Rr(no, ni);
      for (int i = 0; i < ni; ++i)
        for (int oo = 0; oo < no; ++oo) Rr(oo, i) = res(static_cast<Eigen::Index>(r), oo + i * no);
      out.push_back(Rr);
    }
    return out;
  };
  auto principal = [](const Eigen::MatrixXcd& Rr) -> Eigen::VectorXcd {
    Eigen::JacobiSVD<Eigen::MatrixXcd> svd(Rr, Eigen::ComputeThinU);
    return svd.matrixU().col(0) * svd.singularValues()[0];
  };
  std::vector<Candidate> cands(clusters.size());
  std::vector<internal::IndicatorEvidence> peak(clusters.size());
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    cands[c].cluster = clusters[c];
    cands[c].strength = clusters[c].support;
    // The windowed data's peaks are wider by the window's decay.
    const double zw = clusters[c].damping_ratio + frf.window_decay / (2 * kPi * clusters[c].frequency_hz);
    peak[c] = internal::indicator_evidence(s.frequency_hz, s.background.cwiseAbs2(), clusters[c].frequency_hz, zw);
    if (clusters[c].support < internal::kShapedShare * o.min_cluster_fraction) continue;
    const std::complex<double> pw = internal::pole_of(clusters[c].frequency_hz, clusters[c].damping_ratio) - frf.window_decay;
    const Eigen::VectorXcd R = local_residues(w, H, pw, std::max(3 * zw * std::abs(pw), 5 * 2 * kPi * s.resolution_hz));
    Eigen::MatrixXcd Rr(no, ni);
    for (int i = 0; i < ni; ++i)
      for (int oo = 0; oo < no; ++oo) Rr(oo, i) = R[oo + i * no];
    cands[c].shape = principal(Rr);
  }
  internal::make_modes(cands, peak, internal::check_evidence(cands, peak, o, orders.size(), s), orders.size(), s);
  if (!s.modes.empty()) {
    // LSFD at the modes' poles of the windowed data (the window's decay put back).
    std::vector<std::complex<double>> poles;
    for (const IdentifiedMode& m : s.modes) poles.push_back(internal::pole_of(m.frequency_hz, m.damping_ratio) - frf.window_decay);
    const std::vector<Eigen::MatrixXcd> res = residues(poles);
    double top = 0;
    for (std::size_t r = 0; r < s.modes.size(); ++r) {
      s.modes[r].shape = principal(res[r]);
      finish_shape(s.modes[r]);
      s.modes[r].contribution = res[r].norm() / std::abs(poles[r].real());
      top = std::max(top, s.modes[r].contribution);
    }
    for (IdentifiedMode& m : s.modes) m.contribution = top > 0 ? m.contribution / top : 0;
    mark_twins(s.modes, true);
  }
  s.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return s;
}

IdentificationSummary identify_ssi(const Recording& rec, const IdentificationOptions& o) {
  check_band(o);
  const auto t0 = Clock::now();
  rec.validate("SSI: " + rec.source);
  const std::vector<int> outs = rec.output_channels();
  const int l = static_cast<int>(outs.size());
  if (l < 1) throw InputError("SSI: " + rec.source + " has no output channels");
  const double fs0 = rec.sample_rate_hz;
  const double hi = o.band_hi_hz > 0 ? o.band_hi_hz : 0.4 * fs0;
  if (hi > fs0 / 2) throw InputError("SSI: the band's top is above the Nyquist frequency " + std::to_string(fs0 / 2) + " Hz");
  const int dec = o.decimate > 0 ? o.decimate : std::max(1, static_cast<int>(std::floor(fs0 / (2.5 * hi))));
  const double fs = fs0 / dec;
  const double lo = o.band_lo_hz;
  const int nmax = o.max_order > 0 ? o.max_order : 80;
  const int nmin = o.min_order > 0 ? o.min_order : 2;
  const int step = o.order_step > 0 ? o.order_step : 2;
  const double flow = lo > 0 ? lo : fs / 100;
  int i = o.block_rows > 0 ? o.block_rows : std::max((nmax + l - 1) / l + 2, static_cast<int>(std::ceil(fs / flow)));
  i = std::min(i, std::max((nmax + l - 1) / l + 2, 1500 / l));
  if ((i - 1) * l < nmax)
    throw InputError("SSI: (block rows - 1) x outputs (" + std::to_string((i - 1) * l) + ") must reach the maximum order " + std::to_string(nmax) +
                     "; raise the block rows or lower the order");

  IdentificationSummary s;
  s.method = "ssi";
  for (int c : outs) s.dofs.push_back(rec.channels[c].dof);
  s.min_order = nmin;
  s.max_order = nmax;

  // Correlations R_k = E[y_{t+k} y_t^T], k = 0..2i, pooled over records (each demeaned, decimated).
  std::vector<Eigen::MatrixXd> Rk(static_cast<std::size_t>(2 * i + 1), Eigen::MatrixXd::Zero(l, l));
  Eigen::VectorXd weight = Eigen::VectorXd::Zero(2 * i + 1);
  std::vector<Eigen::MatrixXd> decimated;
  for (const Eigen::MatrixXd& x : rec.records) {
    Eigen::MatrixXd y(x.rows(), l);
    for (int c = 0; c < l; ++c) y.col(c) = x.col(outs[c]).array() - x.col(outs[c]).mean();
    y = decimate(y, dec);
    if (y.rows() <= 4 * i) throw InputError("SSI: a record of " + rec.source + " has too few samples (" + std::to_string(y.rows()) + " after decimation) for " + std::to_string(i) + " block rows");
    const std::vector<Eigen::MatrixXd> r = correlations(y, 2 * i);
    for (int k = 0; k <= 2 * i; ++k) {
      const double n = static_cast<double>(y.rows() - k);
      Rk[k] += n * r[k];
      weight[k] += n;
    }
    decimated.push_back(std::move(y));
  }
  for (int k = 0; k <= 2 * i; ++k) Rk[k] /= weight[k];
  // Block Toeplitz T(a, b) = R_{i + a - b}, a, b = 0..i-1.
  Eigen::MatrixXd Tm(i * l, i * l);
  for (int a = 0; a < i; ++a)
    for (int b = 0; b < i; ++b) Tm.block(a * l, b * l, l, l) = Rk[i + a - b];
  Eigen::MatrixXd U;
  Eigen::VectorXd sv;
  leading_svd(Tm, nmax, &U, &sv);
  // A_n = pinv(O_up) O_down with O = U_n S_n^(1/2): from the leading n x n blocks of G = U_up^T U_up and
  // F = U_up^T U_down (computed once at the largest order), A_n = S^-1/2 G_n^-1 F_n S^1/2.
  const Eigen::MatrixXd Uq = U.leftCols(nmax);
  const Eigen::MatrixXd Gm = Uq.topRows((i - 1) * l).transpose() * Uq.topRows((i - 1) * l);
  const Eigen::MatrixXd Fm = Uq.topRows((i - 1) * l).transpose() * Uq.bottomRows((i - 1) * l);
  std::vector<std::vector<RawPole>> orders;
  std::vector<int> order_of;
  for (int n = nmin; n <= nmax; n += step) {
    const Eigen::VectorXd sq = sv.head(n).cwiseSqrt();
    const Eigen::MatrixXd A = sq.cwiseInverse().asDiagonal() * Gm.topLeftCorner(n, n).ldlt().solve(Fm.topLeftCorner(n, n)) * sq.asDiagonal();
    const Eigen::MatrixXd O = Uq.topRows(l).leftCols(n) * sq.asDiagonal();
    const Eigen::MatrixXd& Cm = O;
    Eigen::EigenSolver<Eigen::MatrixXd> es(A);
    std::vector<RawPole> poles;
    if (es.info() == Eigen::Success)
      for (int k = 0; k < n; ++k) {
        const std::complex<double> mu = es.eigenvalues()[k];
        if (mu.imag() <= 0 || std::abs(mu) == 0) continue;
        RawPole rp;
        rp.lambda = std::log(mu) * fs;
        rp.vec = Cm * es.eigenvectors().col(k);
        poles.push_back(rp);
      }
    orders.push_back(std::move(poles));
    order_of.push_back(n);
  }
  // Background and mode indicator: first singular value of the output cross-spectral matrix.
  WelchOptions wo;
  int seg = 8;
  const Eigen::Index shortest = std::min_element(decimated.begin(), decimated.end(), [](const auto& a, const auto& b) { return a.rows() < b.rows(); })->rows();
  if (o.segment > 0) {  // the plan's resolution, in decimated samples
    while (seg * 2 <= shortest && seg * 2 <= o.segment / dec) seg *= 2;
  } else {
    while (seg * 2 <= shortest && seg < 8 * fs / flow && seg < (1 << 16)) seg *= 2;
  }
  wo.segment = seg;
  const CrossSpectra G = welch(decimated, fs, wo);
  s.frequency_hz = G.frequency;
  s.resolution_hz = fs / seg;
  s.band_lo_hz = lo;
  s.band_hi_hz = hi;
  s.background.resize(G.frequency.size());
  for (Eigen::Index k = 0; k < G.frequency.size(); ++k)
    s.background[k] = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXcd>(G.G[k], Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
  // Selection: clusters; a cluster's shape is the weighted mean of its poles' shapes (each turned to the
  // strongest member's phase); evidence.
  const std::vector<PoleCluster> clusters = internal::stabilize_and_cluster(orders, order_of, lo, hi, o, s);
  std::vector<Candidate> cands(clusters.size());
  std::vector<internal::IndicatorEvidence> peak(clusters.size());
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    const PoleCluster& pc = clusters[c];
    cands[c].cluster = pc;
    cands[c].strength = pc.support;
    peak[c] = internal::indicator_evidence(s.frequency_hz, s.background, pc.frequency_hz, pc.damping_ratio);
    if (pc.support < internal::kShapedShare * o.min_cluster_fraction) continue;
    const std::size_t top = static_cast<std::size_t>(std::max_element(pc.member_weight.begin(), pc.member_weight.end()) - pc.member_weight.begin());
    const Eigen::VectorXcd ref = orders[pc.members[top].first][pc.members[top].second].vec.normalized();
    Eigen::VectorXcd sum = Eigen::VectorXcd::Zero(ref.size());
    for (std::size_t m = 0; m < pc.members.size(); ++m) {
      Eigen::VectorXcd v = orders[pc.members[m].first][pc.members[m].second].vec.normalized();
      const std::complex<double> d = ref.dot(v);  // conj(ref) . v
      if (std::abs(d) > 0) v *= std::conj(d) / std::abs(d);
      sum += pc.member_weight[m] * v;
    }
    cands[c].shape = sum;
  }
  internal::make_modes(cands, peak, internal::check_evidence(cands, peak, o, orders.size(), s), orders.size(), s);
  for (IdentifiedMode& m : s.modes) finish_shape(m);
  mark_twins(s.modes, false);
  s.background_label = "first singular value of the output spectral matrix";
  s.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return s;
}

}  // namespace dynid
