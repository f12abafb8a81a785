#include "dynid/io/case_file.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "dynid/engine/modal.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/point_map.hpp"
#include "internal/case_util.hpp"
#include "internal/text_util.hpp"
#include "internal/model_yaml.hpp"

namespace dynid {

namespace fs = std::filesystem;
using internal::YamlCtx;

namespace internal {

// measured_dofs: all | translations | {types: [ux, uy], nodes: [...]} | [13ux, 13uy, ...]
std::vector<MeasuredDof> parse_dof_selection(const YAML::Node& n, const YamlCtx& ctx, const Model& model,
                                             const std::string& what) {
  std::vector<MeasuredDof> out;
  if (n.IsScalar()) {
    const std::string v = n.Scalar();
    if (v == "all") return all_dofs(model);
    if (v == "translations") return dofs_of_types(model, kTranslations);
    ctx.fail(n, what + ": expected all, translations, {types: [...], nodes: [...]} or a list of DOF labels like 13ux");
  }
  if (n.IsMap()) {
    ctx.only_keys(n, what, {"types", "nodes"});
    DofMask types = 0;
    if (!n["types"]) ctx.fail(n, what + ": types is missing (e.g. types: [ux, uy])");
    ctx.require_sequence(n["types"], what + " types");
    for (const auto& t : n["types"]) {
      Dof d;
      if (!parse_dof(ctx.string(t, what + " type"), &d)) ctx.fail(t, what + ": unknown DOF type '" + t.Scalar() + "'");
      types |= dof_bit(d);
    }
    std::vector<int> nodes;
    if (n["nodes"]) {
      ctx.require_sequence(n["nodes"], what + " nodes");
      for (const auto& q : n["nodes"]) {
        const int id = ctx.integer(q, what + " node");
        if (model.node_index(id) < 0) ctx.fail(q, what + ": node " + std::to_string(id) + " does not exist");
        nodes.push_back(id);
      }
    }
    out = dofs_of_types(model, types, nodes);
    if (out.empty()) ctx.fail(n, what + ": selects no free DOF of the model");
    return out;
  }
  ctx.require_sequence(n, what);
  for (const auto& q : n) {
    MeasuredDof d;
    const std::string lab = ctx.string(q, what + " DOF");
    if (!parse_dof_label(lab, &d)) ctx.fail(q, what + ": '" + lab + "' is not a DOF label (e.g. 13ux)");
    out.push_back(d);
  }
  try {
    measured_equations(model, out);
  } catch (const InputError& e) {
    ctx.fail(n, what + ": " + e.what());
  }
  return out;
}

std::string parse_measured(const YAML::Node& n, const YamlCtx& ctx, const std::string& dir, const std::string& what) {
  if (!n.IsMap()) return resolve(dir, ctx.string(n, what));
  ctx.only_keys(n, what, {"mat", "frequency_hz", "eigenvalues", "shapes", "dofs", "damping", "frequency_std", "eigenvalue_std",
                          "shape_std"});
  if (!n["mat"]) ctx.fail(n, what + ": mat (the .mat file) is missing; give measured: FILE or {mat: FILE, shapes: VAR, ...}");
  if (n["frequency_hz"] && n["eigenvalues"]) ctx.fail(n, what + ": give frequency_hz or eigenvalues, not both");
  if (n["frequency_std"] && n["eigenvalue_std"]) ctx.fail(n, what + ": give frequency_std or eigenvalue_std, not both");
  return resolve(dir, ctx.string(n["mat"], what + " mat"));
}

MatModalNames parse_measured_mat(const YAML::Node& section, const std::string& name, const YamlCtx& ctx, const std::string& dir) {
  MatModalNames names;
  const YAML::Node m = section["measured"];
  if (!m || !m.IsMap()) return names;
  auto var = [&](const char* k, std::string* out) {
    if (m[k]) *out = ctx.string(m[k], name + " measured " + k + " (a variable name)");
  };
  var("frequency_hz", &names.frequency_hz);
  var("eigenvalues", &names.eigenvalues);
  var("shapes", &names.shapes);
  if (m["dofs"] && m["dofs"].IsMap()) {  // the DOFs from another .mat file (e.g. the model's)
    const YAML::Node& d = m["dofs"];
    ctx.only_keys(d, name + " measured dofs", {"mat", "var"});
    if (!d["mat"] || !d["var"]) ctx.fail(d, name + " measured dofs: give {mat: FILE, var: VARIABLE} or a variable name");
    names.dofs_file = resolve(dir, ctx.string(d["mat"], name + " measured dofs mat"));
    names.dofs = ctx.string(d["var"], name + " measured dofs var (a variable name)");
  } else {
    var("dofs", &names.dofs);
  }
  var("damping", &names.damping);
  var("frequency_std", &names.frequency_std);
  var("eigenvalue_std", &names.eigenvalue_std);
  var("shape_std", &names.shape_std);
  return names;
}

GeometrySpec parse_geometry(const YAML::Node& section, const std::string& name, const YamlCtx& ctx, const std::string& dir) {
  GeometrySpec g;
  const YAML::Node n = section["geometry"];
  if (!n) return g;
  if (!section["measured"]) ctx.fail(n, name + ": geometry ties the measured file to the model; it needs measured:");
  if (n.IsScalar()) {
    g.file = resolve(dir, ctx.string(n, "geometry"));
    return g;
  }
  ctx.require_map(n, "geometry");
  ctx.only_keys(n, "geometry", {"file", "match", "tolerance"});
  if (!n["file"]) ctx.fail(n, "geometry: 'file' is missing (a UFF file with the test points, dataset 15 or 2411)");
  g.file = resolve(dir, ctx.string(n["file"], "geometry file"));
  if (n["match"]) {
    const std::string m = ctx.string(n["match"], "geometry match");
    if (m != "position" && m != "id") ctx.fail(n["match"], "geometry: match must be position or id, got '" + m + "'");
    g.by_position = m == "position";
  }
  if (n["tolerance"]) {
    g.tolerance = ctx.number(n["tolerance"], "geometry tolerance");
    if (!(g.tolerance > 0)) ctx.fail(n["tolerance"], "geometry: tolerance must be > 0 (model length units)");
  }
  return g;
}

std::string resolve(const std::string& dir, const std::string& file) {
  const fs::path p(file);
  return p.is_absolute() ? file : (fs::path(dir) / p).lexically_normal().string();
}

// model: {include: other.yaml} takes the model section of another case file (path relative to this one).
YAML::Node model_node(const YAML::Node& root, YamlCtx* ctx, std::string* dir, int depth) {
  YAML::Node m = root["model"];
  if (!m.IsMap() || !m["include"]) return m;
  if (m.size() != 1) ctx->fail(m, "model: include cannot be combined with other model keys");
  if (depth > 8) ctx->fail(m, "model: include nested too deep (a cycle?)");
  const std::string file = resolve(*dir, ctx->string(m["include"], "model include"));
  std::error_code ec;
  const std::string path = resolve_case_path(file);
  std::ifstream in(path, std::ios::binary);
  if (!in) ctx->fail(m["include"], "model include: cannot open '" + file + "'");
  std::ostringstream ss;
  ss << in.rdbuf();
  YAML::Node inc;
  try {
    inc = YAML::Load(ss.str());
  } catch (const YAML::ParserException& e) {
    throw InputError(path + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                     ": malformed case file: " + e.msg);
  }
  if (!inc.IsMap() || !inc["model"]) ctx->fail(m["include"], "model include: '" + path + "' has no model: section");
  ctx->file = path;
  *dir = fs::path(path).parent_path().string();
  return model_node(inc, ctx, dir, depth + 1);
}

}  // namespace internal

using internal::parse_dof_selection;
using internal::resolve;

EigenOptions AnalysisSpec::eigen_options() const {
  EigenOptions o;
  o.num_modes = modes;
  if (!std::isnan(band_lo_hz)) {
    o.band_lo = hz_to_eigenvalue(band_lo_hz);
    o.band_hi = hz_to_eigenvalue(band_hi_hz);
  }
  if (!std::isnan(shift_hz)) o.shift = hz_to_eigenvalue(shift_hz);
  o.method = method;
  return o;
}

namespace {

AnalysisSpec parse_analysis(const YAML::Node& n, const YamlCtx& ctx) {
  AnalysisSpec a;
  if (!n) return a;
  ctx.require_map(n, "analysis");
  ctx.only_keys(n, "analysis", {"modes", "band_hz", "shift_hz", "method"});
  if (n["modes"]) {
    a.modes = ctx.integer(n["modes"], "analysis modes");
    if (a.modes < 1) ctx.fail(n["modes"], "analysis: modes must be >= 1");
  }
  if (n["band_hz"]) {
    const auto b = ctx.numbers(n["band_hz"], "analysis band_hz");
    if (b.size() != 2 || !(b[0] >= 0 && b[1] > b[0]))
      ctx.fail(n["band_hz"], "analysis: band_hz must be [low, high] with 0 <= low < high");
    a.band_lo_hz = b[0];
    a.band_hi_hz = b[1];
  }
  if (n["shift_hz"]) a.shift_hz = ctx.number(n["shift_hz"], "analysis shift_hz");
  if (n["method"]) {
    const std::string m = ctx.string(n["method"], "analysis method");
    if (m == "auto") a.method = EigenOptions::Method::kAuto;
    else if (m == "sparse") a.method = EigenOptions::Method::kSparse;
    else if (m == "dense") a.method = EigenOptions::Method::kDense;
    else ctx.fail(n["method"], "analysis: method must be auto, sparse or dense");
  }
  return a;
}

void parse_noise(const YAML::Node& n, const YamlCtx& ctx, DetectOptions* o) {
  ctx.require_map(n, "noise");
  ctx.only_keys(n, "noise", {"frequency", "shape"});
  if (n["frequency"]) o->frequency_noise = ctx.number(n["frequency"], "noise frequency");
  if (n["shape"]) o->shape_noise = ctx.number(n["shape"], "noise shape");
  if (!(o->frequency_noise > 0) || !(o->shape_noise > 0)) ctx.fail(n, "noise: frequency and shape must be > 0 (relative std)");
}

DetectSpec parse_detect(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& dir) {
  ctx.require_map(n, "detect");
  ctx.only_keys(n, "detect", {"modes", "changed", "measured", "reference_measured", "geometry", "measured_dofs", "noise",
                              "significance", "max_changed", "refine", "serep_modes", "min_mac", "candidates", "study"});
  DetectSpec d;
  DetectOptions& o = d.options;
  if (n["modes"]) {
    o.modes = ctx.integer(n["modes"], "detect modes");
    if (o.modes < 1) ctx.fail(n["modes"], "detect: modes must be >= 1");
  }
  if (n["changed"] && n["measured"]) ctx.fail(n, "detect: give either changed: (a simulation) or measured: (a file), not both");
  if (!n["changed"] && !n["measured"]) ctx.fail(n, "detect: the changed state is missing: give changed: {elements: [...]} or measured: FILE");
  if (n["changed"]) {
    const YAML::Node& c = n["changed"];
    ctx.require_map(c, "changed");
    ctx.only_keys(c, "changed", {"elements"});
    ctx.require_sequence(c["elements"], "changed elements");
    for (const auto& e : c["elements"]) {
      ctx.require_map(e, "changed element");
      ctx.only_keys(e, "changed element", {"id", "dk", "dm"});
      const int id = ctx.integer(e["id"], "changed element id");
      if (model.element_index(id) < 0) ctx.fail(e["id"], "changed element " + std::to_string(id) + " does not exist");
      const double dk = e["dk"] ? ctx.number(e["dk"], "dk") : 0.0, dm = e["dm"] ? ctx.number(e["dm"], "dm") : 0.0;
      if (!(dk > -1 && dm > -1)) ctx.fail(e, "changed element: dk and dm must be > -1 (fractions: -0.15 = 15 % loss)");
      d.changes.push_back({id, {dk, dm}});
    }
    d.measured_dofs = n["measured_dofs"] ? parse_dof_selection(n["measured_dofs"], ctx, model, "measured_dofs") : all_dofs(model);
  } else {
    d.measured_file = parse_measured(n["measured"], ctx, dir, "detect measured");
    d.measured_mat = parse_measured_mat(n, "detect", ctx, dir);
    if (n["measured_dofs"]) ctx.fail(n["measured_dofs"], "detect: measured_dofs is for simulations; measured data carry their own DOFs");
  }
  if (n["reference_measured"]) d.reference_measured_file = resolve(dir, ctx.string(n["reference_measured"], "reference_measured"));
  d.geometry = parse_geometry(n, "detect", ctx, dir);
  if (n["noise"]) parse_noise(n["noise"], ctx, &o);
  if (n["significance"]) o.significance = ctx.number(n["significance"], "significance");
  if (!(o.significance > 0 && o.significance < 1)) ctx.fail(n["significance"], "detect: significance must be in (0, 1)");
  if (n["max_changed"]) o.max_changed = ctx.integer(n["max_changed"], "max_changed");
  if (o.max_changed < 1) ctx.fail(n["max_changed"], "detect: max_changed must be >= 1");
  if (n["refine"]) o.refine = ctx.boolean(n["refine"], "refine");
  if (n["serep_modes"]) o.serep_modes = ctx.integer(n["serep_modes"], "serep_modes");
  if (n["min_mac"]) o.min_mac = ctx.number(n["min_mac"], "min_mac");
  if (n["candidates"]) {
    ctx.require_sequence(n["candidates"], "candidates");
    for (const auto& q : n["candidates"]) {
      const int id = ctx.integer(q, "candidate");
      if (model.element_index(id) < 0) ctx.fail(q, "candidate element " + std::to_string(id) + " does not exist");
      o.candidates.push_back(id);
    }
  }
  if (n["study"]) {
    const YAML::Node& st = n["study"];
    ctx.require_map(st, "study");
    ctx.only_keys(st, "study", {"trials", "modes", "frequency_noise", "shape_noise", "seed", "measured_dofs"});
    d.has_study = true;
    NoiseStudyOptions& so = d.study;
    if (d.changes.size() != 1) ctx.fail(st, "study: a noise study needs exactly one changed element in changed:");
    if (st["trials"]) so.trials = ctx.integer(st["trials"], "study trials");
    if (so.trials < 1) ctx.fail(st["trials"], "study: trials must be >= 1");
    if (st["modes"]) so.modes = ctx.integer(st["modes"], "study modes");
    if (st["frequency_noise"]) so.frequency_noise = ctx.number(st["frequency_noise"], "study frequency_noise");
    if (st["shape_noise"]) so.shape_noise = ctx.numbers(st["shape_noise"], "study shape_noise");
    if (st["seed"]) so.seed = static_cast<std::uint64_t>(ctx.integer(st["seed"], "study seed"));
    so.dofs = st["measured_dofs"] ? parse_dof_selection(st["measured_dofs"], ctx, model, "study measured_dofs") : d.measured_dofs;
  }
  return d;
}

}  // namespace

void require_section(const Case& c, bool present, const std::string& section) {
  if (!present) throw InputError(c.path + ": the case has no " + section + ": section (see docs/case-file.md)");
}

std::string resolve_case_path(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    for (const char* f : {"case.yaml", "case.yml", "case.json"}) {
      const fs::path p = fs::path(path) / f;
      if (fs::exists(p, ec)) return p.string();
    }
    throw InputError(path + ": folder has no case.yaml, case.yml or case.json");
  }
  if (!fs::exists(path, ec)) throw InputError(path + ": no such case file or folder");
  return path;
}

namespace {
// The sections after model: (analysis, detect, update, test, discover), parsed against c->model.
void parse_sections(const YAML::Node& root, const YamlCtx& ctx, Case* c) {
  c->analysis = parse_analysis(root["analysis"], ctx);
  if (root["detect"]) c->detect = parse_detect(root["detect"], ctx, c->model, c->dir);
  if (root["update"]) c->update = internal::parse_update(root["update"], ctx, c->model, c->dir);
  if (root["test"]) c->test = internal::parse_test(root["test"], ctx, c->model, c->dir);
  if (root["discover"]) c->discover = internal::parse_discover(root["discover"], ctx, c->model, c->dir, c->limits);
}
}  // namespace

Case parse_case(const std::string& text, const std::string& name, const std::string& dir, const ReaderLimits& limits) {
  YamlCtx ctx{name};
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(name + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                     ": malformed case file: " + e.msg);
  }
  if (!root || root.IsNull()) throw InputError(name + ": the case file is empty");
  ctx.require_map(root, "case file");
  ctx.only_keys(root, "the case file", {"name", "description", "model", "analysis", "detect", "update", "test", "discover"});
  Case c;
  c.path = name;
  c.dir = dir;
  c.limits = limits;
  c.name = root["name"] ? ctx.string(root["name"], "name") : fs::path(dir).filename().string();
  if (root["description"]) c.description = ctx.string(root["description"], "description");
  if (!root["model"]) ctx.fail(root, "the case has no model: section");
  {
    YamlCtx mctx = ctx;
    std::string mdir = dir;
    const YAML::Node m = internal::model_node(root, &mctx, &mdir, 0);
    c.model = internal::parse_model(m, mctx, mdir, &c.notes, limits);
  }
  parse_sections(root, ctx, &c);
  return c;
}

Case case_with_model(Model model, const std::string& text, const std::string& name, const std::string& dir,
                     const ReaderLimits& limits) {
  if (!model.finalized()) throw InputError(name + ": the model is not finalized (call finalize() first)");
  YamlCtx ctx{name};
  YAML::Node root;
  try {
    root = YAML::Load(text.empty() ? std::string("{}") : text);
  } catch (const YAML::ParserException& e) {
    throw InputError(name + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) + ": malformed: " + e.msg);
  }
  if (!root || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  ctx.require_map(root, "case sections");
  ctx.only_keys(root, "the case sections", {"name", "description", "analysis", "detect", "update", "test", "discover"});
  Case c;
  c.path = name;
  c.dir = dir;
  c.limits = limits;
  c.name = root["name"] ? ctx.string(root["name"], "name") : name;
  if (root["description"]) c.description = ctx.string(root["description"], "description");
  c.model = std::move(model);
  parse_sections(root, ctx, &c);
  return c;
}

namespace {
// Exact modes of `m` at `dofs`: `count` modes after its rigid-body modes.
ModalData simulate(const Model& m, const std::vector<MeasuredDof>& dofs, int count, const std::string& source) {
  EigenOptions eo;
  const int nrb = m.free_free() ? static_cast<int>(m.free_rigid_body_modes().cols()) : 0;
  eo.num_modes = nrb + count;
  const ModalResult r = modal_analysis(m, eo);
  if (!r.ok()) throw NumericalError("modal analysis of " + source + " failed: " + r.summary.message);
  return sample_modes(m, r, dofs, nrb, count, source);
}
}  // namespace

ModalData detect_changed_data(const Case& c, Model* changed) {
  require_section(c, c.detect.has_value(), "detect");
  const DetectSpec& d = *c.detect;
  if (!d.measured_file.empty())
    return read_measured_modal_data(d.measured_file, d.geometry, c.model, nullptr, d.measured_mat, c.limits);
  Model local;
  Model& m = changed ? *changed : local;  // the caller may not want the changed model
  m = changed_model(c.model, d.changes);
  return simulate(m, d.measured_dofs, d.options.modes > 0 ? d.options.modes : 6, "simulation of " + c.name);
}

ModalData update_measured_data(const Case& c) {
  require_section(c, c.update.has_value(), "update");
  const UpdateSpec& u = *c.update;
  ModalData m = !u.measured_file.empty()
                    ? read_measured_modal_data(u.measured_file, u.geometry, c.model, nullptr, u.measured_mat, c.limits)
                    : simulate(apply_factors(c.model, u.target_changes), u.measured_dofs, u.target_modes,
                               "simulated target of " + c.name);
  return first_modes(std::move(m), u.modes);
}

ModalData first_modes(ModalData m, int count) {
  if (count <= 0 || count >= m.num_modes()) return m;
  m.frequencies_hz.conservativeResize(count);
  m.shapes.conservativeResize(Eigen::NoChange, count);
  if (m.shape_entry_std.cols() > count) m.shape_entry_std.conservativeResize(Eigen::NoChange, count);
  // Every per-mode vector given (identified data carry damping, MPC and standard deviations) is cut alike.
  for (Eigen::VectorXd* v : {&m.damping_ratios, &m.mpc, &m.frequency_std_hz, &m.damping_std, &m.shape_std})
    if (v->size() > count) v->conservativeResize(count);
  return m;
}

Case load_case(const std::string& path, const ReaderLimits& limits) {
  const std::string file = resolve_case_path(path);
  return parse_case(internal::read_file_bytes(file), file, fs::path(file).parent_path().string(), limits);
}

}  // namespace dynid
