// semi_rigid_joint / flexible_support: a member end released onto a spring. At a joint of two or more members
// the member connects semi-rigidly (a rotational spring between member end and joint); at a support with one
// member the support is not rigid (a spring between member end and ground).
#include <complex>
#include <set>

#include "candidates/common.hpp"

namespace dynid::internal {
namespace {

using Cd = std::complex<double>;

// The member's DOF i at one end becomes internal, tied to the node (or to the ground when the node's DOF is
// restrained) by a spring of flexibility c = ctil / K_ii. Condensing the internal DOF: with b = row i of the member
// matrix, theta_int = (x_i - c sum_{j != i} B_ij x_j) / (1 + c B_ii), and the condensed stiffness is
// T^T B T + c b b^T / (1 + c B_ii)^2 with T = I + e_i (g - e_i)^T; the mass is condensed with the same T. At c = 0
// it is the rigid connection. Derivatives by complex step (exact to rounding).
class EndRelease : public Candidate {
 public:
  // member_length: the length of the member (chain of elements) element e belongs to.
  EndRelease(const Model& m, int e, int end, Dof d, bool support, double member_length)
      : e_(e), eid_(m.elements()[e].id), nid_(m.nodes()[m.element_nodes(e)[end]].id), dof_(d), support_(support) {
    const auto types = m.element_dof_types(e);
    for (std::size_t k = 0; k < types.size(); ++k)
      if (types[k].first == m.element_nodes(e)[end] && types[k].second == d) i_ = static_cast<int>(k);
    const Member mb = member(m, e);
    if (i_ >= 0) kii_ = mb.K(i_, i_);
    // The element's end stiffness over the whole member's: (L / l)^p with p = 1 for a rotation or an axial
    // translation (E I / l, E A / l), 3 for a transverse one (E I / l^3), so that the prior is the member's, not
    // the mesh's.
    const auto& n = m.element_nodes(e);
    const Eigen::Vector3d axis = (m.nodes()[n[1]].x - m.nodes()[n[0]].x).normalized();
    const bool transverse = !is_rotation(d) && std::abs(axis[static_cast<int>(d)]) < 0.9;
    if (mb.L > 0 && member_length > mb.L) mscale_ = std::pow(member_length / mb.L, transverse ? 3.0 : 1.0);
  }
  bool ok() const { return i_ >= 0 && kii_ > 0; }
  std::string kind() const override { return support_ ? "flexible_support" : "semi_rigid_joint"; }
  Nature nature() const override { return Nature::kStiffness; }
  std::string description() const override {
    return support_ ? std::string(is_rotation(dof_) ? "rotational" : "translational") + " flexibility of the support at node " +
                          std::to_string(nid_) + " (" + std::string(dof_name(dof_)) + ", through element " + std::to_string(eid_) + ")"
                    : "semi-rigid connection of element " + std::to_string(eid_) + " to joint " + std::to_string(nid_) +
                          " (spring on " + std::string(dof_name(dof_)) + ")";
  }
  Site site() const override { return {{nid_}, {eid_}}; }
  // Flexibility in units of the element end's own flexibility 1 / K_ii. Heavy-tailed prior of median the whole
  // member's end flexibility (mscale_ / K_ii): a connection anywhere from rigid to pinned, its fixity against
  // the member 1 / (1 + flexibility / mscale_) uniform, whatever the mesh.
  std::vector<CandidateParameter> parameters() const override {
    return {{"flexibility", 0.0, 0.0, 100.0 * mscale_, mscale_, CandidateParameter::Prior::kHeavyTailed}};
  }

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
  double kii_ = 0;     // the element's stiffness on the released DOF: c = ctil / kii
  double mscale_ = 1;  // K_ii of the element over that of the whole member
};

// Per element, the length of the member (CandidateContext::members) it belongs to; 0 for elements in none.
std::vector<double> member_lengths(const CandidateContext& c) {
  const Model& m = *c.model;
  std::vector<double> out(static_cast<std::size_t>(m.num_elements()), 0.0);
  for (const std::vector<int>& chain : c.members) {
    double L = 0;
    for (int e : chain) {
      const auto& n = m.element_nodes(e);
      L += (m.nodes()[n[1]].x - m.nodes()[n[0]].x).norm();
    }
    for (int e : chain) out[static_cast<std::size_t>(e)] = L;
  }
  return out;
}

// Whether rotation d at a member end is a bending rotation of the member (not a twist about its axis).
bool bends(const Model& m, int e, Dof d) {
  if (!element_kind(m.elements()[e].type).spatial()) return true;
  const auto& n = m.element_nodes(e);
  const Eigen::Vector3d axis = (m.nodes()[n[1]].x - m.nodes()[n[0]].x).normalized();
  return std::abs(axis[static_cast<int>(d) - 3]) < 0.9;
}

}  // namespace

CandidateKind semi_rigid_joint_kind() {
  return {"semi_rigid_joint", Nature::kStiffness, "a member end connected to its joint through a rotational spring",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            const Model& m = *c.model;
            const std::vector<double> length = member_lengths(c);
            // A joint is where two or more members meet: a node inside one member (two of its elements in line)
            // connects nothing; a hinge there is damage of the member, which element_stiffness covers.
            std::vector<int> member_of(static_cast<std::size_t>(m.num_elements()), -1);
            for (std::size_t k = 0; k < c.members.size(); ++k)
              for (int e : c.members[k]) member_of[static_cast<std::size_t>(e)] = static_cast<int>(k);
            for (int n = 0; n < static_cast<int>(m.nodes().size()); ++n) {
              std::set<int> members;
              for (const auto& [e, k] : c.member_ends[n]) members.insert(member_of[static_cast<std::size_t>(e)]);
              if (members.size() < 2) continue;
              for (int t = 3; t < kNumDofTypes; ++t) {
                const Dof d = static_cast<Dof>(t);
                if (m.dof_map().eq(n, d) < 0) continue;
                for (const auto& [e, k] : c.member_ends[n]) {
                  if (!bends(m, e, d)) continue;
                  auto r = std::make_unique<EndRelease>(m, e, k, d, false, length[static_cast<std::size_t>(e)]);
                  if (r->ok()) out.push_back(std::move(r));
                }
              }
            }
            return out;
          }};
}

CandidateKind flexible_support_kind() {
  return {"flexible_support", Nature::kStiffness,
          "a support that is not rigid: the end of its single member released onto a spring to ground",
          [](const CandidateContext& c) {
            std::vector<std::unique_ptr<Candidate>> out;
            const Model& m = *c.model;
            const std::vector<double> length = member_lengths(c);
            for (int n = 0; n < static_cast<int>(m.nodes().size()); ++n) {
              if (c.member_ends[n].size() != 1) continue;  // with several members a spring would need a new DOF
              const auto [e, k] = c.member_ends[n][0];
              for (int t = 0; t < kNumDofTypes; ++t) {
                const Dof d = static_cast<Dof>(t);
                if (!(c.support[static_cast<std::size_t>(n)] & (1u << t))) continue;  // a support's restraint only
                if (is_rotation(d) && !bends(m, e, d)) continue;
                auto r = std::make_unique<EndRelease>(m, e, k, d, true, length[static_cast<std::size_t>(e)]);
                if (r->ok()) out.push_back(std::move(r));
              }
            }
            return out;
          }};
}

}  // namespace dynid::internal
