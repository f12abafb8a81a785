#include "dynid/mesh/model.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "dynid/mesh/error.hpp"
#include "internal/element_kernels.hpp"

namespace dynid {

namespace {
constexpr std::array<std::string_view, 6> kTypeNames = {"beam2d", "frame2d", "frame3d", "point_mass", "spring", "matrix"};

std::string elem_label(const Element& e) {
  return "element " + std::to_string(e.id) + " (" + std::string(element_type_name(e.type)) + ")";
}

bool finite_positive(double v) { return std::isfinite(v) && v > 0; }

// DOF types a structural element uses at each of its nodes.
DofMask structural_dofs(ElementType t) {
  switch (t) {
    case ElementType::Beam2D: return dof_bit(Dof::UY) | dof_bit(Dof::RZ);
    case ElementType::Frame2D: return dof_bit(Dof::UX) | dof_bit(Dof::UY) | dof_bit(Dof::RZ);
    case ElementType::Frame3D: return kAllDofs;
    default: return 0;
  }
}

std::string fmt_num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

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

std::string_view element_type_name(ElementType t) { return kTypeNames[static_cast<int>(t)]; }

bool parse_element_type(std::string_view name, ElementType* out) {
  for (std::size_t i = 0; i < kTypeNames.size(); ++i)
    if (kTypeNames[i] == name) {
      *out = static_cast<ElementType>(i);
      return true;
    }
  return false;
}

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

void Model::finalize_matrix_element(int k, std::vector<DofMask>* active) {
  const Element& e = elements_[k];
  const std::string who = elem_label(e);
  if (!e.matrix) throw InputError(who + ": no matrices given");
  if (e.num_nodes < 0 || e.num_nodes > 2)
    throw InputError(who + ": num_nodes must be 0, 1 or 2 (the ends drawn); build it with make_matrix_element()");
  const MatrixElementData& d = *e.matrix;
  const Eigen::Index n = static_cast<Eigen::Index>(d.dofs.size());
  if (n == 0) throw InputError(who + ": has no DOFs");
  if (d.K.rows() != n || d.K.cols() != n || d.M.rows() != n || d.M.cols() != n)
    throw InputError(who + ": its stiffness and mass matrices must be " + std::to_string(n) + " x " +
                     std::to_string(n) + " (one row per DOF), got " + std::to_string(d.K.rows()) + " x " +
                     std::to_string(d.K.cols()) + " and " + std::to_string(d.M.rows()) + " x " + std::to_string(d.M.cols()));
  for (double f : {e.factors.E, e.factors.rho})
    if (!finite_positive(f)) throw InputError(who + ": property factors must be finite and > 0");
  auto& out = matrix_dofs_[k];
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& [id, t] = d.dofs[i];
    const int node = node_index(id);
    if (node < 0) throw InputError(who + ": node " + std::to_string(id) + " does not exist");
    for (const auto& [m, u] : out)
      if (m == node && u == t)
        throw InputError(who + ": DOF " + std::string(dof_name(t)) + " at node " + std::to_string(id) + " is listed twice");
    out.emplace_back(node, t);
    (*active)[node] |= dof_bit(t);
  }
  for (const auto* A : {&d.K, &d.M}) {
    const char* what = A == &d.K ? "stiffness" : "mass";
    if (!A->allFinite()) throw InputError(who + ": its " + what + " matrix has a NaN or infinite entry");
    const double scale = A->cwiseAbs().maxCoeff();
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = j + 1; i < n; ++i)
        if (std::abs((*A)(i, j) - (*A)(j, i)) > 1e-12 * scale)
          throw InputError(who + ": its " + what + " matrix is not symmetric (entries " + std::to_string(i + 1) + "," +
                           std::to_string(j + 1) + " and " + std::to_string(j + 1) + "," + std::to_string(i + 1) + " differ)");
  }
  for (int id : d.nodes)
    if (node_index(id) < 0) throw InputError(who + ": node " + std::to_string(id) + " does not exist");
  // Coupling node by node: the blocks of node pairs with a nonzero K or M entry between them, and every node's own
  // block. A group matrix exported from another FE code touches hundreds of DOFs but couples few of them.
  {
    std::vector<int> local(nodes_.size(), -1), node_of(static_cast<std::size_t>(n));
    int nn = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const int node = out[static_cast<std::size_t>(i)].first;
      if (local[node] < 0) local[node] = nn++;
      node_of[static_cast<std::size_t>(i)] = local[node];
    }
    std::vector<char> coupled(static_cast<std::size_t>(nn) * nn, 0);
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = 0; i < n; ++i)
        if (d.K(i, j) != 0.0 || d.M(i, j) != 0.0 || node_of[i] == node_of[j])
          coupled[static_cast<std::size_t>(node_of[i]) * nn + node_of[j]] = 1;
    auto& pairs = matrix_coupling_[k];
    for (int b = 1; b < n; ++b)
      for (int a = 0; a < b; ++a)
        if (coupled[static_cast<std::size_t>(node_of[a]) * nn + node_of[b]]) pairs.emplace_back(a, b);
    matrix_sparse_[k] = static_cast<long long>(pairs.size()) < static_cast<long long>(n) * (n - 1) / 2;
    if (!matrix_sparse_[k]) pairs = {};
  }
  for (int a = 0; a < 2; ++a) {
    element_nodes_[k][a] = a < e.num_nodes ? node_index(e.node_ids[a]) : -1;
    if (a < e.num_nodes && element_nodes_[k][a] < 0)
      throw InputError(who + ": node " + std::to_string(e.node_ids[a]) + " does not exist");
  }
}

void Model::finalize() {
  warnings_.clear();
  const int nn = static_cast<int>(nodes_.size());
  if (elements_.empty()) throw InputError("the model has no elements");
  element_nodes_.assign(elements_.size(), {{-1, -1}});
  point_mass_dofs_.assign(elements_.size(), 0);
  matrix_dofs_.assign(elements_.size(), {});
  matrix_coupling_.assign(elements_.size(), {});
  matrix_sparse_.assign(elements_.size(), 0);
  std::vector<DofMask> active(nn, 0), restrained(nn, 0);
  std::vector<int> pm;  // point masses, resolved after DOF activation

  for (std::size_t k = 0; k < elements_.size(); ++k) {
    const Element& e = elements_[k];
    const std::string who = elem_label(e);
    if (e.type == ElementType::Matrix) {
      finalize_matrix_element(static_cast<int>(k), &active);
      continue;
    }
    if (e.num_nodes < 1 || e.num_nodes > 2) throw InputError(who + ": must have 1 or 2 nodes");
    for (int a = 0; a < e.num_nodes; ++a) {
      const int n = node_index(e.node_ids[a]);
      if (n < 0) throw InputError(who + ": node " + std::to_string(e.node_ids[a]) + " does not exist");
      element_nodes_[k][a] = n;
    }
    for (double f : {e.factors.E, e.factors.rho, e.factors.A, e.factors.I})
      if (!finite_positive(f)) throw InputError(who + ": property factors must be finite and > 0");
    if (is_member(e.type)) {
      if (e.num_nodes != 2) throw InputError(who + ": needs 2 nodes");
      const Eigen::Vector3d& a = nodes_[element_nodes_[k][0]].x;
      const Eigen::Vector3d& b = nodes_[element_nodes_[k][1]].x;
      const double L = (b - a).norm();
      if (element_nodes_[k][0] == element_nodes_[k][1] || !(L > 0))
        throw InputError(who + ": zero length (nodes " + std::to_string(e.node_ids[0]) + " and " +
                         std::to_string(e.node_ids[1]) + " coincide)");
      if (e.material < 0 || e.material >= static_cast<int>(materials_.size()))
        throw InputError(who + ": no material assigned");
      if (e.section < 0 || e.section >= static_cast<int>(sections_.size()))
        throw InputError(who + ": no section assigned");
      const Material& m = materials_[e.material];
      const Section& s = sections_[e.section];
      const std::string mat = who + ": material '" + m.name + "'";
      const std::string sec = who + ": section '" + s.name + "'";
      if (!finite_positive(m.E)) throw InputError(mat + " has Young's modulus E = " + fmt_num(m.E) + "; it must be > 0");
      if (!(std::isfinite(m.rho) && m.rho >= 0)) throw InputError(mat + " has density rho = " + fmt_num(m.rho) + "; it must be >= 0");
      if (!finite_positive(s.A)) throw InputError(sec + " has area A = " + fmt_num(s.A) + "; it must be > 0");
      if (!finite_positive(s.Iz)) throw InputError(sec + " has second moment Iz = " + fmt_num(s.Iz) + "; it must be > 0");
      if (!(std::isfinite(s.shear_factor) && s.shear_factor >= 0))
        throw InputError(sec + " has shear factor " + fmt_num(s.shear_factor) + "; it must be >= 0 (0 = no shear deformation)");
      if (s.shear_factor > 0 && !(m.G > 0 || (std::isfinite(m.nu) && m.nu > -1 && m.nu < 0.5)))
        throw InputError(mat + ": shear deformation (section shear_factor) needs a shear modulus G or a Poisson's ratio in (-1, 0.5)");
      if (!std::isfinite(e.axial_force)) throw InputError(who + ": axial_force must be finite");
      if (e.type == ElementType::Frame3D) {
        if (!finite_positive(s.Iy)) throw InputError(sec + " has second moment Iy = " + fmt_num(s.Iy) + "; it must be > 0");
        if (!(std::isfinite(s.J) && s.J >= 0)) throw InputError(sec + " has torsion constant J = " + fmt_num(s.J) + "; it must be >= 0");
        if (!(m.G > 0 || (std::isfinite(m.nu) && m.nu > -1 && m.nu < 0.5)))
          throw InputError(mat + ": shear modulus G or a Poisson's ratio in (-1, 0.5) is needed for 3D frames");
        Eigen::Matrix3d R;
        if (!internal::frame3d_axes(a, b, e.orientation, &R))
          throw InputError(who + ": orientation vector is parallel to the member axis");
      } else if (std::abs(b.z() - a.z()) > 1e-9 * L) {
        throw InputError(who + ": 2D elements must lie in the x-y plane (node z coordinates differ)");
      }
      if (e.type == ElementType::Beam2D && std::abs(b.y() - a.y()) > 1e-9 * L)
        throw InputError(who + ": a beam2d element must lie along the x axis; use frame2d for inclined members");
      const DofMask d = structural_dofs(e.type);
      for (int a2 = 0; a2 < 2; ++a2) active[element_nodes_[k][a2]] |= d;
    } else if (e.type == ElementType::Spring) {
      if (!finite_positive(e.stiffness))
        throw InputError(who + ": stiffness = " + fmt_num(e.stiffness) + "; it must be finite and > 0");
      if (e.spring_dofs == 0) throw InputError(who + ": no DOF types given (e.g. dofs: [ux] or [rz])");
      if (e.num_nodes == 2 && element_nodes_[k][0] == element_nodes_[k][1])
        throw InputError(who + ": both ends on the same node " + std::to_string(e.node_ids[0]));
      for (int a2 = 0; a2 < e.num_nodes; ++a2) active[element_nodes_[k][a2]] |= e.spring_dofs;
    } else {  // point mass
      if (e.num_nodes != 1) throw InputError(who + ": needs exactly 1 node");
      if (!(std::isfinite(e.mass) && e.mass >= 0)) throw InputError(who + ": mass must be finite and >= 0");
      if (!(e.rotary_inertia.allFinite() && e.rotary_inertia.minCoeff() >= 0))
        throw InputError(who + ": rotary inertia must be finite and >= 0");
      pm.push_back(static_cast<int>(k));
    }
  }
  for (int k : pm) {
    const Element& e = elements_[k];
    const int n = element_nodes_[k][0];
    DofMask d = 0;
    for (int t = 0; t < kNumDofTypes; ++t) {
      const bool want = t < 3 ? e.mass > 0 : e.rotary_inertia[t - 3] > 0;
      if (want && (active[n] & (1u << t))) d |= static_cast<DofMask>(1u << t);
    }
    if (active[n] == 0)
      throw InputError(elem_label(e) + ": node " + std::to_string(e.node_ids[0]) +
                       " has no DOFs (no beam, frame or spring is attached to it)");
    point_mass_dofs_[k] = d;
  }
  for (const auto& [id, mask] : restraints_) {
    const int n = node_index(id);
    if (n < 0) throw InputError("support at node " + std::to_string(id) + ": node does not exist");
    restrained[n] |= mask;
  }
  std::vector<char> drawn(nn, 0);  // nodes of matrix elements without DOFs (supported ends) are connected too
  for (std::size_t k = 0; k < elements_.size(); ++k)
    if (elements_[k].type == ElementType::Matrix)
      for (int id : elements_[k].matrix->nodes) drawn[node_index(id)] = 1;
  for (int n = 0; n < nn; ++n)
    if (active[n] == 0 && !drawn[n]) warnings_.push_back("node " + std::to_string(nodes_[n].id) + " is not connected to any element");
  dofs_ = DofMap(active, restrained);
  if (dofs_.num_free() == 0) throw InputError("the model has no free DOFs (every DOF is restrained)");
  finalized_ = true;

  if (!free_free_) {
    // Supports and springs must prevent every rigid-body motion, unless the user declared the model free-free.
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
}

Eigen::MatrixXd Model::free_rigid_body_modes(std::vector<std::string>* descriptions) const {
  std::vector<std::string> labels;
  const Eigen::MatrixXd R = rigid_body_motions(&labels);
  const Eigen::Index nc = R.cols();
  if (descriptions) descriptions->clear();
  if (nc == 0) return Eigen::MatrixXd(num_dofs(), 0);
  // Y = K R and Ya = |K| |R|, element by element (no global assembly). A motion r that supports and springs
  // leave free has ||K r|| at rounding level compared with || |K| |r| ||; a restrained one is strained at the
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
  constexpr double tol = 1e-10;
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
  dofs->clear();
  for (const auto& [n, d] : element_dof_types(e)) dofs->push_back(dofs_.eq(n, d));
}

std::vector<std::pair<int, Dof>> Model::element_dof_types(int e) const {
  require_finalized("element_dof_types");
  const Element& el = elements_[e];
  DofMask mask = 0;
  switch (el.type) {
    case ElementType::PointMass: mask = point_mass_dofs_[e]; break;
    case ElementType::Spring: mask = el.spring_dofs; break;
    case ElementType::Matrix: return matrix_dofs_[e];
    default: mask = structural_dofs(el.type);
  }
  std::vector<std::pair<int, Dof>> out;
  for (int a = 0; a < el.num_nodes; ++a)
    for (int t = 0; t < kNumDofTypes; ++t)
      if (mask & (1u << t)) out.emplace_back(element_nodes_[e][a], static_cast<Dof>(t));
  return out;
}

void Model::member_local(int e, internal::MemberLocal* loc, Eigen::MatrixXd* T, const double* axial_force) const {
  const Element& el = elements_[e];
  const Material& mat = materials_[el.material];
  const Section& sec = sections_[el.section];
  const PropertyFactors& f = el.factors;
  const Eigen::Vector3d& a = nodes_[element_nodes_[e][0]].x;
  const Eigen::Vector3d& b = nodes_[element_nodes_[e][1]].x;
  internal::MemberProps mp;
  mp.L = (b - a).norm();
  const double E = mat.E * f.E, rho = mat.rho * f.rho, A = sec.A * f.A;
  mp.EA = E * A;
  mp.EIz = E * sec.Iz * f.I;
  mp.EIy = E * sec.Iy * f.I;
  mp.GJ = mat.shear_modulus() * f.E * sec.torsion_constant() * f.I;
  mp.rhoA = rho * A;
  mp.rhoIz = rho * sec.Iz * f.I;
  mp.rhoIy = rho * sec.Iy * f.I;
  mp.lumped = mass_type_ == MassType::Lumped;
  mp.rotary = rotary_inertia_;
  if (sec.shear_factor > 0) {
    const double GAs = sec.shear_factor * mat.shear_modulus() * f.E * A * mp.L * mp.L;
    mp.phiz = 12.0 * mp.EIz / GAs;
    mp.phiy = 12.0 * mp.EIy / GAs;
  }
  mp.P = axial_force ? *axial_force : el.axial_force;
  if (el.type == ElementType::Frame3D) {
    internal::frame3d_local(mp, loc);
    Eigen::Matrix3d R;
    internal::frame3d_axes(a, b, el.orientation, &R);
    T->setZero(12, 12);
    for (int k = 0; k < 4; ++k) T->block<3, 3>(3 * k, 3 * k) = R;
  } else {
    internal::frame2d_local(mp, loc);
    const double c = (b.x() - a.x()) / mp.L, s = (b.y() - a.y()) / mp.L;
    Eigen::Matrix3d R;
    R << c, s, 0, -s, c, 0, 0, 0, 1;
    T->setZero(6, 6);
    T->topLeftCorner<3, 3>() = R;
    T->bottomRightCorner<3, 3>() = R;
    if (el.type == ElementType::Beam2D) {
      // Beam DOFs (uy, rz) per node embed into the frame's (ux, uy, rz); the beam lies along x, so its local
      // axial DOF receives nothing and the axial parts vanish.
      Eigen::MatrixXd Tg = Eigen::MatrixXd::Zero(6, 4);
      Tg(1, 0) = Tg(2, 1) = Tg(4, 2) = Tg(5, 3) = 1.0;
      *T = *T * Tg;
    }
  }
}

namespace {
// out = T^T A T for T block-diagonal with 3x3 blocks R (frames): cheaper than the dense triple product.
void rotate_blocks(const Eigen::MatrixXd& A, const Eigen::Matrix3d& R, Eigen::MatrixXd* out) {
  const Eigen::Index nb = A.rows() / 3;
  out->resize(A.rows(), A.cols());
  for (Eigen::Index i = 0; i < nb; ++i)
    for (Eigen::Index j = 0; j < nb; ++j)
      out->block<3, 3>(3 * i, 3 * j).noalias() = R.transpose() * A.block<3, 3>(3 * i, 3 * j) * R;
}
}  // namespace

ElementParts Model::element_parts(int e) const {
  require_finalized("element_parts");
  const Element& el = elements_[e];
  ElementParts p;
  if (el.type == ElementType::Matrix) {
    const Eigen::Index n = el.matrix->K.rows();
    for (Eigen::MatrixXd* m : {&p.K_axial, &p.K_bending, &p.K_torsion, &p.K_geometric, &p.M_translational, &p.M_rotary})
      m->setZero(n, n);
    p.K_discrete = el.factors.E * el.matrix->K;
    p.M_discrete = el.factors.rho * el.matrix->M;
    return p;
  }
  if (el.type == ElementType::PointMass || el.type == ElementType::Spring) {
    const int n = static_cast<int>(element_dof_types(e).size());
    for (Eigen::MatrixXd* m : {&p.K_axial, &p.K_bending, &p.K_torsion, &p.K_discrete, &p.K_geometric,
                               &p.M_translational, &p.M_rotary, &p.M_discrete})
      m->setZero(n, n);
    if (el.type == ElementType::PointMass) {
      int i = 0;
      for (int t = 0; t < kNumDofTypes; ++t)
        if (point_mass_dofs_[e] & (1u << t)) {
          p.M_discrete(i, i) = t < 3 ? el.mass : el.rotary_inertia[t - 3];
          ++i;
        }
    } else {
      const int nd = n / el.num_nodes;
      for (int i = 0; i < nd; ++i) {
        p.K_discrete(i, i) = el.stiffness;
        if (el.num_nodes == 2) {
          p.K_discrete(nd + i, nd + i) = el.stiffness;
          p.K_discrete(i, nd + i) = p.K_discrete(nd + i, i) = -el.stiffness;
        }
      }
    }
    return p;
  }
  internal::MemberLocal loc;
  Eigen::MatrixXd T;
  member_local(e, &loc, &T);
  auto tr = [&](const Eigen::MatrixXd& m) -> Eigen::MatrixXd { return T.transpose() * m * T; };
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

Eigen::MatrixXd Model::unit_geometric_stiffness(int e) const {
  require_finalized("unit_geometric_stiffness");
  if (!is_member(elements_[e].type))
    throw InputError("element " + std::to_string(elements_[e].id) + ": only beams and frames have a geometric stiffness");
  internal::MemberLocal loc;
  Eigen::MatrixXd T;
  const double unit = 1.0;
  member_local(e, &loc, &T, &unit);
  return T.transpose() * loc.Kg * T;
}

Eigen::MatrixXd Model::member_point_interpolation(int e, double xi, Eigen::MatrixXd* dN) const {
  require_finalized("member_point_interpolation");
  const ElementType t = elements_[e].type;
  if (!is_member(t))
    throw InputError("element " + std::to_string(elements_[e].id) + ": only beams and frames have a member axis");
  internal::MemberLocal loc;
  Eigen::MatrixXd T;  // local DOFs from the element's global DOFs
  member_local(e, &loc, &T);
  const double L = (nodes_[element_nodes_[e][1]].x - nodes_[element_nodes_[e][0]].x).norm();
  // Hermite functions for (w1, L t1, w2, L t2) and the linear ones for (u1, u2), with their xi-derivatives.
  const double x2 = xi * xi, x3 = x2 * xi;
  const Eigen::Vector4d H(1 - 3 * x2 + 2 * x3, L * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, L * (-x2 + x3));
  const Eigen::Vector4d dH(-6 * xi + 6 * x2, L * (1 - 4 * xi + 3 * x2), 6 * xi - 6 * x2, L * (-2 * xi + 3 * x2));
  const bool three = t == ElementType::Frame3D;
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
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (three) {
    internal::frame3d_axes(nodes_[element_nodes_[e][0]].x, nodes_[element_nodes_[e][1]].x, elements_[e].orientation, &R);
  } else {
    const Eigen::Vector3d d = (nodes_[element_nodes_[e][1]].x - nodes_[element_nodes_[e][0]].x) / L;
    R << d.x(), d.y(), 0, -d.y(), d.x(), 0, 0, 0, 1;
  }
  if (dN) *dN = R.transpose() * dNl * T;
  return R.transpose() * Nl * T;
}

double Model::member_axial_force(int e, const Eigen::VectorXd& u) const {
  require_finalized("member_axial_force");
  const ElementType t = elements_[e].type;
  if (t != ElementType::Frame2D && t != ElementType::Frame3D) return 0.0;  // Beam2D: no axial DOFs
  internal::MemberLocal loc;
  Eigen::MatrixXd T;
  member_local(e, &loc, &T);
  const Eigen::VectorXd ul = T * u;
  const int per = static_cast<int>(ul.size()) / 2;
  return loc.Ka(per, per) * (ul[per] - ul[0]);
}

void Model::element_matrices(int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const {
  const ElementType t = elements_[e].type;
  if (t == ElementType::Frame2D || t == ElementType::Frame3D) {  // fast path used by assembly
    internal::MemberLocal loc;
    Eigen::MatrixXd T;
    member_local(e, &loc, &T);
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    if (K) rotate_blocks(loc.Ka + loc.Kb + loc.Kt + loc.Kg, R, K);
    if (M) rotate_blocks(loc.Mt + loc.Mr, R, M);
    return;
  }
  const ElementParts p = element_parts(e);
  if (K) *K = p.K();
  if (M) *M = p.M();
}

bool Model::element_coupling(int e, std::vector<std::pair<int, int>>* pairs) const {
  require_finalized("element_coupling");
  *pairs = matrix_coupling_[e];
  return matrix_sparse_[e] != 0;
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
