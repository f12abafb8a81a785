// point_mass: mass m on the node's active translations and rotary inertia (Jx, Jy, Jz) on its active rotations;
// M = diag(m, m, m, Jx, Jy, Jz) restricted to the DOFs the rest of the model gives the node; no stiffness.
#include <cmath>

#include "dynid/mesh/error.hpp"
#include "dynid/mesh/model.hpp"
#include "internal/element_kinds.hpp"

namespace dynid::internal {
namespace {

class PointMass : public ElementKind {
 public:
  ElementType type() const override { return ElementType::PointMass; }
  std::string_view name() const override { return "point_mass"; }
  bool has_stiffness() const override { return false; }

  void setup(const ElementSetup& s) const override {
    setup_ends(s);
    const Element& e = s.element;
    if (e.num_nodes != 1) throw InputError(s.who + ": needs exactly 1 node");
    if (!(std::isfinite(e.mass) && e.mass >= 0)) throw InputError(s.who + ": mass must be finite and >= 0");
    if (!(e.rotary_inertia.allFinite() && e.rotary_inertia.minCoeff() >= 0))
      throw InputError(s.who + ": rotary inertia must be finite and >= 0");
  }

  // The node's active DOFs that carry a mass (translations) or an inertia (rotations); known only once every
  // other element has activated its DOFs.
  std::vector<std::pair<int, Dof>> layout(const Model& m, int e, const std::vector<DofMask>& active) const override {
    const Element& el = m.elements()[e];
    const int n = m.element_nodes(e)[0];
    DofMask d = 0;
    for (int t = 0; t < kNumDofTypes; ++t) {
      const bool want = t < 3 ? el.mass > 0 : el.rotary_inertia[t - 3] > 0;
      if (want && (active[n] & (1u << t))) d |= static_cast<DofMask>(1u << t);
    }
    if (active[n] == 0)
      throw InputError(element_label(el) + ": node " + std::to_string(el.node_ids[0]) +
                       " has no DOFs (no beam, frame or spring is attached to it)");
    return node_major_layout(m, e, d);
  }

  ElementParts parts(const Model& m, int e) const override {
    const Element& el = m.elements()[e];
    const std::vector<std::pair<int, Dof>> dofs = m.element_dof_types(e);
    ElementParts p;
    zero_parts(static_cast<Eigen::Index>(dofs.size()), &p);
    for (std::size_t i = 0; i < dofs.size(); ++i) {
      const int t = static_cast<int>(dofs[i].second);
      p.M_discrete(i, i) = t < 3 ? el.mass : el.rotary_inertia[t - 3];
    }
    return p;
  }
};

}  // namespace

const ElementKind& point_mass_kind() {
  static const PointMass kind;
  return kind;
}

}  // namespace dynid::internal
