// The result figures of the steps (dynid/io/figures.hpp).
#include "dynid/io/figures.hpp"

#include <algorithm>
#include <cmath>

namespace dynid::plot {

namespace {
Series series(const std::string& label, Kind kind, int color) {
  Series s;
  s.label = label;
  s.kind = kind;
  s.color = color;
  return s;
}
}  // namespace

ModeComparisonPanels mode_comparison_panels(const std::vector<ModeComparison>& states, double bar_width) {
  ModeComparisonPanels out;
  out.mac.ylabel = "MAC";
  Series lost = series("x  no plausible model partner", Kind::kMarkers, 0);
  lost.symbol = 5;
  lost.symbol_scale = 2.0;
  for (std::size_t i = 0; i < states.size(); ++i) {
    const ModeComparison& st = states[i];
    Series bars = series(st.label, Kind::kBars, st.color), mac = series(st.label, Kind::kLineMarkers, st.color);
    bars.bar_width = bar_width;
    bars.dx = 0.4 * (static_cast<double>(i) - 0.5 * static_cast<double>(states.size() - 1));
    const Eigen::Index n = std::min(st.hz.size(), st.reference_hz.size());
    for (Eigen::Index k = 0; k < n; ++k) {
      const double x = static_cast<double>(k + 1);
      if (st.paired.empty() || st.paired[static_cast<std::size_t>(k)]) {
        bars.x.push_back(x);
        bars.y.push_back(100 * (st.hz[k] - st.reference_hz[k]) / st.reference_hz[k]);
      } else {
        lost.x.push_back(x + bars.dx);
        lost.y.push_back(0.0);
      }
      if (k < st.mac.size()) {
        mac.x.push_back(x);
        mac.y.push_back(st.mac[k]);
      }
    }
    out.frequency.series.push_back(bars);
    out.mac.series.push_back(mac);
  }
  if (!lost.x.empty()) out.frequency.series.push_back(lost);
  return out;
}

Figure detect_figure(const Case& c, const DetectSummary& S) {
  const Model& model = c.model;
  Figure f;
  f.title = "dynid detect: " + c.name;
  f.rows = 3;
  f.height = 1300;
  // Per DOF: the pseudo residual force (log), DOFs of flagged elements highlighted.
  std::vector<int> flagged_nodes;
  for (const ElementScore& e : S.elements)
    if (e.flagged) {
      const auto& en = model.element_nodes(model.element_index(e.element));
      for (int q = 0; q < model.elements()[model.element_index(e.element)].num_nodes; ++q)
        flagged_nodes.push_back(model.nodes()[en[q]].id);
    }
  Panel p1;
  p1.title = S.full_dofs ? "Pseudo residual force per DOF (eq. 7-8)" : "Pseudo residual per measured DOF (SEREP)";
  p1.ylabel = "|r| (geometric mean over modes)";
  p1.log_y = true;
  Series in = series("DOFs of flagged elements", Kind::kStems, 3), out = series("other DOFs", Kind::kStems, 0);
  for (std::size_t r = 0; r < S.dofs.size(); ++r) {
    const bool hit = std::find(flagged_nodes.begin(), flagged_nodes.end(), S.dofs[r].node) != flagged_nodes.end();
    Series& s = hit ? in : out;
    s.x.push_back(static_cast<double>(r + 1));
    s.y.push_back(S.delta_pseudo[r]);
    p1.xticks.push_back({static_cast<double>(r + 1), to_string(S.dofs[r])});
  }
  p1.series = {out, in};
  // Per element: the paper's mapping (log) and dynid's localization.
  Panel p2, p3;
  p2.title = "Pseudo residual force mapped to elements (paper)";
  p2.ylabel = "element score";
  p2.log_y = true;
  p3.title = S.full_dofs ? "dynid: share each element explains alone" : "dynid: probability the element alone changed";
  p3.ylabel = S.full_dofs ? "explained fraction" : "probability";
  p3.xlabel = "element id";
  Series a2, b2, a3, b3;
  a2.kind = b2.kind = a3.kind = b3.kind = Kind::kBars;
  a2.color = a3.color = 0;
  b2.color = b3.color = 3;
  b2.label = b3.label = "flagged";
  for (const ElementScore& e : S.elements) {
    (e.flagged ? b2 : a2).x.push_back(e.element);
    (e.flagged ? b2 : a2).y.push_back(std::isnan(e.pseudo) ? 0.0 : e.pseudo);
    (e.flagged ? b3 : a3).x.push_back(e.element);
    (e.flagged ? b3 : a3).y.push_back(e.probability);
  }
  p2.series = {a2, b2};
  p3.series = {a3, b3};
  // The same localization as a map on the structure.
  std::vector<std::pair<int, double>> values;
  std::vector<int> hits;
  for (const ElementScore& e : S.elements) {
    values.emplace_back(e.element, e.probability);
    if (e.flagged) hits.push_back(e.element);
  }
  Panel p4 = element_map_panel(
      model, values, hits,
      std::string("Localization on the structure (width: ") + (S.full_dofs ? "share" : "probability") + ")");
  // Frequencies and MAC of the paired modes: the model (reference state) against the changed structure.
  const Eigen::Index n = std::min(S.model_hz.size(), S.changed_hz.size());
  ModeComparisonPanels fm = mode_comparison_panels({{"", 0, S.changed_hz.head(n), S.model_hz.head(n), S.mac, {}}});
  Panel& p5 = fm.frequency;
  Panel& p6 = fm.mac;
  p5.title = "Frequency change per mode (changed vs model)";
  p5.ylabel = "change [%]";
  p5.xlabel = "mode";
  p6.title = "MAC per mode (changed vs model)";
  p6.xlabel = "mode";
  p5.legend = p6.legend = false;
  f.rows = 3;
  f.cols = 2;
  f.width = 1800;
  f.height = 1700;
  f.panels = {p1, p4, p2, p3, p5, p6};
  return f;
}

Figure update_figure(const Case& c, const ParametricModel& pm, const UpdateSpec& u, const FitSummary& f) {
  Figure fig;
  fig.title = "dynid update: " + c.name + " (objective " + std::string(fit_objective_name(u.options.objective)) + ")";
  fig.rows = 3;
  fig.height = 1300;
  ModeComparisonPanels fm =
      mode_comparison_panels({{"initial model", 1, f.initial_hz, f.measured_hz, f.initial_mac, {}},
                              {"updated model", 0, f.final_hz, f.measured_hz, f.final_mac, {}}},
                             0.35);
  Panel& p1 = fm.frequency;
  Panel& p2 = fm.mac;
  p1.title = "Frequency error against the measured modes";
  p1.ylabel = "frequency error [%]";
  p1.xlabel = "measured mode";
  p1.hlines = {{0.0, ""}};
  p2.title = "MAC of the paired modes";
  p2.xlabel = "measured mode";
  for (std::size_t k = 0; k < p2.series.size(); ++k) {  // the MAC as bars beside each other, like the frequencies
    p2.series[k].kind = Kind::kBars;
    p2.series[k].bar_width = p1.series[k].bar_width;
    p2.series[k].dx = p1.series[k].dx;
  }
  p2.ymin = 0;
  p2.ymax = 1.05;
  Panel p3;
  p3.title = "Parameters (updated value with one standard deviation)";
  p3.ylabel = "value (factor 1 = nominal)";
  Series v0 = series("initial", Kind::kMarkers, 1), v1 = series("updated", Kind::kMarkers, 0);
  for (int p = 0; p < pm.num_parameters(); ++p) {
    v0.x.push_back(p + 1);
    v1.x.push_back(p + 1);
    v0.y.push_back(u.initial[p]);
    v1.y.push_back(f.theta[p]);
    v1.yerr.push_back(f.stddev[p]);
    p3.xticks.push_back({static_cast<double>(p + 1), pm.parameter(p).name});
  }
  p3.series = {v0, v1};
  fig.panels = {p1, p2, p3};
  return fig;
}

}  // namespace dynid::plot
