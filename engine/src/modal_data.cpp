#include "dynid/engine/modal_data.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/mesh/error.hpp"

namespace dynid {

std::string to_string(const MeasuredDof& d) { return std::to_string(d.node) + std::string(dof_name(d.dof)); }

void ModalData::validate(const std::string& what) const {
  const Eigen::Index m = frequencies_hz.size();
  if (shapes.cols() != m)
    throw InputError(what + ": " + std::to_string(m) + " frequencies but " + std::to_string(shapes.cols()) + " mode shapes");
  if (shapes.rows() != static_cast<Eigen::Index>(dofs.size()))
    throw InputError(what + ": mode shapes have " + std::to_string(shapes.rows()) + " rows for " +
                     std::to_string(dofs.size()) + " DOFs");
  if (damping_ratios.size() != 0 && damping_ratios.size() != m)
    throw InputError(what + ": " + std::to_string(damping_ratios.size()) + " damping ratios for " + std::to_string(m) + " modes");
  auto optional = [&](const Eigen::VectorXd& v, const char* name) {
    if (v.size() != 0 && v.size() != m)
      throw InputError(what + ": " + std::to_string(v.size()) + " " + name + " values for " + std::to_string(m) + " modes");
  };
  optional(mpc, "MPC");
  optional(frequency_std_hz, "frequency standard deviation");
  optional(damping_std, "damping standard deviation");
  optional(shape_std, "shape standard deviation");
  auto non_negative = [&](const Eigen::VectorXd& v, const char* name) {
    for (Eigen::Index k = 0; k < v.size(); ++k)
      if (!std::isfinite(v[k]) || v[k] < 0)
        throw InputError(what + ": mode " + std::to_string(k + 1) + " has " + name + " " + std::to_string(v[k]) +
                         "; standard deviations must be finite and >= 0");
  };
  non_negative(frequency_std_hz, "frequency standard deviation");
  non_negative(shape_std, "shape standard deviation");
  if (shape_entry_std.size() != 0) {
    if (shape_entry_std.rows() != shapes.rows() || shape_entry_std.cols() != m)
      throw InputError(what + ": shape entry standard deviations are " + std::to_string(shape_entry_std.rows()) + " x " +
                       std::to_string(shape_entry_std.cols()) + " for shapes of " + std::to_string(shapes.rows()) + " DOFs x " +
                       std::to_string(m) + " modes; give one per shape entry");
    for (Eigen::Index k = 0; k < m; ++k)
      for (Eigen::Index i = 0; i < shapes.rows(); ++i)
        if (!std::isfinite(shape_entry_std(i, k)) || shape_entry_std(i, k) < 0)
          throw InputError(what + ": mode " + std::to_string(k + 1) + " has shape standard deviation " +
                           std::to_string(shape_entry_std(i, k)) + " at DOF " + to_string(dofs[static_cast<std::size_t>(i)]) +
                           "; standard deviations must be finite and >= 0");
    for (Eigen::Index k = 0; k < m; ++k)
      if ((shape_entry_std.col(k).array() > 0).count() == 0)
        throw InputError(what + ": mode " + std::to_string(k + 1) + " has a standard deviation of 0 at every shape entry; "
                         "only the entry a mode is normalised by is exact");
  }
  for (Eigen::Index k = 0; k < m; ++k) {
    if (!std::isfinite(frequencies_hz[k]) || frequencies_hz[k] <= 0)
      throw InputError(what + ": mode " + std::to_string(k + 1) + " has frequency " + std::to_string(frequencies_hz[k]) +
                       " Hz; frequencies must be finite and > 0 (leave rigid-body modes out)");
    for (Eigen::Index i = 0; i < shapes.rows(); ++i)
      if (!std::isfinite(shapes(i, k)))
        throw InputError(what + ": mode " + std::to_string(k + 1) + " has a NaN or Inf shape entry at DOF " +
                         to_string(dofs[static_cast<std::size_t>(i)]));
    if (shapes.col(k).squaredNorm() == 0) throw InputError(what + ": mode " + std::to_string(k + 1) + " has an all-zero shape");
  }
  for (std::size_t i = 0; i < dofs.size(); ++i)
    for (std::size_t j = i + 1; j < dofs.size(); ++j)
      if (dofs[i] == dofs[j]) throw InputError(what + ": DOF " + to_string(dofs[i]) + " is listed twice");
}

std::vector<int> translation_equations(const Model& model) {
  std::vector<int> eq;
  for (int n = 0; n < static_cast<int>(model.nodes().size()); ++n)
    for (int t = 0; t < 3; ++t)
      if (model.dof_map().eq(n, static_cast<Dof>(t)) >= 0) eq.push_back(model.dof_map().eq(n, static_cast<Dof>(t)));
  return eq;
}

double sensor_visibility(const Eigen::Ref<const Eigen::VectorXd>& mode, const std::vector<int>& rows, const std::vector<int>& translations) {
  double seen = 0, all = 0;
  for (int r : rows) seen += mode[r] * mode[r];
  for (int r : translations) all += mode[r] * mode[r];
  if (rows.empty() || translations.empty() || !(all > 0)) return 0;
  return (seen / static_cast<double>(rows.size())) / (all / static_cast<double>(translations.size()));
}

std::vector<int> measured_equations(const Model& model, const std::vector<MeasuredDof>& dofs) {
  std::vector<int> eq;
  eq.reserve(dofs.size());
  for (const MeasuredDof& d : dofs) {
    const int n = model.node_index(d.node);
    if (n < 0) throw InputError("measured DOF " + to_string(d) + ": node " + std::to_string(d.node) + " is not in the model");
    const int e = model.dof_map().eq(n, d.dof);
    if (e < 0) {
      const DofMask act = model.dof_map().active(n), res = model.dof_map().restrained(n);
      std::string why = has_dof(res, d.dof) ? "is restrained (a support)" : "is not a DOF of the model";
      throw InputError("measured DOF " + to_string(d) + ": " + std::string(dof_name(d.dof)) + " at node " +
                       std::to_string(d.node) + " " + why + "; the node's free DOFs are: " +
                       (dof_mask_string(act & ~res).empty() ? "none" : dof_mask_string(act & ~res)));
    }
    eq.push_back(e);
  }
  return eq;
}

std::vector<MeasuredDof> all_dofs(const Model& model) {
  std::vector<MeasuredDof> out;
  const DofMap& dm = model.dof_map();
  for (int i = 0; i < dm.num_free(); ++i) out.push_back({model.nodes()[dm.node_of(i)].id, dm.type_of(i)});
  return out;
}

std::vector<MeasuredDof> dofs_of_types(const Model& model, DofMask types, const std::vector<int>& nodes) {
  std::vector<MeasuredDof> out;
  const DofMap& dm = model.dof_map();
  for (int i = 0; i < dm.num_free(); ++i) {
    if (!has_dof(types, dm.type_of(i))) continue;
    const int id = model.nodes()[dm.node_of(i)].id;
    if (!nodes.empty() && std::find(nodes.begin(), nodes.end(), id) == nodes.end()) continue;
    out.push_back({id, dm.type_of(i)});
  }
  return out;
}

ModalData sample_modes(const Model& model, const ModalResult& modes, const std::vector<MeasuredDof>& dofs,
                       int first, int count, const std::string& source) {
  if (first < 0 || count < 1 || first + count > modes.eigenvalues.size())
    throw InputError("sample_modes: modes " + std::to_string(first + 1) + ".." + std::to_string(first + count) +
                     " requested, " + std::to_string(modes.eigenvalues.size()) + " computed");
  const std::vector<int> eq = measured_equations(model, dofs);
  ModalData d;
  d.dofs = dofs;
  d.source = source;
  d.frequencies_hz = modes.frequencies_hz.segment(first, count);
  d.shapes.resize(static_cast<Eigen::Index>(eq.size()), count);
  for (std::size_t i = 0; i < eq.size(); ++i) d.shapes.row(static_cast<Eigen::Index>(i)) = modes.modes.row(eq[i]).segment(first, count);
  return d;
}

ModalData modes_subset(const ModalData& d, const std::vector<int>& keep) {
  ModalData o = d;
  const Eigen::Index n = static_cast<Eigen::Index>(keep.size()), had = d.frequencies_hz.size();
  for (int k : keep)
    if (k < 0 || k >= had)
      throw InputError("modal data: mode " + std::to_string(k + 1) + " asked for, " + std::to_string(had) + " given");
  auto pick = [&](const Eigen::VectorXd& src, Eigen::VectorXd* dst) {
    if (src.size() != had) return;
    dst->resize(n);
    for (Eigen::Index j = 0; j < n; ++j) (*dst)[j] = src[keep[static_cast<std::size_t>(j)]];
  };
  auto pick_columns = [&](const Eigen::MatrixXd& src, Eigen::MatrixXd* dst) {
    if (src.cols() != had || src.size() == 0) return;
    dst->resize(src.rows(), n);
    for (Eigen::Index j = 0; j < n; ++j) dst->col(j) = src.col(keep[static_cast<std::size_t>(j)]);
  };
  pick(d.frequencies_hz, &o.frequencies_hz);
  pick_columns(d.shapes, &o.shapes);
  pick(d.damping_ratios, &o.damping_ratios);
  pick(d.mpc, &o.mpc);
  pick(d.frequency_std_hz, &o.frequency_std_hz);
  pick(d.damping_std, &o.damping_std);
  pick(d.shape_std, &o.shape_std);
  pick_columns(d.shape_entry_std, &o.shape_entry_std);
  return o;
}

}  // namespace dynid
