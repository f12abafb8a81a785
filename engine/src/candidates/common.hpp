// Helpers shared by the candidate kinds (internal).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "dynid/engine/candidate.hpp"

namespace dynid::internal {

std::string fmt_value(double v, int digits);
std::string with_std(const PhysicalValue& v);  ///< "2.1e4 N m/rad ± 4 %"

/// A term linear in one parameter: dK = theta AK, dM = theta AM (either may be empty).
CustomTerm linear_term(std::vector<int> dofs, Eigen::MatrixXd AK, Eigen::MatrixXd AM, int param);

/// An element's stiffness without geometric stiffness (Ks), with it (K), its mass (M), bending stiffness (Kb)
/// and translational mass (Mt); beams and frames also their length and section properties.
struct Member {
  int e = -1;
  std::vector<int> dofs;
  std::vector<std::pair<int, Dof>> types;
  Eigen::MatrixXd K, Ks, M, Kb, Mt;
  double L = 0, EI = 0, EA = 0, GA = 0, rhoA = 0, rhoI = 0;
};
Member member(const Model& model, int e);

/// The mass an element moves in a rigid translation, largest over x, y, z (r^T M r with r = 1 on the element's
/// DOFs of that direction): the mass of a matrix element, which has no section to compute it from.
double translational_mass(const Model& model, int e);

/// Members (beams and frames) of group `g` ("" = all), as element indices.
std::vector<int> group_members(const Model& m, const std::string& g);
/// The group names of a model's members when there is more than one ("" first: all members).
std::vector<std::string> member_groups(const Model& m);
/// "all members" or "the members of group 'beam'".
std::string group_words(const std::string& g);

/// Per node index, its restrained DOFs that are supports. A DOF type restrained at every node that has it (active)
/// is no support: it holds a plane model in its plane (a plane frame given as a space frame with uz, rx, ry fixed,
/// a beam2d line as frame2d with ux fixed), and a support, a support spring, the end of a member chain or the
/// level gravity points from would all be read into it. Restraints on other DOF types are supports.
std::vector<DofMask> support_restraints(const Model& m);

}  // namespace dynid::internal
