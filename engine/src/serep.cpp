#include "dynid/engine/serep.hpp"

#include <Eigen/SVD>
#include <limits>

#include "dynid/mesh/error.hpp"

namespace dynid {

SerepReduction serep_reduce(const Eigen::MatrixXd& Phi, const Eigen::VectorXd& lambda, const std::vector<int>& masters,
                            double rcond) {
  const Eigen::Index n = Phi.rows(), m = Phi.cols(), a = static_cast<Eigen::Index>(masters.size());
  if (lambda.size() != m) throw InputError("SEREP: " + std::to_string(m) + " modes but " + std::to_string(lambda.size()) + " eigenvalues");
  if (a == 0) throw InputError("SEREP: no master DOFs");
  if (m == 0) throw InputError("SEREP: no modes");
  SerepReduction s;
  s.masters = masters;
  s.modes = static_cast<int>(m);
  Eigen::MatrixXd Pa(a, m);
  for (Eigen::Index i = 0; i < a; ++i) {
    if (masters[i] < 0 || masters[i] >= n) throw InputError("SEREP: master DOF index " + std::to_string(masters[i]) + " out of range");
    Pa.row(i) = Phi.row(masters[i]);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Pa, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sv = svd.singularValues();
  const double smax = sv.size() ? sv[0] : 0.0;
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(sv.size());
  for (Eigen::Index i = 0; i < sv.size(); ++i)
    if (sv[i] > rcond * smax) {
      inv[i] = 1.0 / sv[i];
      ++s.rank;
    }
  const double smin = sv.size() == m ? sv[m - 1] : 0.0;
  s.condition = smin > 0 ? smax / smin : std::numeric_limits<double>::infinity();
  s.P = svd.matrixV() * inv.asDiagonal() * svd.matrixU().transpose();  // m x a
  s.T = Phi * s.P;
  s.K = s.P.transpose() * lambda.asDiagonal() * s.P;
  s.M = s.P.transpose() * s.P;
  s.K = 0.5 * (s.K + s.K.transpose());
  s.M = 0.5 * (s.M + s.M.transpose());
  return s;
}

Eigen::MatrixXd serep_expand(const SerepReduction& s, const Eigen::MatrixXd& shapes) {
  if (shapes.rows() != static_cast<Eigen::Index>(s.masters.size()))
    throw InputError("SEREP expansion: shapes have " + std::to_string(shapes.rows()) + " rows for " +
                     std::to_string(s.masters.size()) + " master DOFs");
  return s.T * shapes;
}

}  // namespace dynid
