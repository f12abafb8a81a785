#include "dynid/io/identify_io.hpp"

#include <fmt/core.h>

#include "dynid/io/modal_data_io.hpp"
#include "internal/json_util.hpp"

namespace dynid {

nlohmann::ordered_json identification_json(const IdentificationSummary& s) {
  nlohmann::ordered_json j;
  j["method"] = s.method;
  nlohmann::ordered_json dofs = nlohmann::ordered_json::array();
  for (const MeasuredDof& d : s.dofs) dofs.push_back(to_string(d));
  j["dofs"] = dofs;
  j["orders"] = {s.min_order, s.max_order};
  j["band_hz"] = {s.band_lo_hz, s.band_hi_hz};
  j["band_from_data"] = s.band_from_data;
  j["resolution_hz"] = s.resolution_hz;
  j["seconds"] = s.seconds;
  j["window_decay_removed"] = s.window_decay_removed;
  if (s.uncertainty_halves > 0)
    j["uncertainty"] = {{"halves", s.uncertainty_halves},
                        {"pooled_frequency_std", s.pooled_frequency_std},
                        {"pooled_shape_std", s.pooled_shape_std},
                        {"stationary_record_s", s.stationary_record_s}};
  nlohmann::ordered_json modes = modal_data_json(s.modal_data(s.method))["modes"];
  for (std::size_t k = 0; k < s.modes.size(); ++k) {
    const IdentifiedMode& m = s.modes[k];
    modes[k]["contribution"] = m.contribution;
    modes[k]["poles"] = m.poles;
    modes[k]["support"] = m.support;
    modes[k]["indicator_db"] = m.indicator_db;
    modes[k]["order_frequency_std_hz"] = m.order_frequency_std_hz;
    if (m.twin_of >= 0) modes[k]["same_shape_as"] = {{"mode", m.twin_of + 1}, {"mac", m.twin_mac}};
  }
  j["modes"] = modes;
  // The stabilization diagram (the report draws it zoomable): every pole as [order, frequency, damping, class,
  // mode] (class 0 new or unstable, 1 stable in frequency, 2 and in damping, 3 and in vector; mode = the selected
  // mode it supports, 0 none), and the spectrum behind it.
  nlohmann::ordered_json poles = nlohmann::ordered_json::array();
  for (const StabilizationPole& p : s.poles) {
    if (!p.physical) continue;
    const int cls = !p.stable_frequency ? 0 : !p.stable_damping ? 1 : !p.stable_vector ? 2 : 3;
    poles.push_back({p.order, p.frequency_hz, p.damping_ratio, cls, p.cluster + 1});
  }
  j["stabilization"] = {{"poles", poles},
                        {"frequency_hz", internal::vec(s.frequency_hz)},
                        {"background", internal::vec(s.background)},
                        {"background_label", s.background_label}};
  nlohmann::ordered_json rejected = nlohmann::ordered_json::array();
  for (const RejectedCluster& r : s.rejected) {
    nlohmann::ordered_json x = {{"frequency_hz", r.frequency_hz},
                                {"damping_ratio", r.damping_ratio},
                                {"poles", r.poles},
                                {"support", r.support},
                                {"reason", to_string(r.reason)},
                                {"value", r.value},
                                {"limit", r.limit}};
    if (r.reason == Rejection::kSplit) x["merged_into"] = r.merged_into + 1;
    rejected.push_back(x);
  }
  j["rejected"] = rejected;
  nlohmann::ordered_json notes = nlohmann::ordered_json::array();
  for (const std::string& n : s.notes) notes.push_back(n);
  j["notes"] = notes;
  return j;
}

plot::Figure stabilization_figure(const IdentificationSummary& s, const std::string& title) {
  plot::Figure f;
  f.title = title;
  f.width = 1400;
  f.height = 850;
  plot::Panel p;
  p.title = "Stabilization diagram (" + s.method + ", orders " + std::to_string(s.min_order) + "-" + std::to_string(s.max_order) + ")";
  p.xlabel = "frequency [Hz]";
  p.ylabel = "model order";
  p.ylabel_right = s.background_label;
  plot::Series bg;
  bg.label = "";
  for (Eigen::Index k = 0; k < s.frequency_hz.size(); ++k) {
    bg.x.push_back(s.frequency_hz[k]);
    bg.y.push_back(s.background[k]);
  }
  bg.width = 1.2;
  p.right.push_back(bg);
  // Pole classes, drawn from the least to the most stable.
  auto markers = [](const char* label, int color) {
    plot::Series m;
    m.label = label;
    m.kind = plot::Kind::kMarkers;
    m.color = color;
    return m;
  };
  plot::Series fresh = markers(".  new or unstable pole", 7), f_only = markers("x  stable in frequency", 1),
               fd = markers("+  stable in frequency, damping", 2),
               all = markers("o  stable in frequency, damping, vector", 0);
  fresh.symbol = 1, fresh.symbol_scale = 1.6;
  f_only.symbol = 5, f_only.symbol_scale = 0.7;
  fd.symbol = 2, fd.symbol_scale = 0.8;
  all.symbol = 4, all.symbol_scale = 0.75;
  double lo = 1e300, hi = 0;
  for (const StabilizationPole& q : s.poles) {
    if (!q.physical) continue;
    lo = std::min(lo, q.frequency_hz);
    hi = std::max(hi, q.frequency_hz);
    plot::Series& t = q.stable() ? all : (q.stable_frequency && q.stable_damping) ? fd : q.stable_frequency ? f_only : fresh;
    t.x.push_back(q.frequency_hz);
    t.y.push_back(q.order);
  }
  for (plot::Series* t : {&fresh, &f_only, &fd, &all})
    if (!t->x.empty()) p.series.push_back(*t);
  for (std::size_t k = 0; k < s.modes.size(); ++k) {
    plot::Series v;
    v.label = k == 0 ? "selected modes" : "";
    v.x = {s.modes[k].frequency_hz, s.modes[k].frequency_hz};
    v.y = {static_cast<double>(s.min_order), static_cast<double>(s.max_order)};
    v.color = 3;
    v.width = 1.4;
    p.series.push_back(v);
  }
  if (hi > lo) {
    const double pad = 0.02 * (hi - lo);
    p.xmin = std::max(0.0, lo - pad);
    p.xmax = hi + pad;
  }
  p.ymin = 0;
  p.ymax = s.max_order + 2;
  f.panels.push_back(p);
  return f;
}

}  // namespace dynid
