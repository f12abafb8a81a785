#include "internal/blas_threads.hpp"

#include <dlfcn.h>

namespace dynid::internal {

namespace {
using SetFn = void (*)(int);
using GetFn = int (*)();
SetFn set_fn() { return reinterpret_cast<SetFn>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads")); }
GetFn get_fn() { return reinterpret_cast<GetFn>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads")); }
}  // namespace

SingleThreadedBlas::SingleThreadedBlas() {
  if (GetFn g = get_fn()) saved_ = g();
  if (SetFn s = set_fn(); s && saved_ > 1) s(1);
}

SingleThreadedBlas::~SingleThreadedBlas() {
  if (SetFn s = set_fn(); s && saved_ > 1) s(saved_);
}

}  // namespace dynid::internal
