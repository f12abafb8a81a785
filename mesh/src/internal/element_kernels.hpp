// Element kernels: local matrices and transformations of the beam and frame elements (internal).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynid::internal {

/// Local matrices of a straight two-node member, each part linear in one property.
/// 2D (beam/frame, 6x6, order u1 w1 t1 u2 w2 t2): Kb uses EI = E*Iz, Mr the Rayleigh rotary inertia rho*Iz.
/// 3D (12x12, order u v w tx ty tz per node): Kb uses E*Iy and E*Iz, Kt uses G*J, Mr holds torsional inertia
/// rho*(Iy+Iz) always and the Rayleigh bending rotary inertia when `rotary` is set.
struct MemberProps {
  double L = 0;
  double EA = 0, EIy = 0, EIz = 0, GJ = 0;
  double rhoA = 0, rhoIy = 0, rhoIz = 0;
  bool lumped = false;
  bool rotary = false;
};

struct MemberLocal {
  Eigen::MatrixXd Ka, Kb, Kt, Mt, Mr;
};

void frame2d_local(const MemberProps& p, MemberLocal* out);
void frame3d_local(const MemberProps& p, MemberLocal* out);

/// Rotation to local axes (rows = local x, y, z in global coordinates) of a 3D member from node a to node b.
/// `orientation` is a vector in the local x-z plane; zero picks global Z, or global X for members along Z.
/// Returns false if the orientation is parallel to the member.
bool frame3d_axes(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& orientation,
                  Eigen::Matrix3d* R);

}  // namespace dynid::internal
