// Two halves of a computation on two cores, without a thread pool that spins.
#pragma once

#include <functional>

namespace dynid::detail {

/// The size (rows) from which a simplicial factor's solves run on two threads (tree_solve.hpp), and with them the
/// Lanczos steps' vector work (LanczosOptions::pair_vectors). Below it the hand-off (tens of microseconds) would
/// cost more than it saves, and the eigen-solve runs exactly as it did before the two-core path: the small models
/// of discovery and updating are unchanged.
constexpr long kPairRows = 20000;

/// Runs here() on the calling thread and there() on a helper thread at the same time, and returns when both are
/// done; or both on the calling thread, here() first, where only one thread is allowed (omp_get_max_threads() is 1,
/// e.g. dynid --threads 1), the caller already runs inside an OpenMP parallel region, the helper is busy with
/// another caller, or the process is a fork of the one that started the helper. The two must not write the same
/// memory; their results are then the same either way. An exception from either is rethrown here (the first
/// one's first), after both have finished.
///
/// The helper sleeps on a condition variable between calls. An OpenMP team would do, but its idle workers spin
/// after each region, and OpenBLAS's workers spin-yield for ~2^28 cycles after each threaded call: on two cores,
/// either slowed the other's work in the Lanczos run between solves (bench/README.md, "Two-core Lanczos steps").
void run_pair(const std::function<void()>& here, const std::function<void()>& there);

}  // namespace dynid::detail
