// The candidate library of discovery: small parametric model augmentations with a physical meaning.
#include <cmath>
#include <complex>
#include <map>
#include <set>
#include <sstream>

#include "dynid/engine/discovery.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/candidates.hpp"

namespace dynid::internal {

std::string fmt_value(double v, int digits) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

std::string with_std(const PhysicalValue& v) {
  std::string s = fmt_value(v.value, 3) + (v.unit.empty() ? "" : " " + v.unit);
  if (std::isfinite(v.std) && v.value != 0) s += " ± " + fmt_value(100.0 * std::abs(v.std / v.value), 2) + " %";
  return s;
}

namespace {

using Cd = std::complex<double>;

// A term linear in one parameter: dK = theta AK, dM = theta AM.
CustomTerm linear_term(std::vector<int> dofs, Eigen::MatrixXd AK, Eigen::MatrixXd AM, int param) {
  CustomTerm t;
  t.dofs = std::move(dofs);
  t.params = {param};
  t.eval = [AK = std::move(AK), AM = std::move(AM)](const Eigen::VectorXd& th, Eigen::MatrixXd* dK, Eigen::MatrixXd* dM,
                                                    std::vector<Eigen::MatrixXd>* dKd, std::vector<Eigen::MatrixXd>* dMd) {
    if (dK && AK.size()) *dK = th[0] * AK;
    if (dM && AM.size()) *dM = th[0] * AM;
    if (dKd) *dKd = {AK};
    if (dMd) *dMd = {AM};
  };
  return t;
}

bool is_member(const Model& model, int e) {
  const ElementType t = model.elements()[e].type;
  return t == ElementType::Beam2D || t == ElementType::Frame2D || t == ElementType::Frame3D;
}

// An element's stiffness (without geometric stiffness: Ks) and mass matrices; beams and frames also their
// bending part and section properties.
struct Member {
  int e = -1;
  std::vector<int> dofs;
  std::vector<std::pair<int, Dof>> types;
  Eigen::MatrixXd K, Ks, M, Kb, Mt;  // K = Ks (axial, bending, torsion) + geometric
  double L = 0, EI = 0, GA = 0, rhoA = 0, rhoI = 0;
};

// The mass an element moves in a rigid translation, largest over x, y, z (r^T M r with r = 1 on the element's
// DOFs of that direction): the mass of a matrix element, which has no section to compute it from.
double translational_mass(const Model& model, int e) {
  const auto types = model.element_dof_types(e);
  Eigen::MatrixXd M;
  model.element_matrices(e, nullptr, &M);
  double best = 0;
  for (int d = 0; d < 3; ++d) {
    Eigen::VectorXd r = Eigen::VectorXd::Zero(M.rows());
    for (std::size_t i = 0; i < types.size(); ++i) r[static_cast<Eigen::Index>(i)] = static_cast<int>(types[i].second) == d ? 1.0 : 0.0;
    best = std::max(best, r.dot(M * r));
  }
  return best;
}

Member member(const Model& model, int e) {
  Member m;
  m.e = e;
  model.element_dofs(e, &m.dofs);
  m.types = model.element_dof_types(e);
  const ElementParts p = model.element_parts(e);
  m.Ks = p.K_axial + p.K_bending + p.K_torsion + p.K_discrete;
  m.K = m.Ks + p.K_geometric;
  m.M = p.M_translational + p.M_rotary + p.M_discrete;
  m.Kb = p.K_bending;
  m.Mt = p.M_translational;
  const Element& el = model.elements()[e];
  if (!is_member(model, e)) return m;  // springs and point masses: matrices only
  const Material& mat = model.materials()[el.material];
  const Section& sec = model.sections()[el.section];
  const auto& n = model.element_nodes(e);
  m.L = (model.nodes()[n[1]].x - model.nodes()[n[0]].x).norm();
  m.EI = mat.E * el.factors.E * sec.Iz * el.factors.I;
  m.GA = mat.shear_modulus() * el.factors.E * sec.A * el.factors.A;
  m.rhoA = mat.rho * el.factors.rho * sec.A * el.factors.A;
  m.rhoI = mat.rho * el.factors.rho * sec.Iz * el.factors.I;
  return m;
}



// ---- lumped mass at a node ----------------------------------------------------------------------------------
class LumpedMass : public Candidate {
 public:
  LumpedMass(const Model& m, int node, double mref) : node_(node), id_(m.nodes()[node].id), mref_(mref) {
    for (int t = 0; t < 3; ++t)
      if (m.dof_map().eq(node, static_cast<Dof>(t)) >= 0) dofs_.push_back(m.dof_map().eq(node, static_cast<Dof>(t)));
  }
  bool ok() const { return !dofs_.empty(); }
  std::string kind() const override { return "lumped_mass"; }
  std::string description() const override { return "lumped mass attached at node " + std::to_string(id_); }
  Site site() const override { return {{id_}, {}}; }
  std::vector<CandidateParameter> parameters() const override { return {{"mass", 0.0, 0.0, 50.0}}; }
  std::vector<CustomTerm> terms(const Model&, int first) const override {
    const Eigen::Index n = static_cast<Eigen::Index>(dofs_.size());
    return {linear_term(dofs_, {}, mref_ * Eigen::MatrixXd::Identity(n, n), first)};
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"mass", "kg", mref_ * th[0], mref_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "an unmodelled mass is attached at node " + std::to_string(id_) + ": " + with_std(v[0]);
  }

 private:
  int node_, id_;
  double mref_;
  std::vector<int> dofs_;
};

// ---- grounded spring on a free DOF ----------------------------------------------------------------------------
class GroundedSpring : public Candidate {
 public:
  GroundedSpring(const Model& m, int node, Dof d, double kref) : id_(m.nodes()[node].id), dof_(d), kref_(kref) {
    eq_ = m.dof_map().eq(node, d);
  }
  std::string kind() const override { return is_rotation(dof_) ? "rotational_spring" : "grounded_spring"; }
  std::string description() const override {
    return std::string(is_rotation(dof_) ? "rotational" : "translational") + " spring to ground on " +
           std::string(dof_name(dof_)) + " at node " + std::to_string(id_);
  }
  Site site() const override { return {{id_}, {}}; }
  std::vector<CandidateParameter> parameters() const override { return {{"stiffness", 0.0, 0.0, 100.0}}; }
  std::vector<CustomTerm> terms(const Model&, int first) const override {
    return {linear_term({eq_}, Eigen::MatrixXd::Constant(1, 1, kref_), {}, first)};
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"stiffness", is_rotation(dof_) ? "N m/rad" : "N/m", kref_ * th[0], kref_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "node " + std::to_string(id_) + " is restrained elastically in " + std::string(dof_name(dof_)) + " (an unmodelled support or bracing): spring " + with_std(v[0]);
  }

 private:
  int id_;
  Dof dof_;
  double kref_;
  int eq_ = -1;
};

// ---- released member end with a spring: semi-rigid joint, flexible support -----------------------------------
// The member's DOF i at one end becomes internal, tied to the node (or to the ground when the node's DOF is
// restrained) by a spring of flexibility c = ctil / K_ii. Condensing the internal DOF: with b = row i of the member
// matrix, theta_int = (x_i - c sum_{j != i} B_ij x_j) / (1 + c B_ii), and the condensed stiffness is
// T^T B T + c b b^T / (1 + c B_ii)^2 with T = I + e_i (g - e_i)^T; the mass is condensed with the same T. At c = 0
// it is the rigid connection. Derivatives by complex step (exact to rounding).
class EndRelease : public Candidate {
 public:
  EndRelease(const Model& m, int e, int end, Dof d, bool support)
      : e_(e), eid_(m.elements()[e].id), nid_(m.nodes()[m.element_nodes(e)[end]].id), dof_(d), support_(support) {
    const auto types = m.element_dof_types(e);
    for (std::size_t k = 0; k < types.size(); ++k)
      if (types[k].first == m.element_nodes(e)[end] && types[k].second == d) i_ = static_cast<int>(k);
    if (i_ >= 0) kii_ = member(m, e).K(i_, i_);
  }
  bool ok() const { return i_ >= 0; }
  std::string kind() const override { return support_ ? "flexible_support" : "semi_rigid_joint"; }
  std::string description() const override {
    return support_ ? std::string(is_rotation(dof_) ? "rotational" : "translational") + " flexibility of the support at node " +
                          std::to_string(nid_) + " (" + std::string(dof_name(dof_)) + ", through element " + std::to_string(eid_) + ")"
                    : "semi-rigid connection of element " + std::to_string(eid_) + " to joint " + std::to_string(nid_) +
                          " (spring on " + std::string(dof_name(dof_)) + ")";
  }
  Site site() const override { return {{nid_}, {eid_}}; }
  std::vector<CandidateParameter> parameters() const override { return {{"flexibility", 0.0, 0.0, 100.0}}; }

  template <class S>
  static void condense(const Eigen::MatrixXd& B, const Eigen::MatrixXd& Mm, int i, S ct, Eigen::Matrix<S, -1, -1>* K,
                       Eigen::Matrix<S, -1, -1>* M) {
    const Eigen::Index n = B.rows();
    const S c = ct / B(i, i);
    const S den = 1.0 + c * B(i, i);
    Eigen::Matrix<S, -1, 1> g(n);
    for (Eigen::Index j = 0; j < n; ++j) g[j] = (j == i ? S(1.0) : -c * B(i, j)) / den;
    Eigen::Matrix<S, -1, -1> T = Eigen::Matrix<S, -1, -1>::Identity(n, n);
    for (Eigen::Index j = 0; j < n; ++j) T(i, j) = g[j];
    const Eigen::Matrix<S, -1, 1> b = B.row(i).transpose().cast<S>();
    *K = T.transpose() * B.cast<S>() * T + (c / (den * den)) * (b * b.transpose());
    *M = T.transpose() * Mm.cast<S>() * T;
  }

  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    const Member mb = member(m, e_);
    CustomTerm t;
    t.dofs = mb.dofs;
    t.params = {first};
    const int i = i_;
    t.eval = [B = mb.K, Mm = mb.M, i](const Eigen::VectorXd& th, Eigen::MatrixXd* dK, Eigen::MatrixXd* dM,
                                      std::vector<Eigen::MatrixXd>* dKd, std::vector<Eigen::MatrixXd>* dMd) {
      if (dK || dM) {
        Eigen::MatrixXd K, M;
        condense<double>(B, Mm, i, th[0], &K, &M);
        if (dK) *dK = K - B;
        if (dM) *dM = M - Mm;
      }
      if (dKd || dMd) {
        const double h = 1e-30;
        Eigen::MatrixXcd K, M;
        condense<Cd>(B, Mm, i, Cd(th[0], h), &K, &M);
        if (dKd) *dKd = {K.imag() / h};
        if (dMd) *dMd = {M.imag() / h};
      }
    };
    return {t};
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    const double c = std::max(th[0], 1e-300);
    return {{"stiffness", is_rotation(dof_) ? "N m/rad" : "N/m", kii_ / c, kii_ * sd[0] / (c * c)}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    if (support_)
      return "the support at node " + std::to_string(nid_) + " is not rigid in " + std::string(dof_name(dof_)) + ": " +
             std::string(is_rotation(dof_) ? "rotational" : "translational") + " spring " + with_std(v[0]);
    return "the connection of element " + std::to_string(eid_) + " to joint " + std::to_string(nid_) +
           " is semi-rigid: rotational spring " + with_std(v[0]);
  }

 private:
  int e_, eid_, nid_;
  Dof dof_;
  bool support_;
  int i_ = -1;
  double kii_ = 0;  // the member's stiffness on the released DOF: c = ctil / kii
};

// ---- element stiffness or mass change (damage, added material) ----------------------------------------------
class ElementChange : public Candidate {
 public:
  ElementChange(const Model& m, int e, bool mass) : e_(e), eid_(m.elements()[e].id), mass_(mass) {}
  // Springs only change stiffness, point masses only mass.
  static bool applies(const Model& m, int e, bool mass) {
    const ElementType t = m.elements()[e].type;
    return t == ElementType::Spring ? !mass : t == ElementType::PointMass ? mass : true;
  }
  std::string kind() const override { return mass_ ? "element_mass" : "element_stiffness"; }
  std::string description() const override {
    return std::string(mass_ ? "mass" : "stiffness") + " change of element " + std::to_string(eid_);
  }
  Site site() const override { return {{}, {eid_}}; }
  std::vector<CandidateParameter> parameters() const override { return {{"fraction", 0.0, -0.95, 3.0}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    const Member mb = member(m, e_);
    return {mass_ ? linear_term(mb.dofs, {}, mb.M, first) : linear_term(mb.dofs, mb.Ks, {}, first)};
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{mass_ ? "mass change" : "stiffness change", "%", 100.0 * th[0], 100.0 * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    const bool loss = v[0].value < 0;
    return "element " + std::to_string(eid_) + (mass_ ? (loss ? " has lost mass: " : " carries added mass: ") : (loss ? " has lost stiffness (damage): " : " is stiffer than modelled: ")) +
           with_std(v[0]);
  }

 private:
  int e_, eid_;
  bool mass_;
};

// ---- members of a group (global candidates) ----------------------------------------------------------------
std::string group_words(const std::string& g) { return g.empty() ? "all members" : "the members of group '" + g + "'"; }

std::vector<int> group_members(const Model& m, const std::string& g) {
  std::vector<int> out;
  for (int e = 0; e < m.num_elements(); ++e)
    if (is_member(m, e) && (g.empty() || m.elements()[e].group == g)) out.push_back(e);
  return out;
}

// A global candidate acting on a set of elements (all members, or a group): its site is those elements.
class OnElements : public Candidate {
 public:
  OnElements(const Model& m, std::vector<int> els) : els_(std::move(els)) {
    for (int e : els_) site_.elements.push_back(m.elements()[e].id);
  }
  Site site() const override { return site_; }
  bool global() const override { return true; }

 protected:
  std::vector<int> els_;

 private:
  Site site_;
};

// ---- shear deformation and rotary inertia (Timoshenko) ----------------------------------------------------------
// Per member (plane bending): K_b(alpha) = (K_b + alpha phi0 EI/L d d^T) / (1 + alpha phi0), phi0 = 12 EI/(G A L^2),
// d = e_t1 - e_t2 on the rotations; alpha = 1/kappa (0 = Euler-Bernoulli). The rotary inertia rho I (int N'^T N')
// is added with it (Timoshenko theory has both).
class ShearDeformation : public OnElements {
 public:
  ShearDeformation(const Model& m, std::vector<int> els) : OnElements(m, std::move(els)) {}
  std::string kind() const override { return "shear_deformation"; }
  std::string description() const override { return "shear deformation and rotary inertia (Timoshenko beams) in all members"; }
  std::vector<CandidateParameter> parameters() const override { return {{"1/kappa", 0.0, 0.0, 20.0}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      const Member mb = member(m, e);
      Eigen::VectorXd d = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(mb.dofs.size()));
      int seen = 0;
      for (std::size_t k = 0; k < mb.types.size(); ++k)
        if (mb.types[k].second == Dof::RZ) d[static_cast<Eigen::Index>(k)] = seen++ == 0 ? 1.0 : -1.0;
      const Eigen::MatrixXd D = (mb.EI / mb.L) * d * d.transpose();
      const double phi0 = 12.0 * mb.EI / (mb.GA * mb.L * mb.L);
      const Eigen::MatrixXd Mr = m.rotary_inertia() ? Eigen::MatrixXd() : (mb.rhoI * m.unit_geometric_stiffness(e)).eval();
      CustomTerm t;
      t.dofs = mb.dofs;
      t.params = {first};
      t.eval = [Kb = mb.Kb, D, phi0, Mr](const Eigen::VectorXd& th, Eigen::MatrixXd* dK, Eigen::MatrixXd* dM,
                                         std::vector<Eigen::MatrixXd>* dKd, std::vector<Eigen::MatrixXd>* dMd) {
        const double a = th[0], q = 1.0 + a * phi0;
        if (dK) *dK = (Kb + a * phi0 * D) / q - Kb;
        if (dM && Mr.size()) *dM = Mr;
        if (dKd) *dKd = {phi0 * (D - Kb) / (q * q)};
        if (dMd) *dMd = {Eigen::MatrixXd()};
      };
      out.push_back(std::move(t));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    const double a = std::max(th[0], 1e-300);
    return {{"shear coefficient kappa", "", 1.0 / a, sd[0] / (a * a)}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "the members deform in shear (Timoshenko, not Euler-Bernoulli beams): shear coefficient kappa = " + with_std(v[0]);
  }
};

// ---- axial preload (geometric stiffness) --------------------------------------------------------------------
class AxialPreload : public OnElements {
 public:
  AxialPreload(const Model& m, std::string group, std::vector<int> els)
      : OnElements(m, std::move(els)), group_(std::move(group)) {
    // Reference force: the Euler load pi^2 EI / Lg^2 of the group's extent Lg.
    double EI = 0;
    Eigen::Vector3d a = Eigen::Vector3d::Constant(1e300), b = -a;
    for (int e : els_) {
      const Member mb = member(m, e);
      EI += mb.EI / static_cast<double>(els_.size());
      for (int k = 0; k < 2; ++k) {
        a = a.cwiseMin(m.nodes()[m.element_nodes(e)[k]].x);
        b = b.cwiseMax(m.nodes()[m.element_nodes(e)[k]].x);
      }
    }
    const double Lg = std::max((b - a).norm(), 1e-12);
    pref_ = M_PI * M_PI * EI / (Lg * Lg);
  }
  std::string kind() const override { return "axial_preload"; }
  std::string description() const override { return "axial preload (geometric stiffness) in " + group_words(group_); }
  std::vector<CandidateParameter> parameters() const override { return {{"force", 0.0, -0.9, 200.0}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      std::vector<int> dofs;
      m.element_dofs(e, &dofs);
      out.push_back(linear_term(dofs, pref_ * m.unit_geometric_stiffness(e), {}, first));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"axial force", "N", pref_ * th[0], pref_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return group_words(group_) + (v[0].value >= 0 ? " carry an axial tension" : " carry an axial compression") +
           " the model leaves out: " + with_std(PhysicalValue{v[0].name, v[0].unit, std::abs(v[0].value), v[0].std});
  }

 private:
  std::string group_;
  double pref_ = 1;
};

// ---- distributed non-structural mass on a group ---------------------------------------------------------------
class NonStructuralMass : public OnElements {
 public:
  NonStructuralMass(const Model& m, std::string group, std::vector<int> els)
      : OnElements(m, std::move(els)), group_(std::move(group)) {
    double len = 0;
    for (int e : els_) {
      const Member mb = member(m, e);
      mass_ += mb.rhoA * mb.L;
      len += mb.L;
    }
    per_length_ = mass_ / std::max(len, 1e-300);
  }
  std::string kind() const override { return "distributed_mass"; }
  std::string description() const override { return "distributed non-structural mass on " + group_words(group_); }
  std::vector<CandidateParameter> parameters() const override { return {{"fraction", 0.0, 0.0, 5.0}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      const Member mb = member(m, e);
      out.push_back(linear_term(mb.dofs, {}, mb.Mt, first));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"mass per length", "kg/m", per_length_ * th[0], per_length_ * sd[0]}, {"total", "kg", mass_ * th[0], mass_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return group_words(group_) + " carry non-structural mass (cladding, fittings, payload): " + with_std(v[0]) + " (" +
           fmt_value(v[1].value, 3) + " kg in all)";
  }

 private:
  std::string group_;
  double mass_ = 0, per_length_ = 0;
};

// ---- point masses at a set of nodes (sensor mass loading) or springs at a set (suspension) ---------------------
class NodeSet : public Candidate {
 public:
  NodeSet(const Model& m, std::vector<int> nodes, bool springs, double ref) : springs_(springs), ref_(ref) {
    for (int n : nodes) {
      std::vector<int> d;
      for (int t = 0; t < 3; ++t)
        if (m.dof_map().eq(n, static_cast<Dof>(t)) >= 0) d.push_back(m.dof_map().eq(n, static_cast<Dof>(t)));
      if (d.empty()) continue;
      ids_.push_back(m.nodes()[n].id);
      dofs_.push_back(std::move(d));
    }
  }
  bool ok() const { return !ids_.empty(); }
  std::string kind() const override { return springs_ ? "suspension_stiffness" : "sensor_mass"; }
  std::string description() const override {
    return springs_ ? "suspension springs of the free-free test at " + std::to_string(ids_.size()) + " points"
                    : "mass of the sensors at the " + std::to_string(ids_.size()) + " measured nodes";
  }
  Site site() const override { return {ids_, {}}; }
  bool global() const override { return true; }
  std::vector<CandidateParameter> parameters() const override { return {{springs_ ? "stiffness" : "mass", 0.0, 0.0, springs_ ? 1e4 : 20.0}}; }
  std::vector<CustomTerm> terms(const Model&, int first) const override {
    std::vector<CustomTerm> out;
    for (const auto& d : dofs_) {
      const Eigen::MatrixXd I = ref_ * Eigen::MatrixXd::Identity(static_cast<Eigen::Index>(d.size()), static_cast<Eigen::Index>(d.size()));
      out.push_back(springs_ ? linear_term(d, I, {}, first) : linear_term(d, {}, I, first));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{springs_ ? "stiffness per point" : "mass per sensor", springs_ ? "N/m" : "kg", ref_ * th[0], ref_ * sd[0]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return springs_ ? "the free-free test was not free: suspension stiffness " + with_std(v[0]) + " at each support point"
                    : "the sensors load the structure: " + with_std(v[0]) + " at each of the " + std::to_string(ids_.size()) + " measured nodes";
  }

 private:
  bool springs_;
  double ref_;
  std::vector<int> ids_;
  std::vector<std::vector<int>> dofs_;
};

// ---- the classic alternative: recalibrate E and rho globally -------------------------------------------------
class Recalibration : public OnElements {
 public:
  Recalibration(const Model& m, std::vector<int> els) : OnElements(m, std::move(els)) {}
  std::string kind() const override { return "global_recalibration"; }
  std::string description() const override { return "recalibrate the stiffness (E) and mass (rho) of the whole model"; }
  std::vector<CandidateParameter> parameters() const override { return {{"E change", 0.0, -0.9, 3.0}, {"rho change", 0.0, -0.9, 3.0}}; }
  std::vector<CustomTerm> terms(const Model& m, int first) const override {
    std::vector<CustomTerm> out;
    for (int e : els_) {
      const Member mb = member(m, e);
      out.push_back(linear_term(mb.dofs, mb.Ks, {}, first));
      out.push_back(linear_term(mb.dofs, {}, mb.M, first + 1));
    }
    return out;
  }
  std::vector<PhysicalValue> physical(const Eigen::VectorXd& th, const Eigen::VectorXd& sd) const override {
    return {{"E factor", "", 1.0 + th[0], sd[0]}, {"rho factor", "", 1.0 + th[1], sd[1]}};
  }
  std::string finding(const std::vector<PhysicalValue>& v) const override {
    return "the members' E and rho are off: E x " + fmt_value(v[0].value, 4) + ", rho x " + fmt_value(v[1].value, 4);
  }
};

}  // namespace

std::unique_ptr<Candidate> make_recalibration(const Model& model) {
  std::vector<int> all(static_cast<std::size_t>(model.num_elements()));
  for (int e = 0; e < model.num_elements(); ++e) all[static_cast<std::size_t>(e)] = e;
  return std::make_unique<Recalibration>(model, all);
}

std::vector<std::unique_ptr<Candidate>> library(const Model& model, const ModalData& measured, const DiscoveryOptions& o) {
  std::vector<std::unique_ptr<Candidate>> out;
  auto want = [&](const std::string& k) {
    if (o.kinds.empty()) return true;
    for (const std::string& w : o.kinds)
      if (w == k) return true;
    return false;
  };
  auto add = [&](std::unique_ptr<Candidate> c) {
    if (want(c->kind())) out.push_back(std::move(c));
  };
  const int nn = static_cast<int>(model.nodes().size());
  // Node degree (members at each node) and total structural mass (reference scales).
  std::vector<std::vector<std::pair<int, int>>> ends(static_cast<std::size_t>(nn));  // (element, end)
  std::vector<char> used(static_cast<std::size_t>(nn), 0);
  double mass = 0;
  for (int e = 0; e < model.num_elements(); ++e) {
    for (int k = 0; k < model.elements()[e].num_nodes; ++k) used[model.element_nodes(e)[k]] = 1;
    if (model.elements()[e].type == ElementType::PointMass) mass += model.elements()[e].mass;
    if (model.elements()[e].type == ElementType::Matrix) mass += translational_mass(model, e);
    if (!is_member(model, e)) continue;
    for (int k = 0; k < 2; ++k) ends[model.element_nodes(e)[k]].push_back({e, k});
    const Member mb = member(model, e);
    mass += mb.rhoA * mb.L;
  }
  int with_elements = 0;
  for (char u : used) with_elements += u;
  const double mref = mass / std::max(with_elements, 1);
  AssembledSystem sys = assemble_system(model);
  for (int n = 0; n < nn; ++n) {
    if (!used[n]) continue;
    auto lm = std::make_unique<LumpedMass>(model, n, mref);
    if (lm->ok()) add(std::move(lm));
    for (int t = 0; t < kNumDofTypes; ++t) {
      const Dof d = static_cast<Dof>(t);
      if (!(model.dof_map().active(n) & (1u << t))) continue;
      const int eq = model.dof_map().eq(n, d);
      const bool restrained = eq < 0;
      if (restrained) {
        // A support that may not be rigid: release the single member's end (with several members a node spring
        // would need a new DOF).
        if (ends[n].size() == 1) {
          auto r = std::make_unique<EndRelease>(model, ends[n][0].first, ends[n][0].second, d, true);
          if (r->ok()) add(std::move(r));
        }
      } else if (is_rotation(d) && ends[n].size() >= 2 && model.elements()[ends[n][0].first].type != ElementType::Frame3D) {
        // A joint: each member end may be connected semi-rigidly.
        for (const auto& [e, k] : ends[n]) {
          auto r = std::make_unique<EndRelease>(model, e, k, d, false);
          if (r->ok()) add(std::move(r));
        }
      } else if (!model.free_free() || is_rotation(d)) {
        add(std::make_unique<GroundedSpring>(model, n, d, sys.K.coeff(eq, eq)));
      }
    }
  }
  for (int e = 0; e < model.num_elements(); ++e)
    for (bool m : {false, true})
      if (ElementChange::applies(model, e, m)) add(std::make_unique<ElementChange>(model, e, m));
  // Global candidates.
  const std::vector<int> all = group_members(model, "");
  std::set<std::string> groups;
  for (int e : all) groups.insert(model.elements()[e].group);
  std::vector<std::string> gl = {""};
  if (groups.size() > 1)
    for (const std::string& g : groups)
      if (!g.empty()) gl.push_back(g);
  bool plane_members = true;
  for (int e : all) plane_members = plane_members && model.elements()[e].type != ElementType::Frame3D;
  if (plane_members && !all.empty()) add(std::make_unique<ShearDeformation>(model, all));
  for (const std::string& g : gl) {
    const std::vector<int> els = group_members(model, g);
    if (els.empty()) continue;
    add(std::make_unique<AxialPreload>(model, g, els));
    add(std::make_unique<NonStructuralMass>(model, g, els));
  }
  std::vector<int> sensors;
  if (!o.sensor_nodes.empty()) {
    for (int id : o.sensor_nodes) {
      const int n = model.node_index(id);
      if (n < 0) throw InputError("discover: sensor node " + std::to_string(id) + " does not exist");
      sensors.push_back(n);
    }
  } else {
    std::set<int> s;
    for (const MeasuredDof& d : measured.dofs) s.insert(model.node_index(d.node));
    sensors.assign(s.begin(), s.end());
  }
  {
    auto sm = std::make_unique<NodeSet>(model, sensors, false, 0.02 * mass / std::max<double>(1.0, static_cast<double>(sensors.size())));
    if (sm->ok()) add(std::move(sm));
  }
  if (model.free_free()) {
    std::vector<int> sus;
    for (int id : o.suspension_nodes) {
      const int n = model.node_index(id);
      if (n < 0) throw InputError("discover: suspension node " + std::to_string(id) + " does not exist");
      sus.push_back(n);
    }
    if (sus.empty()) {  // the two nodes farthest apart
      double best = -1;
      for (int a = 0; a < nn; ++a)
        for (int b = a + 1; b < nn; ++b) {
          const double d = (model.nodes()[a].x - model.nodes()[b].x).norm();
          if (d > best) {
            best = d;
            sus = {a, b};
          }
        }
    }
    // Reference: a rigid-body frequency of 1 % of the first measured one on the whole mass.
    const double w = 2 * M_PI * 0.01 * measured.frequencies_hz.minCoeff();
    auto ss = std::make_unique<NodeSet>(model, sus, true, mass * w * w / std::max<double>(1.0, static_cast<double>(sus.size())));
    if (ss->ok()) add(std::move(ss));
  }
  return out;
}

}  // namespace dynid::internal
