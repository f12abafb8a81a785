// A supernodal Cholesky factorization on two cores: independent subtrees at once, then the top split by columns.
#pragma once

#include <cholmod.h>

namespace dynid::detail {

/// The numeric supernodal factorization P A P^T = L L^T into the symbolic supernodal factor L of cholmod_analyze,
/// for factors of at least kPairRows rows (pair.hpp); CHOLMOD's own factorization otherwise.
///
/// The algorithm is CHOLMOD's left-looking supernodal one (Supernodal/t_cholmod_super_numeric_worker.c): for each
/// supernode in order, its columns of P A P^T are scattered into its block of L, every descendant whose rows reach
/// it subtracts its update (one dsyrk and one dgemm into a workspace, then a scatter), and the block is factored
/// (dpotrf, dtrsm). CHOLMOD runs it on one core with a threaded BLAS, which keeps both cores busy only in the large
/// supernodes near the root: the 249,900-DOF 3D frame factored at 47 Gflop/s where dgemm reaches 97 (bench/README.md).
/// Supernodes in different subtrees of the supernodal elimination tree neither read nor write each other's
/// blocks, so the tree is split once (tree_split.hpp, work = each supernode's flops) into two subtree sets and a top:
/// the two sets are factored at once, one per core with a one-thread BLAS; then each top supernode takes the
/// updates of all its descendants with its columns split in two halves of about equal work, each half on one core
/// (they write different columns), and is factored with the BLAS's own threads. The split depends on the factor
/// alone and every update is added in a fixed order, so the result is the same with one thread or two; it equals
/// CHOLMOD's to rounding (the updates of a top supernode are added in another order).
///
/// Both of CHOLMOD's index types are accepted (int, and SuiteSparse_long for factors of 2^31 stored values or more: A,
/// L and c of the same type, as CHOLMOD requires). Returns false, with L untouched, where it does not apply (a
/// simplicial factor, other value types, fewer than kPairRows rows): the caller then uses cholmod_factorize. Otherwise
/// true, with c->status CHOLMOD_OK and L a numeric supernodal L L^T factor that CHOLMOD's solves accept;
/// CHOLMOD_NOT_POSDEF with L->minor at the column of the failing pivot (the one CHOLMOD would report: the first in
/// column order); or CHOLMOD_OUT_OF_MEMORY. A is the matrix given to cholmod_analyze (stype 1: its upper triangle).
bool factorize_supernodal_pair(cholmod_sparse* A, cholmod_factor* L, cholmod_common* c);

}  // namespace dynid::detail
