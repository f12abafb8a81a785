// dynid/mesh/model.hpp -- the structural model: nodes, materials, sections, elements, supports.
//
// Units are the user's, consistently (the bundled cases use SI: m, kg, s, N). Element types:
//   Beam2D   Euler-Bernoulli beam along the global x axis; DOFs (uy, rz) per node; bending stiffness E*Iz.
//   Frame2D  plane frame in the x-y plane; DOFs (ux, uy, rz) per node (Chandrupatla & Belegundu).
//   Frame3D  space frame; DOFs (ux, uy, uz, rx, ry, rz) per node; local axes from an orientation vector.
//   PointMass  mass m on the node's active translations, rotary inertia (Jx, Jy, Jz) on its active rotations.
//   Spring   translational or rotational spring on a set of DOF types, grounded (one node) or between two nodes.
//   Matrix   an element given by its matrices: any list of (node, DOF type) pairs with stiffness and mass
//            matrices in global coordinates (element or group matrices exported from another FE code).
// Each element's global DOF map and its stiffness and mass matrices are available per element
// (element_dofs(), element_matrices(), element_parts()); sensitivities and residual forces use them. What each
// type contributes is its ElementKind (dynid/mesh/element.hpp); Model itself does not switch on the type.
#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "dynid/mesh/dof.hpp"
#include "dynid/mesh/element.hpp"
#include "dynid/mesh/element_source.hpp"

namespace dynid {

enum class MassType { Consistent, Lumped };

struct Node {
  int id = 0;                               // user id (any integer, unique)
  Eigen::Vector3d x = Eigen::Vector3d::Zero();  // coordinates
};

struct Material {
  std::string name;
  double E = 0;     // Young's modulus
  double G = 0;     // shear modulus; 0 = E / (2 (1 + nu))
  double nu = 0.3;  // Poisson's ratio, used when G = 0
  double rho = 0;   // density
  double shear_modulus() const { return G > 0 ? G : E / (2.0 * (1.0 + nu)); }
};

struct Section {
  std::string name;
  double A = 0;   // area
  double Iy = 0;  // second moment about the local y axis (3D frames: bending in the local x-z plane)
  double Iz = 0;  // second moment about the local z axis (bending in the plane of 2D beams and frames)
  double J = 0;   // torsion constant (3D frames); 0 = Iy + Iz
  /// Timoshenko shear coefficient kappa (5/6 for a rectangle): bending stiffness with shear deformation,
  /// phi = 12 E I / (kappa G A L^2). 0 = Euler-Bernoulli (no shear deformation).
  double shear_factor = 0;
  double torsion_constant() const { return J > 0 ? J : Iy + Iz; }
};

/// Multiplicative factors on an element's properties (1 = nominal). Damage studies and model updating act
/// through them: stiffness ~ E, mass ~ rho, both ~ A (axial stiffness and translational mass) and I (bending).
struct PropertyFactors {
  double E = 1, rho = 1, A = 1, I = 1;
};

/// The content of a Matrix element: its DOFs as (user node id, DOF type) pairs, in matrix order, and its
/// stiffness and mass matrices on them (global coordinates, symmetric, full storage). Shared between copies of
/// a model (it is never changed after construction).
struct MatrixElementData {
  std::vector<std::pair<int, Dof>> dofs;
  /// The nodes the element connects (user ids), for geometry and drawing; may include supported nodes that
  /// have no DOF in `dofs`. Empty = the nodes of `dofs`.
  std::vector<int> nodes;
  Eigen::MatrixXd K, M;
};

struct Element {
  int id = 0;
  ElementType type = ElementType::Frame2D;
  std::array<int, 2> node_ids{{0, 0}};  // user node ids; node_ids[1] unused for one-node elements
  int num_nodes = 2;                    // 1 for point masses and grounded springs
  int material = -1;                    // index into Model::materials() (beams and frames)
  int section = -1;                     // index into Model::sections()  (beams and frames)
  Eigen::Vector3d orientation = Eigen::Vector3d::Zero();  // Frame3D: a vector in the local x-z plane; 0 = default
  double mass = 0;                                        // PointMass
  Eigen::Vector3d rotary_inertia = Eigen::Vector3d::Zero();  // PointMass: about global x, y, z
  DofMask spring_dofs = 0;                                   // Spring: DOF types it acts on
  double stiffness = 0;                                      // Spring: per DOF (N/m or N m/rad)
  double axial_force = 0;  // beams and frames: axial force (tension > 0) -> geometric stiffness (preload)
  PropertyFactors factors;
  std::string group;  // optional group name (updating parameters may act per group)
  /// Matrix elements: DOFs and matrices; K scales with factors.E, M with factors.rho. node_ids / num_nodes
  /// hold the element's first two distinct nodes (for drawing); make_matrix_element() fills them.
  std::shared_ptr<const MatrixElementData> matrix;
};

/// A Matrix element with user id `id` from its DOFs and matrices (see MatrixElementData).
Element make_matrix_element(int id, MatrixElementData data, std::string group = "");

/// Element matrices split into parts that are linear in one property each, in global coordinates:
///   K = K_axial (~ E A) + K_bending (~ E I) + K_torsion (~ G J) + K_discrete (springs, matrix elements ~ E)
///       + K_geometric (~ axial force; independent of the property factors)
///   M = M_translational (~ rho A) + M_rotary (~ rho I, only with rotary inertia) + M_discrete (point masses, matrix elements ~ rho)
/// Each part already includes the element's current property factors.
struct ElementParts {
  Eigen::MatrixXd K_axial, K_bending, K_torsion, K_discrete, K_geometric;
  Eigen::MatrixXd M_translational, M_rotary, M_discrete;
  Eigen::MatrixXd K() const;
  Eigen::MatrixXd M() const;
};

/// The Timoshenko bending mass at shear parameter phi from three parts (BendingPlane::mass P[0..2] for the
/// translational mass, P[3..5] for the rotary one): (c0 + phi c1 + phi^2 c2) / (1 + phi)^2.
template <class Mat>
Mat shear_mass(const Mat& c0, const Mat& c1, const Mat& c2, double phi) {
  return (c0 + phi * c1 + phi * phi * c2) / ((1.0 + phi) * (1.0 + phi));
}

/// The structural model. Build it with the add_* functions, then call finalize(), which validates everything,
/// resolves node ids and numbers the DOFs. After finalize() the model is an ElementSource.
class Model : public ElementSource {
 public:
  // ---- building --------------------------------------------------------------------------------------
  int add_node(int id, const Eigen::Vector3d& x);  // returns the node index; throws InputError on duplicate id
  int add_material(const Material& m);             // returns the material index
  int add_section(const Section& s);               // returns the section index
  int add_element(const Element& e);               // returns the element index (ids must be unique)
  /// Restrains DOF types at a node (given by user id). Restraining an inactive DOF type is allowed (ignored).
  void restrain(int node_id, DofMask dofs);
  void set_mass_type(MassType t) { mass_type_ = t; }
  void set_rotary_inertia(bool on) { rotary_inertia_ = on; }
  /// Declares that the structure is meant to be unsupported (free-free): rigid-body modes are then expected.
  /// Without this, finalize() rejects a model whose supports and springs leave rigid-body motions free.
  void set_free_free(bool on) { free_free_ = on; }

  /// Validates the model and numbers the DOFs. Throws InputError naming the entity and the problem.
  void finalize();
  bool finalized() const { return finalized_; }

  // ---- access ----------------------------------------------------------------------------------------
  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<Section>& sections() const { return sections_; }
  const std::vector<Element>& elements() const { return elements_; }
  Element& element(int e) { return elements_[e]; }  // e.g. to change property factors; DOFs stay valid
  MassType mass_type() const { return mass_type_; }
  bool rotary_inertia() const { return rotary_inertia_; }
  bool free_free() const { return free_free_; }
  const DofMap& dof_map() const { return dofs_; }
  /// Node index of a user id, or -1.
  int node_index(int id) const;
  /// Element index of a user id, or -1.
  int element_index(int id) const;
  /// Node indices of element e (resolved at finalize()).
  const std::array<int, 2>& element_nodes(int e) const { return element_nodes_[e]; }
  int material_index(const std::string& name) const;  // -1 if absent
  int section_index(const std::string& name) const;   // -1 if absent
  /// Non-fatal remarks collected by finalize() (e.g. nodes not connected to any element).
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Human-readable DOF description: "uy at node 14".
  std::string describe_dof(int eq) const;

  // ---- ElementSource ----------------------------------------------------------------------------------
  int num_dofs() const override { return dofs_.num_free(); }
  int num_elements() const override { return static_cast<int>(elements_.size()); }
  void element_dofs(int e, std::vector<int>* dofs) const override;
  void element_matrices(int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const override;
  /// Matrix elements are coupled node by node: two nodes' DOF blocks are reserved when some K or M entry between
  /// them is nonzero (each node's own block always is). False when that is every pair (and for other elements).
  bool element_coupling(int e, std::vector<std::pair<int, int>>* pairs) const override;

  /// DOF types of element e at each of its nodes, in element-matrix order (node-major).
  std::vector<std::pair<int, Dof>> element_dof_types(int e) const;
  /// The element's matrices split by property (see ElementParts).
  ElementParts element_parts(int e) const;
  /// Beams and frames: the consistent geometric stiffness of a unit axial tension, in global coordinates on the
  /// element's DOFs (int N'^T N' dx per bending plane). Scaled by rho I it is also the Rayleigh rotary inertia.
  Eigen::MatrixXd unit_geometric_stiffness(int e) const;
  /// Beams and frames: the element's bending planes (one for plane members, two for space frames: local x-y
  /// about Iz, local x-z about Iy), each with what a shear-deformable (Timoshenko) member needs (BendingPlane).
  std::vector<BendingPlane> member_bending_planes(int e) const;
  /// Beams and frames: the global translation (x, y, z) of the point at xi in [0, 1] along the member's axis
  /// from the element's DOFs (element_dof_types order), with the shape functions of its stiffness: linear
  /// axially, cubic Hermite transversely (Euler-Bernoulli). A 3 x n matrix N(xi); its derivative in xi in
  /// `dN` when not null. A mass m fixed at that point adds m N^T N to the mass matrix (consistently).
  Eigen::MatrixXd member_point_interpolation(int e, double xi, Eigen::MatrixXd* dN = nullptr) const;
  /// Beams and frames: the axial force (tension > 0) that element displacements `u` (element_dof_types order,
  /// global coordinates) produce: E A / L times the elongation.
  double member_axial_force(int e, const Eigen::VectorXd& u) const;

  /// Geometric rigid-body motions restricted to the free DOFs: columns are unit translations along x, y, z and
  /// unit rotations about x, y, z through the centroid of the nodes; columns that vanish on the free DOFs
  /// (e.g. z motions of a plane model) are left out. Labels in `labels` if non-null.
  Eigen::MatrixXd rigid_body_motions(std::vector<std::string>* labels = nullptr) const;
  /// The rigid-body motions that supports and springs leave free (an orthonormal basis of null(K) within the
  /// span of rigid_body_motions()), judged per motion by ||K r|| against || |K| |r| || (rounding level), not by
  /// any threshold on eigenvalues. Empty for a supported structure; 3 columns for a free-free plane frame.
  /// Each column gets a description in `descriptions` ("translation y", "rotation about z", ...).
  Eigen::MatrixXd free_rigid_body_modes(std::vector<std::string>* descriptions = nullptr) const;

 private:
  void require_finalized(const char* what) const;
  void require_rigid_body_support();
  std::vector<Node> nodes_;
  std::vector<Material> materials_;
  std::vector<Section> sections_;
  std::vector<Element> elements_;
  std::unordered_map<int, int> node_of_id_, element_of_id_;
  std::vector<std::pair<int, DofMask>> restraints_;  // (node id, dofs)
  std::vector<std::array<int, 2>> element_nodes_;
  std::vector<std::vector<std::pair<int, Dof>>> layouts_;  // per element: (node index, DOF type), set at finalize
  std::vector<std::vector<std::pair<int, int>>> coupling_;  // per element kind that couples few DOFs (element_coupling)
  std::vector<char> sparse_coupling_;
  MassType mass_type_ = MassType::Consistent;
  bool rotary_inertia_ = false;
  bool free_free_ = false;
  bool finalized_ = false;
  DofMap dofs_;
  std::vector<std::string> warnings_;
};

}  // namespace dynid
