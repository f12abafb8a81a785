// dynid/engine/modal.hpp -- modal analysis of a Model: assembly, rigid-body detection, eigen-solve.
#pragma once

#include <string>
#include <vector>

#include "dynid/mesh/model.hpp"
#include "dynid/solvers/eigen.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// Global K and M of a model on its free DOFs (shared pattern), with assembly statistics.
struct AssembledSystem {
  SparseMatrix K, M;
  double time_assembly = 0;  ///< seconds (symbolic + numeric)
};
AssembledSystem assemble_system(const ElementSource& source);

struct ModalResult {
  Eigen::VectorXd eigenvalues;     ///< lambda = omega^2 (rad^2/s^2), ascending; rigid-body modes first
  Eigen::VectorXd frequencies_hz;  ///< sqrt(max(lambda, 0)) / (2 pi); exactly 0 for rigid-body modes
  Eigen::MatrixXd modes;           ///< free DOFs x modes, mass-normalised
  std::vector<char> rigid_body;
  Eigen::VectorXd residuals;       ///< relative eigen-residual of each mode (see solve_eigen)
  std::vector<std::string> rigid_body_descriptions;  ///< "translation y", "rotation about z", ...
  EigenSummary summary;            ///< status, timings; message names the DOF on a factorization failure
  int dofs = 0;
  long long nonzeros = 0;
  double time_assembly = 0;
  bool ok() const { return summary.ok(); }
};

/// Modal analysis of a finalized model. Rigid-body modes are found geometrically (Model::free_rigid_body_modes:
/// the rigid motions that supports and springs leave free), never by an eigenvalue threshold, and are deflated
/// from the Lanczos run. Numerical failures come back in summary (status, message naming node and DOF).
ModalResult modal_analysis(const Model& model, const EigenOptions& options);

/// Same on an assembled system (e.g. to re-use K and M); `model` names DOFs in messages and gives the rigid
/// motions.
ModalResult modal_analysis(const Model& model, const AssembledSystem& system, const EigenOptions& options);

/// The discretisation error of a model's elastic frequencies, estimated by refinement: every beam and frame
/// element split in two (refined()), the `count` lowest elastic modes of both compared, each of the model's paired
/// with the refined model's mode of best MAC on the model's own DOFs. Per elastic mode of the model (in order):
/// |f - f_refined| / f, about the error of f itself for cubic elements (errors fall 16-fold per halving), 0 for a
/// mode without a partner of MAC 0.9. Models without beams or frames (matrix models) give zeros.
Eigen::VectorXd discretization_error(const Model& model, int count);
/// The model's lowest modes as discretization_error solves them (`count` + 6 modes, rigid-body ones included).
ModalResult lowest_modes(const Model& model, int count);
/// Same, on those modes already solved (lowest_modes(model, count)), so that a caller needing them too solves once.
Eigen::VectorXd discretization_error(const Model& model, const ModalResult& coarse, int count);

inline double eigenvalue_to_hz(double lambda) {
  return lambda > 0 ? std::sqrt(lambda) / (2.0 * 3.14159265358979323846) : 0.0;
}
inline double hz_to_eigenvalue(double f) {
  const double w = 2.0 * 3.14159265358979323846 * f;
  return w * w;
}

}  // namespace dynid
