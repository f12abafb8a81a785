// dynid -- command line. Exit codes: 0 success; 1 numerical failure (solver did not converge, singular
// matrix); 2 bad input or usage (the message says what and where); 3 internal error (please report).
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "blas_kernels.hpp"
#include "commands.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/distributed.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace dynid::cli {

void set_threads(int n) {
  if (n <= 0) return;
#ifdef _OPENMP
  omp_set_num_threads(n);
#endif
  // OpenBLAS (used by CHOLMOD's supernodal factorization) has its own thread pool.
  set_blas_threads(n);
}

}  // namespace dynid::cli

int main(int argc, char** argv) {
  using namespace dynid::cli;
  ensure_blas_kernels(argv);  // process-level: may re-execute with better OpenBLAS kernels
  CLI::App app{"dynid: finds where a structure differs from its finite-element model, and why, from vibration "
               "measurements.\nExit codes: 0 success, 1 numerical failure, 2 bad input or usage, 3 internal error, 4 a discovery case's expect: not met (discover, run)."};
  app.set_version_flag("--version", std::string("dynid ") + DYNID_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand
  GlobalOptions g;
  app.add_option("--threads", g.threads, "Threads for assembly, factorization and residuals (default: all cores)")
      ->check(CLI::PositiveNumber);
  app.add_flag("-q,--quiet", g.quiet, "Print only errors");
  app.add_flag("-v,--verbose", g.verbose, "Print solver details");
  register_commands(app, g);
  if (dynid::launched_with_several_ranks()) {
    // mpirun -n N dynid modal CASE: every rank reads the case; the eigen-solve is distributed (docs/distributed.md).
    // This loads the distributed backend (libdynid_distributed.so: MPI, PETSc, SLEPc) and starts MPI.
    try {
      dynid::start_distributed_runtime();
      g.root = dynid::distributed_rank() == 0;
    } catch (const std::exception& e) {
      fmt::print(stderr, "dynid: error: {}\n", e.what());
      return 3;
    }
    g.distributed = true;
    std::string command;
    for (int i = 1; i < argc && command.empty(); ++i)
      if (argv[i][0] != '-') command = argv[i];
    if (command != "modal") {
      if (g.root)
        fmt::print(stderr, "dynid: under mpirun only `dynid modal` runs distributed; run `dynid {}` without mpirun\n",
                   command.empty() ? "--help" : command);
      return 2;
    }
    if (!g.root) g.quiet = true;
    // The ranks on one machine share its cores (OMPI_COMM_WORLD_LOCAL_SIZE; --threads overrides).
    if (const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE"))
      g.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / std::max(1, std::atoi(local)));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return g.exit_code;
}
