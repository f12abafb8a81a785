// Element kernels: local matrices and transformations of the beam and frame elements (internal).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace dynid::internal {

/// Local matrices of a straight two-node member, each part linear in one property.
/// 2D (beam/frame, 6x6, order u1 w1 t1 u2 w2 t2): Kb uses EI = E*Iz, Mr the rotary inertia rho*Iz.
/// 3D (12x12, order u v w tx ty tz per node): Kb uses E*Iy and E*Iz, Kt uses G*J, Mr holds torsional inertia
/// rho*(Iy+Iz) always and the bending rotary inertia when `rotary` is set. With shear deformation (phi > 0) the
/// bending masses are the Timoshenko element's (beam_mass), else the cubic-Hermite ones.
struct MemberProps {
  double L = 0;
  double EA = 0, EIy = 0, EIz = 0, GJ = 0;
  double rhoA = 0, rhoIy = 0, rhoIz = 0;
  /// Shear deformation (Timoshenko stiffness): phi = 12 E I / (kappa G A L^2) per bending plane; 0 = Euler-Bernoulli.
  double phiy = 0, phiz = 0;
  /// Axial force (tension > 0) for the geometric stiffness Kg.
  double P = 0;
  bool lumped = false;
  bool rotary = false;
};

struct MemberLocal {
  Eigen::MatrixXd Ka, Kb, Kt, Kg, Mt, Mr;
};

/// Bending stiffness of a two-node beam on (w1, t1, w2, t2) with shear deformation phi = 12 EI / (kappa G A L^2)
/// (Przemieniecki; phi = 0 is Euler-Bernoulli). s = +1 for w' = +t (x-y plane), -1 for the x-z plane. The
/// scalar type may be complex (complex-step derivatives).
template <class S>
Eigen::Matrix<S, 4, 4> beam_bending_k(double EI, double L, S phi, double s) {
  const S c = EI / (L * L * L) / (1.0 + phi);
  const double L2 = L * L;
  Eigen::Matrix<S, 4, 4> k;
  k << S(12), S(6 * L * s), S(-12), S(6 * L * s),                           //
      S(6 * L * s), (4.0 + phi) * L2, S(-6 * L * s), (2.0 - phi) * L2,      //
      S(-12), S(-6 * L * s), S(12), S(-6 * L * s),                          //
      S(6 * L * s), (2.0 - phi) * L2, S(-6 * L * s), (4.0 + phi) * L2;
  return c * k;
}

/// Consistent bending mass of the same two-node beam on (w1, t1, w2, t2), with the shape functions that make its
/// stiffness exact (Friedman & Kosmatka, "An improved two-node Timoshenko beam finite element", Computers &
/// Structures 47, 1993): translational rho A L / 210 (C0 + phi C1 + phi^2 C2) / (1 + phi)^2 and rotary (section
/// rotation t, not w') rho I / (30 L) (R0 + phi R1 + phi^2 R2) / (1 + phi)^2. At phi = 0 they are the cubic-Hermite
/// mass and the Rayleigh rotary inertia. Coefficient j = C_j (j = 0, 1, 2: translational) or R_{j-3} (j = 3, 4, 5:
/// rotary), already scaled by rho A L / 210 or rho I / (30 L); s as for beam_bending_k.
Eigen::Matrix4d beam_mass_coefficient(int j, double rhoA, double rhoI, double L, double s);

/// The translational (rotary = false) or rotary bending mass at shear parameter phi (shear_mass of those
/// coefficients; at phi = 0 the cubic-Hermite one alone).
Eigen::Matrix4d beam_mass(double rhoA, double rhoI, double L, double phi, double s, bool rotary);

void frame2d_local(const MemberProps& p, MemberLocal* out);
void frame3d_local(const MemberProps& p, MemberLocal* out);

/// Rotation to local axes (rows = local x, y, z in global coordinates) of a 3D member from node a to node b.
/// `orientation` is a vector in the local x-z plane; zero picks global Z, or global X for members along Z.
/// Returns false if the orientation is parallel to the member.
bool frame3d_axes(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& orientation,
                  Eigen::Matrix3d* R);

}  // namespace dynid::internal
