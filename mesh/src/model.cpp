#include "dynid/mesh/model.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "dynid/mesh/error.hpp"
#include "internal/element_kinds.hpp"

namespace dynid {

namespace {
// The six unit rigid motions (translations x, y, z; rotations about x, y, z through the centroid c) on the free
// DOFs, unnormalised.
Eigen::MatrixXd rigid_columns(const std::vector<Node>& nodes, const DofMap& dofs, Eigen::Vector3d* centroid) {
  const int n = dofs.num_free();
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Node& nd : nodes) c += nd.x;
  c /= static_cast<double>(std::max<std::size_t>(1, nodes.size()));
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(n, 6);
  for (int i = 0; i < n; ++i) {
    const int t = static_cast<int>(dofs.type_of(i));
    const Eigen::Vector3d r = nodes[dofs.node_of(i)].x - c;
    R(i, t) = 1.0;
    if (t < 3)
      for (int w = 0; w < 3; ++w) R(i, 3 + w) = Eigen::Vector3d::Unit(w).cross(r)[t];
  }
  if (centroid) *centroid = c;
  return R;
}

std::string fmt_point(const Eigen::Vector3d& p) {
  std::ostringstream s;
  auto z = [](double v) { return std::abs(v) < 1e-12 ? 0.0 : v; };
  s << "(" << z(p.x()) << ", " << z(p.y()) << ", " << z(p.z()) << ")";
  return s.str();
}

// Describes a rigid motion u: a translation, or a rotation about an axis through a point.
std::string describe_rigid(const Eigen::MatrixXd& R6, const Eigen::Vector3d& c, const Eigen::VectorXd& u) {
  const Eigen::VectorXd p = R6.completeOrthogonalDecomposition().solve(u);
  Eigen::Vector3d t = p.head<3>(), w = p.tail<3>();
  const double scale = std::max(t.norm(), w.norm() * 1.0);
  if (w.norm() < 1e-8 * scale) {
    t /= t.norm();
    for (int k = 0; k < 3; ++k)
      if (std::abs(std::abs(t[k]) - 1) < 1e-8) return std::string("translation ") + "xyz"[k];
    return "translation along " + fmt_point(t);
  }
  // u = t + w x (x - c) = w x (x - a) with a - c = (w x t) / |w|^2, if t is perpendicular to w.
  if (std::abs(t.dot(w)) > 1e-8 * t.norm() * w.norm()) return "screw motion about " + fmt_point(w.normalized());
  const Eigen::Vector3d a = c + w.cross(t) / w.squaredNorm();
  const Eigen::Vector3d d = w.normalized();
  std::string axis = "axis " + fmt_point(d);
  for (int k = 0; k < 3; ++k)
    if (std::abs(std::abs(d[k]) - 1) < 1e-8) axis = std::string(1, "xyz"[k]);
  return "rotation about " + axis + " through " + fmt_point(a);
}

}  // namespace

Element make_matrix_element(int id, MatrixElementData data, std::string group) {
  Element e;
  e.id = id;
  e.type = ElementType::Matrix;
  e.num_nodes = 0;
  std::vector<int> nodes = data.nodes;
  if (nodes.empty())
    for (const auto& [node, d] : data.dofs) nodes.push_back(node);
  for (int node : nodes) {
    if (e.num_nodes == 2 || (e.num_nodes == 1 && e.node_ids[0] == node)) continue;
    e.node_ids[e.num_nodes++] = node;
  }
  e.group = std::move(group);
  e.matrix = std::make_shared<const MatrixElementData>(std::move(data));
  return e;
}

Eigen::MatrixXd ElementParts::K() const { return K_axial + K_bending + K_torsion + K_discrete + K_geometric; }
Eigen::MatrixXd ElementParts::M() const { return M_translational + M_rotary + M_discrete; }

int Model::add_node(int id, const Eigen::Vector3d& x) {
  if (node_of_id_.count(id)) throw InputError("node " + std::to_string(id) + " is defined twice");
  if (!x.allFinite()) throw InputError("node " + std::to_string(id) + " has a non-finite coordinate");
  finalized_ = false;
  nodes_.push_back({id, x});
  node_of_id_[id] = static_cast<int>(nodes_.size()) - 1;
  return static_cast<int>(nodes_.size()) - 1;
}

int Model::add_material(const Material& m) {
  finalized_ = false;
  materials_.push_back(m);
  return static_cast<int>(materials_.size()) - 1;
}

int Model::add_section(const Section& s) {
  finalized_ = false;
  sections_.push_back(s);
  return static_cast<int>(sections_.size()) - 1;
}

int Model::add_element(const Element& e) {
  if (element_of_id_.count(e.id)) throw InputError("element " + std::to_string(e.id) + " is defined twice");
  finalized_ = false;
  elements_.push_back(e);
  element_of_id_[e.id] = static_cast<int>(elements_.size()) - 1;
  return static_cast<int>(elements_.size()) - 1;
}

void Model::restrain(int node_id, DofMask dofs) {
  finalized_ = false;
  restraints_.emplace_back(node_id, dofs);
}

int Model::node_index(int id) const {
  auto it = node_of_id_.find(id);
  return it == node_of_id_.end() ? -1 : it->second;
}

int Model::element_index(int id) const {
  auto it = element_of_id_.find(id);
  return it == element_of_id_.end() ? -1 : it->second;
}

int Model::material_index(const std::string& name) const {
  for (std::size_t i = 0; i < materials_.size(); ++i)
    if (materials_[i].name == name) return static_cast<int>(i);
  return -1;
}

int Model::section_index(const std::string& name) const {
  for (std::size_t i = 0; i < sections_.size(); ++i)
    if (sections_[i].name == name) return static_cast<int>(i);
  return -1;
}

std::string Model::describe_dof(int eq) const {
  if (eq < 0 || eq >= dofs_.num_free()) return "DOF " + std::to_string(eq) + " (out of range)";
  return std::string(dof_name(dofs_.type_of(eq))) + " at node " + std::to_string(nodes_[dofs_.node_of(eq)].id);
}

void Model::require_finalized(const char* what) const {
  if (!finalized_) throw InputError(std::string(what) + ": the model is not finalized (call Model::finalize())");
}

void Model::finalize() {
  warnings_.clear();
  const int nn = static_cast<int>(nodes_.size());
  if (elements_.empty()) throw InputError("the model has no elements");
  element_nodes_.assign(elements_.size(), {{-1, -1}});
  layouts_.assign(elements_.size(), {});
  coupling_.assign(elements_.size(), {});
  sparse_coupling_.assign(elements_.size(), 0);
  std::vector<DofMask> active(nn, 0), restrained(nn, 0);
  std::vector<char> connected(nn, 0);  // nodes drawn by an element without carrying its DOFs
  for (std::size_t k = 0; k < elements_.size(); ++k) {
    const std::string who = internal::element_label(elements_[k]);
    element_kind(elements_[k].type).setup({*this, elements_[k], who, &element_nodes_[k], &active, &connected});
  }
  for (std::size_t k = 0; k < elements_.size(); ++k) {
    const ElementKind& kind = element_kind(elements_[k].type);
    layouts_[k] = kind.layout(*this, static_cast<int>(k), active);
    sparse_coupling_[k] = kind.coupling(*this, static_cast<int>(k), layouts_[k], &coupling_[k]);
  }
  for (const auto& [id, mask] : restraints_) {
    const int n = node_index(id);
    if (n < 0) throw InputError("support at node " + std::to_string(id) + ": node does not exist");
    restrained[n] |= mask;
  }
  for (int n = 0; n < nn; ++n)
    if (active[n] == 0 && !connected[n])
      warnings_.push_back("node " + std::to_string(nodes_[n].id) + " is not connected to any element");
  dofs_ = DofMap(active, restrained);
  if (dofs_.num_free() == 0) throw InputError("the model has no free DOFs (every DOF is restrained)");
  finalized_ = true;
  if (!free_free_) require_rigid_body_support();
}

// Supports and springs must prevent every rigid-body motion, unless the user declared the model free-free.
void Model::require_rigid_body_support() {
  std::vector<std::string> what;
  const Eigen::MatrixXd N = free_rigid_body_modes(&what);
  if (N.cols() > 0) {
    std::string freed;
    for (const std::string& w : what) freed += (freed.empty() ? "" : "; ") + w;
    finalized_ = false;
    throw InputError("the structure is not supported against: " + freed +
                     ". Add supports or springs, or declare it free-free (supports: free) if it is meant to be "
                     "unsupported");
  }
}

Eigen::MatrixXd Model::free_rigid_body_modes(std::vector<std::string>* descriptions) const {
  std::vector<std::string> labels;
  const Eigen::MatrixXd R = rigid_body_motions(&labels);
  const Eigen::Index nc = R.cols();
  if (descriptions) descriptions->clear();
  if (nc == 0) return Eigen::MatrixXd(num_dofs(), 0);
  // Y = K R and Ya = |K| |R|, element by element (no global assembly). A motion r that supports and springs
  // leave free has K r at rounding level compared with |K| |r|, row by row; a restrained one is strained at the
  // supports and springs. Columns of R are unit vectors; rotations are about the centroid, so R is well
  // conditioned.
  Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(num_dofs(), nc), Ya = Y;
  std::vector<int> dofs;
  Eigen::MatrixXd Ke;
  for (int k = 0; k < num_elements(); ++k) {
    element_dofs(k, &dofs);
    element_matrices(k, &Ke, nullptr);
    const int nd = static_cast<int>(dofs.size());
    for (int i = 0; i < nd; ++i) {
      if (dofs[i] < 0) continue;
      for (int j = 0; j < nd; ++j) {
        if (dofs[j] < 0) continue;
        for (Eigen::Index c = 0; c < nc; ++c) {
          const double v = Ke(i, j) * R(dofs[j], c);
          Y(dofs[i], c) += v;
          Ya(dofs[i], c) += std::abs(v);
        }
      }
    }
  }
  // Each row against its own absolute sum: a row's unit (a force, a moment; N or N mm) cancels, and a row where
  // the structure's terms cancel to rounding (~10 eps of that sum) is told from one a spring holds (its k r does
  // not cancel) however stiff the rest of the model is. Against the whole |K| |R| instead, the stiff rows of a fine
  // mesh (12 E I / L^3 grows as the elements shrink) set the level, and a 3 Hz suspension of a 100-element bar
  // passed for free.
  const Eigen::VectorXd sum = Ya.rowwise().sum();
  for (Eigen::Index i = 0; i < Y.rows(); ++i) {
    const double w = sum[i] > 0 ? 1.0 / sum[i] : 0.0;
    Y.row(i) *= w;
    Ya.row(i) *= w;
  }
  constexpr double tol = 1e-12;
  const double scale = Ya.norm() / std::sqrt(static_cast<double>(nc));
  // The motions may be dependent on the free DOFs (a tiny model: fewer free DOFs than motions), so work in an
  // orthonormal basis Q = R W of their span (W = V_r / s_r from the SVD of R; rank by rounding level), and
  // find the combinations Q u with ||K Q u|| = ||Y W u|| at rounding level.
  const Eigen::JacobiSVD<Eigen::MatrixXd> rsvd(R, Eigen::ComputeThinV);
  Eigen::Index rank = 0;
  while (rank < rsvd.singularValues().size() && rsvd.singularValues()[rank] > 1e-12 * rsvd.singularValues()[0]) ++rank;
  const Eigen::MatrixXd W = rsvd.matrixV().leftCols(rank) * rsvd.singularValues().head(rank).cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Y * W, Eigen::ComputeFullV);
  std::vector<Eigen::Index> null;
  const Eigen::Index ns = svd.singularValues().size();
  for (Eigen::Index i = 0; i < rank; ++i)
    if (i >= ns || svd.singularValues()[i] <= tol * scale) null.push_back(i);
  // Prefer the individual motions (translation x, rotation about z, ...) when they span the free subspace.
  std::vector<Eigen::Index> single;
  for (Eigen::Index c = 0; c < nc; ++c)
    if (Y.col(c).norm() <= tol * Ya.col(c).norm()) single.push_back(c);
  Eigen::MatrixXd N(num_dofs(), static_cast<Eigen::Index>(null.size()));
  if (single.size() == null.size()) {
    for (std::size_t k = 0; k < single.size(); ++k) {
      N.col(static_cast<Eigen::Index>(k)) = R.col(single[k]);
      if (descriptions) descriptions->push_back(labels[single[k]]);
    }
  } else {
    for (std::size_t k = 0; k < null.size(); ++k) {
      const Eigen::VectorXd v = W * svd.matrixV().col(null[k]);
      N.col(static_cast<Eigen::Index>(k)) = R * v;
    }
    if (descriptions) {
      Eigen::Vector3d c;
      const Eigen::MatrixXd R6 = rigid_columns(nodes_, dofs_, &c);
      for (Eigen::Index k = 0; k < N.cols(); ++k) descriptions->push_back(describe_rigid(R6, c, N.col(k)));
    }
  }
  return N;
}

void Model::element_dofs(int e, std::vector<int>* dofs) const {
  require_finalized("element_dofs");
  dofs->clear();
  for (const auto& [n, d] : layouts_[e]) dofs->push_back(dofs_.eq(n, d));
}

std::vector<std::pair<int, Dof>> Model::element_dof_types(int e) const {
  require_finalized("element_dof_types");
  return layouts_[e];
}

ElementParts Model::element_parts(int e) const {
  require_finalized("element_parts");
  return element_kind(elements_[e].type).parts(*this, e);
}

Eigen::MatrixXd Model::unit_geometric_stiffness(int e) const {
  require_finalized("unit_geometric_stiffness");
  return element_kind(elements_[e].type).unit_geometric_stiffness(*this, e);
}

std::vector<BendingPlane> Model::member_bending_planes(int e) const {
  require_finalized("member_bending_planes");
  return element_kind(elements_[e].type).bending_planes(*this, e);
}

Eigen::MatrixXd Model::member_point_interpolation(int e, double xi, Eigen::MatrixXd* dN) const {
  require_finalized("member_point_interpolation");
  return element_kind(elements_[e].type).point_interpolation(*this, e, xi, dN);
}

double Model::member_axial_force(int e, const Eigen::VectorXd& u) const {
  require_finalized("member_axial_force");
  return element_kind(elements_[e].type).axial_force(*this, e, u);
}

void Model::element_matrices(int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const {
  require_finalized("element_matrices");
  element_kind(elements_[e].type).matrices(*this, e, K, M);
}

bool Model::element_coupling(int e, std::vector<std::pair<int, int>>* pairs) const {
  require_finalized("element_coupling");
  *pairs = coupling_[e];
  return sparse_coupling_[e] != 0;
}

Eigen::MatrixXd Model::rigid_body_motions(std::vector<std::string>* labels) const {
  require_finalized("rigid_body_motions");
  const Eigen::MatrixXd R = rigid_columns(nodes_, dofs_, nullptr);
  static const std::array<const char*, 6> names = {"translation x", "translation y", "translation z",
                                                   "rotation about x", "rotation about y", "rotation about z"};
  const Eigen::Index n = R.rows();
  Eigen::MatrixXd out(n, 0);
  if (labels) labels->clear();
  for (int k = 0; k < 6; ++k) {
    const double nrm = R.col(k).norm();
    if (nrm == 0.0) continue;
    out.conservativeResize(n, out.cols() + 1);
    out.col(out.cols() - 1) = R.col(k) / nrm;
    if (labels) labels->push_back(names[k]);
  }
  return out;
}

}  // namespace dynid
