// Control of the BLAS thread pool (OpenBLAS, if that is the loaded BLAS), found at run time with dlsym so that
// any BLAS works (internal to solvers).
#pragma once

namespace dynid::internal {

/// While alive, BLAS runs on one thread. The Lanczos phase is a sequence of memory-bound triangular solves and
/// sparse products: BLAS threads gain nothing there, and OpenBLAS's spinning pthreads would compete with the
/// OpenMP threads of the sparse products. The previous thread count is restored on destruction.
class SingleThreadedBlas {
 public:
  SingleThreadedBlas();
  ~SingleThreadedBlas();
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;

 private:
  int saved_ = 0;
};

}  // namespace dynid::internal
