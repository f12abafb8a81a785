#include "dynid/solvers/blas.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace dynid {

namespace {
const char* openblas_core() {
  using Fn = char* (*)();
  auto f = reinterpret_cast<Fn>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  return f ? f() : nullptr;
}
}  // namespace

void ensure_blas_kernels(char** argv) {
  if (std::getenv("OPENBLAS_CORETYPE") || std::getenv("DYNID_NO_BLAS_REEXEC")) return;
  const char* core = openblas_core();
  if (!core || std::strcmp(core, "Prescott") != 0) return;
  const char* want = nullptr;
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) want = "SkylakeX";
  else if (__builtin_cpu_supports("avx2")) want = "Haswell";
#endif
  if (!want) return;
  setenv("OPENBLAS_CORETYPE", want, 1);
  setenv("DYNID_NO_BLAS_REEXEC", "1", 1);  // never loop
  execv("/proc/self/exe", argv);
  // execv returned: keep running with the generic kernels.
}

std::string blas_description() {
  const char* core = openblas_core();
  return core ? std::string("OpenBLAS ") + core : std::string("unknown (not OpenBLAS)");
}

}  // namespace dynid
