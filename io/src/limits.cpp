#include "dynid/io/limits.hpp"

#include <cmath>
#include <cstdio>

namespace dynid {

std::string limit_text(double value) {
  const double e = std::log10(value);
  if (value >= 1000 && std::abs(e - std::round(e)) < 1e-12) return "10^" + std::to_string(std::lround(e));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", value);
  return buf;
}

}  // namespace dynid
