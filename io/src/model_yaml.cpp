// The `model:` section of a case file. See docs/case-file.md for the annotated reference.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <set>

#include "dynid/io/mat_file.hpp"
#include "dynid/io/matrix_model.hpp"
#include "dynid/io/mesh_files.hpp"
#include "dynid/io/limits.hpp"
#include "dynid/mesh/generators.hpp"
#include "internal/case_util.hpp"
#include "internal/model_yaml.hpp"
#include "internal/sections.hpp"

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
  std::string dir;                          // the case file's folder (mesh file paths resolve against it)
  std::vector<std::string>* notes = nullptr;  // remarks for the caller (mesh-file content not used)
  std::map<int, std::string> element_where;   // element id -> "file:line" in a mesh file
  MeshData mesh;                              // model.file, if given
  std::vector<int> file_material, file_section;  // mesh material/section index -> model index
  ReaderLimits limits;                           // of the files read and of generate:

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
      ctx.only_keys(v, w, {"A", "I", "Iz", "Iy", "J", "rectangle", "circle", "shear_factor"});
      Section s;
      s.name = name;
      if (v["rectangle"]) {
        const YAML::Node& r = v["rectangle"];
        ctx.require_map(r, w + " rectangle");
        ctx.only_keys(r, w + " rectangle", {"width", "depth"});
        if (!r["width"] || !r["depth"]) fail(r, w + ": rectangle needs width and depth (depth lies in the bending plane)");
        const double b = ctx.number(r["width"], w + " width"), h = ctx.number(r["depth"], w + " depth");
        if (b <= 0 || h <= 0) fail(r, w + ": rectangle width and depth must be > 0");
        s = rectangle_section(name, b, h);
      } else if (v["circle"]) {
        const YAML::Node& c = v["circle"];
        ctx.require_map(c, w + " circle");
        ctx.only_keys(c, w + " circle", {"diameter"});
        const double d = ctx.number(c["diameter"], w + " diameter");
        if (d <= 0) fail(c, w + ": diameter must be > 0");
        s = pipe_section(name, d / 2, d / 2);
      }
      if (v["A"]) s.A = ctx.number(v["A"], w + " A");
      if (v["I"]) s.Iz = ctx.number(v["I"], w + " I");
      if (v["Iz"]) s.Iz = ctx.number(v["Iz"], w + " Iz");
      if (v["Iy"]) s.Iy = ctx.number(v["Iy"], w + " Iy");
      if (v["J"]) s.J = ctx.number(v["J"], w + " J");
      if (v["shear_factor"]) s.shear_factor = ctx.number(v["shear_factor"], w + " shear_factor");
      if (v["I"] && v["Iz"]) fail(v, w + ": give either I or Iz, not both");
      if (!(v["A"] || v["rectangle"] || v["circle"])) fail(v, w + ": area A is missing");
      sections[name] = model.add_section(s);
    }
  }

  /// A beam or frame element type: beam2d | frame2d | frame3d.
  ElementType member_type(const YAML::Node& n, const std::string& w, const std::string& hint = "") const {
    const std::string t = ctx.string(n, w + " type");
    ElementType type;
    if (!parse_element_type(t, &type) || !is_member(type))
      fail(n, w + ": unknown element type '" + t + "' (known: beam2d, frame2d, frame3d" + hint + ")");
    return type;
  }
  /// orientation: [x, y, z] (frame3d: a vector in the local x-z plane).
  Eigen::Vector3d orientation_of(const YAML::Node& n, const std::string& w) const {
    const auto v = ctx.numbers(n, w + " orientation");
    if (v.size() != 3) fail(n, w + ": orientation must be [x, y, z]");
    return Eigen::Vector3d(v[0], v[1], v[2]);
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
        ctx.only_keys(e, "element", {"id", "nodes", "type", "material", "section", "orientation", "group", "axial_force"});
        el.id = ctx.integer(e["id"], "element id");
        w = "element " + std::to_string(el.id);
        if (e["type"]) {
          el.type = member_type(e["type"], w, "; point masses and springs have their own lists");
        } else if (!have_default_type) {
          fail(e, w + ": no element type (give type: or model.element)");
        }
        const YAML::Node& nd = e["nodes"];
        if (!nd || !nd.IsSequence() || nd.size() != 2) fail(e, w + ": nodes must be a list of 2 node ids");
        el.node_ids = {{node_ref(nd[0], w), node_ref(nd[1], w)}};
        el.material = material_of(e["material"], w);
        el.section = section_of(e["section"], w);
        if (e["orientation"]) el.orientation = orientation_of(e["orientation"], w);
        if (e["group"]) el.group = ctx.string(e["group"], w + " group");
        if (e["axial_force"]) el.axial_force = ctx.number(e["axial_force"], w + " axial_force");
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

  /// all | fixed | clamped | pinned | [ux, uy, ...]
  DofMask fix_mask(const YAML::Node& f, const std::string& w) {
    if (!f.IsScalar()) return dof_list(f, w);
    const std::string s = f.Scalar();
    if (s == "all" || s == "fixed" || s == "clamped") return kAllDofs;
    if (s == "pinned") return kTranslations;
    fail(f, w + ": must be all, fixed, pinned, or a list of DOFs such as [ux, uy]; got '" + s + "'");
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
      if (!e["fix"]) fail(e, "support: fix is missing (all, pinned, or a list such as [ux, uy])");
      const DofMask m = fix_mask(e["fix"], "support");
      for (int id : ids) model.restrain(id, m);
    }
  }

  /// What a `groups:` entry of a mesh-file model assigns to the elements and nodes of one group.
  struct GroupSpec {
    std::string name;
    YAML::Node node;
    int material = -1, section = -1;
    std::optional<ElementType> type;
    std::optional<Eigen::Vector3d> orientation;
  };

  GroupSpec parse_group(const std::string& name, const YAML::Node& v, const MeshData& mesh) {
    const std::string w = "group '" + name + "'";
    ctx.require_map(v, w);
    ctx.only_keys(v, w, {"section", "material", "type", "orientation", "support"});
    const MeshGroup* g = mesh.find_group(name);
    if (!g) fail(v, w + " is not in " + mesh.file + " (its groups: " + mesh.group_names() + ")");
    GroupSpec s{name, v, -1, -1, {}, {}};
    if (v["material"]) s.material = material_of(v["material"], w);
    if (v["section"]) s.section = section_of(v["section"], w);
    if (v["type"]) s.type = member_type(v["type"], w);
    if (v["orientation"]) s.orientation = orientation_of(v["orientation"], w);
    if (v["support"]) {
      const DofMask m = fix_mask(v["support"], w + " support");
      for (int id : g->nodes) model.restrain(id, m);
    }
    return s;
  }

  /// model: {matrices: {dofs, nodes, elements, groups: {name: {K, M}}, K, M}}: a model exported from another FE
  /// code as matrices (docs/matrix-input.md); its elements are Matrix elements.
  /// model: {matrices: {mat: FILE, K: VAR, M: VAR, groups: [VAR, ...] | {name: VAR | {K: VAR, M: VAR}},
  /// elements: {K: VAR, M: VAR, dofs: VAR, groups: VAR}, dofs: VAR, nodes: VAR}}: the same from a MATLAB file,
  /// every part named by its variable (docs/matrix-input.md).
  void read_mat_matrices(const YAML::Node& m) {
    ctx.only_keys(m, "model matrices (mat)", {"mat", "dofs", "nodes", "elements", "groups", "K", "M"});
    MatModelNames n;
    n.file = resolve(dir, ctx.string(m["mat"], "matrices mat"));
    std::error_code ec;
    if (!std::filesystem::is_regular_file(n.file, ec)) fail(m["mat"], "matrices mat: cannot open '" + n.file + "'");
    auto var = [&](const YAML::Node& v, const std::string& w) { return ctx.string(v, w + " (a variable name)"); };
    if (!m["K"] != !m["M"]) fail(m, "model matrices: give both K and M (the assembled matrices), or neither");
    if (m["K"]) {
      n.K = var(m["K"], "matrices K");
      n.M = var(m["M"], "matrices M");
    }
    if (m["dofs"]) n.dofs = var(m["dofs"], "matrices dofs");
    if (m["nodes"]) n.nodes = var(m["nodes"], "matrices nodes");
    if (m["groups"]) {
      const YAML::Node& g = m["groups"];
      if (g.IsSequence()) {
        for (const auto& v : g) {
          const std::string k = var(v, "matrices groups");
          n.groups.push_back({k, k, ""});
        }
      } else {
        ctx.require_map(g, "matrices groups");
        for (const auto& kv : g) {
          const std::string name = kv.first.Scalar(), w = "matrices group '" + name + "'";
          if (kv.second.IsScalar()) {
            n.groups.push_back({name, var(kv.second, w), ""});
          } else {
            ctx.require_map(kv.second, w);
            ctx.only_keys(kv.second, w, {"K", "M"});
            if (!kv.second["K"] && !kv.second["M"]) fail(kv.second, w + ": give K, M or both (variable names)");
            n.groups.push_back({name, kv.second["K"] ? var(kv.second["K"], w + " K") : "",
                                kv.second["M"] ? var(kv.second["M"], w + " M") : ""});
          }
        }
      }
    }
    if (m["elements"]) {
      const YAML::Node& e = m["elements"];
      ctx.require_map(e, "matrices elements");
      ctx.only_keys(e, "matrices elements", {"K", "M", "dofs", "groups"});
      if (!e["K"] || !e["dofs"]) fail(e, "matrices elements: K and dofs (cell arrays) are needed");
      n.element_K = var(e["K"], "elements K");
      n.element_dofs = var(e["dofs"], "elements dofs");
      if (e["M"]) n.element_M = var(e["M"], "elements M");
      if (e["groups"]) n.element_groups = var(e["groups"], "elements groups");
    }
    if (n.groups.empty() && n.element_K.empty()) fail(m, "model matrices: name groups (group stiffness variables) or elements (cell arrays)");
    add_matrix_model(read_mat_matrix_model(n, notes, limits), &model, notes, limits);
  }

  void read_matrices(const YAML::Node& m) {
    ctx.require_map(m, "model matrices");
    if (m["mat"]) return read_mat_matrices(m);
    ctx.only_keys(m, "model matrices", {"dofs", "nodes", "elements", "groups", "K", "M"});
    if (!m["dofs"]) fail(m, "model matrices: 'dofs' is missing (the DOF table: one line 'node, dof' per equation)");
    if (!m["elements"] && !m["groups"]) fail(m, "model matrices: give 'elements' (element matrices) or 'groups' (group matrices)");
    if (!m["K"] != !m["M"]) fail(m, "model matrices: give both K and M (the assembled matrices), or neither");
    MatrixModelFiles f;
    auto file = [&](const YAML::Node& n, const std::string& w) {
      const std::string path = resolve(dir, ctx.string(n, w));
      std::error_code ec;
      if (!std::filesystem::is_regular_file(path, ec)) fail(n, w + ": cannot open '" + path + "'");
      return path;
    };
    f.dofs = file(m["dofs"], "matrices dofs");
    if (m["nodes"]) f.nodes = file(m["nodes"], "matrices nodes");
    if (m["elements"]) f.elements = file(m["elements"], "matrices elements");
    if (m["K"]) {
      f.K = file(m["K"], "matrices K");
      f.M = file(m["M"], "matrices M");
    }
    if (m["groups"]) {
      ctx.require_map(m["groups"], "matrices groups");
      for (const auto& kv : m["groups"]) {
        const std::string name = kv.first.Scalar(), w = "matrices group '" + name + "'";
        ctx.require_map(kv.second, w);
        ctx.only_keys(kv.second, w, {"K", "M"});
        if (!kv.second["K"] && !kv.second["M"]) fail(kv.second, w + ": give K, M or both (Matrix Market files)");
        f.groups.push_back({name, kv.second["K"] ? file(kv.second["K"], w + " K") : "",
                            kv.second["M"] ? file(kv.second["M"], w + " M") : ""});
      }
    }
    add_matrix_model(f, &model, notes, limits);
  }

  /// model: {file: frame.msh | frame.inp}: reads the mesh file and adds its materials and sections (Abaqus),
  /// except those the case file defines under the same name.
  void read_mesh(const YAML::Node& f) {
    const std::string path = resolve(dir, ctx.string(f, "model file"));
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) fail(f, "model file: cannot open '" + path + "'");
    mesh = read_mesh_file(path, limits);
    if (notes)
      for (const std::string& s : mesh.skipped) notes->push_back(mesh.file + ": skipped " + s);
    for (const Material& m : mesh.materials) {
      auto it = materials.find(m.name);
      file_material.push_back(it != materials.end() ? it->second : (materials[m.name] = model.add_material(m)));
    }
    for (const Section& s : mesh.sections) {
      auto it = sections.find(s.name);
      file_section.push_back(it != sections.end() ? it->second : (sections[s.name] = model.add_section(s)));
    }
  }

  /// The mesh's nodes, elements and supports, with `groups: {name: {section, material, type, orientation,
  /// support}}` applied to the mesh groups (Gmsh physical groups, Abaqus sets).
  void build_mesh_model(const YAML::Node& groups) {
    for (const Node& n : mesh.nodes) {
      model.add_node(n.id, n.x);
      node_ids.insert(n.id);
    }
    for (const auto& [id, m] : mesh.restraints) model.restrain(id, m);
    // Group assignments, per element id (two groups may not give one element different values).
    std::vector<GroupSpec> specs;
    std::map<int, std::vector<const GroupSpec*>> by_element;
    if (groups) {
      ctx.require_map(groups, "groups");
      for (const auto& kv : groups) specs.push_back(parse_group(kv.first.Scalar(), kv.second, mesh));
      for (const GroupSpec& s : specs)
        for (int id : mesh.find_group(s.name)->elements) by_element[id].push_back(&s);
    }
    for (const MeshElement& me : mesh.elements) {
      const std::string w = "element " + std::to_string(me.id);
      auto mfail = [&](const std::string& m) -> void { throw InputError(me.where + ": " + w + ": " + m); };
      Element el;
      el.id = me.id;
      el.node_ids = me.nodes;
      el.group = me.group;
      el.material = me.material >= 0 ? file_material[me.material] : -1;
      el.section = me.section >= 0 ? file_section[me.section] : -1;
      el.orientation = me.orientation;
      std::optional<ElementType> type = me.type;
      const GroupSpec* from[4] = {nullptr, nullptr, nullptr, nullptr};  // material, section, type, orientation
      for (const GroupSpec* s : by_element[me.id]) {
        auto take = [&](int k, bool has, const char* what) {
          if (!has) return false;
          if (from[k]) fail(s->node, "group '" + s->name + "' and group '" + from[k]->name + "' both set the " + what + " of " + w);
          from[k] = s;
          return true;
        };
        if (take(0, s->material >= 0, "material")) el.material = s->material;
        if (take(1, s->section >= 0, "section")) el.section = s->section;
        if (take(2, s->type.has_value(), "type")) type = s->type;
        if (take(3, s->orientation.has_value(), "orientation")) el.orientation = *s->orientation;
      }
      if (!type && have_default_type) type = default_type;
      if (!type) mfail("no element type: give model.element (beam2d, frame2d, frame3d) or type: in one of its groups");
      el.type = *type;
      if (el.material < 0 && !default_material.empty()) el.material = materials.at(default_material);
      if (el.section < 0 && !default_section.empty()) el.section = sections.at(default_section);
      if (el.material < 0 || el.section < 0)
        mfail(std::string("no ") + (el.material < 0 ? "material" : "section") +
              ": assign one in the case file (model.groups.<group>.material/section, or model.defaults)");
      if (me.type == ElementType::Frame3D && el.type == ElementType::Frame3D && el.orientation.squaredNorm() == 0)
        mfail("no beam orientation: give the n1 direction as the second data line of its *BEAM SECTION (Abaqus's "
              "default would be 0, 0, -1), an orientation node, or orientation: in its case-file group");
      if (element_nodes.count(el.id) || element_where.count(el.id)) mfail("is defined twice");
      element_where[el.id] = me.where;
      model.add_element(el);
    }
  }

  void parse_generate(const YAML::Node& g) {
    ctx.require_map(g, "generate");
    if (g.size() != 1) fail(g, "generate: give exactly one of beam, frame2d, frame3d");
    const std::string kind = g.begin()->first.Scalar();
    const YAML::Node s = g.begin()->second;  // a copy: the iterator's pair is a temporary
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
    // The size a generator is asked for is checked before anything is allocated (in doubles: no overflow).
    auto check_size = [&](double elements) {
      // The largest model `generate:` builds, so that a case file cannot ask for more memory than a machine has
      // (bench/ goes to 10^6 DOFs, about 3 x 10^5 elements): ReaderLimits::max_generated_elements.
      const double max_elements = limits.max_generated_elements;
      if (elements <= max_elements) return;
      char buf[96];
      std::snprintf(buf, sizeof buf, "%.4g elements; at most %.4g can be generated", elements, max_elements);
      fail(s, "generate." + kind + ": " + buf);
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
      check_size(b.elements);
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
      check_size((2.0 * f.bays + 1) * f.stories * f.divisions);
      gen = make_frame2d(f);
    } else if (kind == "frame3d") {
      ctx.only_keys(s, "generate.frame3d", {"bays_x", "bays_y", "stories", "divisions", "span_x", "span_y", "height", "material", "column", "beam"});
      Frame3DSpec f;
      f.bays_x = integer("bays_x", 1);
      f.bays_y = integer("bays_y", 1);
      f.span_x = num("span_x", 1.0);
      f.span_y = num("span_y", 1.0);
      members(&f);
      const double bx = f.bays_x, by = f.bays_y;
      check_size(((bx + 1) * (by + 1) + bx * (by + 1) + by * (bx + 1)) * f.stories * f.divisions);
      gen = make_frame3d(f);
    } else {
      fail(g.begin()->first, "generate: unknown generator '" + kind + "' (known: beam, frame2d, frame3d)");
    }
    gen.set_rotary_inertia(model.rotary_inertia());
    model = std::move(gen);
  }
};

}  // namespace

Model parse_model(const YAML::Node& node, const YamlCtx& ctx, const std::string& dir, std::vector<std::string>* notes,
                  const ReaderLimits& limits) {
  ctx.require_map(node, "model");
  ctx.only_keys(node, "model", {"element", "mass", "rotary_inertia", "materials", "sections", "defaults", "nodes",
                                "elements", "point_masses", "springs", "supports", "generate", "units", "file",
                                "groups", "matrices"});
  Parser p{ctx, {}, {}, {}, {}, {}, {}, {}, ElementType::Frame2D, false, dir, notes, {}, {}, {}, {}, limits};
  if (node["element"]) {
    p.default_type = p.member_type(node["element"], "model");
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
  if (node["file"]) p.read_mesh(node["file"]);
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
  if (node["groups"] && !node["file"]) ctx.fail(node["groups"], "model: groups: needs file: (a mesh file)");
  if (node["matrices"]) {
    for (const char* k : {"nodes", "elements", "generate", "file", "element", "mass", "rotary_inertia", "materials", "sections", "defaults"})
      if (node[k]) ctx.fail(node[k], std::string("model: '") + k + "' cannot be combined with matrices (the matrices define the model)");
    p.read_matrices(node["matrices"]);
  } else if (node["file"]) {
    for (const char* k : {"nodes", "elements", "generate"})
      if (node[k]) ctx.fail(node[k], std::string("model: '") + k + "' cannot be combined with file");
    p.build_mesh_model(node["groups"]);
  } else if (node["generate"]) {
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
  else if (!node["generate"] && !node["file"] && !node["matrices"]) ctx.fail(node, "model: supports are missing (a list of supports, or 'free' for a free-free structure)");
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
      auto mesh = p.element_where.find(std::stoi(m[2]));
      if (mesh != p.element_where.end()) throw InputError(mesh->second + ": " + msg);
    }
    ctx.fail(node, msg);
  }
  return std::move(p.model);
}

}  // namespace dynid::internal
