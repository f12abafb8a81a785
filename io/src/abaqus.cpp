// Abaqus .inp reader: the beam-model subset listed in dynid/io/mesh_files.hpp. Keywords and names are
// case-insensitive (names are kept in upper case, as Abaqus does); unsupported keywords are skipped and listed
// in MeshData::skipped.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <unordered_map>

#include "dynid/io/mesh_files.hpp"
#include "dynid/io/limits.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/text_util.hpp"
#include "internal/sections.hpp"

namespace dynid {

namespace fs = std::filesystem;

const MeshGroup* MeshData::find_group(const std::string& name) const {
  std::string key = name;
  if (names_ignore_case) std::transform(key.begin(), key.end(), key.begin(), ::toupper);
  auto it = groups.find(key);
  return it == groups.end() ? nullptr : &it->second;
}

std::string MeshData::group_names() const {
  std::string s;
  for (const auto& kv : groups) s += (s.empty() ? "" : ", ") + kv.first;
  return s.empty() ? "(none)" : s;
}

MeshData read_mesh_file(const std::string& path, const ReaderLimits& limits) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext == ".msh") return read_gmsh(path);
  if (ext == ".inp") return read_abaqus(path, limits);
  throw InputError(path + ": unknown mesh file type '" + ext + "' (known: .msh Gmsh, .inp Abaqus)");
}

namespace {

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), ::toupper);
  return s;
}
std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}
/// The folder holding `path` ("." for a bare file name), against which its *INCLUDEs resolve.
std::string folder_of(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? "." : parent.string();
}
std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> f;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, ',');) f.push_back(trim(x));
  while (!f.empty() && f.back().empty()) f.pop_back();
  return f;
}

/// One logical line of the input (continuations joined), with where it starts.
struct Line {
  std::string text, where;
};

/// A keyword with its parameters and data lines.
struct Card {
  std::string name;  // upper case, single spaces: "BEAM SECTION"
  std::map<std::string, std::string> params;  // upper-case keys; values as written
  std::vector<Line> data;
  std::string where;
  bool has(const std::string& k) const { return params.count(k) != 0; }
  [[noreturn]] void fail(const std::string& msg) const { throw InputError(where + ": *" + name + ": " + msg); }
  std::string param(const std::string& k) const {
    auto it = params.find(k);
    if (it == params.end() || it->second.empty()) fail("the " + k + "= parameter is missing");
    return it->second;
  }
};

class AbaqusReader {
 public:
  AbaqusReader(const std::string& name, const ReaderLimits& limits) : limits_(limits) {
    out_.file = name;
    out_.names_ignore_case = true;
  }

  /// `bytes` is the file named `name`; its *INCLUDEs are read from `include_dir` ("": not allowed).
  MeshData read(const std::string& bytes, const std::string& include_dir) {
    std::vector<Line> lines;
    load(bytes, out_.file, include_dir, 0, &lines);
    for (const Card& c : cards(lines)) card(c);
    finish();
    return std::move(out_);
  }

 private:
  /// Splits a file's bytes into lines, expanding *INCLUDE (files in `dir`; "": none allowed), dropping comments
  /// and blank lines, joining continuations.
  void load(const std::string& bytes, const std::string& path, const std::string& dir, int depth,
            std::vector<Line>* lines) {
    if (depth > 10) throw InputError(path + ": *INCLUDE nested more than 10 deep (a cycle?)");
    std::istringstream in(bytes);
    int n = 0;
    bool continued = false;
    for (std::string raw; std::getline(in, raw);) {
      ++n;
      const std::string t = trim(raw);
      if (t.empty() || t.rfind("**", 0) == 0) continue;
      const std::string where = path + ":" + std::to_string(n);
      if (continued) {
        lines->back().text += t;
      } else if (upper(t).rfind("*INCLUDE", 0) == 0) {
        Card c = keyword(t, where);
        if (dir.empty()) c.fail("*INCLUDE is not available when the file is read from memory");
        const fs::path inc = fs::path(dir) / c.param("INPUT");
        if (!fs::exists(inc)) c.fail("cannot open '" + inc.string() + "'");
        load(internal::read_file_bytes(inc.string()), inc.string(), folder_of(inc.string()), depth + 1, lines);
        continue;
      } else {
        lines->push_back({t, where});
      }
      continued = t.back() == ',';
    }
  }

  static Card keyword(const std::string& text, const std::string& where) {
    Card c;
    c.where = where;
    const auto f = split(text.substr(1));
    if (f.empty()) throw InputError(where + ": empty keyword '*'");
    std::istringstream words(upper(f[0]));
    for (std::string w; words >> w;) c.name += (c.name.empty() ? "" : " ") + w;
    for (std::size_t k = 1; k < f.size(); ++k) {
      const auto eq = f[k].find('=');
      c.params[upper(trim(f[k].substr(0, eq)))] = eq == std::string::npos ? "" : trim(f[k].substr(eq + 1));
    }
    return c;
  }

  static std::vector<Card> cards(const std::vector<Line>& lines) {
    std::vector<Card> out;
    for (const Line& l : lines) {
      if (l.text[0] == '*') out.push_back(keyword(l.text, l.where));
      else if (out.empty()) throw InputError(l.where + ": data line before any keyword");
      else out.back().data.push_back(l);
    }
    return out;
  }

  static double number(const std::string& s, const Line& l, const std::string& what) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(v)) throw InputError(l.where + ": " + what + ": '" + s + "' is not a number");
    return v;
  }
  static int integer(const std::string& s, const Line& l, const std::string& what) {
    const double v = number(s, l, what);
    if (v != std::floor(v) || std::abs(v) > 2e9) throw InputError(l.where + ": " + what + ": '" + s + "' is not an integer");
    return static_cast<int>(v);
  }
  /// The numbers of a data line; at least `min` of them.
  static std::vector<double> numbers(const Line& l, std::size_t min, const std::string& what) {
    std::vector<double> v;
    for (const std::string& f : split(l.text)) v.push_back(f.empty() ? 0.0 : number(f, l, what));
    if (v.size() < min) throw InputError(l.where + ": " + what + ": expected at least " + std::to_string(min) + " values");
    return v;
  }

  void card(const Card& c) {
    if (c.name != "ELASTIC" && c.name != "DENSITY") material_ = -1;  // material options follow their *MATERIAL
    if (c.name == "HEADING") return;
    if (c.name == "NODE") return nodes(c);
    if (c.name == "ELEMENT") return elements(c);
    if (c.name == "NSET" || c.name == "ELSET") return set(c);
    if (c.name == "MATERIAL") return material(c);
    if (c.name == "ELASTIC" || c.name == "DENSITY") return material_option(c);
    if (c.name == "BEAM SECTION" || c.name == "BEAM GENERAL SECTION") return sections_.push_back(c);
    if (c.name == "BOUNDARY") return boundaries_.push_back(c);
    out_.skipped.push_back("*" + c.name + " (" + at(c.where) + ")");
  }

  /// "line 12" for the main file, "other.inp:12" for included ones.
  std::string at(const std::string& where) const {
    const std::string main = out_.file + ":";
    return where.rfind(main, 0) == 0 ? "line " + where.substr(main.size()) : where;
  }

  void nodes(const Card& c) {
    for (const Line& l : c.data) {
      const auto f = split(l.text);
      if (f.size() < 3 || f.size() > 4) throw InputError(l.where + ": *NODE: expected 'id, x, y' or 'id, x, y, z'");
      const int id = integer(f[0], l, "node id");
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (std::size_t k = 1; k < f.size(); ++k) x[k - 1] = number(f[k], l, "node " + std::to_string(id) + " coordinate");
      if (!node_ids_.insert(id).second) throw InputError(l.where + ": node " + std::to_string(id) + " is defined twice");
      out_.nodes.push_back({id, x});
      if (c.has("NSET")) out_.groups[upper(c.params.at("NSET"))].nodes.push_back(id);
    }
  }

  void elements(const Card& c) {
    const std::string type = upper(c.param("TYPE"));
    std::optional<ElementType> t;
    if (type == "B21" || type == "B23") t = ElementType::Frame2D;
    if (type == "B31" || type == "B33") t = ElementType::Frame3D;
    if (!t) {
      out_.skipped.push_back(std::to_string(c.data.size()) + " elements of TYPE=" + type + " (" + at(c.where) +
                             "; only B21, B23, B31, B33 are used)");
      return;
    }
    const std::string elset = c.has("ELSET") ? upper(c.params.at("ELSET")) : "";
    for (const Line& l : c.data) {
      const auto f = split(l.text);
      const bool space = *t == ElementType::Frame3D;
      if (f.size() < 3 || f.size() > (space ? 4u : 3u))
        throw InputError(l.where + ": *ELEMENT TYPE=" + type + ": expected 'id, node 1, node 2'" + (space ? " (, orientation node)" : ""));
      MeshElement e;
      e.id = integer(f[0], l, "element id");
      e.type = t;
      e.nodes = {{integer(f[1], l, "element node"), integer(f[2], l, "element node")}};
      e.group = elset;
      e.where = l.where;
      if (!element_index_.emplace(e.id, out_.elements.size()).second)
        throw InputError(l.where + ": element " + std::to_string(e.id) + " is defined twice");
      if (f.size() == 4) orientation_nodes_[e.id] = integer(f[3], l, "orientation node");
      out_.elements.push_back(e);
      if (!elset.empty()) out_.groups[elset].elements.push_back(e.id);
    }
  }

  /// *NSET / *ELSET: ids, names of sets defined before, or first, last, increment with GENERATE.
  void set(const Card& c) {
    const bool nodes = c.name == "NSET";
    const std::string name = upper(c.param(c.name));
    std::vector<int> ids;
    for (const Line& l : c.data) {
      const auto f = split(l.text);
      if (c.has("GENERATE")) {
        if (f.size() < 2 || f.size() > 3) throw InputError(l.where + ": *" + c.name + ", GENERATE: expected 'first, last, increment'");
        const int a = integer(f[0], l, "first"), b = integer(f[1], l, "last"), d = f.size() == 3 ? integer(f[2], l, "increment") : 1;
        if (a < 1 || d < 1 || b < a)
          throw InputError(l.where + ": *" + c.name + ", GENERATE: needs 1 <= first <= last and increment >= 1");
        const long long limit = limits_.max_generated_ids;
        if ((static_cast<long long>(b) - a) / d >= limit)
          throw InputError(l.where + ": *" + c.name + ", GENERATE: more than " + limit_text(double(limit)) + " ids");
        for (long long k = a; k <= b; k += d) ids.push_back(static_cast<int>(k));
        continue;
      }
      for (const std::string& x : f) {
        if (!x.empty() && (std::isdigit(static_cast<unsigned char>(x[0])) || x[0] == '-')) {
          ids.push_back(integer(x, l, c.name + " member"));
          continue;
        }
        const MeshGroup* g = out_.find_group(x);
        if (!g) throw InputError(l.where + ": *" + c.name + " " + name + ": '" + x + "' is neither an id nor a set defined above");
        const auto& from = nodes ? g->nodes : g->elements;
        ids.insert(ids.end(), from.begin(), from.end());
      }
    }
    auto& to = nodes ? out_.groups[name].nodes : out_.groups[name].elements;
    to.insert(to.end(), ids.begin(), ids.end());
  }

  void material(const Card& c) {
    Material m;
    m.name = upper(c.param("NAME"));
    for (const Material& q : out_.materials)
      if (q.name == m.name) c.fail("material " + m.name + " is defined twice");
    material_ = static_cast<int>(out_.materials.size());
    out_.materials.push_back(m);
  }

  void material_option(const Card& c) {
    if (material_ < 0) c.fail("must follow a *MATERIAL");
    if (c.data.size() != 1) c.fail("expected one data line (temperature-dependent data is not supported)");
    Material& m = out_.materials[material_];
    const auto v = numbers(c.data[0], 1, "*" + c.name);
    if (c.name == "DENSITY") {
      m.rho = v[0];
      return;
    }
    if (c.has("TYPE") && upper(c.params.at("TYPE")) != "ISOTROPIC") c.fail("only TYPE=ISOTROPIC is supported");
    m.E = v[0];
    if (v.size() > 1) m.nu = v[1];
  }

  int material_index(const Card& c, const std::string& name) const {
    for (std::size_t k = 0; k < out_.materials.size(); ++k)
      if (out_.materials[k].name == upper(name)) return static_cast<int>(k);
    c.fail("material '" + name + "' is not defined (no *MATERIAL, NAME=" + name + ")");
  }

  /// *BEAM SECTION / *BEAM GENERAL SECTION: a section (named after its ELSET) for the elements of the ELSET.
  void section(const Card& c) {
    const std::string elset = upper(c.param("ELSET"));
    const std::string shape = c.has("SECTION") ? upper(c.params.at("SECTION")) : "GENERAL";
    const MeshGroup* g = out_.find_group(elset);
    if (!g) c.fail("ELSET=" + elset + " is not defined");
    if (c.data.empty()) c.fail("the section data line is missing");
    const auto d = numbers(c.data[0], 1, "*" + c.name + " data");
    Section s;
    int mat = -1;
    auto need = [&](std::size_t n, const char* what) {
      if (d.size() < n) c.fail("SECTION=" + shape + " needs " + what + " on its first data line");
      for (std::size_t k = 0; k < n; ++k)
        if (!(d[k] > 0) && !(shape == "GENERAL" && (k == 2 || k == 4))) c.fail(std::string(what) + " must be > 0");
    };
    if (c.name == "BEAM SECTION") {
      mat = material_index(c, c.param("MATERIAL"));
      if (shape == "RECT") {
        need(2, "a, b");
        s = internal::rectangle_section(elset, d[0], d[1]);
      } else if (shape == "CIRC") {
        need(1, "r");
        s = internal::pipe_section(elset, d[0], d[0]);
      } else if (shape == "PIPE") {
        need(2, "r, t");
        if (d[1] > d[0]) c.fail("PIPE wall thickness t exceeds the radius r");
        s = internal::pipe_section(elset, d[0], d[1]);
      } else {
        c.fail("SECTION=" + shape + " is not supported (RECT, CIRC, PIPE; or *BEAM GENERAL SECTION)");
      }
      if (c.data.size() > 2) c.fail("expected at most 2 data lines (dimensions, n1 direction)");
    } else {
      if (shape != "GENERAL") c.fail("SECTION=" + shape + " is not supported (only SECTION=GENERAL)");
      need(5, "A, I11, I12, I22, J");
      if (d[2] != 0) c.fail("I12 must be 0: dynid needs principal axes (give the n1 direction of a principal axis)");
      s.name = elset;
      s.A = d[0], s.Iz = d[1], s.Iy = d[3], s.J = d[4];
      if (c.data.size() != 3) c.fail("SECTION=GENERAL needs 3 data lines: A, I11, I12, I22, J; the n1 direction; E, G");
      const auto eg = numbers(c.data[2], 2, "*BEAM GENERAL SECTION E, G");
      Material m;
      m.name = elset;
      m.E = eg[0], m.G = eg[1];
      if (c.has("DENSITY")) m.rho = number(c.params.at("DENSITY"), c.data[0], "DENSITY");
      mat = static_cast<int>(out_.materials.size());
      out_.materials.push_back(m);
    }
    Eigen::Vector3d n1 = Eigen::Vector3d::Zero();
    if (c.data.size() >= 2) {
      const auto v = numbers(c.data[1], 3, "n1 direction");
      n1 = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    const int sec = static_cast<int>(out_.sections.size());
    out_.sections.push_back(s);
    for (int id : g->elements) {
      auto it = element_index_.find(id);
      if (it == element_index_.end()) c.fail("element " + std::to_string(id) + " of ELSET=" + elset + " does not exist");
      MeshElement& e = out_.elements[it->second];
      if (e.section >= 0) c.fail("element " + std::to_string(id) + " already has a section (" + out_.sections[e.section].name + ")");
      e.section = sec;
      e.material = mat;
      if (*e.type == ElementType::Frame3D) e.orientation = n1;  // planar beams: n1 is (0, 0, -1) by definition
    }
  }

  /// *BOUNDARY: node or NSET, first DOF[, last DOF[, 0]]; or node or NSET, ENCASTRE | PINNED | XSYMM ...
  void boundary(const Card& c) {
    if (c.has("TYPE") && upper(c.params.at("TYPE")) != "DISPLACEMENT") c.fail("only TYPE=DISPLACEMENT is supported");
    for (const Line& l : c.data) {
      const auto f = split(l.text);
      if (f.size() < 2) throw InputError(l.where + ": *BOUNDARY: expected 'node or set, first DOF, last DOF' or 'node or set, ENCASTRE'");
      std::vector<int> ids;
      if (std::isdigit(static_cast<unsigned char>(f[0][0]))) {
        ids.push_back(integer(f[0], l, "*BOUNDARY node"));
      } else if (const MeshGroup* g = out_.find_group(f[0])) {
        ids = g->nodes;
      } else {
        throw InputError(l.where + ": *BOUNDARY: node set '" + f[0] + "' is not defined");
      }
      DofMask m = 0;
      const std::string kind = upper(f[1]);
      auto bits = [](std::initializer_list<Dof> ds) {
        DofMask b = 0;
        for (Dof d : ds) b |= dof_bit(d);
        return b;
      };
      if (kind == "ENCASTRE") m = kAllDofs;
      else if (kind == "PINNED") m = kTranslations;
      else if (kind == "XSYMM") m = bits({Dof::UX, Dof::RY, Dof::RZ});
      else if (kind == "YSYMM") m = bits({Dof::UY, Dof::RX, Dof::RZ});
      else if (kind == "ZSYMM") m = bits({Dof::UZ, Dof::RX, Dof::RY});
      else {
        const int a = integer(f[1], l, "*BOUNDARY first DOF");
        const int b = f.size() > 2 && !f[2].empty() ? integer(f[2], l, "*BOUNDARY last DOF") : a;
        if (a < 1 || b < a || b > 6) throw InputError(l.where + ": *BOUNDARY: DOFs must satisfy 1 <= first <= last <= 6");
        if (f.size() > 3 && number(f[3], l, "*BOUNDARY magnitude") != 0)
          throw InputError(l.where + ": *BOUNDARY: prescribed nonzero displacements are not supported (modal analysis)");
        for (int k = a; k <= b; ++k) m |= dof_bit(static_cast<Dof>(k - 1));
      }
      for (int id : ids) {
        if (!node_ids_.count(id)) throw InputError(l.where + ": *BOUNDARY: node " + std::to_string(id) + " does not exist");
        out_.restraints.push_back({id, m});
      }
    }
  }

  /// Checks the elements' nodes, resolves orientation nodes, then applies sections and boundaries (which may
  /// name sets, materials and elements defined anywhere in the file).
  void finish() {
    std::unordered_map<int, int> node_of;
    for (std::size_t k = 0; k < out_.nodes.size(); ++k) node_of[out_.nodes[k].id] = static_cast<int>(k);
    for (MeshElement& e : out_.elements) {
      for (int id : e.nodes)
        if (!node_of.count(id)) throw InputError(e.where + ": element " + std::to_string(e.id) + ": node " + std::to_string(id) + " does not exist");
    }
    for (const Card& c : sections_) section(c);
    for (const auto& [id, n] : orientation_nodes_) {
      MeshElement& e = out_.elements[element_index_.at(id)];
      if (!node_of.count(n)) throw InputError(e.where + ": element " + std::to_string(id) + ": orientation node " + std::to_string(n) + " does not exist");
      e.orientation = out_.nodes[node_of.at(n)].x - out_.nodes[node_of.at(e.nodes[0])].x;
    }
    for (auto& [name, g] : out_.groups) {  // nodes of an element set: those of its elements
      for (int id : g.elements) {
        auto it = element_index_.find(id);
        if (it == element_index_.end()) continue;  // elements of skipped types
        for (int n : out_.elements[it->second].nodes) g.nodes.push_back(n);
      }
    }
    for (const Card& c : boundaries_) boundary(c);
  }

  MeshData out_;
  ReaderLimits limits_;
  std::set<int> node_ids_;
  std::unordered_map<int, std::size_t> element_index_;
  std::map<int, int> orientation_nodes_;  // element id -> node id
  std::vector<Card> sections_, boundaries_;
  int material_ = -1;
};

}  // namespace

MeshData parse_abaqus(const std::string& bytes, const std::string& name, const std::string& include_dir,
                      const ReaderLimits& limits) {
  return AbaqusReader(name, limits).read(bytes, include_dir);
}
MeshData read_abaqus(const std::string& path, const ReaderLimits& limits) {
  return AbaqusReader(path, limits).read(internal::read_file_bytes(path), folder_of(path));
}

}  // namespace dynid
