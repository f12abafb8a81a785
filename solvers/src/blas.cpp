#include "dynid/solvers/blas.hpp"

#include <dlfcn.h>

namespace dynid {

namespace {
const char* openblas_core() {
  using Fn = char* (*)();
  auto f = reinterpret_cast<Fn>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  return f ? f() : nullptr;
}
}  // namespace

std::string blas_description() {
  const char* core = openblas_core();
  return core ? std::string("OpenBLAS ") + core : std::string("unknown (not OpenBLAS)");
}

}  // namespace dynid
