// dynid/solvers/distributed.hpp -- the distributed eigen-solve: K phi = lambda M phi over all ranks of
// MPI_COMM_WORLD with PETSc and SLEPc (Debian libpetsc-real-dev, libslepc-real-dev; docs/distributed.md).
//
// Same options and results as solve_eigen (EigenOptions with backend = kDistributed, EigenSolution): the lowest
// num_modes modes, rigid-body modes from options.rigid_body_basis deflated and returned first, mass-normalised,
// the same sign convention. Every rank must make the same call with the same arguments (collective); every rank
// receives the whole result (the modes gathered to all ranks: n x num_modes doubles per rank).
//
// Method: the DOFs are split into one contiguous block of rows per rank by a METIS k-way partition of the graph
// of supervariables (runs of consecutive DOFs carried by the same elements, e.g. a node's six DOFs), computed on
// rank 0 and broadcast; each rank evaluates only the elements touching its rows and assembles those rows
// (dynid's Assembler on its share of the elements). SLEPc's Krylov-Schur with shift-and-invert at sigma (0, or
// -sqrt(eps) max K_ii/M_ii for a free-free structure, as in solve_eigen), on MUMPS's distributed L D L^T of
// K - sigma M (or CG + BoomerAMG: EigenOptions::DistributedSolver). PETSc options (e.g. -log_view,
// -st_mat_mumps_icntl_14 50, -eps_view) come from the PETSC_OPTIONS environment variable.
//
// Loading: MPI, PETSc and SLEPc are linked only into the plugin libdynid_distributed.so, which the first call that
// needs them (start_distributed_runtime, distributed_rank/size, the solves) opens: beside the program, in
// <prefix>/lib, or where DYNID_DISTRIBUTED_LIBRARY says (docs/distributed.md, "The backend library"). A program that
// never makes such a call never loads them. If the plugin cannot be opened, those calls throw InternalError naming
// it and the dynamic linker's message. partition_dofs and launched_with_several_ranks never open it.
#pragma once

#include <vector>

#include "dynid/mesh/element_source.hpp"
#include "dynid/solvers/eigen.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// Starts MPI (unless the program did), PETSc and SLEPc once per process; they are finalized at exit (PETSc's
/// -log_view report is printed then). Safe to call again. Called by the distributed solves themselves; a program
/// calls it first to learn its rank before doing rank-specific work (printing, writing files).
void start_distributed_runtime();
/// This process's rank in MPI_COMM_WORLD and the number of ranks (starts the run-time if needed).
int distributed_rank();
int distributed_size();
/// True if this process was started by an MPI launcher with more than one rank (mpirun -n N, N > 1; OpenMPI,
/// MPICH/Hydra, srun), read from the environment without starting MPI.
bool launched_with_several_ranks();

/// The rank (0 .. parts-1) owning each DOF: a METIS k-way partition of the supervariable graph of `source`,
/// weighted by DOFs per supervariable (every part non-empty when num_dofs >= parts). parts == 1: all zero.
std::vector<int> partition_dofs(const ElementSource& source, int parts);

/// The distributed solve from elements: each rank assembles its own rows (see above). options.backend is ignored
/// (this is the distributed backend). Throws InputError for invalid options; numerical failures come back in
/// summary.status like solve_eigen's.
EigenSolution solve_eigen_distributed(const ElementSource& source, const EigenOptions& options);

/// The distributed solve of given matrices (replicated on every rank, e.g. read from files): rank r takes the
/// r-th contiguous block of rows (no repartition). solve_eigen() comes here when options.backend is kDistributed.
EigenSolution solve_eigen_distributed(const SparseMatrix& K, const SparseMatrix& M, const EigenOptions& options);

}  // namespace dynid
