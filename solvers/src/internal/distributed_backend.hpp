// The boundary between dynid_solvers and its distributed backend, the plugin libdynid_distributed.so
// (src/distributed_petsc.cpp: MPI, PETSc, SLEPc) that src/distributed.cpp loads with dlopen on first use, so that a
// program that never asks for the distributed backend never loads MPI, PETSc or SLEPc (issue 18: `import dynid`).
//
// Both sides are built from the same tree by the same compiler, so C++ types cross as they are (exceptions too).
// The plugin links no dynid library: what it needs of dynid_solvers (the assembler, the modes' conventions, the
// METIS partition) it calls through DistributedHost, so that the code exists once in the process.
#pragma once

#include <cstddef>
#include <vector>

#include "dynid/mesh/element_source.hpp"
#include "dynid/solvers/eigen.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid::detail {

/// What the plugin calls back in dynid_solvers.
struct DistributedHost {
  /// Assembler(source).assemble(K, M).
  void (*assemble)(const ElementSource& source, SparseMatrix* K, SparseMatrix* M);
  /// detail::finish: modes sorted (rigid-body first), the sign convention applied.
  void (*finish)(EigenSolution* s);
  /// partition_dofs (solvers/distributed.hpp).
  std::vector<int> (*partition)(const ElementSource& source, int parts);
};

/// What the plugin offers: the run-time and the two solves of solvers/distributed.hpp. The caller has checked the
/// solves' options and sizes (detail::check_inputs; no band).
struct DistributedBackend {
  void (*start)();  ///< start_distributed_runtime
  int (*rank)();    ///< distributed_rank
  int (*size)();    ///< distributed_size
  EigenSolution (*solve_elements)(const DistributedHost& host, const ElementSource& source, const EigenOptions& o);
  EigenSolution (*solve_matrices)(const DistributedHost& host, const SparseMatrix& K, const SparseMatrix& M,
                                  const EigenOptions& o);
};

/// The layout both sides were compiled with: the plugin refuses a host that differs (a stale copy of the library).
struct DistributedAbi {
  int version = 1;  ///< raise when DistributedHost or DistributedBackend change
  std::size_t options = sizeof(EigenOptions), solution = sizeof(EigenSolution), summary = sizeof(EigenSummary);
  bool operator==(const DistributedAbi& o) const {
    return version == o.version && options == o.options && solution == o.solution && summary == o.summary;
  }
};

/// Rows [*b, *e) of rank `rank` when n rows are split into `size` contiguous blocks.
inline void split_evenly(int n, int size, int rank, int* b, int* e) {
  *b = static_cast<int>(static_cast<long long>(n) * rank / size);
  *e = static_cast<int>(static_cast<long long>(n) * (rank + 1) / size);
}

}  // namespace dynid::detail

/// The file name of the plugin and its one exported function: the backend, or null if the host's `abi` is not the
/// plugin's own.
#define DYNID_DISTRIBUTED_LIBRARY_NAME "libdynid_distributed.so"
#define DYNID_DISTRIBUTED_ENTRY "dynid_distributed_backend"
extern "C" const dynid::detail::DistributedBackend* dynid_distributed_backend(const dynid::detail::DistributedAbi* abi);
