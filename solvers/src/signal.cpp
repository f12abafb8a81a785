#include "dynid/solvers/signal.hpp"

#include <fftw3.h>

#include <cmath>
#include <mutex>
#include <string>

#include "dynid/mesh/error.hpp"

namespace dynid {

namespace {
std::mutex g_fftw_plan;  // FFTW's planner is not thread-safe; execution is
}  // namespace

Eigen::VectorXd make_window(Window w, int n, double param) {
  if (n < 1) throw InputError("window: length must be >= 1");
  Eigen::VectorXd v(n);
  switch (w) {
    case Window::kRectangular: v.setOnes(); break;
    case Window::kHann:
      for (int i = 0; i < n; ++i) v[i] = 0.5 - 0.5 * std::cos(2 * M_PI * i / n);  // periodic Hann (Welch)
      break;
    case Window::kExponential: {
      if (!(param > 0 && param < 1)) throw InputError("exponential window: the end value must be in (0, 1)");
      const double tau = (n - 1) / -std::log(param);
      for (int i = 0; i < n; ++i) v[i] = std::exp(-i / tau);
      break;
    }
    case Window::kForce: {
      if (!(param > 0 && param <= 1)) throw InputError("force window: the pulse fraction must be in (0, 1]");
      const int m = std::max(1, static_cast<int>(std::round(param * n)));
      for (int i = 0; i < n; ++i) v[i] = i < m ? 1.0 : 0.0;
      break;
    }
  }
  return v;
}

struct RealFft::Impl {
  fftw_plan fwd = nullptr, inv = nullptr;
  double* rbuf = nullptr;
  fftw_complex* cbuf = nullptr;
  ~Impl() {
    std::lock_guard<std::mutex> lock(g_fftw_plan);
    if (fwd) fftw_destroy_plan(fwd);
    if (inv) fftw_destroy_plan(inv);
    fftw_free(rbuf);
    fftw_free(cbuf);
  }
};

RealFft::RealFft(int n) : impl_(std::make_unique<Impl>()), n_(n) {
  if (n < 2) throw InputError("FFT: length must be >= 2");
  std::lock_guard<std::mutex> lock(g_fftw_plan);
  impl_->rbuf = fftw_alloc_real(static_cast<size_t>(n));
  impl_->cbuf = fftw_alloc_complex(static_cast<size_t>(n / 2 + 1));
  if (!impl_->rbuf || !impl_->cbuf) throw std::bad_alloc();
  impl_->fwd = fftw_plan_dft_r2c_1d(n, impl_->rbuf, impl_->cbuf, FFTW_ESTIMATE);
  impl_->inv = fftw_plan_dft_c2r_1d(n, impl_->cbuf, impl_->rbuf, FFTW_ESTIMATE);
}

RealFft::~RealFft() = default;

void RealFft::forward(const double* in, std::complex<double>* out) {
  std::copy(in, in + n_, impl_->rbuf);
  fftw_execute(impl_->fwd);
  for (int k = 0; k <= n_ / 2; ++k) out[k] = {impl_->cbuf[k][0], impl_->cbuf[k][1]};
}

void RealFft::inverse(const std::complex<double>* in, double* out) {
  for (int k = 0; k <= n_ / 2; ++k) {
    impl_->cbuf[k][0] = in[k].real();
    impl_->cbuf[k][1] = in[k].imag();
  }
  fftw_execute(impl_->inv);
  for (int t = 0; t < n_; ++t) out[t] = impl_->rbuf[t] / n_;
}

bool WelchOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (segment < 8) return fail("segment must be >= 8 samples");
  if (!(overlap >= 0 && overlap < 1)) return fail("overlap must be in [0, 1)");
  return true;
}

CrossSpectra welch(const std::vector<Eigen::MatrixXd>& records, double fs, const WelchOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("Welch: " + why);
  if (!(fs > 0)) throw InputError("Welch: the sampling rate must be > 0");
  if (records.empty()) throw InputError("Welch: no records");
  const Eigen::Index nch = records[0].cols();
  const int n = o.segment, nf = n / 2 + 1;
  const int step = std::max(1, static_cast<int>(std::round(n * (1.0 - o.overlap))));
  const Eigen::VectorXd w = make_window(o.window, n, o.window_param);
  const double wss = w.squaredNorm();
  CrossSpectra out;
  out.frequency = Eigen::VectorXd::LinSpaced(nf, 0.0, fs / 2.0 * (nf - 1) / (n / 2.0));
  out.G.assign(static_cast<std::size_t>(nf), Eigen::MatrixXcd::Zero(nch, nch));
  RealFft fft(n);
  Eigen::MatrixXcd X(nf, nch);
  Eigen::VectorXd seg(n);
  for (const Eigen::MatrixXd& r : records) {
    if (r.cols() != nch) throw InputError("Welch: records have different numbers of channels");
    if (!r.allFinite()) throw InputError("Welch: a record holds NaN or Inf samples");
    if (r.rows() < n) throw InputError("Welch: a record has " + std::to_string(r.rows()) + " samples, fewer than the segment (" + std::to_string(n) + ")");
    for (Eigen::Index s0 = 0; s0 + n <= r.rows(); s0 += step) {
      for (Eigen::Index c = 0; c < nch; ++c) {
        seg = r.col(c).segment(s0, n).cwiseProduct(w);
        fft.forward(seg.data(), reinterpret_cast<std::complex<double>*>(X.col(c).data()));
      }
      for (int k = 0; k < nf; ++k) out.G[k].noalias() += X.row(k).adjoint() * X.row(k);
      ++out.averages;
    }
  }
  // One-sided density: 2 / (fs sum w^2) (DC and Nyquist not doubled).
  for (int k = 0; k < nf; ++k) {
    const double scale = (k == 0 || (n % 2 == 0 && k == nf - 1) ? 1.0 : 2.0) / (fs * wss * out.averages);
    out.G[k] *= scale;
  }
  return out;
}

std::vector<Eigen::MatrixXd> correlations(const Eigen::MatrixXd& y, int max_lag) {
  const Eigen::Index N = y.rows(), l = y.cols();
  if (max_lag < 0 || max_lag >= N) throw InputError("correlations: max_lag must be in [0, samples)");
  int n = 1;
  while (n < N + max_lag + 1) n *= 2;
  const int nf = n / 2 + 1;
  std::vector<Eigen::VectorXcd> Y(static_cast<std::size_t>(l), Eigen::VectorXcd(nf));
  std::vector<Eigen::MatrixXd> R(static_cast<std::size_t>(max_lag) + 1, Eigen::MatrixXd(l, l));
  // Pairs a <= b; the inverse transform of Y_a conj(Y_b) holds sum_t y_a[t + k] y_b[t] at k and
  // sum_t y_b[t + k] y_a[t] at n - k. Each thread has its own plan and buffers; results do not depend on the
  // thread count (each entry is computed by one thread the same way).
  std::vector<std::pair<Eigen::Index, Eigen::Index>> pairs;
  for (Eigen::Index a = 0; a < l; ++a)
    for (Eigen::Index b = a; b < l; ++b) pairs.emplace_back(a, b);
#pragma omp parallel
  {
    RealFft fft(n);
    Eigen::VectorXd buf = Eigen::VectorXd::Zero(n);
#pragma omp for schedule(static)
    for (Eigen::Index c = 0; c < l; ++c) {
      buf.setZero();
      buf.head(N) = y.col(c);
      fft.forward(buf.data(), Y[c].data());
    }
    Eigen::VectorXcd prod(nf);
#pragma omp for schedule(dynamic)
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      const auto [a, b] = pairs[p];
      prod = Y[a].cwiseProduct(Y[b].conjugate());
      fft.inverse(prod.data(), buf.data());
      for (int k = 0; k <= max_lag; ++k) {
        R[k](a, b) = buf[k] / static_cast<double>(N - k);
        R[k](b, a) = buf[k == 0 ? 0 : n - k] / static_cast<double>(N - k);
      }
    }
  }
  return R;
}

Eigen::MatrixXd decimate(const Eigen::MatrixXd& y, int factor) {
  if (factor < 1) throw InputError("decimate: factor must be >= 1");
  if (factor == 1) return y;
  // Windowed-sinc low-pass (Hann), cut-off at 0.8 of the new Nyquist frequency, 20 taps per factor on each side.
  const int half = 20 * factor;
  const double fc = 0.8 * 0.5 / factor;  // cycles per input sample
  Eigen::VectorXd h(2 * half + 1);
  for (int i = -half; i <= half; ++i) {
    const double x = 2 * fc * i;
    const double sinc = i == 0 ? 1.0 : std::sin(M_PI * x) / (M_PI * x);
    const double win = 0.5 + 0.5 * std::cos(M_PI * i / (half + 1));
    h[i + half] = 2 * fc * sinc * win;
  }
  h /= h.sum();
  const Eigen::Index N = y.rows(), M = (N + factor - 1) / factor;
  Eigen::MatrixXd out(M, y.cols());
#pragma omp parallel for schedule(static)
  for (Eigen::Index m = 0; m < M; ++m) {
    const Eigen::Index t = m * factor;
    for (Eigen::Index c = 0; c < y.cols(); ++c) {
      double s = 0;
      for (int i = -half; i <= half; ++i) {
        Eigen::Index q = t - i;
        if (q < 0) q = -q;  // mirror at the ends
        if (q >= N) q = 2 * (N - 1) - q;
        if (q < 0 || q >= N) continue;
        s += h[i + half] * y(q, c);
      }
      out(m, c) = s;
    }
  }
  return out;
}

}  // namespace dynid
