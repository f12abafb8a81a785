// dynid/solvers/blas.hpp -- making sure the optimized BLAS runs its best kernels.
#pragma once

#include <string>

namespace dynid {

/// OpenBLAS chooses its kernels from the CPU model at load time. On CPUs it does not recognise (common on cloud
/// virtual machines) it falls back to generic SSE3 kernels ("Prescott"), which halves the speed of CHOLMOD's
/// supernodal factorization. If that happened and OPENBLAS_CORETYPE is not set, this re-executes the program
/// once (same argv) with OPENBLAS_CORETYPE chosen from the CPU's features (SkylakeX for AVX-512, Haswell for
/// AVX2). Call it first thing in main(). Returns normally if nothing needs doing (or re-exec failed).
void ensure_blas_kernels(char** argv);

/// The BLAS in use: "OpenBLAS <core>" or "unknown (not OpenBLAS)".
std::string blas_description();

}  // namespace dynid
