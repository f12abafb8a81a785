// Progress display for long work: a single status line on stderr, only when stderr is a terminal.
#pragma once

#include <chrono>
#include <string>
#include <string_view>

namespace dynid::cli {

class Progress {
 public:
  explicit Progress(bool enabled);
  ~Progress();
  /// Shows "stage ... 12.3 s" (fraction < 0: unknown).
  void update(std::string_view stage, double fraction);
  void done();

 private:
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point t0_;
};

}  // namespace dynid::cli
