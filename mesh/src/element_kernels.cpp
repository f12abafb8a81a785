// Element matrices of the Euler-Bernoulli beam and frame elements (Chandrupatla & Belegundu, "Introduction to
// Finite Elements in Engineering", ch. 8; Przemieniecki, "Theory of Matrix Structural Analysis", for 3D).
#include "internal/element_kernels.hpp"

#include <array>
#include <cmath>

#include "dynid/mesh/model.hpp"

namespace dynid::internal {
namespace {

// Bending stiffness block for (w1, t1, w2, t2) with the convention w' = +t (x-y plane).
// For the x-z plane (w' = -t) the sign of the off-diagonal L terms flips: pass s = -1.
void bending_k(double EI, double L, double phi, double s, Eigen::Matrix4d* k) {
  *k = beam_bending_k<double>(EI, L, phi, s);
}

// The consistent geometric stiffness of an axial force P on a cubic-Hermite beam, int N'^T N' dx (with P -> rho I
// the Rayleigh rotary inertia, beam_mass_coefficient 3).
void geometric_k(double P, double L, double s, Eigen::Matrix4d* m) {
  const double c = P / (30.0 * L), L2 = L * L;
  *m << 36, 3 * L * s, -36, 3 * L * s,  //
      3 * L * s, 4 * L2, -3 * L * s, -L2,  //
      -36, -3 * L * s, 36, -3 * L * s,   //
      3 * L * s, -L2, -3 * L * s, 4 * L2;
  *m *= c;
}

template <class Idx>
void scatter4(const Eigen::Matrix4d& b, const Idx& idx, Eigen::MatrixXd* out) {
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) (*out)(idx[i], idx[j]) += b(i, j);
}

void scatter_bar(double k, int i, int j, Eigen::MatrixXd* out) {
  (*out)(i, i) += k;
  (*out)(j, j) += k;
  (*out)(i, j) -= k;
  (*out)(j, i) -= k;
}

void scatter_bar_mass(double m, int i, int j, bool lumped, Eigen::MatrixXd* out) {
  if (lumped) {
    (*out)(i, i) += m / 2;
    (*out)(j, j) += m / 2;
  } else {
    (*out)(i, i) += m / 3;
    (*out)(j, j) += m / 3;
    (*out)(i, j) += m / 6;
    (*out)(j, i) += m / 6;
  }
}

void zero_all(int n, MemberLocal* o) {
  for (Eigen::MatrixXd* m : {&o->Ka, &o->Kb, &o->Kt, &o->Kg, &o->Mt, &o->Mr}) m->setZero(n, n);
}

}  // namespace

Eigen::Matrix4d beam_mass_coefficient(int j, double rhoA, double rhoI, double L, double s) {
  const double L2 = L * L, a = L * s / 4, b = L * s;  // a: the L / 4 of Friedman & Kosmatka's terms, with the sign
  Eigen::Matrix4d c;
  switch (j) {
    case 0:
      c << 78, 44 * a, 27, -26 * a,           //
          44 * a, 2 * L2, 26 * a, -1.5 * L2,  //
          27, 26 * a, 78, -44 * a,            //
          -26 * a, -1.5 * L2, -44 * a, 2 * L2;
      break;
    case 1:
      c << 147, 77 * a, 63, -63 * a,            //
          77 * a, 3.5 * L2, 63 * a, -3.5 * L2,  //
          63, 63 * a, 147, -77 * a,             //
          -63 * a, -3.5 * L2, -77 * a, 3.5 * L2;
      break;
    case 2:
      c << 70, 35 * a, 35, -35 * a,               //
          35 * a, 1.75 * L2, 35 * a, -1.75 * L2,  //
          35, 35 * a, 70, -35 * a,                //
          -35 * a, -1.75 * L2, -35 * a, 1.75 * L2;
      break;
    case 3:
      c << 36, 3 * b, -36, 3 * b,      //
          3 * b, 4 * L2, -3 * b, -L2,  //
          -36, -3 * b, 36, -3 * b,     //
          3 * b, -L2, -3 * b, 4 * L2;
      break;
    case 4:
      c << 0, -15 * b, 0, -15 * b,           //
          -15 * b, 5 * L2, 15 * b, -5 * L2,  //
          0, 15 * b, 0, 15 * b,              //
          -15 * b, -5 * L2, 15 * b, 5 * L2;
      break;
    default:
      c << 0, 0, 0, 0,            //
          0, 10 * L2, 0, 5 * L2,  //
          0, 0, 0, 0,             //
          0, 5 * L2, 0, 10 * L2;
  }
  return c * (j < 3 ? rhoA * L / 210.0 : rhoI / (30.0 * L));
}

Eigen::Matrix4d beam_mass(double rhoA, double rhoI, double L, double phi, double s, bool rotary) {
  const int o = rotary ? 3 : 0;
  auto c = [&](int j) { return beam_mass_coefficient(j, rhoA, rhoI, L, s); };
  if (phi == 0.0) return c(o);
  return shear_mass<Eigen::Matrix4d>(c(o), c(o + 1), c(o + 2), phi);
}

void frame2d_local(const MemberProps& p, MemberLocal* o) {
  zero_all(6, o);
  const double L = p.L;
  scatter_bar(p.EA / L, 0, 3, &o->Ka);
  const std::array<int, 4> bi{{1, 2, 4, 5}};
  Eigen::Matrix4d b;
  bending_k(p.EIz, L, p.phiz, 1.0, &b);
  scatter4(b, bi, &o->Kb);
  if (p.P != 0.0) {
    geometric_k(p.P, L, 1.0, &b);
    scatter4(b, bi, &o->Kg);
  }
  const double m = p.rhoA * L;
  scatter_bar_mass(m, 0, 3, p.lumped, &o->Mt);
  if (p.lumped) {
    o->Mt(1, 1) += m / 2;
    o->Mt(4, 4) += m / 2;
  } else {
    scatter4(beam_mass(p.rhoA, p.rhoIz, L, p.phiz, 1.0, false), bi, &o->Mt);
    if (p.rotary) scatter4(beam_mass(p.rhoA, p.rhoIz, L, p.phiz, 1.0, true), bi, &o->Mr);
  }
}

void frame3d_local(const MemberProps& p, MemberLocal* o) {
  zero_all(12, o);
  const double L = p.L;
  scatter_bar(p.EA / L, 0, 6, &o->Ka);
  scatter_bar(p.GJ / L, 3, 9, &o->Kt);
  const std::array<int, 4> xy{{1, 5, 7, 11}}, xz{{2, 4, 8, 10}};
  Eigen::Matrix4d b;
  bending_k(p.EIz, L, p.phiz, 1.0, &b);
  scatter4(b, xy, &o->Kb);
  bending_k(p.EIy, L, p.phiy, -1.0, &b);
  scatter4(b, xz, &o->Kb);
  if (p.P != 0.0) {
    geometric_k(p.P, L, 1.0, &b);
    scatter4(b, xy, &o->Kg);
    geometric_k(p.P, L, -1.0, &b);
    scatter4(b, xz, &o->Kg);
  }
  const double m = p.rhoA * L;
  scatter_bar_mass(m, 0, 6, p.lumped, &o->Mt);
  // Torsional inertia (polar moment Iy + Iz) is always included: without it twisting DOFs would be massless.
  scatter_bar_mass((p.rhoIy + p.rhoIz) * L, 3, 9, p.lumped, &o->Mr);
  if (p.lumped) {
    for (int i : {1, 2, 7, 8}) o->Mt(i, i) += m / 2;
  } else {
    scatter4(beam_mass(p.rhoA, p.rhoIz, L, p.phiz, 1.0, false), xy, &o->Mt);
    scatter4(beam_mass(p.rhoA, p.rhoIy, L, p.phiy, -1.0, false), xz, &o->Mt);
    if (p.rotary) {
      scatter4(beam_mass(p.rhoA, p.rhoIz, L, p.phiz, 1.0, true), xy, &o->Mr);
      scatter4(beam_mass(p.rhoA, p.rhoIy, L, p.phiy, -1.0, true), xz, &o->Mr);
    }
  }
}

bool frame3d_axes(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& orientation,
                  Eigen::Matrix3d* R) {
  const Eigen::Vector3d ex = (b - a).normalized();
  Eigen::Vector3d v = orientation;
  if (v.squaredNorm() == 0.0) v = std::abs(ex.z()) > 0.999 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
  Eigen::Vector3d ey = v.cross(ex);
  if (ey.norm() < 1e-8 * v.norm()) return false;
  ey.normalize();
  const Eigen::Vector3d ez = ex.cross(ey);
  R->row(0) = ex;
  R->row(1) = ey;
  R->row(2) = ez;
  return true;
}

}  // namespace dynid::internal
