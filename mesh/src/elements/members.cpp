// Beams and frames: what the three member kinds share (MemberKind) and the three kinds.
//   beam2d   Euler-Bernoulli (or Timoshenko) beam along x; (uy, rz) per node; K = K_b(E Iz), M = M_t(rho A) + M_r(rho
//   Iz). frame2d  plane frame in x-y; (ux, uy, rz) per node; K = K_a(E A) + K_b(E Iz) + K_g(P), M as beam2d plus axial.
//   frame3d  space frame; six DOFs per node; adds K_t(G J), bending about both local axes and torsional inertia.
#include <Eigen/Dense>
#include <cmath>

#include "dynid/mesh/error.hpp"
#include "dynid/mesh/model.hpp"
#include "internal/element_kinds.hpp"

namespace dynid::internal {
namespace {

// out = T^T A T for T block-diagonal with 3x3 blocks R (frames): cheaper than the dense triple product.
void rotate_blocks(const Eigen::MatrixXd& A, const Eigen::Matrix3d& R, Eigen::MatrixXd* out) {
  const Eigen::Index nb = A.rows() / 3;
  out->resize(A.rows(), A.cols());
  for (Eigen::Index i = 0; i < nb; ++i)
    for (Eigen::Index j = 0; j < nb; ++j)
      out->block<3, 3>(3 * i, 3 * j).noalias() = R.transpose() * A.block<3, 3>(3 * i, 3 * j) * R;
}

bool shear_modulus_known(const Material& m) { return m.G > 0 || (std::isfinite(m.nu) && m.nu > -1 && m.nu < 0.5); }

// 2D members must lie in the x-y plane.
void check_plane(const ElementSetup& s, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double L) {
  if (std::abs(b.z() - a.z()) > 1e-9 * L)
    throw InputError(s.who + ": 2D elements must lie in the x-y plane (node z coordinates differ)");
}

}  // namespace

void MemberKind::setup(const ElementSetup& s) const {
  setup_ends(s);
  const Element& e = s.element;
  const std::string& who = s.who;
  const std::array<int, 2>& nodes = *s.nodes;
  if (e.num_nodes != 2) throw InputError(who + ": needs 2 nodes");
  const Eigen::Vector3d& a = s.model.nodes()[nodes[0]].x;
  const Eigen::Vector3d& b = s.model.nodes()[nodes[1]].x;
  const double L = (b - a).norm();
  if (nodes[0] == nodes[1] || !(L > 0))
    throw InputError(who + ": zero length (nodes " + std::to_string(e.node_ids[0]) + " and " +
                     std::to_string(e.node_ids[1]) + " coincide)");
  if (e.material < 0 || e.material >= static_cast<int>(s.model.materials().size()))
    throw InputError(who + ": no material assigned");
  if (e.section < 0 || e.section >= static_cast<int>(s.model.sections().size()))
    throw InputError(who + ": no section assigned");
  const Material& m = s.model.materials()[e.material];
  const Section& sec = s.model.sections()[e.section];
  const std::string mat = who + ": material '" + m.name + "'";
  const std::string sn = who + ": section '" + sec.name + "'";
  if (!finite_positive(m.E)) throw InputError(mat + " has Young's modulus E = " + fmt_num(m.E) + "; it must be > 0");
  if (!(std::isfinite(m.rho) && m.rho >= 0))
    throw InputError(mat + " has density rho = " + fmt_num(m.rho) + "; it must be >= 0");
  if (!finite_positive(sec.A)) throw InputError(sn + " has area A = " + fmt_num(sec.A) + "; it must be > 0");
  if (!finite_positive(sec.Iz))
    throw InputError(sn + " has second moment Iz = " + fmt_num(sec.Iz) + "; it must be > 0");
  if (!(std::isfinite(sec.shear_factor) && sec.shear_factor >= 0))
    throw InputError(sn + " has shear factor " + fmt_num(sec.shear_factor) +
                     "; it must be >= 0 (0 = no shear deformation)");
  if (sec.shear_factor > 0 && !shear_modulus_known(m))
    throw InputError(
        mat + ": shear deformation (section shear_factor) needs a shear modulus G or a Poisson's ratio in (-1, 0.5)");
  if (!std::isfinite(e.axial_force)) throw InputError(who + ": axial_force must be finite");
  check_geometry(s, m, sec, a, b, L);
  const DofMask d = node_dofs();
  for (int k = 0; k < 2; ++k) (*s.active)[nodes[k]] |= d;
}

std::vector<std::pair<int, Dof>> MemberKind::layout(const Model& m, int e, const std::vector<DofMask>&) const {
  return node_major_layout(m, e, node_dofs());
}

Eigen::Matrix3d MemberKind::axes(const Model& m, int e) const {
  const Eigen::Vector3d& a = m.nodes()[m.element_nodes(e)[0]].x;
  const Eigen::Vector3d& b = m.nodes()[m.element_nodes(e)[1]].x;
  Eigen::Matrix3d R;
  if (spatial()) {
    frame3d_axes(a, b, m.elements()[e].orientation, &R);
  } else {
    const double L = (b - a).norm();
    const double c = (b.x() - a.x()) / L, s = (b.y() - a.y()) / L;
    R << c, s, 0, -s, c, 0, 0, 0, 1;
  }
  return R;
}

void MemberKind::local(const Model& m, int e, MemberLocal* loc, Eigen::MatrixXd* T, const double* axial_force,
                       MemberProps* props) const {
  const Element& el = m.elements()[e];
  const Material& mat = m.materials()[el.material];
  const Section& sec = m.sections()[el.section];
  const PropertyFactors& f = el.factors;
  const Eigen::Vector3d& a = m.nodes()[m.element_nodes(e)[0]].x;
  const Eigen::Vector3d& b = m.nodes()[m.element_nodes(e)[1]].x;
  MemberProps mp;
  mp.L = (b - a).norm();
  const double E = mat.E * f.E, rho = mat.rho * f.rho, A = sec.A * f.A;
  mp.EA = E * A;
  mp.EIz = E * sec.Iz * f.I;
  mp.EIy = E * sec.Iy * f.I;
  mp.GJ = mat.shear_modulus() * f.E * sec.torsion_constant() * f.I;
  mp.rhoA = rho * A;
  mp.rhoIz = rho * sec.Iz * f.I;
  mp.rhoIy = rho * sec.Iy * f.I;
  mp.lumped = m.mass_type() == MassType::Lumped;
  mp.rotary = m.rotary_inertia();
  if (sec.shear_factor > 0) {
    const double GAs = sec.shear_factor * mat.shear_modulus() * f.E * A * mp.L * mp.L;
    mp.phiz = 12.0 * mp.EIz / GAs;
    mp.phiy = 12.0 * mp.EIy / GAs;
  }
  mp.P = axial_force ? *axial_force : el.axial_force;
  if (spatial())
    frame3d_local(mp, loc);
  else
    frame2d_local(mp, loc);
  const Eigen::Matrix3d R = axes(m, e);
  const int blocks = spatial() ? 4 : 2;
  T->setZero(3 * blocks, 3 * blocks);
  for (int k = 0; k < blocks; ++k) T->block<3, 3>(3 * k, 3 * k) = R;
  embed(T);
  if (props) *props = mp;
}

ElementParts MemberKind::parts(const Model& m, int e) const {
  MemberLocal loc;
  Eigen::MatrixXd T;
  local(m, e, &loc, &T);
  auto tr = [&](const Eigen::MatrixXd& a) -> Eigen::MatrixXd { return T.transpose() * a * T; };
  ElementParts p;
  p.K_axial = tr(loc.Ka);
  p.K_bending = tr(loc.Kb);
  p.K_torsion = tr(loc.Kt);
  p.K_geometric = tr(loc.Kg);
  p.M_translational = tr(loc.Mt);
  p.M_rotary = tr(loc.Mr);
  const Eigen::Index n = p.K_axial.rows();
  p.K_discrete.setZero(n, n);
  p.M_discrete.setZero(n, n);
  return p;
}

void MemberKind::matrices(const Model& m, int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const {
  if (!block_rotation()) {
    ElementKind::matrices(m, e, K, M);
    return;
  }
  MemberLocal loc;  // fast path used by assembly
  Eigen::MatrixXd T;
  local(m, e, &loc, &T);
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if (K) rotate_blocks(loc.Ka + loc.Kb + loc.Kt + loc.Kg, R, K);
  if (M) rotate_blocks(loc.Mt + loc.Mr, R, M);
}

Eigen::MatrixXd MemberKind::unit_geometric_stiffness(const Model& m, int e) const {
  MemberLocal loc;
  Eigen::MatrixXd T;
  const double unit = 1.0;
  local(m, e, &loc, &T, &unit);
  return T.transpose() * loc.Kg * T;
}

std::vector<BendingPlane> MemberKind::bending_planes(const Model& m, int e) const {
  MemberLocal loc;
  Eigen::MatrixXd T;  // local DOFs from the element's global DOFs
  MemberProps p;
  local(m, e, &loc, &T, nullptr, &p);
  const Element& el = m.elements()[e];
  const double GA =
      m.materials()[el.material].shear_modulus() * el.factors.E * m.sections()[el.section].A * el.factors.A;
  // Local (w1, t1, w2, t2) of each plane, its E I, rho I and the sign of t against w' (frame3d_local).
  struct Plane {
    std::array<int, 4> at;
    double EI, rhoI, s;
  };
  const std::array<Plane, 2> space{{{{{1, 5, 7, 11}}, p.EIz, p.rhoIz, 1.0}, {{{2, 4, 8, 10}}, p.EIy, p.rhoIy, -1.0}}};
  const Plane plane{{{1, 2, 4, 5}}, p.EIz, p.rhoIz, 1.0};
  const Eigen::Index nl = loc.Kb.rows();
  std::vector<BendingPlane> out;
  for (int i = 0; i < (spatial() ? 2 : 1); ++i) {
    const Plane& q = spatial() ? space[static_cast<std::size_t>(i)] : plane;
    BendingPlane b;
    b.EI = q.EI;
    b.GA = GA;
    b.L = p.L;
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(nl, nl);
    Eigen::VectorXd d = Eigen::VectorXd::Zero(nl);
    for (int r = 0; r < 4; ++r)
      for (int s = 0; s < 4; ++s) k(q.at[r], q.at[s]) = loc.Kb(q.at[r], q.at[s]);
    d[q.at[1]] = 1.0;
    d[q.at[3]] = -1.0;
    b.K = T.transpose() * k * T;
    b.d = T.transpose() * d;
    for (int j = 0; j < 6; ++j) {
      const Eigen::Matrix4d c = beam_mass_coefficient(j, p.rhoA, q.rhoI, p.L, q.s);
      Eigen::MatrixXd l = Eigen::MatrixXd::Zero(nl, nl);
      for (int r = 0; r < 4; ++r)
        for (int s = 0; s < 4; ++s) l(q.at[r], q.at[s]) = c(r, s);
      b.mass[static_cast<std::size_t>(j)] = T.transpose() * l * T;
    }
    out.push_back(std::move(b));
  }
  return out;
}

Eigen::MatrixXd MemberKind::point_interpolation(const Model& m, int e, double xi, Eigen::MatrixXd* dN) const {
  MemberLocal loc;
  Eigen::MatrixXd T;  // local DOFs from the element's global DOFs
  local(m, e, &loc, &T);
  const double L = (m.nodes()[m.element_nodes(e)[1]].x - m.nodes()[m.element_nodes(e)[0]].x).norm();
  // Hermite functions for (w1, L t1, w2, L t2) and the linear ones for (u1, u2), with their xi-derivatives.
  const double x2 = xi * xi, x3 = x2 * xi;
  const Eigen::Vector4d H(1 - 3 * x2 + 2 * x3, L * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, L * (-x2 + x3));
  const Eigen::Vector4d dH(-6 * xi + 6 * x2, L * (1 - 4 * xi + 3 * x2), 6 * xi - 6 * x2, L * (-2 * xi + 3 * x2));
  const bool three = spatial();
  const int nl = three ? 12 : 6, per = nl / 2;
  Eigen::MatrixXd Nl = Eigen::MatrixXd::Zero(3, nl), dNl = Eigen::MatrixXd::Zero(3, nl);  // local translations
  Nl(0, 0) = 1 - xi, Nl(0, per) = xi, dNl(0, 0) = -1, dNl(0, per) = 1;
  // Local v from (v, t_z) at both ends (v' = +t_z); 3D local w from (w, t_y) with w' = -t_y.
  const std::array<int, 4> xy = three ? std::array<int, 4>{{1, 5, 7, 11}} : std::array<int, 4>{{1, 2, 4, 5}};
  for (int k = 0; k < 4; ++k) Nl(1, xy[k]) = H[k], dNl(1, xy[k]) = dH[k];
  if (three) {
    const std::array<int, 4> xz{{2, 4, 8, 10}};
    const Eigen::Vector4d s(1, -1, 1, -1);
    for (int k = 0; k < 4; ++k) Nl(2, xz[k]) = s[k] * H[k], dNl(2, xz[k]) = s[k] * dH[k];
  }
  // Local translation axes in global coordinates: the rows of T's first 3x3 block (Beam2D: T maps (uy, rz)).
  const Eigen::Matrix3d R = axes(m, e);
  if (dN) *dN = R.transpose() * dNl * T;
  return R.transpose() * Nl * T;
}

double MemberKind::axial_force(const Model& m, int e, const Eigen::VectorXd& u) const {
  MemberLocal loc;
  Eigen::MatrixXd T;
  local(m, e, &loc, &T);
  const Eigen::VectorXd ul = T * u;
  const int per = static_cast<int>(ul.size()) / 2;
  return loc.Ka(per, per) * (ul[per] - ul[0]);
}

namespace {

class Beam2D : public MemberKind {
 public:
  ElementType type() const override { return ElementType::Beam2D; }
  std::string_view name() const override { return "beam2d"; }
  // No axial DOFs: no axial force.
  double axial_force(const Model&, int, const Eigen::VectorXd&) const override { return 0.0; }

 protected:
  DofMask node_dofs() const override { return dof_bit(Dof::UY) | dof_bit(Dof::RZ); }
  void check_geometry(const ElementSetup& s, const Material&, const Section&, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b, double L) const override {
    check_plane(s, a, b, L);
    if (std::abs(b.y() - a.y()) > 1e-9 * L)
      throw InputError(s.who + ": a beam2d element must lie along the x axis; use frame2d for inclined members");
  }
  // Beam DOFs (uy, rz) per node embed into the frame's (ux, uy, rz); the beam lies along x, so its local axial
  // DOF receives nothing and the axial parts vanish.
  void embed(Eigen::MatrixXd* T) const override {
    Eigen::MatrixXd Tg = Eigen::MatrixXd::Zero(6, 4);
    Tg(1, 0) = Tg(2, 1) = Tg(4, 2) = Tg(5, 3) = 1.0;
    *T = *T * Tg;
  }
  bool block_rotation() const override { return false; }
};

class Frame2D : public MemberKind {
 public:
  ElementType type() const override { return ElementType::Frame2D; }
  std::string_view name() const override { return "frame2d"; }

 protected:
  DofMask node_dofs() const override { return dof_bit(Dof::UX) | dof_bit(Dof::UY) | dof_bit(Dof::RZ); }
  void check_geometry(const ElementSetup& s, const Material&, const Section&, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b, double L) const override {
    check_plane(s, a, b, L);
  }
};

class Frame3D : public MemberKind {
 public:
  ElementType type() const override { return ElementType::Frame3D; }
  std::string_view name() const override { return "frame3d"; }
  bool spatial() const override { return true; }

 protected:
  DofMask node_dofs() const override { return kAllDofs; }
  void check_geometry(const ElementSetup& s, const Material& m, const Section& sec, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b, double) const override {
    const std::string sn = s.who + ": section '" + sec.name + "'";
    if (!finite_positive(sec.Iy))
      throw InputError(sn + " has second moment Iy = " + fmt_num(sec.Iy) + "; it must be > 0");
    if (!(std::isfinite(sec.J) && sec.J >= 0))
      throw InputError(sn + " has torsion constant J = " + fmt_num(sec.J) + "; it must be >= 0");
    if (!shear_modulus_known(m))
      throw InputError(s.who + ": material '" + m.name +
                       "': shear modulus G or a Poisson's ratio in (-1, 0.5) is needed for 3D frames");
    Eigen::Matrix3d R;
    if (!frame3d_axes(a, b, s.element.orientation, &R))
      throw InputError(s.who + ": orientation vector is parallel to the member axis");
  }
};

}  // namespace

const ElementKind& beam2d_kind() {
  static const Beam2D kind;
  return kind;
}
const ElementKind& frame2d_kind() {
  static const Frame2D kind;
  return kind;
}
const ElementKind& frame3d_kind() {
  static const Frame3D kind;
  return kind;
}

}  // namespace dynid::internal
