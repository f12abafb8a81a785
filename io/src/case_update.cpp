// The `update:` section of a case file (model updating). See docs/case-file.md.
#include <cctype>
#include <cmath>
#include <limits>
#include <map>

#include "dynid/io/case_file.hpp"
#include "internal/case_util.hpp"

namespace dynid::internal {

namespace {

bool parse_factor_kind(const std::string& s, ParameterKind* k) {
  if (s == "E") *k = ParameterKind::kStiffness;
  else if (s == "rho") *k = ParameterKind::kMass;
  else if (s == "A") *k = ParameterKind::kArea;
  else if (s == "I") *k = ParameterKind::kInertia;
  else return false;
  return true;
}

std::vector<int> element_list(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& w) {
  std::vector<int> out;
  if (n.IsScalar() && n.Scalar() == "all") {
    for (int e = 0; e < model.num_elements(); ++e) {
      const ElementKind& k = element_kind(model.elements()[e].type);  // members and matrix elements
      if (k.has_stiffness() && k.has_mass()) out.push_back(e);
    }
    return out;
  }
  ctx.require_sequence(n, w);
  for (const auto& q : n) {
    const int id = ctx.integer(q, w + " element id");
    const int e = model.element_index(id);
    if (e < 0) ctx.fail(q, w + ": element " + std::to_string(id) + " does not exist");
    out.push_back(e);
  }
  return out;
}

}  // namespace

UpdateSpec parse_update(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& dir) {
  ctx.require_map(n, "update");
  ctx.only_keys(
      n, "update",
      {"measured", "geometry", "target", "modes", "objective", "parameters", "noise", "regularization", "loss",
       "loss_scale", "solver", "max_iterations", "min_mac", "extra_modes", "multistart", "reduced_basis"});
  UpdateSpec u;
  FitOptions& o = u.options;
  if (n["measured"] && n["target"]) ctx.fail(n, "update: give either measured: (a file) or target: (a simulation), not both");
  if (!n["measured"] && !n["target"]) ctx.fail(n, "update: the measured data are missing: give measured: FILE or target: {...}");
  if (n["measured"]) u.measured_file = parse_measured(n["measured"], ctx, dir, "update measured");
  u.measured_mat = parse_measured_mat(n, "update", ctx, dir);
  u.geometry = internal::parse_geometry(n, "update", ctx, dir);
  if (n["target"]) {
    const YAML::Node& t = n["target"];
    ctx.require_map(t, "target");
    ctx.only_keys(t, "target", {"elements", "measured_dofs", "modes"});
    if (t["elements"]) {
      ctx.require_sequence(t["elements"], "target elements");
      for (const auto& e : t["elements"]) {
        ctx.require_map(e, "target element");
        ctx.only_keys(e, "target element", {"id", "E", "rho", "A", "I"});
        const int id = ctx.integer(e["id"], "target element id");
        if (model.element_index(id) < 0) ctx.fail(e["id"], "target element " + std::to_string(id) + " does not exist");
        PropertyFactors f;
        auto get = [&](const char* k, double* v) {
          if (!e[k]) return;
          *v = ctx.number(e[k], std::string("target ") + k);
          if (!(*v > 0)) ctx.fail(e[k], std::string("target: factor ") + k + " must be > 0 (1.2 = +20 %)");
        };
        get("E", &f.E);
        get("rho", &f.rho);
        get("A", &f.A);
        get("I", &f.I);
        u.target_changes.push_back({id, f});
      }
    }
    u.measured_dofs = t["measured_dofs"] ? parse_dof_selection(t["measured_dofs"], ctx, model, "target measured_dofs")
                                         : all_dofs(model);
    if (t["modes"]) u.target_modes = ctx.integer(t["modes"], "target modes");
    if (u.target_modes < 1) ctx.fail(t["modes"], "target: modes must be >= 1");
  }
  if (n["modes"]) u.modes = ctx.integer(n["modes"], "update modes");
  if (n["objective"]) {
    const std::string s = ctx.string(n["objective"], "objective");
    if (s == "f1") o.objective = FitObjective::kFrequencyMac;
    else if (s == "f2") o.objective = FitObjective::kSerep;
    else if (s == "combined") o.objective = FitObjective::kCombined;
    else if (s == "frequency") o.objective = FitObjective::kFrequency;
    else ctx.fail(n["objective"], "update: objective must be f1, f2, combined or frequency");
  }
  if (n["noise"]) {
    const YAML::Node& q = n["noise"];
    ctx.require_map(q, "noise");
    ctx.only_keys(q, "noise", {"frequency", "shape"});
    if (q["frequency"]) o.frequency_noise = ctx.number(q["frequency"], "noise frequency");
    if (q["shape"]) o.shape_noise = ctx.number(q["shape"], "noise shape");
  }
  if (n["regularization"]) {  // a weight, or l-curve (chosen by the rule: docs/method.md)
    const YAML::Node& q = n["regularization"];
    if (q.IsScalar() && q.Scalar() == "l-curve")
      u.lcurve = true;
    else if (q.IsScalar() && !q.Scalar().empty() && std::isalpha(static_cast<unsigned char>(q.Scalar()[0])))
      ctx.fail(q, "update: regularization must be a weight (a number >= 0) or l-curve, got '" + q.Scalar() + "'");
    else
      o.regularization = ctx.number(q, "regularization");
  }
  if (n["loss"]) {
    const std::string s = ctx.string(n["loss"], "loss");
    if (s == "none") o.loss = FitOptions::Loss::kNone;
    else if (s == "huber") o.loss = FitOptions::Loss::kHuber;
    else if (s == "cauchy") o.loss = FitOptions::Loss::kCauchy;
    else ctx.fail(n["loss"], "update: loss must be none, huber or cauchy");
  }
  if (n["loss_scale"]) o.loss_scale = ctx.number(n["loss_scale"], "loss_scale");
  if (n["solver"]) {
    const std::string s = ctx.string(n["solver"], "solver");
    if (s == "lm") o.dogleg = false;
    else if (s == "dogleg") o.dogleg = true;
    else ctx.fail(n["solver"], "update: solver must be lm (Levenberg-Marquardt) or dogleg");
  }
  if (n["max_iterations"]) o.max_iterations = ctx.integer(n["max_iterations"], "max_iterations");
  if (n["min_mac"]) o.min_mac = ctx.number(n["min_mac"], "min_mac");
  if (n["extra_modes"]) o.extra_modes = ctx.integer(n["extra_modes"], "extra_modes");
  if (n["reduced_basis"]) {
    const std::string s = ctx.string(n["reduced_basis"], "reduced_basis");
    if (s == "off")
      o.reduced_basis = FitOptions::ReducedBasis::kOff;
    else if (s == "on")
      o.reduced_basis = FitOptions::ReducedBasis::kOn;
    else if (s == "auto")
      o.reduced_basis = FitOptions::ReducedBasis::kAuto;
    else
      ctx.fail(n["reduced_basis"], "update: reduced_basis must be off, on or auto (on from " +
                                       std::to_string(o.reduced_basis_min_dofs) + " DOFs)");
  }
  if (n["multistart"]) {  // true | false | {starts: N, continuation: bool, seed: N}
    const YAML::Node& q = n["multistart"];
    if (q.IsScalar()) {
      u.multistart = ctx.boolean(q, "multistart");
    } else {
      ctx.require_map(q, "multistart");
      ctx.only_keys(q, "multistart", {"starts", "continuation", "seed"});
      u.multistart = true;
      if (q["starts"]) u.search.starts = ctx.integer(q["starts"], "multistart starts");
      if (q["starts"] && u.search.starts < 2) ctx.fail(q["starts"], "multistart: starts must be >= 2 (leave it out for the rule)");
      if (q["continuation"]) u.search.continuation = ctx.boolean(q["continuation"], "multistart continuation");
      if (q["seed"]) {
        const int seed = ctx.integer(q["seed"], "multistart seed");
        if (seed < 0) ctx.fail(q["seed"], "multistart: seed must be >= 0");
        u.search.seed = static_cast<std::uint64_t>(seed);
      }
    }
  }
  std::string why;
  if (!o.IsValid(&why)) ctx.fail(n, "update: " + why);

  // Parameters.
  if (!n["parameters"]) ctx.fail(n, "update: parameters are missing");
  ctx.require_sequence(n["parameters"], "parameters");
  std::map<std::string, int> by_name;
  std::vector<std::pair<std::string, std::pair<YAML::Node, double>>> pending_ties;  // name -> (to node, ratio)
  std::vector<double> init;
  for (const auto& q : n["parameters"]) {
    ctx.require_map(q, "parameter");
    ctx.only_keys(q, "parameter", {"name", "factor", "each", "elements", "group", "region", "mass", "spring",
                                   "initial", "bounds", "fixed", "tie", "scale"});
    const std::string name = q["name"] ? ctx.string(q["name"], "parameter name") : "";
    if (name.empty()) ctx.fail(q, "parameter: name is missing");
    std::vector<Parameter> made;
    Parameter base;
    base.name = name;
    const bool additive = q["mass"] || q["spring"];
    if (additive) {
      const YAML::Node& a = q["mass"] ? q["mass"] : q["spring"];
      base.kind = q["mass"] ? ParameterKind::kPointMass : ParameterKind::kSpring;
      ctx.require_map(a, "parameter " + name);
      ctx.only_keys(a, "parameter " + name, {"node", "dofs"});
      const int id = ctx.integer(a["node"], name + " node");
      base.node = model.node_index(id);
      if (base.node < 0) ctx.fail(a["node"], "parameter " + name + ": node " + std::to_string(id) + " does not exist");
      ctx.require_sequence(a["dofs"], name + " dofs");
      for (const auto& d : a["dofs"]) {
        Dof t;
        if (!parse_dof(ctx.string(d, "dof"), &t)) ctx.fail(d, "parameter " + name + ": unknown DOF '" + d.Scalar() + "'");
        base.dofs |= dof_bit(t);
      }
      base.nominal = 0;
      base.lower = 0;
      made.push_back(base);
    } else {
      if (!q["factor"]) ctx.fail(q, "parameter " + name + ": give factor: E | rho | A | I, or mass: / spring:");
      if (!parse_factor_kind(ctx.string(q["factor"], "factor"), &base.kind))
        ctx.fail(q["factor"], "parameter " + name + ": factor must be E, rho, A or I");
      base.lower = 0.01;
      base.upper = 100;
      const int how = (q["each"] ? 1 : 0) + (q["elements"] ? 1 : 0) + (q["group"] ? 1 : 0) + (q["region"] ? 1 : 0);
      if (how != 1) ctx.fail(q, "parameter " + name + ": give exactly one of each:, elements:, group:, region:");
      if (q["each"]) {
        for (int e : element_list(q["each"], ctx, model, name)) {
          Parameter p = base;
          p.name = name + ":" + std::to_string(model.elements()[e].id);
          p.elements = {e};
          made.push_back(p);
        }
      } else {
        Parameter p = base;
        if (q["elements"]) p.elements = element_list(q["elements"], ctx, model, name);
        if (q["group"]) {
          const std::string g = ctx.string(q["group"], "group");
          for (int e = 0; e < model.num_elements(); ++e)
            if (model.elements()[e].group == g) p.elements.push_back(e);
          if (p.elements.empty()) ctx.fail(q["group"], "parameter " + name + ": no element in group '" + g + "'");
        }
        if (q["region"]) {
          const YAML::Node& r = q["region"];
          ctx.require_map(r, "region");
          ctx.only_keys(r, "region", {"min", "max"});
          const auto lo = ctx.numbers(r["min"], "region min"), hi = ctx.numbers(r["max"], "region max");
          if (lo.size() != 3 || hi.size() != 3) ctx.fail(r, "region: min and max must be [x, y, z]");
          for (int e = 0; e < model.num_elements(); ++e) {
            const auto& en = model.element_nodes(e);
            const int nn = model.elements()[e].num_nodes;
            Eigen::Vector3d c = Eigen::Vector3d::Zero();
            for (int k = 0; k < nn; ++k) c += model.nodes()[en[k]].x / nn;
            bool in = true;
            for (int k = 0; k < 3; ++k) in = in && c[k] >= lo[k] && c[k] <= hi[k];
            const ElementKind& k = element_kind(model.elements()[e].type);
            const bool fits = base.kind == ParameterKind::kStiffness ? k.has_stiffness()
                              : base.kind == ParameterKind::kMass    ? k.has_mass()
                                                                     : k.is_member();  // A, I: sections only
            if (in && fits) p.elements.push_back(e);
          }
          if (p.elements.empty()) ctx.fail(r, "parameter " + name + ": the region holds no element");
        }
        made.push_back(p);
      }
    }
    double initial = additive ? 0.0 : 1.0;
    if (q["initial"]) initial = ctx.number(q["initial"], "initial");
    if (q["bounds"]) {
      const auto b = ctx.numbers(q["bounds"], "bounds");
      if (b.size() != 2 || !(b[0] < b[1])) ctx.fail(q["bounds"], "parameter " + name + ": bounds must be [low, high] with low < high");
      for (Parameter& p : made) {
        p.lower = b[0];
        p.upper = b[1];
      }
    }
    if (q["scale"]) {
      const double sc = ctx.number(q["scale"], "scale");
      if (!(sc > 0)) ctx.fail(q["scale"], "parameter " + name + ": scale must be > 0");
      for (Parameter& p : made) p.scale = sc;
    }
    const bool fixed = q["fixed"] ? ctx.boolean(q["fixed"], "fixed") : false;
    for (Parameter& p : made) {
      if (!(initial >= p.lower && initial <= p.upper))
        ctx.fail(q["initial"] ? q["initial"] : q, "parameter " + p.name + ": initial value outside its bounds");
      if (!(p.nominal >= p.lower && p.nominal <= p.upper)) p.nominal = std::min(std::max(p.nominal, p.lower), p.upper);
      if (by_name.count(p.name)) ctx.fail(q, "parameter " + p.name + " is defined twice");
      u.parameters.push_back(p);
      by_name[p.name] = static_cast<int>(u.parameters.size()) - 1;
      init.push_back(initial);
      u.free.push_back(fixed ? 0 : 1);
      if (q["tie"]) {
        const YAML::Node& t = q["tie"];
        ctx.require_map(t, "tie");
        ctx.only_keys(t, "tie", {"to", "ratio"});
        pending_ties.push_back({p.name, {t["to"], t["ratio"] ? ctx.number(t["ratio"], "tie ratio") : 1.0}});
      }
    }
  }
  u.initial = Eigen::Map<Eigen::VectorXd>(init.data(), static_cast<Eigen::Index>(init.size()));
  for (const auto& [name, t] : pending_ties) {
    const std::string to = ctx.string(t.first, "tie to");
    auto it = by_name.find(to);
    if (it == by_name.end()) ctx.fail(t.first, "tie: parameter '" + to + "' does not exist (ties name a parameter, e.g. rho:4)");
    u.ties.push_back({by_name[name], {it->second, t.second}});
  }
  u.options.ties = u.ties;
  return u;
}

}  // namespace dynid::internal
