// Pieces of solve_eigen shared by the local (eigen.cpp) and the distributed (distributed.cpp) paths, so that both
// return their modes with the same conventions.
#pragma once

#include <Eigen/Core>

#include "dynid/solvers/eigen.hpp"

namespace dynid::detail {

/// Throws InputError for invalid options, non-square or mismatched K (kr x kc) and M (mr x mc), or a rigid-body
/// basis with the wrong number of rows.
void check_inputs(Eigen::Index kr, Eigen::Index kc, Eigen::Index mr, Eigen::Index mc, const EigenOptions& o);
/// M-orthonormalises the columns of B (n x r), MB = M B: Phi with Phi^T M Phi = I spanning the same space.
Eigen::MatrixXd m_orthonormalize(const Eigen::MatrixXd& B, const Eigen::MatrixXd& MB);
/// max_i |K_ii| / M_ii over M_ii > 0 (else max |K_ii|, else 1): the scale of the free-free shift.
double max_stiffness_to_mass(const Eigen::VectorXd& kd, const Eigen::VectorXd& md);
/// Sorts the modes (rigid-body first, then by eigenvalue) and makes each mode's entry of largest magnitude positive.
void finish(EigenSolution* s);

}  // namespace dynid::detail
