// dynid/engine/candidate.hpp -- the hypotheses of missing-physics discovery: candidate augmentations of a
// model (a small parametric dK(theta), dM(theta) with bounds, a prior and a physical meaning) and the registry
// of their kinds.
//
// A new kind of missing physics is one class derived from Candidate (its parameters, its terms, its values in
// physical units) and one CandidateKind (its name, nature and how it places candidates on a model) added to
// DiscoveryOptions::extra_kinds, or to builtin_candidate_kinds() for a kind that ships with dynid
// (engine/src/candidates/registry.cpp). check_candidate() (candidate_checks.hpp) tests the invariants every
// candidate must satisfy; examples/custom_candidate.cpp is a complete example.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/modal_data.hpp"
#include "dynid/engine/parametric.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

/// Where a candidate acts (user ids).
struct Site {
  std::vector<int> nodes, elements;
};

/// One parameter of a candidate, in the candidate's own dimensionless units (well scaled for the optimiser). The
/// first parameter is the effect's magnitude (zero effect at its nominal value); others (a position) follow.
/// Its prior, truncated to [lower, upper], is centred on `nominal` with `prior_scale` the physically plausible
/// magnitude of the effect: a normal of that standard deviation (a property that changes by a fraction), or,
/// heavy-tailed, the density (1/s) / (1 + |x - nominal| / s)^2 with median s (a stiffness, a flexibility, a mass, a
/// force that may lie anywhere over orders of magnitude: a joint from rigid to pinned has fixity factor
/// 1 / (1 + x / s) uniform on [0, 1]); prior_scale = 0 means uniform on the bounds. Discovery's evidence weighs
/// the prior's width against the posterior's (the Occam factor).
struct CandidateParameter {
  enum class Prior { kNormal, kHeavyTailed };
  std::string name;
  double nominal = 0, lower = 0, upper = 1;
  double prior_scale = 1;
  Prior prior = Prior::kNormal;
};

/// A parameter in physical units (what the report states).
struct PhysicalValue {
  std::string name, unit;
  double value = 0, std = 0;
};

/// What a candidate changes: stiffness (a spring, a release, damage, a preload), mass, or both.
enum class Nature { kStiffness, kMass, kBoth };
const char* to_string(Nature n);  // "stiffness", "mass", "stiffness and mass"

/// A model augmentation hypothesis.
class Candidate {
 public:
  virtual ~Candidate() = default;
  virtual std::string kind() const = 0;           ///< "semi_rigid_joint", "lumped_mass", ...
  /// The physics the candidate stands for, shared by the kinds that model one effect at different
  /// discretisations: "attached_mass" for a mass at a node, between the nodes of a member or spread over one
  /// element; "local_stiffness" for one element or a run of elements stiffer or softer. Discovery's prior is
  /// uniform over the physics and over all the sites of each, and it weighs the stories by it
  /// (DiscoverySummary::kind_probability); by default the kind itself.
  virtual std::string physics() const { return kind(); }
  virtual Nature nature() const = 0;
  virtual std::string description() const = 0;    ///< one line: "rotational spring between element 12 and node 5"
  virtual Site site() const = 0;
  virtual bool global() const { return false; }   ///< acts on the whole structure (or a group)
  /// Parameters, with the model at its nominal state at their `nominal` values (dK = dM = 0 there).
  virtual std::vector<CandidateParameter> parameters() const = 0;
  /// dK, dM as custom terms on `model`, on this candidate's parameters numbered from `first` in the
  /// ParametricModel (the caller adds the parameters, then these terms; see install_candidates()).
  virtual std::vector<CustomTerm> terms(const Model& model, int first) const = 0;
  /// The fitted parameters in physical units (theta, std: this candidate's, dimensionless).
  virtual std::vector<PhysicalValue> physical(const Eigen::VectorXd& theta, const Eigen::VectorXd& std) const = 0;
  /// What was left out, in words, with the values ("the base at node 1 is not fixed: rotational spring ...").
  virtual std::string finding(const std::vector<PhysicalValue>& values) const = 0;
  /// Whether fitted values (theta) are physically possible for what the candidate stands for, beyond its bounds
  /// (which shape its prior): a fit outside is no explanation. Sensors of tens of kilograms are not the sensors'
  /// mass. By default every value within the bounds.
  virtual bool plausible(const Eigen::VectorXd& /*theta*/) const { return true; }
};

/// What a kind needs to place its candidates on a model, computed once per discovery: the model, the data and
/// the structure's own scales.
struct CandidateContext {
  const Model* model = nullptr;
  const ModalData* measured = nullptr;
  double structure_mass = 0;      ///< members (rho A L), point masses and matrix elements (rigid-translation mass)
  std::vector<char> node_used;    ///< per node index: some element connects to it
  /// Per node index: the restrained DOFs that are supports (a DOF type restrained at every node that has it holds a
  /// plane model in its plane: no support).
  std::vector<DofMask> support;
  /// Per node index: the members ending there, as (element index, end 0 or 1).
  std::vector<std::vector<std::pair<int, int>>> member_ends;
  /// Members as the engineer sees them: maximal chains of collinear elements of one group joined at nodes where
  /// only they meet (element indices from one end to the other); a member of one element is a chain of one.
  std::vector<std::vector<int>> members;
  Eigen::VectorXd stiffness_diagonal;  ///< K_ii of the assembled model, per equation
  /// The band: the model's elastic modes (free DOFs x r, mass-normalised) paired with the data, and their
  /// eigenvalues omega^2. Candidates take their units from it (what the data can see), never from the mesh.
  Eigen::MatrixXd band_modes;
  Eigen::VectorXd band_eigenvalues;
  /// Per equation, the stiffness the band's modes see there: 1 / sum_r phi_ir^2 / omega_r^2 over the band,
  /// capped at K_ii. A spring this stiff shifts the band's eigenvalues by 100 % in all (first order); unlike K_ii it
  /// does not grow as the mesh is refined.
  Eigen::VectorXd band_stiffness;
  std::vector<int> sensor_nodes;       ///< node indices carrying sensors
  std::vector<int> suspension_nodes;   ///< free-free models: node indices of the suspension points
  Eigen::Vector3d gravity = Eigen::Vector3d(0, -1, 0);  ///< direction of gravity (unit)
  double gravity_acceleration = 9.81; ///< in the model's units (SI: m/s^2)
  /// One kilogram in the model's mass unit, for candidates about hardware of known size (sensors): as the
  /// densities say (mesh/units.hpp: 1 for kg, 1e-3 for t), else 1 when values are labelled SI
  /// (DiscoveryOptions::si_units), 0 (unknown) when not.
  double kilogram = 1;
};

/// A kind of candidate: its name (as in case files' `kinds:`), nature, a one-line summary, and how it places
/// its candidates on a model (every admissible site, or one global candidate).
struct CandidateKind {
  std::string name;
  Nature nature = Nature::kStiffness;
  std::string summary;
  std::function<std::vector<std::unique_ptr<Candidate>>(const CandidateContext&)> place;
};

/// The kinds dynid ships, in a fixed order (engine/src/candidates/registry.cpp).
const std::vector<CandidateKind>& builtin_candidate_kinds();

/// Adds the candidates' parameters (kCustom, with their bounds) and terms to `pm`, in order; returns the index of
/// each candidate's first parameter. For host codes that fit or evaluate candidates themselves.
std::vector<int> install_candidates(ParametricModel* pm, const std::vector<const Candidate*>& set);

}  // namespace dynid
