// The `model:` section of a case file. See docs/case-file.md for the annotated reference.
#include <cmath>
#include <map>
#include <regex>
#include <set>

#include "dynid/mesh/generators.hpp"
#include "internal/model_yaml.hpp"

namespace dynid::internal {

namespace {

struct Parser {
  const YamlCtx& ctx;
  Model model;
  std::map<std::string, int> materials, sections;
  std::map<int, YAML::Node> element_nodes;  // element id -> its YAML node (for messages after finalize)
  std::set<int> node_ids;
  std::string default_material, default_section;
  ElementType default_type = ElementType::Frame2D;
  bool have_default_type = false;

  [[noreturn]] void fail(const YAML::Node& n, const std::string& m) const { ctx.fail(n, m); }

  void parse_materials(const YAML::Node& n) {
    ctx.require_map(n, "materials");
    for (const auto& kv : n) {
      const std::string name = kv.first.Scalar();
      const YAML::Node& v = kv.second;
      ctx.require_map(v, "material '" + name + "'");
      ctx.only_keys(v, "material '" + name + "'", {"E", "rho", "nu", "G"});
      Material m;
      m.name = name;
      const std::string w = "material '" + name + "'";
      if (!v["E"]) fail(v, w + ": Young's modulus E is missing");
      m.E = ctx.number(v["E"], w + " E");
      if (m.E <= 0) fail(v["E"], w + ": E must be > 0");
      if (!v["rho"]) fail(v, w + ": density rho is missing (use rho: 0 for a massless material)");
      m.rho = ctx.number(v["rho"], w + " rho");
      if (m.rho < 0) fail(v["rho"], w + ": rho must be >= 0");
      if (v["nu"]) m.nu = ctx.number(v["nu"], w + " nu");
      if (v["G"]) m.G = ctx.number(v["G"], w + " G");
      materials[name] = model.add_material(m);
    }
  }

  void parse_sections(const YAML::Node& n) {
    ctx.require_map(n, "sections");
    for (const auto& kv : n) {
      const std::string name = kv.first.Scalar();
      const YAML::Node& v = kv.second;
      const std::string w = "section '" + name + "'";
      ctx.require_map(v, w);
      ctx.only_keys(v, w, {"A", "I", "Iz", "Iy", "J", "rectangle", "circle"});
      Section s;
      s.name = name;
      if (v["rectangle"]) {
        const YAML::Node& r = v["rectangle"];
        ctx.require_map(r, w + " rectangle");
        ctx.only_keys(r, w + " rectangle", {"width", "depth"});
        if (!r["width"] || !r["depth"]) fail(r, w + ": rectangle needs width and depth (depth lies in the bending plane)");
        const double b = ctx.number(r["width"], w + " width"), h = ctx.number(r["depth"], w + " depth");
        if (b <= 0 || h <= 0) fail(r, w + ": rectangle width and depth must be > 0");
        s.A = b * h;
        s.Iz = b * h * h * h / 12.0;
        s.Iy = h * b * b * b / 12.0;
        const double a = std::max(b, h), t = std::min(b, h);
        s.J = a * t * t * t * (1.0 / 3.0 - 0.21 * (t / a) * (1.0 - std::pow(t / a, 4) / 12.0));
      } else if (v["circle"]) {
        const YAML::Node& c = v["circle"];
        ctx.require_map(c, w + " circle");
        ctx.only_keys(c, w + " circle", {"diameter"});
        const double d = ctx.number(c["diameter"], w + " diameter");
        if (d <= 0) fail(c, w + ": diameter must be > 0");
        s.A = M_PI * d * d / 4.0;
        s.Iy = s.Iz = M_PI * std::pow(d, 4) / 64.0;
        s.J = 2.0 * s.Iz;
      }
      if (v["A"]) s.A = ctx.number(v["A"], w + " A");
      if (v["I"]) s.Iz = ctx.number(v["I"], w + " I");
      if (v["Iz"]) s.Iz = ctx.number(v["Iz"], w + " Iz");
      if (v["Iy"]) s.Iy = ctx.number(v["Iy"], w + " Iy");
      if (v["J"]) s.J = ctx.number(v["J"], w + " J");
      if (v["I"] && v["Iz"]) fail(v, w + ": give either I or Iz, not both");
      if (!(v["A"] || v["rectangle"] || v["circle"])) fail(v, w + ": area A is missing");
      sections[name] = model.add_section(s);
    }
  }

  int material_of(const YAML::Node& n, const std::string& w) {
    const std::string name = n ? ctx.string(n, w + " material") : default_material;
    if (name.empty()) fail(n, w + ": no material (give material: or model.defaults.material)");
    auto it = materials.find(name);
    if (it == materials.end()) fail(n, w + ": unknown material '" + name + "'" + known(materials));
    return it->second;
  }
  int section_of(const YAML::Node& n, const std::string& w) {
    const std::string name = n ? ctx.string(n, w + " section") : default_section;
    if (name.empty()) fail(n, w + ": no section (give section: or model.defaults.section)");
    auto it = sections.find(name);
    if (it == sections.end()) fail(n, w + ": unknown section '" + name + "'" + known(sections));
    return it->second;
  }
  static std::string known(const std::map<std::string, int>& m) {
    if (m.empty()) return " (none defined)";
    std::string s;
    for (const auto& kv : m) s += (s.empty() ? "" : ", ") + kv.first;
    return " (defined: " + s + ")";
  }

  void parse_nodes(const YAML::Node& n) {
    ctx.require_sequence(n, "nodes");
    for (const auto& e : n) {
      int id = 0;
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      if (e.IsSequence()) {
        if (e.size() < 3 || e.size() > 4) fail(e, "node: expected [id, x, y] or [id, x, y, z]");
        id = ctx.integer(e[0], "node id");
        for (std::size_t k = 1; k < e.size(); ++k) x[k - 1] = ctx.number(e[k], "node " + std::to_string(id) + " coordinate");
      } else if (e.IsMap()) {
        ctx.only_keys(e, "node", {"id", "x", "y", "z"});
        id = ctx.integer(e["id"], "node id");
        for (int k = 0; k < 3; ++k) {
          const char* key = k == 0 ? "x" : k == 1 ? "y" : "z";
          if (e[key]) x[k] = ctx.number(e[key], "node " + std::to_string(id) + " " + key);
        }
      } else {
        fail(e, "node: expected [id, x, y(, z)] or {id:, x:, y:, z:}");
      }
      if (!node_ids.insert(id).second) fail(e, "node " + std::to_string(id) + " is defined twice");
      model.add_node(id, x);
    }
  }

  int node_ref(const YAML::Node& n, const std::string& w) {
    const int id = ctx.integer(n, w + " node");
    if (!node_ids.count(id)) fail(n, w + ": node " + std::to_string(id) + " does not exist");
    return id;
  }

  void add_element(Element& el, const YAML::Node& where) {
    if (element_nodes.count(el.id)) fail(where, "element " + std::to_string(el.id) + " is defined twice (ids are shared by elements, point masses and springs)");
    element_nodes[el.id] = where;
    model.add_element(el);
  }

  void parse_elements(const YAML::Node& n) {
    ctx.require_sequence(n, "elements");
    for (const auto& e : n) {
      Element el;
      el.type = default_type;
      std::string w;
      if (e.IsSequence()) {
        if (e.size() != 3) fail(e, "element: expected [id, node_a, node_b] or a mapping");
        el.id = ctx.integer(e[0], "element id");
        w = "element " + std::to_string(el.id);
        el.node_ids = {{node_ref(e[1], w), node_ref(e[2], w)}};
        el.material = material_of(YAML::Node(YAML::NodeType::Undefined), w);
        el.section = section_of(YAML::Node(YAML::NodeType::Undefined), w);
      } else if (e.IsMap()) {
        ctx.only_keys(e, "element", {"id", "nodes", "type", "material", "section", "orientation", "group"});
        el.id = ctx.integer(e["id"], "element id");
        w = "element " + std::to_string(el.id);
        if (e["type"]) {
          const std::string t = ctx.string(e["type"], w + " type");
          if (!parse_element_type(t, &el.type) || el.type == ElementType::PointMass || el.type == ElementType::Spring)
            fail(e["type"], w + ": unknown element type '" + t + "' (known: beam2d, frame2d, frame3d; point masses and springs have their own lists)");
        } else if (!have_default_type) {
          fail(e, w + ": no element type (give type: or model.element)");
        }
        const YAML::Node& nd = e["nodes"];
        if (!nd || !nd.IsSequence() || nd.size() != 2) fail(e, w + ": nodes must be a list of 2 node ids");
        el.node_ids = {{node_ref(nd[0], w), node_ref(nd[1], w)}};
        el.material = material_of(e["material"], w);
        el.section = section_of(e["section"], w);
        if (e["orientation"]) {
          const auto v = ctx.numbers(e["orientation"], w + " orientation");
          if (v.size() != 3) fail(e["orientation"], w + ": orientation must be [x, y, z]");
          el.orientation = Eigen::Vector3d(v[0], v[1], v[2]);
        }
        if (e["group"]) el.group = ctx.string(e["group"], w + " group");
      } else {
        fail(e, "element: expected [id, node_a, node_b] or a mapping");
      }
      add_element(el, e);
    }
  }

  void parse_point_masses(const YAML::Node& n) {
    ctx.require_sequence(n, "point_masses");
    for (const auto& e : n) {
      ctx.require_map(e, "point mass");
      ctx.only_keys(e, "point mass", {"id", "node", "mass", "inertia", "group"});
      Element el;
      el.type = ElementType::PointMass;
      el.id = ctx.integer(e["id"], "point mass id");
      const std::string w = "point mass " + std::to_string(el.id);
      el.num_nodes = 1;
      el.node_ids = {{node_ref(e["node"], w), 0}};
      if (e["mass"]) el.mass = ctx.number(e["mass"], w + " mass");
      if (e["inertia"]) {
        const auto v = ctx.numbers(e["inertia"], w + " inertia");
        if (v.size() != 3) fail(e["inertia"], w + ": inertia must be [Jx, Jy, Jz]");
        el.rotary_inertia = Eigen::Vector3d(v[0], v[1], v[2]);
      }
      if (el.mass < 0 || el.rotary_inertia.minCoeff() < 0) fail(e, w + ": mass and inertia must be >= 0");
      if (e["group"]) el.group = ctx.string(e["group"], w + " group");
      add_element(el, e);
    }
  }

  DofMask dof_list(const YAML::Node& n, const std::string& w) {
    ctx.require_sequence(n, w + " dofs");
    DofMask m = 0;
    for (const auto& d : n) {
      Dof t;
      const std::string s = ctx.string(d, w + " dof");
      if (!parse_dof(s, &t)) fail(d, w + ": unknown DOF '" + s + "' (known: ux, uy, uz, rx, ry, rz)");
      m |= dof_bit(t);
    }
    return m;
  }

  void parse_springs(const YAML::Node& n) {
    ctx.require_sequence(n, "springs");
    for (const auto& e : n) {
      ctx.require_map(e, "spring");
      ctx.only_keys(e, "spring", {"id", "nodes", "node", "dofs", "k", "group"});
      Element el;
      el.type = ElementType::Spring;
      el.id = ctx.integer(e["id"], "spring id");
      const std::string w = "spring " + std::to_string(el.id);
      if (e["node"]) {
        el.num_nodes = 1;
        el.node_ids = {{node_ref(e["node"], w), 0}};
      } else {
        const YAML::Node& nd = e["nodes"];
        if (!nd || !nd.IsSequence() || nd.size() < 1 || nd.size() > 2)
          fail(e, w + ": give node: N (grounded) or nodes: [a, b] (between two nodes)");
        el.num_nodes = static_cast<int>(nd.size());
        el.node_ids = {{node_ref(nd[0], w), nd.size() == 2 ? node_ref(nd[1], w) : 0}};
      }
      el.spring_dofs = dof_list(e["dofs"], w);
      if (!e["k"]) fail(e, w + ": stiffness k is missing");
      el.stiffness = ctx.number(e["k"], w + " k");
      if (el.stiffness <= 0) fail(e["k"], w + ": k must be > 0");
      if (e["group"]) el.group = ctx.string(e["group"], w + " group");
      add_element(el, e);
    }
  }

  void parse_supports(const YAML::Node& n) {
    if (n.IsScalar()) {
      const std::string s = n.Scalar();
      if (s != "free") fail(n, "supports: expected 'free' (free-free structure) or a list of supports");
      model.set_free_free(true);
      return;
    }
    ctx.require_sequence(n, "supports");
    for (const auto& e : n) {
      ctx.require_map(e, "support");
      ctx.only_keys(e, "support", {"node", "nodes", "fix"});
      std::vector<int> ids;
      if (e["node"]) ids.push_back(node_ref(e["node"], "support"));
      if (e["nodes"]) {
        ctx.require_sequence(e["nodes"], "support nodes");
        for (const auto& q : e["nodes"]) ids.push_back(node_ref(q, "support"));
      }
      if (ids.empty()) fail(e, "support: give node: N or nodes: [...]");
      const YAML::Node& f = e["fix"];
      DofMask m = 0;
      if (!f) fail(e, "support: fix is missing (all, pinned, or a list such as [ux, uy])");
      if (f.IsScalar()) {
        const std::string s = f.Scalar();
        if (s == "all" || s == "fixed" || s == "clamped") m = kAllDofs;
        else if (s == "pinned") m = kTranslations;
        else fail(f, "support: fix must be all, pinned, or a list of DOFs such as [ux, uy]; got '" + s + "'");
      } else {
        m = dof_list(f, "support");
      }
      for (int id : ids) model.restrain(id, m);
    }
  }

  void parse_generate(const YAML::Node& g) {
    ctx.require_map(g, "generate");
    if (g.size() != 1) fail(g, "generate: give exactly one of beam, frame2d, frame3d");
    const std::string kind = g.begin()->first.Scalar();
    const YAML::Node& s = g.begin()->second;
    ctx.require_map(s, "generate." + kind);
    auto num = [&](const char* k, double def) { return s[k] ? ctx.number(s[k], kind + " " + k) : def; };
    auto integer = [&](const char* k, int def) {
      const int v = s[k] ? ctx.integer(s[k], kind + " " + k) : def;
      if (v < 1) fail(s[k], kind + ": " + k + " must be >= 1");
      return v;
    };
    auto mat = [&]() -> Material {
      const int i = material_of(s["material"], kind);
      return model.materials()[i];
    };
    auto sec = [&](const char* k) -> Section { return model.sections()[section_of(s[k], kind)]; };
    auto members = [&](auto* f) {  // what every frame generator shares
      f->stories = integer("stories", 1);
      f->divisions = integer("divisions", 1);
      f->height = num("height", 1.0);
      f->material = mat();
      f->column = sec("column");
      f->beam = sec("beam");
      f->mass = model.mass_type();
    };
    Model gen;
    if (kind == "beam") {
      ctx.only_keys(s, "generate.beam", {"length", "elements", "material", "section", "support"});
      BeamSpec b;
      b.length = num("length", 1.0);
      b.elements = integer("elements", 10);
      b.material = mat();
      b.section = sec("section");
      b.mass = model.mass_type();
      const std::string sup = s["support"] ? ctx.string(s["support"], "beam support") : "free";
      if (sup == "free") b.support = BeamSupport::Free;
      else if (sup == "cantilever") b.support = BeamSupport::Cantilever;
      else if (sup == "simply_supported") b.support = BeamSupport::SimplySupported;
      else if (sup == "clamped") b.support = BeamSupport::Clamped;
      else fail(s["support"], "beam support must be free, cantilever, simply_supported or clamped");
      gen = make_beam(b);
    } else if (kind == "frame2d") {
      ctx.only_keys(s, "generate.frame2d", {"bays", "stories", "divisions", "span", "height", "material", "column", "beam"});
      Frame2DSpec f;
      f.bays = integer("bays", 1);
      f.span = num("span", 1.0);
      members(&f);
      gen = make_frame2d(f);
    } else if (kind == "frame3d") {
      ctx.only_keys(s, "generate.frame3d", {"bays_x", "bays_y", "stories", "divisions", "span_x", "span_y", "height", "material", "column", "beam"});
      Frame3DSpec f;
      f.bays_x = integer("bays_x", 1);
      f.bays_y = integer("bays_y", 1);
      f.span_x = num("span_x", 1.0);
      f.span_y = num("span_y", 1.0);
      members(&f);
      gen = make_frame3d(f);
    } else {
      fail(g.begin()->first, "generate: unknown generator '" + kind + "' (known: beam, frame2d, frame3d)");
    }
    gen.set_rotary_inertia(model.rotary_inertia());
    model = std::move(gen);
  }
};

}  // namespace

Model parse_model(const YAML::Node& node, const YamlCtx& ctx) {
  ctx.require_map(node, "model");
  ctx.only_keys(node, "model", {"element", "mass", "rotary_inertia", "materials", "sections", "defaults", "nodes",
                                "elements", "point_masses", "springs", "supports", "generate", "units"});
  Parser p{ctx, {}, {}, {}, {}, {}, {}, {}, ElementType::Frame2D, false};
  if (node["element"]) {
    const std::string t = ctx.string(node["element"], "model element");
    if (!parse_element_type(t, &p.default_type) || p.default_type == ElementType::PointMass ||
        p.default_type == ElementType::Spring)
      ctx.fail(node["element"], "model: unknown element type '" + t + "' (known: beam2d, frame2d, frame3d)");
    p.have_default_type = true;
  }
  if (node["mass"]) {
    const std::string m = ctx.string(node["mass"], "model mass");
    if (m == "consistent") p.model.set_mass_type(MassType::Consistent);
    else if (m == "lumped") p.model.set_mass_type(MassType::Lumped);
    else ctx.fail(node["mass"], "model: mass must be consistent or lumped, got '" + m + "'");
  }
  if (node["rotary_inertia"]) p.model.set_rotary_inertia(ctx.boolean(node["rotary_inertia"], "rotary_inertia"));
  if (node["materials"]) p.parse_materials(node["materials"]);
  if (node["sections"]) p.parse_sections(node["sections"]);
  if (node["defaults"]) {
    const YAML::Node& d = node["defaults"];
    ctx.require_map(d, "defaults");
    ctx.only_keys(d, "defaults", {"material", "section"});
    if (d["material"]) {
      p.default_material = ctx.string(d["material"], "defaults material");
      p.material_of(d["material"], "defaults");
    }
    if (d["section"]) {
      p.default_section = ctx.string(d["section"], "defaults section");
      p.section_of(d["section"], "defaults");
    }
  }
  if (node["generate"]) {
    for (const char* k : {"nodes", "elements"})
      if (node[k]) ctx.fail(node[k], std::string("model: '") + k + "' cannot be combined with generate");
    p.parse_generate(node["generate"]);
    for (const Node& n : p.model.nodes()) p.node_ids.insert(n.id);
    for (const Element& e : p.model.elements()) p.element_nodes[e.id] = node["generate"];
  } else {
    if (!node["nodes"]) ctx.fail(node, "model: nodes are missing");
    if (!node["elements"] && !node["springs"] && !node["point_masses"])
      ctx.fail(node, "model: elements are missing (or give springs and point_masses for a lumped model)");
    p.parse_nodes(node["nodes"]);
    if (node["elements"]) p.parse_elements(node["elements"]);
  }
  if (node["point_masses"]) p.parse_point_masses(node["point_masses"]);
  if (node["springs"]) p.parse_springs(node["springs"]);
  if (node["supports"]) p.parse_supports(node["supports"]);
  else if (!node["generate"]) ctx.fail(node, "model: supports are missing (a list of supports, or 'free' for a free-free structure)");
  try {
    p.model.finalize();
  } catch (const InputError& e) {
    // Point at the element the message names, if any.
    static const std::regex re("^(element|point mass|spring) (-?[0-9]+)");
    std::smatch m;
    const std::string msg = e.what();
    if (std::regex_search(msg, m, re)) {
      auto it = p.element_nodes.find(std::stoi(m[2]));
      if (it != p.element_nodes.end()) ctx.fail(it->second, msg);
    }
    ctx.fail(node, msg);
  }
  return std::move(p.model);
}

}  // namespace dynid::internal
