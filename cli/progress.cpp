#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace dynid::cli {

Progress::Progress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO)), t0_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { done(); }

void Progress::update(std::string_view stage, double fraction) {
  if (!enabled_) return;
  const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
  if (fraction >= 0)
    std::fprintf(stderr, "\r\033[K  %-12.*s %5.1f %%  %7.1f s", static_cast<int>(stage.size()), stage.data(),
                 100 * fraction, t);
  else
    std::fprintf(stderr, "\r\033[K  %-12.*s          %7.1f s", static_cast<int>(stage.size()), stage.data(), t);
  std::fflush(stderr);
  shown_ = true;
}

void Progress::done() {
  if (enabled_ && shown_) std::fprintf(stderr, "\r\033[K");
  shown_ = false;
}

}  // namespace dynid::cli
