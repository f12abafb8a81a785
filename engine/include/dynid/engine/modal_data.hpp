// dynid/engine/modal_data.hpp -- modal data at measured DOFs (a test, or a simulation sampled like one).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dynid/engine/modal.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

/// A measured DOF: a node (user id) and a direction.
struct MeasuredDof {
  int node = 0;
  Dof dof = Dof::UY;
  bool operator==(const MeasuredDof& o) const { return node == o.node && dof == o.dof; }
};
std::string to_string(const MeasuredDof& d);  // "14uy"

/// Frequencies and real mode shapes at a set of DOFs. Shapes may have any scaling and sign.
struct ModalData {
  std::vector<MeasuredDof> dofs;   ///< rows of `shapes`
  Eigen::VectorXd frequencies_hz;  ///< one per mode (column of `shapes`)
  Eigen::MatrixXd shapes;          ///< dofs x modes
  Eigen::VectorXd damping_ratios;  ///< optional (empty or one per mode)
  Eigen::VectorXd mpc;             ///< optional modal phase collinearity of identified modes (1 = real mode)
  Eigen::VectorXd frequency_std_hz;  ///< optional standard deviation of each frequency (identification)
  Eigen::VectorXd damping_std;       ///< optional standard deviation of each damping ratio
  /// Optional standard deviation of each mode's shape entries, relative to the mode's largest entry.
  Eigen::VectorXd shape_std;
  /// Optional standard deviation of every shape entry (dofs x modes, in the units of `shapes`). An entry with
  /// std 0 is exact: the entry each mode was normalised by (its value fixes the mode's scale).
  Eigen::MatrixXd shape_entry_std;
  std::string source;              ///< where it came from (file, "simulation of ...")
  int num_modes() const { return static_cast<int>(frequencies_hz.size()); }
  /// Throws InputError if sizes disagree or values are not finite / frequencies not positive.
  void validate(const std::string& what) const;
};

/// Equation numbers of measured DOFs in a model. Throws InputError naming the DOF when a node does not exist,
/// or the DOF is not a DOF of the model (inactive or restrained), with what the node does have.
std::vector<int> measured_equations(const Model& model, const std::vector<MeasuredDof>& dofs);

/// Equation numbers of the translational DOFs (x, y, z) of every node.
std::vector<int> translation_equations(const Model& model);
/// How well sensors see a mode (a column of a modal result): its mean square at the sensor equations `rows`
/// over its mean square at `translations` (translation_equations). 1 = as well as an average translation; an
/// axial or out-of-plane mode under transverse or in-plane sensors is near 0 (its MAC with any measurement is
/// noise). 0 when the mode does not move the translations.
double sensor_visibility(const Eigen::Ref<const Eigen::VectorXd>& mode, const std::vector<int>& rows, const std::vector<int>& translations);
/// Model modes seen below this visibility are no pairing partners for measured modes (issue 16).
constexpr double kMinPairingVisibility = 0.01;

/// Every free DOF of a model, in equation order.
std::vector<MeasuredDof> all_dofs(const Model& model);
/// The free DOFs of the given types (e.g. translations) at every node (or at `nodes` if not empty).
std::vector<MeasuredDof> dofs_of_types(const Model& model, DofMask types, const std::vector<int>& nodes = {});

/// The modes `keep` (0-based, in that order) of modal data, every per-mode field (damping, MPC, standard
/// deviations, entry standard deviations) cut alike.
ModalData modes_subset(const ModalData& d, const std::vector<int>& keep);

/// A model's modes sampled at DOFs, as a test would see them: `first` is the first mode taken (0-based, e.g. 2
/// to skip two rigid-body modes), `count` modes. Shapes are the mass-normalised mode shapes at those DOFs.
ModalData sample_modes(const Model& model, const ModalResult& modes, const std::vector<MeasuredDof>& dofs,
                       int first, int count, const std::string& source);

}  // namespace dynid
