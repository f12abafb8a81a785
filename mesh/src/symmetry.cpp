#include "dynid/mesh/symmetry.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace dynid {

namespace {

// Mirrors and half turns about the coordinate axes: diagonal R, so every DOF type maps to itself (up to sign)
// and a node's active and restrained DOF sets must be equal to its image's.
struct Transform {
  std::string name;
  Eigen::Matrix3d R;  // acting on positions relative to the centroid
};

bool same_element_data(const Element& a, const Element& b) {
  return a.type == b.type && a.num_nodes == b.num_nodes && a.material == b.material && a.section == b.section &&
         a.mass == b.mass && a.stiffness == b.stiffness && a.spring_dofs == b.spring_dofs &&
         a.factors.E == b.factors.E && a.factors.rho == b.factors.rho && a.factors.A == b.factors.A &&
         a.factors.I == b.factors.I && a.rotary_inertia == b.rotary_inertia;
}

}  // namespace

std::vector<Symmetry> find_symmetries(const Model& model) {
  std::vector<Symmetry> out;
  if (!model.finalized() || model.nodes().empty()) return out;
  const auto& nodes = model.nodes();
  Eigen::Vector3d c = Eigen::Vector3d::Zero(), lo = nodes[0].x, hi = nodes[0].x;
  for (const Node& n : nodes) {
    c += n.x;
    lo = lo.cwiseMin(n.x);
    hi = hi.cwiseMax(n.x);
  }
  c /= static_cast<double>(nodes.size());
  const double size = std::max((hi - lo).maxCoeff(), 1e-300);
  const double tol = 1e-9 * size;
  std::vector<Transform> ts;
  const char* axes = "xyz";
  for (int k = 0; k < 3; ++k) {
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    R(k, k) = -1;
    std::ostringstream s;
    s << "mirror " << axes[k] << " = " << c[k];
    ts.push_back({s.str(), R});
  }
  for (int k = 0; k < 3; ++k) {
    Eigen::Matrix3d R = -Eigen::Matrix3d::Identity();
    R(k, k) = 1;
    std::ostringstream s;
    s << "half turn about the " << axes[k] << " axis through (" << c.x() << ", " << c.y() << ", " << c.z() << ")";
    ts.push_back({s.str(), R});
  }
  // Node lookup by rounded position.
  auto key = [&](const Eigen::Vector3d& x) {
    return std::array<long long, 3>{{std::llround(x.x() / (tol * 10)), std::llround(x.y() / (tol * 10)),
                                     std::llround(x.z() / (tol * 10))}};
  };
  std::map<std::array<long long, 3>, int> where;
  for (std::size_t i = 0; i < nodes.size(); ++i) where[key(nodes[i].x)] = static_cast<int>(i);
  auto find_node = [&](const Eigen::Vector3d& x) -> int {
    auto it = where.find(key(x));
    if (it != where.end() && (nodes[it->second].x - x).norm() <= tol) return it->second;
    for (std::size_t i = 0; i < nodes.size(); ++i)  // rounding straddled a cell boundary
      if ((nodes[i].x - x).norm() <= tol) return static_cast<int>(i);
    return -1;
  };
  const DofMap& dm = model.dof_map();
  std::map<std::array<int, 3>, std::vector<int>> elems;  // (type, min node, max node) -> elements
  for (int e = 0; e < model.num_elements(); ++e) {
    const auto& en = model.element_nodes(e);
    const Element& el = model.elements()[e];
    const int a = en[0], b = el.num_nodes == 2 ? en[1] : -1;
    elems[{{static_cast<int>(el.type), std::min(a, b == -1 ? a : b), std::max(a, b)}}].push_back(e);
  }
  for (const Transform& t : ts) {
    Symmetry s;
    s.description = t.name;
    s.node.assign(nodes.size(), -1);
    bool ok = true;
    for (std::size_t i = 0; i < nodes.size() && ok; ++i) {
      const int j = find_node(c + t.R * (nodes[i].x - c));
      if (j < 0 || dm.active(j) != dm.active(static_cast<int>(i)) ||
          dm.restrained(j) != dm.restrained(static_cast<int>(i)))
        ok = false;
      else
        s.node[i] = j;
    }
    if (!ok) continue;
    bool identity = true;
    for (std::size_t i = 0; i < nodes.size(); ++i) identity = identity && s.node[i] == static_cast<int>(i);
    if (identity) continue;  // e.g. a mirror normal to z of a plane model
    s.element.assign(model.elements().size(), -1);
    for (int e = 0; e < model.num_elements() && ok; ++e) {
      const auto& en = model.element_nodes(e);
      const Element& el = model.elements()[e];
      const int a = s.node[en[0]], b = el.num_nodes == 2 ? s.node[en[1]] : -1;
      auto it = elems.find({{static_cast<int>(el.type), std::min(a, b == -1 ? a : b), std::max(a, b)}});
      int img = -1;
      if (it != elems.end())
        for (int f : it->second)
          if (same_element_data(el, model.elements()[f])) {
            img = f;
            break;
          }
      if (img < 0) ok = false;
      else s.element[e] = img;
    }
    if (ok) out.push_back(std::move(s));
  }
  return out;
}

std::vector<int> element_twins(const std::vector<Symmetry>& symmetries, int e) {
  std::vector<int> t;
  for (const Symmetry& s : symmetries)
    if (s.element[e] != e) t.push_back(s.element[e]);
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

}  // namespace dynid
