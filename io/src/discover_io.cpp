#include "dynid/io/discover_io.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "dynid/io/modal_data_io.hpp"

namespace dynid {

namespace {

bool contains_all(const std::vector<int>& have, const std::vector<int>& want) {
  for (int w : want)
    if (std::find(have.begin(), have.end(), w) == have.end()) return false;
  return true;
}

// Whether a finding matches one expected effect; its parameter error in *err.
bool matches(const DiscoverSpec::Expect& e, const ScoredHypothesis& h, bool* kind, bool* loc, bool* par, double* err) {
  *kind = h.kind == e.kind;
  *loc = contains_all(h.site.nodes, e.nodes) && contains_all(h.site.elements, e.elements);
  *par = true;
  *err = 0;
  if (!e.parameter.empty()) {
    *par = false;
    for (const PhysicalValue& v : h.values)
      if (v.name == e.parameter) {
        *err = std::abs(v.value - e.value) / std::max(std::abs(e.value), 1e-300);
        *par = *err <= e.tolerance;
      }
  }
  return *kind && *loc && *par;
}

std::string location_words(const Site& s) {
  std::string w;
  if (!s.nodes.empty()) {
    w += "node";
    w += s.nodes.size() > 1 ? "s " : " ";
    for (std::size_t k = 0; k < s.nodes.size() && k < 6; ++k) w += (k ? "," : "") + std::to_string(s.nodes[k]);
    if (s.nodes.size() > 6) w += ",...";
  }
  if (!s.elements.empty()) {
    w += std::string(w.empty() ? "" : " ") + "element";
    w += s.elements.size() > 1 ? "s " : " ";
    for (std::size_t k = 0; k < s.elements.size() && k < 6; ++k) w += (k ? "," : "") + std::to_string(s.elements[k]);
    if (s.elements.size() > 6) w += ",...";
  }
  return w;
}

std::string short_kind(const std::string& k) {
  static const std::pair<const char*, const char*> names[] = {
      {"semi_rigid_joint", "joint"},       {"flexible_support", "support"},  {"lumped_mass", "mass"},
      {"element_stiffness", "EI"},         {"element_mass", "m"},            {"grounded_spring", "spring"},
      {"rotational_spring", "rot.spring"}, {"shear_deformation", "shear"},   {"axial_preload", "preload"},
      {"distributed_mass", "dist.mass"},   {"sensor_mass", "sensors"},       {"suspension_stiffness", "suspension"}};
  for (const auto& [a, b] : names)
    if (k == a) return b;
  return k;
}

nlohmann::ordered_json location_json(const ScoredHypothesis& h) {
  nlohmann::ordered_json j;
  j["nodes"] = h.global ? std::vector<int>{} : h.site.nodes;
  j["elements"] = h.site.elements;
  j["global"] = h.global;
  return j;
}

nlohmann::ordered_json values_json(const std::vector<PhysicalValue>& v, bool std_only) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const PhysicalValue& p : v) {
    if (std_only) j[p.name] = std::isfinite(p.std) ? nlohmann::ordered_json(p.std) : nlohmann::ordered_json(nullptr);
    else j[p.name] = p.value;
  }
  return j;
}

nlohmann::ordered_json quality_json(const FitQuality& q) {
  nlohmann::ordered_json j;
  j["max_freq_error_pct"] = q.max_freq_error_pct;
  j["unpaired_modes"] = q.unpaired;
  j["mean_mac"] = q.mean_mac;
  j["chi2"] = q.chi2;
  j["measured_hz"] = std::vector<double>(q.measured_hz.data(), q.measured_hz.data() + q.measured_hz.size());
  j["model_hz"] = std::vector<double>(q.model_hz.data(), q.model_hz.data() + q.model_hz.size());
  j["mac"] = std::vector<double>(q.mac.data(), q.mac.data() + q.mac.size());
  return j;
}

}  // namespace

std::string site_label(const Site& s, const std::string& sep) {
  std::string w;
  for (int n : s.nodes) w += (w.empty() ? "n" : sep + "n") + std::to_string(n);
  for (int e : s.elements) w += (w.empty() ? "e" : sep + "e") + std::to_string(e);
  return w;
}

ExpectCheck check_expectation(const DiscoverSpec::Expect& e, const DiscoverySummary& s) {
  ExpectCheck c;
  c.verdict = s.verdict == e.verdict;
  if (e.verdict != "missing_physics") {
    c.kind = c.location = true;
    c.words = c.verdict ? "verdict '" + s.verdict + "' as expected" : "verdict '" + s.verdict + "', expected '" + e.verdict + "'";
    return c;
  }
  if (s.findings.empty()) {
    c.words = "no finding (verdict '" + s.verdict + "'), expected " + e.kind;
    return c;
  }
  // With several expected effects, the first finding must be one of them (any) and each of the others must be
  // among the findings.
  std::vector<const DiscoverSpec::Expect*> all = {&e};
  for (const DiscoverSpec::Expect& a : e.also) all.push_back(&a);
  std::size_t first = 0;
  for (std::size_t q = 0; q < all.size(); ++q) {
    bool kk, ll, pp;
    double err;
    if (all[q]->kind == s.findings[0].kind && matches(*all[q], s.findings[0], &kk, &ll, &pp, &err)) first = q;
  }
  matches(*all[first], s.findings[0], &c.kind, &c.location, &c.parameter, &c.parameter_error);
  for (std::size_t q = 0; q < all.size(); ++q) {
    if (q == first) continue;
    bool any = false;
    for (std::size_t k = 1; k < s.findings.size(); ++k) {
      bool kk, ll, pp;
      double err;
      if (matches(*all[q], s.findings[k], &kk, &ll, &pp, &err)) {
        any = true;
        c.parameter_error = std::max(c.parameter_error, err);
      }
    }
    c.also = c.also && any;
  }
  c.words = std::string(c.ok() ? "as expected" : "NOT as expected") + ": first finding " + s.findings[0].kind + " at " +
            location_words(s.findings[0].site) + (c.kind ? "" : " (expected " + e.kind + ")") +
            (c.location ? "" : " (wrong location)") + (s.findings.size() > 1 ? " (+" + std::to_string(s.findings.size() - 1) + " more)" : "") +
            (e.parameter.empty() ? "" : ", " + e.parameter + " error " + std::to_string(100 * c.parameter_error).substr(0, 5) + " %") +
            (c.also ? "" : "; a further expected effect was not found");
  return c;
}

nlohmann::ordered_json discovery_json(const Case& c, const DiscoveryData& d, const DiscoverySummary& s, const ExpectCheck* check) {
  nlohmann::ordered_json j;
  j["case"] = c.name;
  j["verdict"] = s.verdict;
  j["explanation"] = s.explanation;
  j["findings"] = nlohmann::ordered_json::array();
  for (const ScoredHypothesis& h : s.findings) {
    nlohmann::ordered_json f;
    f["kind"] = h.kind;
    f["location"] = location_json(h);
    f["parameters"] = values_json(h.values, false);
    f["std"] = values_json(h.values, true);
    nlohmann::ordered_json units = nlohmann::ordered_json::object();
    for (const PhysicalValue& v : h.values) units[v.name] = v.unit;
    f["units"] = units;
    f["description"] = h.finding;
    f["at_bound"] = h.at_bound;
    j["findings"].push_back(f);
  }
  j["candidates"] = nlohmann::ordered_json::array();
  for (const ScoredHypothesis& h : s.candidates) {
    nlohmann::ordered_json q;
    q["kind"] = h.kind;
    q["location"] = location_json(h);
    q["description"] = h.description;
    q["score"] = h.fitted ? nlohmann::ordered_json(h.delta_bic) : nlohmann::ordered_json(nullptr);
    q["bic"] = h.fitted ? nlohmann::ordered_json(h.bic) : nlohmann::ordered_json(nullptr);
    q["screening"] = h.screening;
    q["parameters"] = values_json(h.values, false);
    q["max_freq_error_pct"] = h.max_freq_error_pct;
    q["mean_mac"] = h.mean_mac;
    q["at_bound"] = h.at_bound;
    j["candidates"].push_back(q);
  }
  {
    const ScoredHypothesis& r = s.recalibration;
    j["recalibration"] = {{"score", r.fitted ? nlohmann::ordered_json(r.delta_bic) : nlohmann::ordered_json(nullptr)},
                          {"parameters", values_json(r.values, false)},
                          {"max_freq_error_pct", r.max_freq_error_pct},
                          {"mean_mac", r.mean_mac}};
  }
  j["fit"] = {{"before", quality_json(s.before)}, {"after", quality_json(s.after)}};
  const Localization& L = s.localization;
  nlohmann::ordered_json loc;
  loc["words"] = L.words;
  loc["localized"] = L.localized;
  loc["concentration"] = L.concentration;
  loc["nature"] = L.nature;
  loc["mass_alignment"] = L.mass_alignment;
  loc["mean_frequency_error_pct"] = L.mean_frequency_error_pct;
  loc["direction_share"] = {L.direction_share[0], L.direction_share[1], L.direction_share[2]};
  loc["nodes"] = nlohmann::ordered_json::array();
  for (const auto& n : L.nodes) loc["nodes"].push_back({{"node", n.node}, {"share", n.share}, {"x", n.x}, {"y", n.y}, {"z", n.z}});
  j["localization"] = loc;
  j["data"] = {{"source", d.source},
               {"identified", d.identified},
               {"modes", s.before.measured_hz.size()},
               {"dofs", d.measured.dofs.size()},
               {"residuals", s.data},
               {"chi2_per_datum_before", s.chi2_per_datum_before},
               {"notes", d.notes}};
  j["measured"] = modal_data_json(d.measured);
  j["cost"] = {{"seconds", s.seconds}, {"eigen_solves", s.eigen_solves}};
  if (check) j["check"] = {{"ok", check->ok()}, {"words", check->words}, {"parameter_error", check->parameter_error}};
  j["warnings"] = s.warnings;
  return j;
}

plot::Figure discovery_figure(const Case& c, const DiscoverySummary& s) {
  const Model& m = c.model;
  plot::Figure f;
  f.title = "dynid discover: " + c.name + " - " + s.verdict;
  f.rows = 2;
  f.cols = 2;
  f.width = 1600;
  f.height = 1250;
  // (1) residual-force map on the structure: members as lines, measured nodes sized by their share.
  plot::Panel map;
  map.title = "Where: residual-force share per measured node";
  map.xlabel = "x";
  map.ylabel = "y";
  // A beam along x is drawn with its nodes' share as the height; frames in their plane.
  bool flat = true;
  for (const Node& n : m.nodes()) flat = flat && std::abs(n.x.y()) < 1e-12;
  for (int e = 0; e < m.num_elements(); ++e) {
    if (m.elements()[e].num_nodes != 2) continue;
    plot::Series ln;
    ln.color = 9;
    ln.width = 2.0;
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d& x = m.nodes()[m.element_nodes(e)[k]].x;
      ln.x.push_back(x.x());
      ln.y.push_back(flat ? 0.0 : x.y());
    }
    map.series.push_back(ln);
  }
  const char* bins[] = {"< 5 % of the residual", "5-20 %", "> 20 %"};
  plot::Series levels[3];
  for (int b = 0; b < 3; ++b) {
    levels[b].label = bins[b];
    levels[b].kind = flat ? plot::Kind::kStems : plot::Kind::kMarkers;
    levels[b].color = b == 0 ? 0 : b == 1 ? 1 : 3;
    levels[b].symbol_scale = 1.0 + 1.2 * b;
  }
  for (const auto& ns : s.localization.nodes) {
    const int n = m.node_index(ns.node);
    if (n < 0) continue;
    const int b = ns.share < 0.05 ? 0 : ns.share < 0.2 ? 1 : 2;
    levels[b].x.push_back(m.nodes()[n].x.x());
    levels[b].y.push_back(flat ? ns.share : m.nodes()[n].x.y());
  }
  for (auto& l : levels)
    if (!l.x.empty()) map.series.push_back(l);
  if (flat) map.ylabel = "share of the residual force";
  // Sites of the findings.
  plot::Series site;
  site.label = "finding";
  site.kind = plot::Kind::kMarkers;
  site.symbol = 4;
  site.symbol_scale = 3.0;
  site.color = 2;
  for (const ScoredHypothesis& h : s.findings) {
    if (h.global) continue;
    std::set<int> nodes(h.site.nodes.begin(), h.site.nodes.end());
    for (int id : h.site.elements) {
      const int e = m.element_index(id);
      if (e < 0) continue;
      if (h.site.nodes.empty())
        for (int k = 0; k < 2; ++k) nodes.insert(m.nodes()[m.element_nodes(e)[k]].id);
    }
    for (int id : nodes) {
      const int n = m.node_index(id);
      site.x.push_back(m.nodes()[n].x.x());
      double y = m.nodes()[n].x.y();
      if (flat) {
        y = 0;
        for (const auto& ns : s.localization.nodes)
          if (ns.node == id) y = ns.share;
      }
      site.y.push_back(y);
    }
  }
  if (!site.x.empty()) map.series.push_back(site);

  // (2) candidates ranked by evidence (BIC improvement over the model as given).
  plot::Panel rank;
  rank.title = "Why: candidates by evidence (BIC gain)";
  rank.ylabel = "BIC improvement";
  plot::Series good, rest, recal;
  good.kind = rest.kind = recal.kind = plot::Kind::kBars;
  good.color = 3;
  rest.color = 0;
  recal.color = 6;
  good.label = "finding";
  recal.label = "recalibrate E, rho";
  const int show = std::min<int>(10, static_cast<int>(s.candidates.size()));
  double lo = 0;
  for (int k = 0; k < show; ++k) {
    const ScoredHypothesis& h = s.candidates[k];
    const bool found = !s.findings.empty() && h.description == s.findings[0].description;
    plot::Series& t = found ? good : rest;
    t.x.push_back(k + 1);
    t.y.push_back(h.fitted ? h.delta_bic : 0.0);
    lo = std::min(lo, h.fitted ? h.delta_bic : 0.0);
    const std::string lab = short_kind(h.kind) + " " +
                            (h.global ? "[" + std::to_string(h.site.elements.size()) + " el]" : site_label(h.site, " "));
    rank.xticks.push_back({static_cast<double>(k + 1), lab});
  }
  recal.x.push_back(show + 1);
  recal.y.push_back(s.recalibration.fitted ? s.recalibration.delta_bic : 0.0);
  rank.xticks.push_back({static_cast<double>(show + 1), "E, rho"});
  rank.series = {rest, good, recal};
  rank.hlines = {{10.0, "decisive"}};
  rank.ymin = std::min(lo, 0.0);

  // (3) frequency errors and (4) MAC, before and after.
  plot::Panel fe, mac;
  fe.title = "Fit: frequency error per mode";
  fe.ylabel = "model - measured [%]";
  fe.xlabel = "measured mode";
  mac.title = "Fit: MAC per mode";
  mac.ylabel = "MAC";
  mac.xlabel = "measured mode";
  plot::Series fb, fa, mb, ma;
  fb.kind = fa.kind = plot::Kind::kBars;
  fb.bar_width = fa.bar_width = 0.38;
  fb.dx = -0.2;
  fa.dx = 0.2;
  fb.label = mb.label = "model as given";
  fa.label = ma.label = s.findings.empty() ? "model as given" : "with the findings";
  fb.color = mb.color = 0;
  fa.color = ma.color = 3;
  mb.kind = ma.kind = plot::Kind::kLineMarkers;
  plot::Series lost;
  lost.label = "x  no model counterpart (MAC < 0.5)";
  lost.kind = plot::Kind::kMarkers;
  lost.symbol = 5;
  lost.symbol_scale = 2.0;
  lost.color = 0;
  for (Eigen::Index k = 0; k < s.before.measured_hz.size(); ++k) {
    const double x = static_cast<double>(k + 1);
    if (s.before.mac[k] >= 0.5) {
      fb.x.push_back(x);
      fb.y.push_back(100 * (s.before.model_hz[k] - s.before.measured_hz[k]) / s.before.measured_hz[k]);
    } else {
      lost.x.push_back(x - 0.2);
      lost.y.push_back(0.0);
    }
    mb.x.push_back(x);
    mb.y.push_back(s.before.mac[k]);
    if (k < s.after.model_hz.size()) {
      fa.x.push_back(x);
      fa.y.push_back(100 * (s.after.model_hz[k] - s.after.measured_hz[k]) / s.after.measured_hz[k]);
      ma.x.push_back(x);
      ma.y.push_back(s.after.mac[k]);
    }
  }
  fe.series = {fb, fa};
  if (!lost.x.empty()) fe.series.push_back(lost);
  fe.hlines = {{0.0, ""}};
  mac.series = {mb, ma};
  double mmin = 1;
  for (double v : mb.y) mmin = std::min(mmin, v);
  mac.ymin = std::max(0.0, std::min(0.9, mmin - 0.02));
  mac.ymax = 1.005;
  f.panels = {map, rank, fe, mac};
  return f;
}

}  // namespace dynid
