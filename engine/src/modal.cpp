#include "dynid/engine/modal.hpp"

#include <chrono>
#include <cmath>

namespace dynid {

AssembledSystem assemble_system(const ElementSource& source) {
  const auto t0 = std::chrono::steady_clock::now();
  AssembledSystem s;
  const Assembler a(source);
  a.assemble(&s.K, &s.M);
  s.time_assembly = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

ModalResult modal_analysis(const Model& model, const EigenOptions& options) {
  return modal_analysis(model, assemble_system(model), options);
}

ModalResult modal_analysis(const Model& model, const AssembledSystem& sys, const EigenOptions& options) {
  ModalResult r;
  r.dofs = static_cast<int>(sys.K.rows());
  r.nonzeros = sys.K.nonZeros();
  r.time_assembly = sys.time_assembly;
  EigenOptions opt = options;
  if (model.free_free() && opt.rigid_body_basis.size() == 0) {
    opt.rigid_body_basis = model.free_rigid_body_modes(&r.rigid_body_descriptions);
  }
  EigenSolution s = solve_eigen(sys.K, sys.M, opt);
  if (s.summary.failed_dof >= 0) s.summary.message += ": " + model.describe_dof(s.summary.failed_dof);
  r.summary = s.summary;
  r.eigenvalues = s.eigenvalues;
  r.modes = std::move(s.modes);
  r.rigid_body = s.rigid_body;
  r.residuals = s.residuals;
  r.frequencies_hz.resize(r.eigenvalues.size());
  for (Eigen::Index k = 0; k < r.eigenvalues.size(); ++k)
    r.frequencies_hz[k] = r.rigid_body[k] ? 0.0 : eigenvalue_to_hz(r.eigenvalues[k]);
  return r;
}

}  // namespace dynid
