// parallel_for (internal to the engine): independent tasks over OpenMP threads, exceptions carried out.
#pragma once

#include <algorithm>
#include <exception>
#include <vector>

namespace dynid::internal {

/// fn(i) for i in [0, n), in parallel over OpenMP threads. An exception thrown by any call is rethrown after the
/// loop (the one of the lowest i), never through OpenMP, where it would terminate the process.
template <class F>
void parallel_for(int n, F&& fn) {
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(std::max(n, 0)));
#pragma omp parallel for schedule(dynamic)
  for (int i = 0; i < n; ++i) {
    try {
      fn(i);
    } catch (...) {
      errors[static_cast<std::size_t>(i)] = std::current_exception();
    }
  }
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace dynid::internal
