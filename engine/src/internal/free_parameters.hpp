// Which parameters a fit moves (internal to the engine): shared by fit_parameters and fit_multistart.
#pragma once

#include <vector>

#include "dynid/engine/model_fit.hpp"

namespace dynid::internal {

/// The free parameters: those marked in `is_free` (all if empty) that are not tied to another. Throws InputError
/// for a mask of the wrong size, an invalid tie or a tie to a tied parameter.
std::vector<int> free_parameters(const ParametricModel& pm, const std::vector<char>& is_free, const FitOptions& o);

}  // namespace dynid::internal
