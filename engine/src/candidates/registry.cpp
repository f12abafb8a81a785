// The candidate kinds dynid ships: one line per kind (each kind is one file in this folder).
#include "candidates/registry.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "candidates/common.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid {
namespace internal {

CandidateKind lumped_mass_kind();
CandidateKind element_point_mass_kind();
CandidateKind grounded_spring_kind();
CandidateKind rotational_spring_kind();
CandidateKind semi_rigid_joint_kind();
CandidateKind flexible_support_kind();
CandidateKind element_stiffness_kind();
CandidateKind element_mass_kind();
CandidateKind member_damage_kind();
CandidateKind shear_deformation_kind();
CandidateKind axial_preload_kind();
CandidateKind self_weight_kind();
CandidateKind distributed_mass_kind();
CandidateKind sensor_mass_kind();
CandidateKind suspension_stiffness_kind();

namespace {

// Chains of collinear members of one group and type joined at unsupported nodes where only they meet.
std::vector<std::vector<int>> member_chains(const Model& m, const std::vector<std::vector<std::pair<int, int>>>& ends,
                                            const std::vector<DofMask>& support) {
  const int nn = static_cast<int>(m.nodes().size());
  auto dir = [&](int e) {
    const auto& n = m.element_nodes(e);
    return Eigen::Vector3d((m.nodes()[n[1]].x - m.nodes()[n[0]].x).normalized());
  };
  // A node continues a chain when exactly two members of the same group and type meet there in line, and the
  // node is no support.
  std::vector<char> through(static_cast<std::size_t>(nn), 0);
  for (int n = 0; n < nn; ++n) {
    if (ends[n].size() != 2) continue;
    const int a = ends[n][0].first, b = ends[n][1].first;
    const Element &ea = m.elements()[a], &eb = m.elements()[b];
    through[n] = !support[static_cast<std::size_t>(n)] && ea.group == eb.group && ea.type == eb.type &&
                 std::abs(dir(a).dot(dir(b))) > 1 - 1e-9;
  }
  std::vector<char> seen(static_cast<std::size_t>(m.num_elements()), 0);
  std::vector<std::vector<int>> out;
  for (int e = 0; e < m.num_elements(); ++e) {
    if (seen[e] || !is_member(m.elements()[e].type)) continue;
    // Walk to one end of e's chain, then collect along it.
    int cur = e, from = m.element_nodes(e)[1];
    for (int guard = 0; guard < m.num_elements(); ++guard) {
      const int n = m.element_nodes(cur)[0] == from ? m.element_nodes(cur)[1] : m.element_nodes(cur)[0];
      if (!through[n]) break;
      const int next = ends[n][0].first == cur ? ends[n][1].first : ends[n][0].first;
      if (next == e) break;  // a closed ring
      from = n;
      cur = next;
    }
    // cur is an end element; its far node from the chain is the end node.
    std::vector<int> chain;
    int end_node = m.element_nodes(cur)[0] == from ? m.element_nodes(cur)[1] : m.element_nodes(cur)[0];
    int el = cur;
    for (int guard = 0; guard <= m.num_elements() && el >= 0 && !seen[el]; ++guard) {
      seen[el] = 1;
      chain.push_back(el);
      const int n = m.element_nodes(el)[0] == end_node ? m.element_nodes(el)[1] : m.element_nodes(el)[0];
      if (!through[n]) break;
      const int next = ends[n][0].first == el ? ends[n][1].first : ends[n][0].first;
      end_node = n;
      el = next;
    }
    out.push_back(std::move(chain));
  }
  return out;
}

}  // namespace

CandidateContext make_context(const Model& model, const ModalData& measured, const std::vector<int>& sensor_ids,
                              const std::vector<int>& suspension_ids, const Eigen::Vector3d& gravity,
                              const ModalResult& modes, const std::vector<int>& band_modes) {
  CandidateContext c;
  c.model = &model;
  c.measured = &measured;
  const int nn = static_cast<int>(model.nodes().size());
  c.member_ends.assign(static_cast<std::size_t>(nn), {});
  c.node_used.assign(static_cast<std::size_t>(nn), 0);
  for (int e = 0; e < model.num_elements(); ++e) {
    const Element& el = model.elements()[e];
    for (int k = 0; k < el.num_nodes; ++k) c.node_used[model.element_nodes(e)[k]] = 1;
    if (el.type == ElementType::Matrix && el.matrix) {
      for (const auto& [id, d] : el.matrix->dofs) c.node_used[model.node_index(id)] = 1;
      for (int id : el.matrix->nodes) c.node_used[model.node_index(id)] = 1;
    }
    if (el.type == ElementType::PointMass) c.structure_mass += el.mass;
    if (el.type == ElementType::Matrix) c.structure_mass += translational_mass(model, e);
    if (!is_member(el.type)) continue;
    for (int k = 0; k < 2; ++k) c.member_ends[model.element_nodes(e)[k]].push_back({e, k});
    const Member mb = member(model, e);
    c.structure_mass += mb.rhoA * mb.L;
  }
  c.support = support_restraints(model);
  c.members = member_chains(model, c.member_ends, c.support);
  const AssembledSystem sys = assemble_system(model);
  c.stiffness_diagonal = sys.K.diagonal();
  // The band: the model's elastic modes paired with the data (the first as many as the data hold if none given).
  c.band_stiffness = c.stiffness_diagonal;
  std::vector<int> band = band_modes;
  if (band.empty())
    for (int k = 0; k < measured.num_modes(); ++k) band.push_back(k);
  if (!band.empty() && sys.K.rows() > 0) {
    std::vector<Eigen::Index> elastic;
    for (Eigen::Index j = 0; modes.ok() && j < modes.eigenvalues.size(); ++j)
      if (!modes.rigid_body[static_cast<std::size_t>(j)] && modes.eigenvalues[j] > 0) elastic.push_back(j);
    std::set<int> unique(band.begin(), band.end());
    std::vector<Eigen::Index> cols;
    for (int k : unique)
      if (k >= 0 && static_cast<std::size_t>(k) < elastic.size()) cols.push_back(elastic[static_cast<std::size_t>(k)]);
    c.band_modes.resize(sys.K.rows(), static_cast<Eigen::Index>(cols.size()));
    c.band_eigenvalues.resize(static_cast<Eigen::Index>(cols.size()));
    for (std::size_t j = 0; j < cols.size(); ++j) {
      c.band_modes.col(static_cast<Eigen::Index>(j)) = modes.modes.col(cols[j]);
      c.band_eigenvalues[static_cast<Eigen::Index>(j)] = modes.eigenvalues[cols[j]];
    }
    Eigen::VectorXd flex = Eigen::VectorXd::Zero(sys.K.rows());
    for (Eigen::Index j = 0; j < c.band_modes.cols(); ++j)
      flex += c.band_modes.col(j).cwiseAbs2() / c.band_eigenvalues[j];
    for (Eigen::Index i = 0; i < flex.size(); ++i)
      if (flex[i] * c.stiffness_diagonal[i] > 1.0) c.band_stiffness[i] = 1.0 / flex[i];
  }
  auto resolve = [&](const std::vector<int>& ids, const char* what) {
    std::vector<int> out;
    for (int id : ids) {
      const int n = model.node_index(id);
      if (n < 0) throw InputError(std::string("discover: ") + what + " node " + std::to_string(id) + " does not exist");
      out.push_back(n);
    }
    return out;
  };
  c.sensor_nodes = resolve(sensor_ids, "sensor");
  if (c.sensor_nodes.empty()) {
    std::set<int> s;
    for (const MeasuredDof& d : measured.dofs)
      if (model.node_index(d.node) >= 0) s.insert(model.node_index(d.node));
    c.sensor_nodes.assign(s.begin(), s.end());
  }
  if (model.free_free()) {
    c.suspension_nodes = resolve(suspension_ids, "suspension");
    if (c.suspension_nodes.empty()) {  // the two nodes farthest apart
      double best = -1;
      for (int a = 0; a < nn; ++a)
        for (int b = a + 1; b < nn; ++b) {
          const double d = (model.nodes()[a].x - model.nodes()[b].x).norm();
          if (c.node_used[a] && c.node_used[b] && d > best) best = d, c.suspension_nodes = {a, b};
        }
    }
  }
  c.gravity = gravity.normalized();
  return c;
}

Eigen::Vector3d default_gravity(const Model& model, bool* unconventional) {
  bool space = false;
  for (const Element& el : model.elements()) space = space || element_kind(el.type).spatial();
  if (unconventional) *unconventional = false;
  if (!space) return Eigen::Vector3d(0, -1, 0);  // plane models: y up in every code we know of
  // The extent of the nodes elements use, and the highest coordinates of the supported ones (a translation
  // restrained as a support: support_restraints).
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = Eigen::Vector3d::Constant(-INFINITY), shi = hi;
  const DofMask translations = dof_bit(Dof::UX) | dof_bit(Dof::UY) | dof_bit(Dof::UZ);
  const std::vector<DofMask> support = support_restraints(model);
  const int nn = static_cast<int>(model.nodes().size());
  for (int n = 0; n < nn; ++n) {
    if (!model.dof_map().active(n)) continue;
    const Eigen::Vector3d& x = model.nodes()[n].x;
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
    if (support[static_cast<std::size_t>(n)] & translations) shi = shi.cwiseMax(x);
  }
  // Space models are drawn with z up or with y up. A structure that extends along two axes or more and has every
  // support at its lowest z (1 % of its extent there) stands on z; otherwise, every support at its lowest y, it
  // stands on y; otherwise (supports at several levels, a line of members) z up.
  const Eigen::Vector3d ext = hi - lo;
  const int extended = (ext.array() > 0).count();
  auto at_bottom = [&](int a) { return ext[a] > 0 && shi[a] - lo[a] <= 0.01 * ext[a]; };
  if (!shi.allFinite() || extended < 2 || at_bottom(2) || !at_bottom(1)) return Eigen::Vector3d(0, 0, -1);
  if (unconventional) *unconventional = ext[2] > 0;  // a space model flat in x-y (a plane frame) has y up: no doubt
  return Eigen::Vector3d(0, -1, 0);
}

std::vector<std::unique_ptr<Candidate>> place_candidates(const CandidateContext& c, const std::vector<CandidateKind>& registry,
                                                         const std::vector<std::string>& kinds) {
  for (const std::string& k : kinds) {
    bool known = false;
    for (const CandidateKind& r : registry) known = known || r.name == k;
    if (!known) {
      std::string list;
      for (const CandidateKind& r : registry) list += (list.empty() ? "" : ", ") + r.name;
      throw InputError("discover: unknown candidate kind '" + k + "' (known kinds: " + list + ")");
    }
  }
  std::vector<std::unique_ptr<Candidate>> out;
  for (const CandidateKind& r : registry) {
    bool want = kinds.empty();
    for (const std::string& k : kinds) want = want || k == r.name;
    if (!want) continue;
    for (auto& cand : r.place(c)) out.push_back(std::move(cand));
  }
  return out;
}

}  // namespace internal

const std::vector<CandidateKind>& builtin_candidate_kinds() {
  using namespace internal;
  static const std::vector<CandidateKind> kinds = {
      lumped_mass_kind(),        element_point_mass_kind(), grounded_spring_kind(),  rotational_spring_kind(),
      semi_rigid_joint_kind(),   flexible_support_kind(),   element_stiffness_kind(), element_mass_kind(),
      member_damage_kind(),      shear_deformation_kind(),  axial_preload_kind(),     self_weight_kind(),
      distributed_mass_kind(),   sensor_mass_kind(),        suspension_stiffness_kind(),
  };
  return kinds;
}

}  // namespace dynid
