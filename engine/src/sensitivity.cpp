#include "dynid/engine/sensitivity.hpp"

#include <cmath>

#include "dynid/mesh/error.hpp"

namespace dynid {

Eigen::MatrixXd eigenvalue_derivatives(const ParametricModel& pm, const ModalState& s, const std::vector<int>& modes) {
  Eigen::MatrixXd Phi(s.Phi.rows(), static_cast<Eigen::Index>(modes.size()));
  Eigen::VectorXd lam(static_cast<Eigen::Index>(modes.size()));
  for (std::size_t k = 0; k < modes.size(); ++k) {
    Phi.col(static_cast<Eigen::Index>(k)) = s.Phi.col(modes[k]);
    lam[static_cast<Eigen::Index>(k)] = s.lambda[modes[k]];
  }
  return pm.eigenvalue_sensitivities(s.theta, lam, Phi);
}

std::vector<Eigen::MatrixXd> shape_derivatives(const ParametricModel& pm, const ModalState& s,
                                               const std::vector<int>& modes, const std::vector<int>& rows) {
  const Eigen::Index n = s.Phi.rows(), m = s.Phi.cols(), a = static_cast<Eigen::Index>(rows.size());
  const int P = pm.num_parameters();
  if (!s.complete && !s.factor)
    throw InternalError("shape_derivatives: an incomplete modal basis needs the factorization for the static correction");
  Eigen::MatrixXd Pa(a, m);  // modes at the rows
  for (Eigen::Index r = 0; r < a; ++r) Pa.row(r) = s.Phi.row(rows[r]);
  // G = (K - sigma M)^{-1} E_rows^T: the static correction's adjoint solves, one block.
  Eigen::MatrixXd G;
  if (!s.complete) {
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, a);
    for (Eigen::Index r = 0; r < a; ++r) E(rows[r], r) = 1.0;
    s.factor->solve_block(E, &G);
  }
  const Eigen::MatrixXd dlam = eigenvalue_derivatives(pm, s, modes);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor PhiR = s.Phi;  // rows of Phi (one DOF, all modes) contiguous
  const RowMajor GR = G;
  std::vector<Eigen::MatrixXd> out(modes.size(), Eigen::MatrixXd::Zero(a, P));
#pragma omp parallel
  {
    ParametricModel::SparseProducts sp;
    Eigen::VectorXd c(m), d(a), gt(a);
#pragma omp for schedule(dynamic)
    for (int p = 0; p < P; ++p) {
      for (std::size_t k = 0; k < modes.size(); ++k) {
        const int i = modes[k];
        const double li = s.lambda[i];
        pm.derivative_products(p, s.theta, s.Phi.col(i), &sp);
        // g = (dK - lambda_i dM) phi_i on the parameter's DOFs; c_j = phi_j^T g; q = phi_i^T dM phi_i.
        c.setZero();
        gt.setZero();
        double q = 0;
        for (std::size_t t = 0; t < sp.dof.size(); ++t) {
          const int r = sp.dof[t];
          const double g = sp.dKv[t] - li * sp.dMv[t];
          c += g * PhiR.row(r).transpose();
          q += s.Phi(r, i) * sp.dMv[t];
          if (!s.complete) gt += g * GR.row(r).transpose();
        }
        d = -0.5 * q * Pa.col(i);
        for (Eigen::Index j = 0; j < m; ++j) {
          if (j == i) continue;
          const double gap = s.lambda[j] - li;
          if (std::abs(gap) < 1e-9 * std::max(std::abs(li), 1e-300)) continue;  // repeated eigenvalue
          double w = 1.0 / gap;
          if (!s.complete) w -= 1.0 / (s.lambda[j] - s.sigma);  // this mode's share of the static correction
          d -= Pa.col(j) * (c[j] * w);
        }
        // Static correction: (K - sigma M)^{-1} f at the rows with f = -g + dlambda_i M phi_i, and
        // (K - sigma M)^{-1} M phi_i = phi_i / (lambda_i - sigma).
        if (!s.complete) d += -gt + Pa.col(i) * (dlam(static_cast<Eigen::Index>(k), p) / (li - s.sigma));
        out[k].col(p) = d;
      }
    }
  }
  return out;
}

}  // namespace dynid
