// dynid/solvers/signal.hpp -- signal processing on FFTW: windows, Welch spectra, correlations, decimation.
#pragma once

#include <Eigen/Core>
#include <complex>
#include <memory>
#include <vector>

namespace dynid {

enum class Window {
  kRectangular,
  kHann,
  kExponential,  ///< e^{-t/tau}, tau such that the last sample is `param` of the first (impact responses)
  kForce         ///< 1 over the first `param` fraction of the record (the hammer pulse), 0 after (impact forces)
};
/// The window's n samples.
Eigen::VectorXd make_window(Window w, int n, double param = 0.01);

/// Real-to-complex FFT of a fixed size (an owned FFTW plan; one object per thread).
class RealFft {
 public:
  explicit RealFft(int n);
  ~RealFft();
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;
  int size() const { return n_; }
  /// out[k], k = 0..n/2: sum_t in[t] e^{-2 pi i k t / n}.
  void forward(const double* in, std::complex<double>* out);
  /// The inverse of forward (scaled by 1/n): in[0..n/2] -> out[0..n).
  void inverse(const std::complex<double>* in, double* out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int n_;
};

struct WelchOptions {
  int segment = 4096;     ///< samples per segment (the FFT length)
  double overlap = 0.5;   ///< fraction of a segment shared with the next
  Window window = Window::kHann;
  double window_param = 0.01;
  bool IsValid(std::string* why) const;
};

/// One-sided cross-spectral density matrices of channels (samples x channels), averaged over segments (Welch)
/// and over several records (each samples x channels, e.g. one per impact). G[k](a, b) = E[X_a(f_k)^* X_b(f_k)]
/// scaled to a density (units^2/Hz); for a = b the auto spectra.
struct CrossSpectra {
  Eigen::VectorXd frequency;          ///< Hz
  std::vector<Eigen::MatrixXcd> G;    ///< one channels x channels matrix per frequency
  int averages = 0;
};
CrossSpectra welch(const std::vector<Eigen::MatrixXd>& records, double fs, const WelchOptions& options);

/// Output correlations R_k = 1/(N-k) sum_t y_{t+k} y_t^T for k = 0..max_lag (unbiased), by FFT. Returned as
/// max_lag + 1 matrices (channels x channels).
std::vector<Eigen::MatrixXd> correlations(const Eigen::MatrixXd& y, int max_lag);

/// Low-pass (windowed-sinc FIR, cut-off 0.8 of the new Nyquist frequency) and keep every `factor`-th sample.
Eigen::MatrixXd decimate(const Eigen::MatrixXd& y, int factor);

}  // namespace dynid
