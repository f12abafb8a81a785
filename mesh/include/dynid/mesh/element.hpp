// dynid/mesh/element.hpp -- the element interface: what one element type contributes to a Model (its checks, DOF
// layout, stiffness, mass and geometric stiffness) and the registry that maps an ElementType to it.
//
// Adding an element type: one ElementKind subclass (its own file in mesh/src/elements/) plus one line in the
// registry (mesh/src/elements/registry.cpp) and its ElementType value below. Model, the assembly, the sensitivities
// and the candidates ask the kind; nothing else switches on the type.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dynid/mesh/dof.hpp"

namespace dynid {

class Model;
struct Element;
struct ElementParts;

/// One bending plane of a member, in global coordinates on the element's DOFs (Model::member_bending_planes): its
/// bending stiffness K as the model has it, the end rotations' difference d = theta_1 - theta_2 about the plane's
/// normal, E I, G A (no shear coefficient), L; and the bending mass it has as a Timoshenko beam of shear parameter
/// phi = 12 E I / (kappa G A L^2), consistent with its stiffness (Friedman & Kosmatka 1993): translational
/// (P[0] + phi P[1] + phi^2 P[2]) / (1 + phi)^2 and rotary (P[3] + phi P[4] + phi^2 P[5]) / (1 + phi)^2, P = mass.
/// P[0] is the cubic-Hermite mass, P[3] the Rayleigh rotary inertia. The two-node Timoshenko stiffness at phi is
/// (K_EB + phi (E I / L) d d^T) / (1 + phi), K_EB the Euler-Bernoulli K.
struct BendingPlane {
  Eigen::MatrixXd K;
  Eigen::VectorXd d;
  double EI = 0, GA = 0, L = 0;
  std::array<Eigen::MatrixXd, 6> mass;
};

/// The element types; element_kind(t) gives each one's behaviour. Names (case files): element_type_name().
enum class ElementType { Beam2D, Frame2D, Frame3D, PointMass, Spring, Matrix };

/// What Model::finalize() hands an element kind to check one element and activate its DOFs (first pass).
struct ElementSetup {
  const Model& model;            ///< nodes, materials, sections, node_index(), mass options (not finalized yet)
  const Element& element;        ///< the element being set up
  const std::string& who;        ///< "element 12 (frame2d)", to start error messages
  std::array<int, 2>* nodes;     ///< out: node indices of the element's ends (-1 = none)
  std::vector<DofMask>* active;  ///< in/out: DOF types active at each node (indexed by node index)
  std::vector<char>* connected;  ///< out: nodes drawn by the element that need not carry its DOFs (set to 1)
};

/// The behaviour of one element type. Stateless and immutable (one shared instance per type): every method reads
/// the element from the model and may be called concurrently.
///
/// DOF layout: (node index, DOF type) pairs in element-matrix order, fixed at Model::finalize(). Matrices are in
/// global coordinates on that layout, symmetric, full storage, and include the element's property factors.
class ElementKind {
 public:
  virtual ~ElementKind() = default;
  virtual ElementType type() const = 0;
  /// The name in case files: "beam2d", "frame2d", "frame3d", "point_mass", "spring", "matrix".
  virtual std::string_view name() const = 0;

  /// A two-node member with a material, a section and an axis (beams and frames), which has a geometric
  /// stiffness, a point interpolation along its axis and an axial force.
  virtual bool is_member() const { return false; }
  /// A member in space: six DOFs per node, local axes from an orientation vector.
  virtual bool spatial() const { return false; }
  /// Whether the element can have stiffness (springs: only stiffness) and mass (point masses: only mass).
  virtual bool has_stiffness() const { return true; }
  virtual bool has_mass() const { return true; }

  /// finalize(), first pass: checks the element's data (throws InputError starting with s.who), resolves its end
  /// nodes into *s.nodes and activates the DOF types it uses at its nodes in *s.active.
  virtual void setup(const ElementSetup& s) const = 0;
  /// finalize(), second pass (after every element is set up): the element's DOF layout, given the DOF types
  /// active at each node.
  virtual std::vector<std::pair<int, Dof>> layout(const Model& m, int e, const std::vector<DofMask>& active) const = 0;

  /// Stiffness and mass split into parts linear in one property each (see ElementParts).
  virtual ElementParts parts(const Model& m, int e) const = 0;
  /// K and M (either may be null). Default: the sums of parts(); a kind may compute them faster, with the same
  /// result.
  virtual void matrices(const Model& m, int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const;
  /// finalize(), after layout(): which pairs (a, b), a < b, of the element's layout positions can hold nonzero
  /// K or M entries, for an element that couples few of its DOFs (ElementSource::element_coupling). Default: every
  /// pair (false, no pairs).
  virtual bool coupling(const Model& m, int e, const std::vector<std::pair<int, Dof>>& layout,
                        std::vector<std::pair<int, int>>* pairs) const;

  // ---- members only (the defaults throw InputError naming the element, or return 0) ------------------------
  /// The consistent geometric stiffness of a unit axial tension (int N'^T N' dx per bending plane).
  virtual Eigen::MatrixXd unit_geometric_stiffness(const Model& m, int e) const;
  /// The 3 x n interpolation of the global translation at xi in [0, 1] along the axis (see Model).
  virtual Eigen::MatrixXd point_interpolation(const Model& m, int e, double xi, Eigen::MatrixXd* dN) const;
  /// The member's bending planes (see BendingPlane).
  virtual std::vector<BendingPlane> bending_planes(const Model& m, int e) const;
  /// The axial force (tension > 0) that element displacements u produce; 0 for elements without axial DOFs.
  virtual double axial_force(const Model& m, int e, const Eigen::VectorXd& u) const;
};

/// The registered kind of an element type.
const ElementKind& element_kind(ElementType t);
/// Every registered kind, in ElementType order.
const std::vector<const ElementKind*>& element_kinds();

/// "beam2d", "frame2d", "frame3d", "point_mass", "spring", "matrix"
std::string_view element_type_name(ElementType t);
bool parse_element_type(std::string_view name, ElementType* out);
/// Beams and frames: two-node members with a section, an axis and bending (the others are point masses,
/// springs and matrix elements).
inline bool is_member(ElementType t) { return element_kind(t).is_member(); }

}  // namespace dynid
