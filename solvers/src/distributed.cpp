// The distributed backend's entry points (solvers/distributed.hpp) on the dynid_solvers side: the METIS partition,
// the launcher check, and the loader of the plugin libdynid_distributed.so (src/distributed_petsc.cpp) that does
// the MPI, PETSc and SLEPc work. The plugin is loaded on the first call that needs it and never unloaded (MPI
// cannot be started twice in a process); a program that never asks for the distributed backend never loads it.
#include "dynid/solvers/distributed.hpp"

#include <dlfcn.h>
#include <link.h>
#include <metis.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <numeric>
#include <string>
#include <vector>

#include "dynid/mesh/error.hpp"
#include "internal/distributed_backend.hpp"
#include "internal/eigen_detail.hpp"

namespace dynid {

namespace {

// The folder of the file this code was linked into (dynid_solvers is static: the dynid command, the Python module,
// a test or a host program), symbolic links resolved. The main program's link map has no name (dladdr would give
// argv[0], which may be a bare command name): /proc/self/exe is its file then.
std::string own_folder() {
  Dl_info info{};
  link_map* map = nullptr;
  if (dladdr1(reinterpret_cast<void*>(&own_folder), &info, reinterpret_cast<void**>(&map), RTLD_DL_LINKMAP) == 0)
    return {};
  const char* file = map && map->l_name && map->l_name[0] ? map->l_name : "/proc/self/exe";
  char real[PATH_MAX];
  if (!realpath(file, real)) return {};
  const std::string f = real;
  return f.substr(0, f.rfind('/'));
}

// Where the plugin may be, in order (docs/distributed.md, "The backend library"), unless $DYNID_DISTRIBUTED_LIBRARY
// names it:
//  1. beside the file holding this code;
//  2. the library folder relative to it: <prefix>/bin/dynid -> <prefix>/lib, and in the build tree, which mirrors
//     that layout, build/cli/dynid or build/tests/test_x -> build/lib;
//  3. the dynamic linker's search (LD_LIBRARY_PATH, the run path of the program, ld.so.cache): host programs, which
//     the installed CMake package gives a run path to <prefix>/lib.
std::vector<std::string> candidates() {
  const std::string name = DYNID_DISTRIBUTED_LIBRARY_NAME, here = own_folder();
  std::vector<std::string> c;
  if (!here.empty()) {
    c.push_back(here + "/" + name);
    c.push_back(here + "/" DYNID_BIN_TO_LIB "/" + name);
  }
  c.push_back(name);
  return c;
}

using Entry = const detail::DistributedBackend* (*)(const detail::DistributedAbi*);

// Opens the first candidate that exists. Throws InternalError naming the library and the dynamic linker's message
// (dlerror) if none does, if the one found cannot be loaded (e.g. a PETSc library missing), or if it belongs to
// another build of dynid.
const detail::DistributedBackend* load_backend() {
  const std::string what = "the distributed backend " DYNID_DISTRIBUTED_LIBRARY_NAME " (MPI, PETSc, SLEPc)";
  const char* env = std::getenv("DYNID_DISTRIBUTED_LIBRARY");
  const bool named = env && *env;
  std::string tried;
  for (const std::string& path : named ? std::vector<std::string>{env} : candidates()) {
    // RTLD_GLOBAL: Open MPI's documentation asks for it when libmpi is opened with dlopen (its own components,
    // opened later, use libmpi's symbols); Debian's Open MPI 4.1 works either way.
    void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
    if (!h) {
      const char* e = dlerror();
      const std::string why = e ? e : "unknown error";
      if (named) throw InternalError("could not load " + what + " named by DYNID_DISTRIBUTED_LIBRARY: " + why);
      if (path.find('/') != std::string::npos && access(path.c_str(), F_OK) == 0)
        throw InternalError("could not load " + what + " from " + path + ": " + why);
      tried += (tried.empty() ? "" : "; ") + why;
      continue;
    }
    const auto entry = reinterpret_cast<Entry>(dlsym(h, DYNID_DISTRIBUTED_ENTRY));
    if (!entry) {
      const char* e = dlerror();
      throw InternalError(path + " is not " + what + ": " + (e ? e : "no " DYNID_DISTRIBUTED_ENTRY));
    }
    const detail::DistributedAbi abi;
    const detail::DistributedBackend* b = entry(&abi);
    if (!b) throw InternalError(path + " belongs to another build of dynid (its types differ from this program's)");
    return b;
  }
  throw InternalError("could not find " + what + ": " + tried + " (DYNID_DISTRIBUTED_LIBRARY may name its path)");
}

// The plugin, loaded on first use; a failed load is tried again on the next call.
const detail::DistributedBackend& backend() {
  static std::mutex mu;
  static const detail::DistributedBackend* loaded = nullptr;
  std::lock_guard<std::mutex> lock(mu);
  if (!loaded) loaded = load_backend();
  return *loaded;
}

// What the plugin calls back in this library.
void assemble(const ElementSource& source, SparseMatrix* K, SparseMatrix* M) { Assembler(source).assemble(K, M); }
const detail::DistributedHost kHost{&assemble, &detail::finish, &partition_dofs};

// Contiguous blocks of DOFs, one per part (detail::split_evenly): the partition when METIS cannot give one.
std::vector<int> contiguous_parts(int n, int parts) {
  std::vector<int> part(static_cast<std::size_t>(n), 0);
  for (int p = 0; p < parts; ++p) {
    int b = 0, e = 0;
    detail::split_evenly(n, parts, p, &b, &e);
    std::fill(part.begin() + b, part.begin() + e, p);
  }
  return part;
}

void refuse_band(const EigenOptions& options) {
  if (!std::isnan(options.band_lo))
    throw InputError(
        "eigen-solve options: the distributed backend solves the lowest modes only; a band needs the local backend");
}

}  // namespace

void start_distributed_runtime() { backend().start(); }

int distributed_rank() { return backend().rank(); }

int distributed_size() { return backend().size(); }

bool launched_with_several_ranks() {
  // OpenMPI's mpirun, MPICH/Hydra's mpiexec (PMI_SIZE, MPI_LOCALNRANKS), Slurm's srun (inside a job step only).
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "MPI_LOCALNRANKS", "SLURM_STEP_NUM_TASKS"}) {
    const char* s = std::getenv(v);
    if (s && std::atoi(s) > 1) return true;
  }
  return false;
}

std::vector<int> partition_dofs(const ElementSource& src, int parts) {
  const int n = src.num_dofs();
  if (parts < 1) throw InputError("partition_dofs: parts must be >= 1");
  std::vector<int> part(static_cast<std::size_t>(n), 0);
  if (parts == 1 || n == 0) return part;
  const int ne = src.num_elements();
  // DOF -> elements (CSR).
  std::vector<int> cnt(static_cast<std::size_t>(n) + 1, 0), dofs;
  for (int e = 0; e < ne; ++e) {
    src.element_dofs(e, &dofs);
    for (int d : dofs)
      if (d >= 0) ++cnt[static_cast<std::size_t>(d) + 1];
  }
  std::partial_sum(cnt.begin(), cnt.end(), cnt.begin());
  std::vector<int> elems(static_cast<std::size_t>(cnt[static_cast<std::size_t>(n)])), pos(cnt.begin(), cnt.end() - 1);
  for (int e = 0; e < ne; ++e) {
    src.element_dofs(e, &dofs);
    for (int d : dofs)
      if (d >= 0) elems[static_cast<std::size_t>(pos[static_cast<std::size_t>(d)]++)] = e;
  }
  // Supervariables: runs of consecutive DOFs with the same (sorted, unique) element list.
  auto list = [&](int d) {
    std::vector<int> l(elems.begin() + cnt[static_cast<std::size_t>(d)],
                       elems.begin() + cnt[static_cast<std::size_t>(d) + 1]);
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    return l;
  };
  std::vector<int> sv(static_cast<std::size_t>(n));
  std::vector<idx_t> weight;
  std::vector<int> prev;
  for (int d = 0; d < n; ++d) {
    std::vector<int> l = list(d);
    if (d == 0 || l != prev || l.empty()) weight.push_back(0);
    sv[static_cast<std::size_t>(d)] = static_cast<int>(weight.size()) - 1;
    ++weight.back();
    prev = std::move(l);
  }
  idx_t nsv = static_cast<idx_t>(weight.size());
  if (nsv < parts) return contiguous_parts(n, parts);  // fewer supervariables than ranks
  // Supervariable graph: two are adjacent if an element carries both.
  std::vector<std::vector<idx_t>> adj(static_cast<std::size_t>(nsv));
  std::vector<idx_t> svs;
  for (int e = 0; e < ne; ++e) {
    src.element_dofs(e, &dofs);
    svs.clear();
    for (int d : dofs)
      if (d >= 0) svs.push_back(sv[static_cast<std::size_t>(d)]);
    std::sort(svs.begin(), svs.end());
    svs.erase(std::unique(svs.begin(), svs.end()), svs.end());
    for (idx_t a : svs)
      for (idx_t b : svs)
        if (a != b) adj[static_cast<std::size_t>(a)].push_back(b);
  }
  std::vector<idx_t> xadj(static_cast<std::size_t>(nsv) + 1, 0), adjncy;
  for (idx_t v = 0; v < nsv; ++v) {
    auto& a = adj[static_cast<std::size_t>(v)];
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    adjncy.insert(adjncy.end(), a.begin(), a.end());
    xadj[static_cast<std::size_t>(v) + 1] = static_cast<idx_t>(adjncy.size());
    std::vector<idx_t>().swap(a);
  }
  idx_t ncon = 1, np = parts, objval = 0;
  std::vector<idx_t> where(static_cast<std::size_t>(nsv), 0);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;
  if (adjncy.empty()) adjncy.push_back(0);  // METIS reads the array even when there are no edges
  const int rc = METIS_PartGraphKway(&nsv, &ncon, xadj.data(), adjncy.data(), weight.data(), nullptr, nullptr, &np,
                                     nullptr, nullptr, options, &objval, where.data());
  if (rc != METIS_OK) throw InternalError("METIS_PartGraphKway failed (code " + std::to_string(rc) + ")");
  for (int d = 0; d < n; ++d)
    part[static_cast<std::size_t>(d)] =
        static_cast<int>(where[static_cast<std::size_t>(sv[static_cast<std::size_t>(d)])]);
  // METIS may leave a part empty on tiny graphs: then contiguous blocks.
  std::vector<int> used(static_cast<std::size_t>(parts), 0);
  for (int p : part) used[static_cast<std::size_t>(p)] = 1;
  if (std::count(used.begin(), used.end(), 1) < parts) return contiguous_parts(n, parts);
  return part;
}

EigenSolution solve_eigen_distributed(const ElementSource& source, const EigenOptions& options) {
  const int n = source.num_dofs();
  detail::check_inputs(n, n, n, n, options);
  refuse_band(options);
  return backend().solve_elements(kHost, source, options);
}

EigenSolution solve_eigen_distributed(const SparseMatrix& K, const SparseMatrix& M, const EigenOptions& options) {
  detail::check_inputs(K.rows(), K.cols(), M.rows(), M.cols(), options);
  refuse_band(options);
  return backend().solve_matrices(kHost, K, M, options);
}

}  // namespace dynid
