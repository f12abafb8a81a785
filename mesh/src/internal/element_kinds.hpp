// The element kinds registered in elements/registry.cpp, and what they share (internal).
#pragma once

#include <Eigen/Core>
#include <string>

#include "dynid/mesh/element.hpp"
#include "internal/element_kernels.hpp"

namespace dynid {
struct Material;
struct Section;
}  // namespace dynid

namespace dynid::internal {

// One function per kind, each returning its single shared instance (defined in the kind's own file).
const ElementKind& beam2d_kind();
const ElementKind& frame2d_kind();
const ElementKind& frame3d_kind();
const ElementKind& point_mass_kind();
const ElementKind& spring_kind();
const ElementKind& matrix_kind();

/// "element 12 (frame2d)": how error messages name an element.
std::string element_label(const Element& e);
bool finite_positive(double v);
std::string fmt_num(double v);
/// The checks every node-based element starts with: 1 or 2 nodes that exist (resolved into *s.nodes), and
/// finite positive property factors.
void setup_ends(const ElementSetup& s);
/// The layout of an element that uses the DOF types `mask` at each of its nodes (node-major).
std::vector<std::pair<int, Dof>> node_major_layout(const Model& m, int e, DofMask mask);
/// Zero matrices for every part of an n x n element.
void zero_parts(Eigen::Index n, ElementParts* p);

/// Beams and frames: a two-node member with a material and a section, whose local matrices come from the member
/// kernels (element_kernels.hpp) and are rotated to global coordinates by T.
class MemberKind : public ElementKind {
 public:
  bool is_member() const override { return true; }
  void setup(const ElementSetup& s) const override;
  std::vector<std::pair<int, Dof>> layout(const Model& m, int e, const std::vector<DofMask>& active) const override;
  ElementParts parts(const Model& m, int e) const override;
  void matrices(const Model& m, int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const override;
  Eigen::MatrixXd unit_geometric_stiffness(const Model& m, int e) const override;
  Eigen::MatrixXd point_interpolation(const Model& m, int e, double xi, Eigen::MatrixXd* dN) const override;
  std::vector<BendingPlane> bending_planes(const Model& m, int e) const override;
  double axial_force(const Model& m, int e, const Eigen::VectorXd& u) const override;

 protected:
  /// DOF types at each of the two nodes.
  virtual DofMask node_dofs() const = 0;
  /// Checks particular to the type, after the common ones (a, b: end coordinates, L: length).
  virtual void check_geometry(const ElementSetup& s, const Material& m, const Section& sec, const Eigen::Vector3d& a,
                              const Eigen::Vector3d& b, double L) const = 0;
  /// Local matrices (`loc`) and the map T from the element's global DOFs to its local DOFs; `axial_force`
  /// overrides the element's preload when not null.
  void local(const Model& m, int e, MemberLocal* loc, Eigen::MatrixXd* T, const double* axial_force = nullptr,
             MemberProps* props = nullptr) const;
  /// Rows = local x, y, z axes in global coordinates (2D members: z is the global z).
  Eigen::Matrix3d axes(const Model& m, int e) const;
  /// Maps the frame's T (from (ux, uy, rz) or (ux, uy, uz, rx, ry, rz) per node) to the element's own DOFs.
  /// Default: the same DOFs, T unchanged, and T block diagonal with 3x3 rotations, so matrices() rotates
  /// block by block.
  virtual void embed(Eigen::MatrixXd* T) const { (void)T; }
  virtual bool block_rotation() const { return true; }
};

}  // namespace dynid::internal
