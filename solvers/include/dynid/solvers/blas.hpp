// dynid/solvers/blas.hpp -- which BLAS the solvers run on. A query only: choosing OpenBLAS's kernels (and
// re-executing the process to do so) is a program's decision, never a library's (the dynid command:
// cli/blas_kernels.hpp).
#pragma once

#include <string>

namespace dynid {

/// The BLAS in use: "OpenBLAS <core>" or "unknown (not OpenBLAS)".
std::string blas_description();

}  // namespace dynid
