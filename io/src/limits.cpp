#include "dynid/io/limits.hpp"

#include <cmath>

#include "internal/text_util.hpp"

namespace dynid {

std::string limit_text(double value) {
  const double e = std::log10(value);
  if (value >= 1000 && std::abs(e - std::round(e)) < 1e-12) return "10^" + std::to_string(std::lround(e));
  return internal::format_number(value, 15);
}

}  // namespace dynid
