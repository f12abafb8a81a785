// Process-level BLAS set-up for programs (the dynid command, the benchmarks): the libraries never change the
// environment or re-execute the process; a program's main() decides to, by calling these.
#pragma once

namespace dynid::cli {

/// OpenBLAS chooses its kernels from the CPU model at load time. On CPUs it does not recognise (common on cloud
/// virtual machines) it falls back to generic SSE3 kernels ("Prescott"), which halves the speed of CHOLMOD's
/// supernodal factorization. If that happened and OPENBLAS_CORETYPE is not set, this re-executes the program
/// once (same argv) with OPENBLAS_CORETYPE chosen from the CPU's features (SkylakeX for AVX-512, Haswell for
/// AVX2). Call it first thing in main(). Returns normally if nothing needs doing (or re-exec failed).
void ensure_blas_kernels(char** argv);

/// OpenBLAS's own thread count (CHOLMOD's supernodal factorization); no effect with another BLAS.
void set_blas_threads(int n);

}  // namespace dynid::cli
