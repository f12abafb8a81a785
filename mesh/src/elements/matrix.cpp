// matrix: an element given by its matrices on any list of (node, DOF type) pairs, in global coordinates
// (exported from another FE code); K = factors.E K0, M = factors.rho M0.
#include <cmath>

#include "dynid/mesh/error.hpp"
#include "dynid/mesh/model.hpp"
#include "internal/element_kinds.hpp"

namespace dynid::internal {
namespace {

// Both matrices finite and symmetric (to 1e-12 of the largest entry).
void check_matrices(const std::string& who, const MatrixElementData& d) {
  const Eigen::Index n = static_cast<Eigen::Index>(d.dofs.size());
  for (const auto* A : {&d.K, &d.M}) {
    const char* what = A == &d.K ? "stiffness" : "mass";
    if (!A->allFinite()) throw InputError(who + ": its " + what + " matrix has a NaN or infinite entry");
    const double scale = A->cwiseAbs().maxCoeff();
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = j + 1; i < n; ++i)
        if (std::abs((*A)(i, j) - (*A)(j, i)) > 1e-12 * scale)
          throw InputError(who + ": its " + what + " matrix is not symmetric (entries " + std::to_string(i + 1) + "," +
                           std::to_string(j + 1) + " and " + std::to_string(j + 1) + "," + std::to_string(i + 1) +
                           " differ)");
  }
}

class MatrixElement : public ElementKind {
 public:
  ElementType type() const override { return ElementType::Matrix; }
  std::string_view name() const override { return "matrix"; }

  void setup(const ElementSetup& s) const override {
    const Element& e = s.element;
    const std::string& who = s.who;
    if (!e.matrix) throw InputError(who + ": no matrices given");
    if (e.num_nodes < 0 || e.num_nodes > 2)
      throw InputError(who + ": num_nodes must be 0, 1 or 2 (the ends drawn); build it with make_matrix_element()");
    const MatrixElementData& d = *e.matrix;
    const Eigen::Index n = static_cast<Eigen::Index>(d.dofs.size());
    if (n == 0) throw InputError(who + ": has no DOFs");
    if (d.K.rows() != n || d.K.cols() != n || d.M.rows() != n || d.M.cols() != n)
      throw InputError(who + ": its stiffness and mass matrices must be " + std::to_string(n) + " x " +
                       std::to_string(n) + " (one row per DOF), got " + std::to_string(d.K.rows()) + " x " +
                       std::to_string(d.K.cols()) + " and " + std::to_string(d.M.rows()) + " x " +
                       std::to_string(d.M.cols()));
    for (double f : {e.factors.E, e.factors.rho})
      if (!finite_positive(f)) throw InputError(who + ": property factors must be finite and > 0");
    std::vector<std::pair<int, Dof>> seen;
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto& [id, t] = d.dofs[i];
      const int node = s.model.node_index(id);
      if (node < 0) throw InputError(who + ": node " + std::to_string(id) + " does not exist");
      for (const auto& [m, u] : seen)
        if (m == node && u == t)
          throw InputError(who + ": DOF " + std::string(dof_name(t)) + " at node " + std::to_string(id) +
                           " is listed twice");
      seen.emplace_back(node, t);
      (*s.active)[node] |= dof_bit(t);
    }
    check_matrices(who, d);
    for (int id : d.nodes) {
      if (s.model.node_index(id) < 0) throw InputError(who + ": node " + std::to_string(id) + " does not exist");
    }
    for (int a = 0; a < 2; ++a) {
      (*s.nodes)[a] = a < e.num_nodes ? s.model.node_index(e.node_ids[a]) : -1;
      if (a < e.num_nodes && (*s.nodes)[a] < 0)
        throw InputError(who + ": node " + std::to_string(e.node_ids[a]) + " does not exist");
    }
    // Its nodes without DOFs (supported ends) are drawn, so they count as connected.
    for (int id : d.nodes) (*s.connected)[s.model.node_index(id)] = 1;
  }

  std::vector<std::pair<int, Dof>> layout(const Model& m, int e, const std::vector<DofMask>&) const override {
    std::vector<std::pair<int, Dof>> out;
    for (const auto& [id, t] : m.elements()[e].matrix->dofs) out.emplace_back(m.node_index(id), t);
    return out;
  }

  // Node by node: the blocks of node pairs with a nonzero K or M entry between them, and every node's own block. A
  // group matrix exported from another FE code touches hundreds of DOFs but couples few of them. False (and no
  // pairs) when every pair is coupled.
  bool coupling(const Model& m, int e, const std::vector<std::pair<int, Dof>>& layout,
                std::vector<std::pair<int, int>>* pairs) const override {
    const MatrixElementData& d = *m.elements()[e].matrix;
    const Eigen::Index n = static_cast<Eigen::Index>(layout.size());
    std::vector<int> local(m.nodes().size(), -1), node_of(static_cast<std::size_t>(n));
    int nn = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const int node = layout[static_cast<std::size_t>(i)].first;
      if (local[node] < 0) local[node] = nn++;
      node_of[static_cast<std::size_t>(i)] = local[node];
    }
    std::vector<char> coupled(static_cast<std::size_t>(nn) * nn, 0);
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = 0; i < n; ++i)
        if (d.K(i, j) != 0.0 || d.M(i, j) != 0.0 || node_of[i] == node_of[j])
          coupled[static_cast<std::size_t>(node_of[i]) * nn + node_of[j]] = 1;
    pairs->clear();
    for (int b = 1; b < n; ++b)
      for (int a = 0; a < b; ++a)
        if (coupled[static_cast<std::size_t>(node_of[a]) * nn + node_of[b]]) pairs->emplace_back(a, b);
    const bool sparse = static_cast<long long>(pairs->size()) < static_cast<long long>(n) * (n - 1) / 2;
    if (!sparse) pairs->clear();
    return sparse;
  }

  ElementParts parts(const Model& m, int e) const override {
    const Element& el = m.elements()[e];
    ElementParts p;
    zero_parts(el.matrix->K.rows(), &p);
    p.K_discrete = el.factors.E * el.matrix->K;
    p.M_discrete = el.factors.rho * el.matrix->M;
    return p;
  }
};

}  // namespace

const ElementKind& matrix_kind() {
  static const MatrixElement kind;
  return kind;
}

}  // namespace dynid::internal
