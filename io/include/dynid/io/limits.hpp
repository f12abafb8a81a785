// Resource limits of the readers: the largest sizes a file may ask dynid to build. Declared sizes are checked
// against these (and against the bytes the file holds) before anything is allocated (docs/reliability.md).
// The defaults suit real models (dynid reaches about 10^7 DOFs). The limits are an explicit argument of every
// reader that checks one (default: ReaderLimits{}); a program fills them (the dynid command: GlobalOptions), a
// fuzz target lowers them so that the fuzzer explores the parsers instead of building big valid models. There is
// no process-wide setting.
#pragma once

#include <string>

namespace dynid {

struct ReaderLimits {
  double max_generated_elements = 1e7;   ///< elements one case-file `generate:` block builds
  long long max_generated_ids = 10000000;  ///< ids one Abaqus *NSET / *ELSET GENERATE line makes
  long long max_matrix_dimension = 100000000;  ///< rows or columns of a Matrix Market matrix
  int max_element_dofs = 2000;  ///< DOFs of one element, group or remainder of a matrix model (stored dense)
  long long max_mat_elements = 2000000000;  ///< elements of one variable of a .mat file
};

/// "10^7" for exact powers of ten >= 10^3, else the number itself (for messages naming a limit).
std::string limit_text(double value);

}  // namespace dynid
