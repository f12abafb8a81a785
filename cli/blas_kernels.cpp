#include "blas_kernels.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace dynid::cli {

// OpenBLAS is looked up at run time (as blas_description() does): this library links nothing but libdl, so that the
// programs' link lines (and with them which BLAS resolves each symbol) are those of the libraries alone.
void ensure_blas_kernels(char** argv) {
  if (std::getenv("OPENBLAS_CORETYPE") || std::getenv("DYNID_NO_BLAS_REEXEC")) return;
  using CoreName = char* (*)();
  const auto core_name = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  const char* core = core_name ? core_name() : nullptr;
  if (!core || std::strcmp(core, "Prescott") != 0) return;
  const char* want = nullptr;
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f"))
    want = "SkylakeX";
  else if (__builtin_cpu_supports("avx2"))
    want = "Haswell";
#endif
  if (!want) return;
  setenv("OPENBLAS_CORETYPE", want, 1);
  setenv("DYNID_NO_BLAS_REEXEC", "1", 1);  // never loop
  execv("/proc/self/exe", argv);
  // execv returned: keep running with the generic kernels.
}

void set_blas_threads(int n) {
  using SetThreads = void (*)(int);
  if (auto f = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) f(n);
}

}  // namespace dynid::cli
