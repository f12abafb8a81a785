#include "dynid/io/discover_io.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "dynid/io/figures.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "internal/json_util.hpp"
#include "internal/text_util.hpp"

namespace dynid {

using internal::vec;

namespace {

bool shares(const std::vector<int>& have, const std::vector<int>& want) {
  for (int w : want)
    if (std::find(have.begin(), have.end(), w) != have.end()) return true;
  return false;
}

std::string kinds_words(const std::vector<std::string>& k) {
  std::string w;
  for (std::size_t i = 0; i < k.size(); ++i) w += (i ? " or " : "") + k[i];
  return w;
}

// The reference of a stiffness change for the element set a finding names, when the expected elements carry
// e.value each and the others none: the flexibility average over the named set S, 1 / (1 + d_S) - 1 =
// sum L_e (1 / (1 + d_e) - 1) / sum L_e (the rule of bench/discovery/score.py and the discovery benchmark's
// README). Damage in element 38 named as damage along elements 38 to 39 is one softening seen over twice the
// length; e.value itself when the set is the expected one.
double stiffness_reference(const DiscoverSpec::Expect& e, const Site& site, const Model& model) {
  if (site.elements.empty() || e.elements.empty() || site.elements == e.elements) return e.value;
  double flex = 0, total = 0;
  for (int id : site.elements) {
    const int k = model.element_index(id);
    if (k < 0) return e.value;
    const std::array<int, 2>& n = model.element_nodes(k);
    if (n[0] < 0 || n[1] < 0) return e.value;
    const double L = (model.nodes()[n[1]].x - model.nodes()[n[0]].x).norm();
    const bool hit = std::find(e.elements.begin(), e.elements.end(), id) != e.elements.end();
    flex += L * (1 / (1 + (hit ? e.value : 0.0) / 100) - 1);
    total += L;
  }
  return total > 0 ? 100 * (1 / (1 + flex / total) - 1) : e.value;
}

// Whether a finding matches one expected effect (its kind one of the expected, its site sharing a node or an
// element with the expected ones); its parameter error in *err.
bool matches(const DiscoverSpec::Expect& e, const ScoredHypothesis& h, const Model& model, bool* kind, bool* loc,
             bool* par, double* err) {
  *kind = std::find(e.kinds.begin(), e.kinds.end(), h.kind) != e.kinds.end();
  *loc = (e.nodes.empty() && e.elements.empty()) || shares(h.site.nodes, e.nodes) || shares(h.site.elements, e.elements);
  *par = true;
  *err = 0;
  if (!e.parameter.empty()) {
    *par = false;
    const double ref = e.parameter == "stiffness change" ? stiffness_reference(e, h.site, model) : e.value;
    for (const PhysicalValue& v : h.values)
      if (v.name == e.parameter) {
        *err = std::abs(v.value - ref) / std::max(std::abs(ref), 1e-300);
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
      {"distributed_mass", "dist.mass"},   {"sensor_mass", "sensors"},       {"suspension_stiffness", "suspension"},
      {"element_point_mass", "mass on el."}, {"member_damage", "EI run"},   {"self_weight", "weight"}};
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
  j["measured_hz"] = vec(q.measured_hz);
  j["model_hz"] = vec(q.model_hz);
  j["mac"] = vec(q.mac);
  return j;
}

}  // namespace

std::string site_label(const Site& s, const std::string& sep) {
  std::string w;
  for (int n : s.nodes) w += (w.empty() ? "n" : sep + "n") + std::to_string(n);
  for (int e : s.elements) w += (w.empty() ? "e" : sep + "e") + std::to_string(e);
  return w;
}

namespace {

using internal::format_number;

std::string pct(double share) { return std::to_string(static_cast<int>(std::lround(100.0 * share))); }

std::string noise_words(const DiscoverySummary& s) {
  auto src = [](NoiseModel::Source x) {
    return x == NoiseModel::Source::kStated ? "stated" : x == NoiseModel::Source::kData ? "from the data" : "assumed";
  };
  return "noise " + format_number(100 * s.noise.frequency, 3) + " % in frequency (" + src(s.noise.frequency_source) + "), " +
         format_number(100 * s.noise.shape, 3) + " % in shape (" + src(s.noise.shape_source) + ")";
}

std::string fit_words(const DiscoverySummary& s) {
  return "max frequency error " + format_number(s.before.max_freq_error_pct, 3) + " % -> " + format_number(s.after.max_freq_error_pct, 3) +
         " %, mean MAC " + format_number(s.before.mean_mac, 4) + " -> " + format_number(s.after.mean_mac, 4);
}

// "1.2e+03 N/m ± 13 %": a value with its unit and its relative standard deviation.
std::string value_words(const PhysicalValue& v) {
  std::string w = format_number(v.value, 3) + (v.unit.empty() ? "" : " " + v.unit);
  if (std::isfinite(v.std) && v.value != 0) w += " ± " + format_number(100.0 * std::abs(v.std / v.value), 2) + " %";
  return w;
}

std::string findings_words(const DiscoverySummary& s) {
  std::string w;
  for (std::size_t k = 0; k < s.findings.size(); ++k) {
    const ScoredHypothesis& h = s.findings[k];
    w += (k ? "; and " : "") + h.finding;
    if (h.equivalent.empty()) continue;
    w += " (the data cannot tell this site from: ";
    for (std::size_t q = 0; q < h.equivalent.size() && q < 4; ++q) {
      w += (q ? "; " : "") + h.equivalent[q];
      if (q < h.equivalent_values.size() && !h.equivalent_values[q].empty())
        w += ", " + value_words(h.equivalent_values[q][0]);
    }
    if (h.equivalent.size() > 4) w += "; and " + std::to_string(h.equivalent.size() - 4) + " more";
    w += ")";
  }
  return w;
}

std::string misfit_words(const DiscoverySummary& s) {
  return "chi-square per datum: frequencies " + format_number(s.chi2_frequency_before, 3) + ", shapes " +
         format_number(s.chi2_shape_before, 3) + " at the " + noise_words(s) + "; max frequency error " +
         format_number(s.before.max_freq_error_pct, 3) + " %, mean MAC " + format_number(s.before.mean_mac, 4);
}

// The rivals, each with its ln Bayes factor over the model as given.
std::string rivals_words(const DiscoverySummary& s) {
  std::string r;
  for (std::size_t k = 0; k < s.rivals.size(); ++k)
    r += (k ? "; " : "") + s.rivals[k].description + " (ln Bayes factor " + format_number(s.rivals[k].log_evidence, 3) +
         ")";
  return r.empty() ? "the other explanations scored" : r;
}

}  // namespace

std::string discovery_explanation(const DiscoverySummary& s) {
  switch (s.reason) {
    case VerdictReason::kWithinNoise:
      return "No missing physics: the model fits the data within the noise (" + misfit_words(s) + ").";
    case VerdictReason::kNothingDecisive: {
      if (!candidates_fitted(s))
        return "The model misfits the data (" + misfit_words(s) +
               "), but from one measured mode no physics can be "
               "named (any one-parameter candidate matches one frequency): more modes, from more or better-placed "
               "sensors or a wider band, would tell the candidates apart.";
      std::string best = "none fitted";
      for (const ScoredHypothesis& h : s.candidates)
        if (h.fitted) {
          best = h.description + ", ln Bayes factor " + format_number(h.log_evidence, 3);
          break;
        }
      return "The model misfits the data (" + misfit_words(s) + "), but no candidate explains it decisively and without "
             "worsening the fit of any mode (best: " + best + "). An effect outside the library, or several at once, is "
             "possible; more modes or more measured DOFs would constrain the candidates.";
    }
    case VerdictReason::kPartlyExplained:
      return "The model misses something the candidates describe only in part: the best explanation, " + findings_words(s) +
             ", removes " + pct(s.explained) + " % of the misfit beyond the noise (" + fit_words(s) +
             "). An effect outside the library, or several at once, is likely.";
    case VerdictReason::kRivals:
      return "The model misses something, but the data cannot tell which: the best explanation, " + findings_words(s) +
             " (ln Bayes factor " + format_number(s.combined.log_evidence, 3) + "; " + fit_words(s) +
             "), has a probability of only " + pct(s.probability) + " % against " + rivals_words(s) +
             ". More modes, or sensors at the competing sites (rotations or strains there), would decide.";
    case VerdictReason::kSiteUncertain:
      return "Missing physics of this kind, but the data cannot tell exactly where: " + findings_words(s) + ". " +
             fit_words(s) + "; the findings remove " + pct(s.explained) +
             " % of the misfit beyond the noise (ln Bayes factor " + format_number(s.combined.log_evidence, 3) +
             " over the model as given). The kind is clear, the place is not: " +
             "effects of this kind have a probability of " + pct(s.kind_probability) + " % in all, at these sites " +
             pct(s.probability) + " %; the competing explanations: " + rivals_words(s) +
             ". Sensors at the competing sites (rotations or strains there) would decide.";
    case VerdictReason::kExplained: {
      std::string w = "Missing physics: " + findings_words(s) + ". " + fit_words(s) + "; the findings remove " + pct(s.explained) +
                      " % of the misfit beyond the noise, decisively (ln Bayes factor " + format_number(s.combined.log_evidence, 3) +
                      " over the model as given";
      if (s.recalibration.fitted) w += ", " + format_number(s.recalibration.log_evidence, 3) + " for recalibrating E and rho globally";
      w += ").";
      if (!s.rivals.empty())
        w += " Not certain: a probability of " + pct(s.probability) + " % against " + rivals_words(s) +
             ", which fit almost as well; more modes, or sensors at the competing sites, would decide.";
      return w;
    }
  }
  return "";
}

std::string localization_words(const DiscoverySummary& s) {
  const Localization& L = s.localization;
  std::string w;
  if (s.reason == VerdictReason::kWithinNoise) w = "The model fits within the noise, so what follows describes noise, not a mismatch. ";
  if (L.nodes.size() < 3) {
    w += "Only " + std::to_string(L.nodes.size()) + " measured node" + (L.nodes.size() == 1 ? "" : "s") +
         ": the residual forces cannot say where. ";
  } else {
    std::string where;
    for (std::size_t k = 0; k < L.nodes.size() && k < 3; ++k)
      where += (k ? ", " : "") + std::to_string(L.nodes[k].node) + " (" + pct(L.nodes[k].share) + " %)";
    const Eigen::Vector3d& ds = L.direction_share;
    const char* dir = ds[0] >= ds[1] && ds[0] >= ds[2] ? "x" : ds[1] >= ds[2] ? "y" : "z";
    w += std::string("The residual forces are ") + (L.localized ? "localized" : "spread over the structure") + ": largest at nodes " +
         where + "; " + pct(L.concentration) + " % in the top fifth of the measured nodes, mostly in " + dir + ". ";
  }
  w += std::string("The model is ") + (L.mean_frequency_error_pct > 0 ? "stiffer" : "softer") +
       " than the data on average (mean frequency error " + format_number(L.mean_frequency_error_pct, 3) +
       " %); the local candidates that explain most of it change " +
       (L.nature == Nature::kMass ? "mass" : "stiffness") + "; the residual forces align with the inertia forces by " +
       format_number(L.mass_alignment, 2) +
       " (1 for a change in proportion everywhere, such as a uniform E or density; lower for a local change the sensors"
       " resolve).";
  return w;
}

bool candidates_fitted(const DiscoverySummary& s) { return !s.candidates.empty() || s.recalibration.fitted; }

std::vector<std::string> set_aside_words(const DiscoverySummary& s) {
  std::vector<std::string> out;
  for (const SetAside& a : s.set_aside) {
    std::string w = "measured mode " + std::to_string(a.mode + 1) + " (" + format_number(a.frequency_hz, 4) + " Hz) ";
    if (a.reason == SetAside::Reason::kRigidBody) {
      w += "is a rigid-body motion on the test's suspension (MAC " + format_number(a.mac, 3) +
           " with the model's rigid-body motions, below its first elastic mode): set aside from the selection; "
           "suspension_stiffness describes it";
      if (a.paired_after)
        w += ", and the findings' values are fitted with it: predicted at " + format_number(a.model_hz_after, 4) +
             " Hz (MAC " + format_number(a.mac_after, 3) + ")";
    } else {
      w += "has no plausible partner in the model as given (best MAC " + format_number(a.mac, 3) + "): set aside, never forced onto another mode";
      if (a.paired_after)
        w += "; with the findings the model predicts it at " + format_number(a.model_hz_after, 4) + " Hz (MAC " + format_number(a.mac_after, 3) + ")";
    }
    out.push_back(w);
  }
  return out;
}

ExpectCheck check_expectation(const DiscoverSpec::Expect& e, const DiscoverySummary& s, const Model& model) {
  ExpectCheck c;
  const std::string verdict = to_string(s.verdict);
  c.verdict = verdict == e.verdict;
  if (e.verdict != "missing_physics") {
    c.kind = c.location = true;
    c.words = c.verdict ? "verdict '" + verdict + "' as expected" : "verdict '" + verdict + "', expected '" + e.verdict + "'";
    return c;
  }
  if (s.findings.empty()) {
    c.words = "no finding (verdict '" + verdict + "'), expected " + kinds_words(e.kinds);
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
    if (matches(*all[q], s.findings[0], model, &kk, &ll, &pp, &err)) first = q;
  }
  matches(*all[first], s.findings[0], model, &c.kind, &c.location, &c.parameter, &c.parameter_error);
  for (std::size_t q = 0; q < all.size(); ++q) {
    if (q == first) continue;
    bool any = false;
    for (std::size_t k = 1; k < s.findings.size(); ++k) {
      bool kk, ll, pp;
      double err;
      if (matches(*all[q], s.findings[k], model, &kk, &ll, &pp, &err)) {
        any = true;
        c.parameter_error = std::max(c.parameter_error, err);
      }
    }
    c.also = c.also && any;
  }
  c.words = std::string(c.ok() ? "as expected" : "NOT as expected") + ": first finding " + s.findings[0].kind + " at " +
            location_words(s.findings[0].site) + (c.kind ? "" : " (expected " + kinds_words(all[first]->kinds) + ")") +
            (c.location ? "" : " (wrong location)") + (s.findings.size() > 1 ? " (+" + std::to_string(s.findings.size() - 1) + " more)" : "") +
            (e.parameter.empty() ? "" : ", " + e.parameter + " error " + std::to_string(100 * c.parameter_error).substr(0, 5) + " %") +
            (c.also ? "" : "; a further expected effect was not found");
  return c;
}

nlohmann::ordered_json discovery_json(const Case& c, const DiscoveryData& d, const DiscoverySummary& s, const ExpectCheck* check) {
  auto or_null = [](bool ok, double v) { return ok && std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); };
  nlohmann::ordered_json j;
  j["case"] = c.name;
  j["verdict"] = to_string(s.verdict);
  j["reason"] = to_string(s.reason);
  j["explanation"] = discovery_explanation(s);
  j["findings"] = nlohmann::ordered_json::array();
  for (const ScoredHypothesis& h : s.findings) {
    nlohmann::ordered_json f;
    f["kind"] = h.kind;
    f["nature"] = to_string(h.nature);
    f["location"] = location_json(h);
    f["parameters"] = values_json(h.values, false);
    f["std"] = values_json(h.values, true);
    nlohmann::ordered_json units = nlohmann::ordered_json::object();
    for (const PhysicalValue& v : h.values) units[v.name] = v.unit;
    f["units"] = units;
    f["description"] = h.finding;
    f["equivalent"] = h.equivalent;
    nlohmann::ordered_json ev = nlohmann::ordered_json::array();
    for (const std::vector<PhysicalValue>& v : h.equivalent_values)
      ev.push_back({{"parameters", values_json(v, false)}, {"std", values_json(v, true)}});
    f["equivalent_values"] = ev;
    f["importance"] = or_null(true, h.log_evidence);
    f["significance"] = h.significance;
    f["at_bound"] = h.at_bound;
    j["findings"].push_back(f);
  }
  j["combined"] = {{"kinds", s.combined.kind},
                   {"log_evidence", or_null(!s.findings.empty(), s.combined.log_evidence)},
                   {"explained", s.explained},
                   {"parameters", s.combined.parameters}};
  j["steps"] = nlohmann::ordered_json::array();
  for (const SelectionStep& st : s.steps) {
    const char* a = st.action == SelectionStep::Action::kStart ? "start" : st.action == SelectionStep::Action::kAdd ? "add" : "remove";
    j["steps"].push_back({{"action", a}, {"effect", st.description}, {"log_evidence", or_null(true, st.log_evidence)},
                          {"explained", st.explained}, {"max_freq_error_pct", st.max_freq_error_pct}, {"mean_mac", st.mean_mac}});
  }
  j["probability"] = s.probability;
  j["kind_probability"] = s.kind_probability;
  j["rivals"] = nlohmann::ordered_json::array();
  for (const ScoredHypothesis& h : s.rivals)
    j["rivals"].push_back({{"kinds", h.kind}, {"description", h.description}, {"log_evidence", or_null(true, h.log_evidence)},
                           {"max_freq_error_pct", h.max_freq_error_pct}, {"mean_mac", h.mean_mac}});
  j["candidates"] = nlohmann::ordered_json::array();
  for (const ScoredHypothesis& h : s.candidates) {
    nlohmann::ordered_json q;
    q["kind"] = h.kind;
    q["location"] = location_json(h);
    q["description"] = h.description;
    q["score"] = or_null(h.fitted, h.log_evidence);
    q["explained"] = h.explained;
    q["significance"] = h.significance;
    q["screening"] = h.screening;
    q["parameters"] = values_json(h.values, false);
    q["max_freq_error_pct"] = h.max_freq_error_pct;
    q["mean_mac"] = h.mean_mac;
    q["at_bound"] = h.at_bound;
    j["candidates"].push_back(q);
  }
  {
    const ScoredHypothesis& r = s.recalibration;
    j["recalibration"] = {{"score", or_null(r.fitted, r.log_evidence)},
                          {"parameters", values_json(r.values, false)},
                          {"max_freq_error_pct", r.max_freq_error_pct},
                          {"mean_mac", r.mean_mac}};
  }
  j["fit"] = {{"before", quality_json(s.before)}, {"after", quality_json(s.after)}};
  const Localization& L = s.localization;
  nlohmann::ordered_json loc;
  loc["words"] = localization_words(s);
  loc["localized"] = L.localized;
  loc["concentration"] = L.concentration;
  loc["nature"] = to_string(L.nature);
  loc["mass_alignment"] = L.mass_alignment;
  loc["mean_frequency_error_pct"] = L.mean_frequency_error_pct;
  loc["direction_share"] = {L.direction_share[0], L.direction_share[1], L.direction_share[2]};
  loc["nodes"] = nlohmann::ordered_json::array();
  for (const auto& n : L.nodes) loc["nodes"].push_back({{"node", n.node}, {"share", n.share}, {"x", n.x}, {"y", n.y}, {"z", n.z}});
  j["localization"] = loc;
  auto source = [](NoiseModel::Source x) { return x == NoiseModel::Source::kStated ? "stated" : x == NoiseModel::Source::kData ? "data" : "default"; };
  j["noise"] = {{"frequency", s.noise.frequency}, {"frequency_source", source(s.noise.frequency_source)},
                {"shape", s.noise.shape}, {"shape_source", source(s.noise.shape_source)}, {"scale_frequency", s.noise_scale_frequency}, {"scale_shape", s.noise_scale_shape}};
  // Per measured mode used: the frequency noise and its discretization part (relative; empty when not per mode).
  j["noise"]["frequency_modes"] = vec(s.noise.frequency_modes);
  j["noise"]["discretization"] = vec(s.noise.discretization);
  j["noise"]["neighbour_mixing"] = vec(s.noise.neighbour_mixing);
  j["noise"]["unresolved"] = vec(s.noise.unresolved);
  j["set_aside"] = nlohmann::ordered_json::array();
  for (const SetAside& a : s.set_aside)
    j["set_aside"].push_back({{"mode", a.mode + 1}, {"frequency_hz", a.frequency_hz},
                              {"reason", a.reason == SetAside::Reason::kRigidBody ? "rigid_body" : "no_partner"}, {"mac", a.mac},
                              {"paired_after", a.paired_after}, {"model_hz_after", a.model_hz_after}, {"mac_after", a.mac_after}});
  j["data"] = {{"source", d.source},
               {"identified", d.identified},
               {"modes", s.before.measured_hz.size()},
               {"dofs", d.measured.dofs.size()},
               {"residuals", s.data},
               {"chi2_frequency_before", s.chi2_frequency_before},
               {"chi2_shape_before", s.chi2_shape_before},
               {"notes", d.notes}};
  j["measured"] = modal_data_json(d.measured);
  j["cost"] = {{"seconds", s.seconds}, {"eigen_solves", s.eigen_solves}};
  if (check) j["check"] = {{"ok", check->ok()}, {"words", check->words}, {"parameter_error", check->parameter_error}};
  std::vector<std::string> warnings = s.warnings;
  for (const std::string& w : set_aside_words(s)) warnings.push_back(w);
  j["warnings"] = warnings;
  return j;
}

plot::Figure discovery_figure(const Case& c, const DiscoverySummary& s) {
  const Model& m = c.model;
  plot::Figure f;
  f.title = std::string("dynid discover: ") + c.name + " - " + to_string(s.verdict);
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

  // (2) candidates ranked by evidence (ln Bayes factor over the model as given).
  plot::Panel rank;
  rank.title = "Why: candidates by evidence (ln Bayes factor)";
  rank.ylabel = "ln Bayes factor over the model as given";
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
    bool found = false;
    for (const ScoredHypothesis& g : s.findings) found = found || h.description == g.description;
    plot::Series& t = found ? good : rest;
    const double y = h.fitted && std::isfinite(h.log_evidence) ? h.log_evidence : 0.0;
    t.x.push_back(k + 1);
    t.y.push_back(y);
    lo = std::min(lo, y);
    const std::string lab = short_kind(h.kind) + " " +
                            (h.global ? "[" + std::to_string(h.site.elements.size()) + " el]" : site_label(h.site, " "));
    rank.xticks.push_back({static_cast<double>(k + 1), lab});
  }
  recal.x.push_back(show + 1);
  recal.y.push_back(s.recalibration.fitted && std::isfinite(s.recalibration.log_evidence) ? s.recalibration.log_evidence : 0.0);
  rank.xticks.push_back({static_cast<double>(show + 1), "E, rho"});
  rank.series = {rest, good, recal};
  rank.hlines = {{c.discover ? c.discover->options.decisive : 5.0, "decisive"}};
  rank.ymin = std::min(lo, 0.0);

  // (3) frequency errors and (4) MAC, before and after.
  const std::string after = s.findings.empty() ? "model as given" : "with the findings";
  plot::ModeComparisonPanels fm = plot::mode_comparison_panels(
      {{"model as given", 0, s.before.model_hz, s.before.measured_hz, s.before.mac, s.before.paired},
       {after, 3, s.after.model_hz, s.after.measured_hz, s.after.mac, {}}},
      0.38);
  plot::Panel& fe = fm.frequency;
  plot::Panel& mac = fm.mac;
  fe.title = "Fit: frequency error per mode";
  fe.ylabel = "model - measured [%]";
  fe.xlabel = "measured mode";
  mac.title = "Fit: MAC per mode";
  mac.xlabel = "measured mode";
  fe.hlines = {{0.0, ""}};
  double mmin = 1;
  for (double v : mac.series[0].y) mmin = std::min(mmin, v);
  mac.ymin = std::max(0.0, std::min(0.9, mmin - 0.02));
  mac.ymax = 1.005;
  f.panels = {map, rank, fe, mac};
  return f;
}

}  // namespace dynid
