#include "dynid/engine/modal.hpp"

#include <chrono>
#include <cmath>

#include "dynid/engine/correlation.hpp"
#include "dynid/mesh/generators.hpp"
#include "dynid/solvers/distributed.hpp"

namespace dynid {

AssembledSystem assemble_system(const ElementSource& source) {
  const auto t0 = std::chrono::steady_clock::now();
  AssembledSystem s;
  const Assembler a(source);
  a.assemble(&s.K, &s.M);
  s.time_assembly = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

namespace {

// The eigen-solve and what modal_analysis adds to it: rigid-body motions, DOF names, frequencies. `sys` null: the
// distributed backend, where each rank assembles its own rows.
ModalResult modal_result(const Model& model, const AssembledSystem* sys, const EigenOptions& options) {
  ModalResult r;
  r.dofs = model.num_dofs();
  EigenOptions opt = options;
  if (model.free_free() && opt.rigid_body_basis.size() == 0) {
    opt.rigid_body_basis = model.free_rigid_body_modes(&r.rigid_body_descriptions);
  }
  EigenSolution s;
  if (sys) {
    r.dofs = static_cast<int>(sys->K.rows());
    r.nonzeros = sys->K.nonZeros();
    r.time_assembly = sys->time_assembly;
    s = solve_eigen(sys->K, sys->M, opt);
  } else {
    s = solve_eigen_distributed(model, opt);
    r.time_assembly = s.summary.time_assembly;
    r.nonzeros = s.summary.matrix_nonzeros;
  }
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

}  // namespace

ModalResult modal_analysis(const Model& model, const EigenOptions& options) {
  if (options.backend == EigenOptions::Backend::kDistributed) return modal_result(model, nullptr, options);
  return modal_analysis(model, assemble_system(model), options);
}

ModalResult modal_analysis(const Model& model, const AssembledSystem& sys, const EigenOptions& options) {
  return modal_result(model, &sys, options);
}

ModalResult lowest_modes(const Model& model, int count) {
  EigenOptions eo;
  eo.num_modes = std::min(model.num_dofs(), count + 6);
  if (model.num_dofs() <= 400) eo.method = EigenOptions::Method::kDense;
  return modal_analysis(model, eo);
}

Eigen::VectorXd discretization_error(const Model& model, int count) {
  return discretization_error(model, lowest_modes(model, count), count);
}

Eigen::VectorXd discretization_error(const Model& model, const ModalResult& coarse, int count) {
  auto elastic = [](const ModalResult& r) {
    std::vector<Eigen::Index> e;
    for (Eigen::Index j = 0; j < r.eigenvalues.size(); ++j)
      if (!r.rigid_body[j]) e.push_back(j);
    return e;
  };
  const std::vector<Eigen::Index> ec = elastic(coarse);
  Eigen::VectorXd err = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(std::min<std::size_t>(ec.size(), static_cast<std::size_t>(count))));
  bool members = false;
  for (const Element& e : model.elements()) members = members || is_member(e.type);
  if (!members || !coarse.ok()) return err;
  const Model fine = refined(model);
  EigenOptions ef;
  ef.num_modes = std::min(fine.num_dofs(), count + 6 + 4);
  if (fine.num_dofs() <= 400) ef.method = EigenOptions::Method::kDense;
  const ModalResult rf = modal_analysis(fine, ef);
  if (!rf.ok()) return err;
  const std::vector<Eigen::Index> ei = elastic(rf);
  // Both models' shapes on the model's own free DOFs (its nodes keep their ids and DOFs in the refined one).
  std::vector<int> rows;
  for (int n = 0; n < static_cast<int>(model.nodes().size()); ++n)
    for (int t = 0; t < kNumDofTypes; ++t)
      if (model.dof_map().eq(n, static_cast<Dof>(t)) >= 0) rows.push_back(fine.dof_map().eq(fine.node_index(model.nodes()[n].id), static_cast<Dof>(t)));
  Eigen::MatrixXd A(static_cast<Eigen::Index>(rows.size()), err.size()), B(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(ei.size()));
  for (Eigen::Index j = 0; j < err.size(); ++j) A.col(j) = coarse.modes.col(ec[static_cast<std::size_t>(j)]);
  for (std::size_t j = 0; j < ei.size(); ++j)
    for (std::size_t r = 0; r < rows.size(); ++r) B(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(j)) = rows[r] >= 0 ? rf.modes(rows[r], ei[j]) : 0.0;
  const Eigen::MatrixXd mac = mac_matrix(A, B);
  for (Eigen::Index j = 0; j < err.size(); ++j) {
    Eigen::Index best = 0;
    if (mac.cols() == 0 || mac.row(j).maxCoeff(&best) < 0.9) continue;
    const double f = coarse.frequencies_hz[ec[static_cast<std::size_t>(j)]], g = rf.frequencies_hz[ei[static_cast<std::size_t>(best)]];
    err[j] = std::abs(f - g) / f;
  }
  return err;
}

}  // namespace dynid
