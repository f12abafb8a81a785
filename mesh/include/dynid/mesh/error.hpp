// dynid/mesh/error.hpp -- the error types every dynid module throws.
//
// Three tiers (see docs/method.md, "Errors"):
//   InputError      bad input: the message names the entity (file, line, node, element) and the problem.
//   NumericalError  a numerical failure the input caused (singular matrix, mechanism); names the DOFs.
//   internal checks DYNID_CHECK: a broken invariant of dynid itself; always on, with context.
// Library code never prints or exits; only the CLI decides what to do with an error.
#pragma once

#include <stdexcept>
#include <string>

namespace dynid {

/// Invalid input: a case file, a mesh, a model, an option. The message says where and what.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A numerical failure caused by the data (singular K - sigma M, mechanism, non-convergence).
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A broken internal invariant (a bug in dynid); raised by DYNID_CHECK.
class InternalError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

namespace internal {
[[noreturn]] void check_failed(const char* expr, const char* file, int line, const std::string& what);
}  // namespace internal

}  // namespace dynid

/// Always-on invariant check: throws dynid::InternalError with the expression, location and a message.
#define DYNID_CHECK(cond, msg)                                                      \
  do {                                                                              \
    if (!(cond)) ::dynid::internal::check_failed(#cond, __FILE__, __LINE__, (msg)); \
  } while (0)
