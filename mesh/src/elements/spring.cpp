// spring: stiffness k on each of a set of DOF types, grounded (one node: K = k I) or between two nodes
// (K = k [I -I; -I I]); no mass.
#include "dynid/mesh/error.hpp"
#include "dynid/mesh/model.hpp"
#include "internal/element_kinds.hpp"

namespace dynid::internal {
namespace {

class Spring : public ElementKind {
 public:
  ElementType type() const override { return ElementType::Spring; }
  std::string_view name() const override { return "spring"; }
  bool has_mass() const override { return false; }

  void setup(const ElementSetup& s) const override {
    setup_ends(s);
    const Element& e = s.element;
    if (!finite_positive(e.stiffness))
      throw InputError(s.who + ": stiffness = " + fmt_num(e.stiffness) + "; it must be finite and > 0");
    if (e.spring_dofs == 0) throw InputError(s.who + ": no DOF types given (e.g. dofs: [ux] or [rz])");
    if (e.num_nodes == 2 && (*s.nodes)[0] == (*s.nodes)[1])
      throw InputError(s.who + ": both ends on the same node " + std::to_string(e.node_ids[0]));
    for (int a = 0; a < e.num_nodes; ++a) (*s.active)[(*s.nodes)[a]] |= e.spring_dofs;
  }

  std::vector<std::pair<int, Dof>> layout(const Model& m, int e, const std::vector<DofMask>&) const override {
    return node_major_layout(m, e, m.elements()[e].spring_dofs);
  }

  ElementParts parts(const Model& m, int e) const override {
    const Element& el = m.elements()[e];
    const int n = static_cast<int>(m.element_dof_types(e).size());
    ElementParts p;
    zero_parts(n, &p);
    const int nd = n / el.num_nodes;
    for (int i = 0; i < nd; ++i) {
      p.K_discrete(i, i) = el.stiffness;
      if (el.num_nodes == 2) {
        p.K_discrete(nd + i, nd + i) = el.stiffness;
        p.K_discrete(i, nd + i) = p.K_discrete(nd + i, i) = -el.stiffness;
      }
    }
    return p;
  }
};

}  // namespace

const ElementKind& spring_kind() {
  static const Spring kind;
  return kind;
}

}  // namespace dynid::internal
