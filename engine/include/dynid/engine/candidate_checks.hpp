// dynid/engine/candidate_checks.hpp -- the invariants every discovery candidate must satisfy, checked on a
// model: for dynid's own kinds (tests/test_candidates.cpp) and for a host code's (call it from your tests:
// EXPECT_TRUE(r.ok()) << r.report()). After Ceres's manifold_test_utils.h.
#pragma once

#include <string>
#include <vector>

#include "dynid/engine/candidate.hpp"

namespace dynid {

struct CandidateCheck {
  std::vector<std::string> failures;  ///< one line per violated invariant
  bool ok() const { return failures.empty(); }
  std::string report() const;
};

/// Checks `c` on `model`:
///  - its parameters have lower < upper, the nominal within the bounds and a prior scale >= 0;
///  - its terms install on a ParametricModel of `model` (DOFs in the sparsity pattern, parameters in range);
///  - at the nominal parameters dK = dM = 0 (to `tolerance` relative to the element matrices it touches): the
///    candidate is the model as given;
///  - at a point inside the bounds away from the nominal, the terms' derivatives agree with central differences
///    of the terms (step 1e-6 of the parameter's range; agreement to `tolerance` relative to the derivative's
///    size, floor 1e-9 of the touched matrices);
///  - physical() gives finite values with a name for every parameter.
CandidateCheck check_candidate(const Model& model, const Candidate& c, double tolerance = 1e-6);

}  // namespace dynid
