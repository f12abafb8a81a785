#include "dynid/mesh/generators.hpp"

#include <array>
#include <functional>
#include <map>

#include "dynid/mesh/error.hpp"

namespace dynid {

namespace {

// Adds `div` elements between existing nodes a and b (user ids), creating interior nodes with ids from
// *next_node. Returns nothing; element ids from *next_elem.
void add_member(Model* m, ElementType type, int a, int b, int div, int mat, int sec, const std::string& group,
                int* next_node, int* next_elem) {
  const Eigen::Vector3d xa = m->nodes()[m->node_index(a)].x, xb = m->nodes()[m->node_index(b)].x;
  int prev = a;
  for (int k = 1; k <= div; ++k) {
    int cur = b;
    if (k < div) {
      cur = (*next_node)++;
      m->add_node(cur, xa + (xb - xa) * (static_cast<double>(k) / div));
    }
    Element e;
    e.id = (*next_elem)++;
    e.type = type;
    e.node_ids = {{prev, cur}};
    e.material = mat;
    e.section = sec;
    e.group = group;
    m->add_element(e);
    prev = cur;
  }
}

void check_positive(int v, const char* what) {
  if (v < 1) throw InputError(std::string("frame generator: ") + what + " must be >= 1");
}

// A frame model's start: its mass type, one material and the column and beam sections (indices in *ids:
// material, column, beam), after checking the counts common to both generators.
template <class Spec>
Model frame_start(const Spec& s, std::array<int, 3>* ids) {
  check_positive(s.stories, "stories");
  check_positive(s.divisions, "divisions");
  Model m;
  m.set_mass_type(s.mass);
  *ids = {{m.add_material(s.material), m.add_section(s.column), m.add_section(s.beam)}};
  return m;
}

}  // namespace

Model make_beam(const BeamSpec& s) {
  check_positive(s.elements, "elements");
  if (!(s.length > 0)) throw InputError("beam generator: length must be > 0");
  Model m;
  m.set_mass_type(s.mass);
  const int mat = m.add_material(s.material);
  const int sec = m.add_section(s.section);
  for (int i = 0; i <= s.elements; ++i)
    m.add_node(i + 1, Eigen::Vector3d(s.length * i / s.elements, 0, 0));
  for (int i = 0; i < s.elements; ++i) {
    Element e;
    e.id = i + 1;
    e.type = ElementType::Beam2D;
    e.node_ids = {{i + 1, i + 2}};
    e.material = mat;
    e.section = sec;
    m.add_element(e);
  }
  const int last = s.elements + 1;
  switch (s.support) {
    case BeamSupport::Free: m.set_free_free(true); break;
    case BeamSupport::Cantilever: m.restrain(1, kAllDofs); break;
    case BeamSupport::SimplySupported:
      m.restrain(1, dof_bit(Dof::UY));
      m.restrain(last, dof_bit(Dof::UY));
      break;
    case BeamSupport::Clamped:
      m.restrain(1, kAllDofs);
      m.restrain(last, kAllDofs);
      break;
  }
  m.finalize();
  return m;
}

long long frame2d_dofs(const Frame2DSpec& s) {
  const long long joints = static_cast<long long>(s.bays + 1) * (s.stories + 1);
  const long long members = static_cast<long long>(s.bays + 1) * s.stories + static_cast<long long>(s.bays) * s.stories;
  return 3 * (joints - (s.bays + 1) + members * (s.divisions - 1));
}

long long frame3d_dofs(const Frame3DSpec& s) {
  const long long plan = static_cast<long long>(s.bays_x + 1) * (s.bays_y + 1);
  const long long beams = static_cast<long long>(s.bays_x) * (s.bays_y + 1) + static_cast<long long>(s.bays_y) * (s.bays_x + 1);
  const long long members = plan * s.stories + beams * s.stories;
  return 6 * (plan * s.stories + members * (s.divisions - 1));
}

Model make_frame2d(const Frame2DSpec& s) {
  check_positive(s.bays, "bays");
  std::array<int, 3> ids;
  Model m = frame_start(s, &ids);
  const int mat = ids[0], col = ids[1], bm = ids[2];
  auto joint = [&](int i, int j) { return 1 + j * (s.bays + 1) + i; };
  for (int j = 0; j <= s.stories; ++j)
    for (int i = 0; i <= s.bays; ++i) m.add_node(joint(i, j), Eigen::Vector3d(i * s.span, j * s.height, 0));
  int next_node = (s.bays + 1) * (s.stories + 1) + 1, next_elem = 1;
  for (int j = 0; j < s.stories; ++j)
    for (int i = 0; i <= s.bays; ++i)
      add_member(&m, ElementType::Frame2D, joint(i, j), joint(i, j + 1), s.divisions, mat, col, "column", &next_node,
                 &next_elem);
  for (int j = 1; j <= s.stories; ++j)
    for (int i = 0; i < s.bays; ++i)
      add_member(&m, ElementType::Frame2D, joint(i, j), joint(i + 1, j), s.divisions, mat, bm, "beam", &next_node,
                 &next_elem);
  for (int i = 0; i <= s.bays; ++i) m.restrain(joint(i, 0), kAllDofs);
  m.finalize();
  return m;
}

Model make_frame3d(const Frame3DSpec& s) {
  check_positive(s.bays_x, "bays_x");
  check_positive(s.bays_y, "bays_y");
  std::array<int, 3> ids;
  Model m = frame_start(s, &ids);
  const int mat = ids[0], col = ids[1], bm = ids[2];
  const int nx = s.bays_x + 1, ny = s.bays_y + 1;
  auto joint = [&](int i, int j, int k) { return 1 + (k * ny + j) * nx + i; };
  for (int k = 0; k <= s.stories; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        m.add_node(joint(i, j, k), Eigen::Vector3d(i * s.span_x, j * s.span_y, k * s.height));
  int next_node = nx * ny * (s.stories + 1) + 1, next_elem = 1;
  for (int k = 0; k < s.stories; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        add_member(&m, ElementType::Frame3D, joint(i, j, k), joint(i, j, k + 1), s.divisions, mat, col, "column",
                   &next_node, &next_elem);
  for (int k = 1; k <= s.stories; ++k) {
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i)
        add_member(&m, ElementType::Frame3D, joint(i, j, k), joint(i + 1, j, k), s.divisions, mat, bm, "beam",
                   &next_node, &next_elem);
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i < nx; ++i)
        add_member(&m, ElementType::Frame3D, joint(i, j, k), joint(i, j + 1, k), s.divisions, mat, bm, "beam",
                   &next_node, &next_elem);
  }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) m.restrain(joint(i, j, 0), kAllDofs);
  m.finalize();
  return m;
}

Model refined(const Model& model) {
  if (!model.finalized()) throw InputError("refined: the model is not finalized");
  Model m;
  int next_node = 0, next_element = 0;
  for (const Node& n : model.nodes()) next_node = std::max(next_node, n.id);
  for (const Element& e : model.elements()) next_element = std::max(next_element, e.id);
  for (const Node& n : model.nodes()) m.add_node(n.id, n.x);
  for (const Material& x : model.materials()) m.add_material(x);
  for (const Section& x : model.sections()) m.add_section(x);
  for (int e = 0; e < model.num_elements(); ++e) {
    const Element& el = model.elements()[e];
    if (!is_member(el.type)) {
      m.add_element(el);
      continue;
    }
    const auto& nn = model.element_nodes(e);
    const int mid = ++next_node;
    m.add_node(mid, 0.5 * (model.nodes()[nn[0]].x + model.nodes()[nn[1]].x));
    Element a = el, b = el;
    a.node_ids = {{el.node_ids[0], mid}};
    b.node_ids = {{mid, el.node_ids[1]}};
    b.id = ++next_element;
    m.add_element(a);
    m.add_element(b);
  }
  // Supports: every DOF type a node has but does not number is restrained.
  for (int n = 0; n < static_cast<int>(model.nodes().size()); ++n) {
    DofMask r = 0;
    for (int t = 0; t < kNumDofTypes; ++t)
      if ((model.dof_map().active(n) & (1u << t)) && model.dof_map().eq(n, static_cast<Dof>(t)) < 0) r |= 1u << t;
    if (r) m.restrain(model.nodes()[n].id, r);
  }
  m.set_mass_type(model.mass_type());
  m.set_rotary_inertia(model.rotary_inertia());
  m.set_free_free(model.free_free());
  m.finalize();
  return m;
}

}  // namespace dynid
