#include "dynid/io/model_plots.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace dynid::plot {

namespace {

// The corners of the box holding every node.
std::pair<Eigen::Vector3d, Eigen::Vector3d> bounds(const Model& model) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const Node& n : model.nodes()) lo = lo.cwiseMin(n.x), hi = hi.cwiseMax(n.x);
  return {lo, hi};
}

// Axis labels and limits that frame the structure with a margin.
void frame_panel(const Model& model, std::pair<int, int> ax, double margin, Panel* p) {
  static const char* names[] = {"x", "y", "z"};
  const auto [lo, hi] = bounds(model);
  const double x0 = lo[ax.first], x1 = hi[ax.first], y0 = lo[ax.second], y1 = hi[ax.second];
  const double size = std::max({x1 - x0, y1 - y0, 1e-12});
  p->xmin = x0 - margin * size, p->xmax = x1 + margin * size;
  p->ymin = y0 - margin * size, p->ymax = y1 + margin * size;
  p->xlabel = names[ax.first];
  p->ylabel = names[ax.second];
}

// The members of the structure as segments, node positions displaced by `u` (per node translations; empty =
// undeformed). Beams and frames are drawn curved: the transverse displacement along a member is the cubic
// Hermite interpolation of the end translations and of the end slopes theta x t (rotations `rot`), as in the
// element's shape functions; the axial displacement is linear. Other elements are straight.
Series members(const Model& model, std::pair<int, int> ax, const std::vector<Eigen::Vector3d>& u,
               const std::vector<Eigen::Vector3d>& rot, double scale) {
  Series s;
  s.kind = Kind::kSegments;
  auto add = [&](const Eigen::Vector3d& x) {
    s.x.push_back(x[ax.first]);
    s.y.push_back(x[ax.second]);
  };
  constexpr int kPieces = 8;
  for (int e = 0; e < model.num_elements(); ++e) {
    const Element& el = model.elements()[e];
    if (el.num_nodes != 2) continue;
    const int a = model.element_nodes(e)[0], b = model.element_nodes(e)[1];
    const Eigen::Vector3d xa = model.nodes()[a].x, xb = model.nodes()[b].x;
    const bool member = is_member(el.type);
    if (u.empty() || !member) {
      add(u.empty() ? xa : Eigen::Vector3d(xa + scale * u[a]));
      add(u.empty() ? xb : Eigen::Vector3d(xb + scale * u[b]));
      continue;
    }
    const double L = (xb - xa).norm();
    const Eigen::Vector3d t = (xb - xa) / L;
    auto transverse = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d { return v - v.dot(t) * t; };
    const Eigen::Vector3d ua = scale * u[a], ub = scale * u[b];
    const Eigen::Vector3d sa = scale * rot[a].cross(t), sb = scale * rot[b].cross(t);  // slopes du/dx
    Eigen::Vector3d prev;
    for (int k = 0; k <= kPieces; ++k) {
      const double r = static_cast<double>(k) / kPieces;
      const double h00 = 2 * r * r * r - 3 * r * r + 1, h10 = r * r * r - 2 * r * r + r, h01 = -2 * r * r * r + 3 * r * r,
                   h11 = r * r * r - r * r;
      const Eigen::Vector3d w = h00 * transverse(ua) + h10 * L * transverse(sa) + h01 * transverse(ub) + h11 * L * transverse(sb);
      const Eigen::Vector3d x = xa + r * (xb - xa) + ((1 - r) * ua.dot(t) + r * ub.dot(t)) * t + w;
      if (k > 0) add(prev), add(x);
      prev = x;
    }
  }
  return s;
}

double structure_size(const Model& model) {
  const auto [lo, hi] = bounds(model);
  return std::max((hi - lo).maxCoeff(), 1e-12);
}

std::string hz(double f) {
  char b[64];
  std::snprintf(b, sizeof b, "%.4g Hz", f);
  return b;
}

}  // namespace

std::pair<int, int> drawing_plane(const Model& model) {
  const auto [lo, hi] = bounds(model);
  const Eigen::Vector3d ext = hi - lo;
  int a = 0, b = 1;  // the two largest extents, in axis order; a beam along x is drawn in x-y
  if (ext[2] > ext[0] || ext[2] > ext[1]) (ext[0] >= ext[1] ? b : a) = 2;
  if (a > b) std::swap(a, b);
  return {a, b};
}

Figure mode_shape_figure(const Model& model, const ModalResult& modes, int max_modes, const std::string& title) {
  Figure f;
  f.title = title;
  const auto ax = drawing_plane(model);
  const double size = structure_size(model);
  const DofMap& dm = model.dof_map();
  std::vector<int> shown;
  for (Eigen::Index k = 0; k < modes.eigenvalues.size() && static_cast<int>(shown.size()) < max_modes; ++k)
    if (!modes.rigid_body[k]) shown.push_back(static_cast<int>(k));
  const int count = std::max<int>(1, static_cast<int>(shown.size()));
  f.cols = count <= 2 ? count : count <= 4 ? 2 : 3;
  f.rows = (count + f.cols - 1) / f.cols;
  f.width = 600 * f.cols;
  f.height = 480 * f.rows + 60;
  const Series undeformed = [&] {
    Series s = members(model, ax, {}, {}, 0);
    s.color = 7;
    s.width = 1.0;
    s.label = "undeformed";
    return s;
  }();
  int elastic = 0;
  for (Eigen::Index k = 0; k < modes.eigenvalues.size(); ++k) {
    if (modes.rigid_body[k]) continue;
    ++elastic;
    if (std::find(shown.begin(), shown.end(), static_cast<int>(k)) == shown.end()) continue;
    std::vector<Eigen::Vector3d> u(model.nodes().size(), Eigen::Vector3d::Zero()), rot = u;
    double umax = 0;
    for (int i = 0; i < dm.num_free(); ++i) {
      const int t = static_cast<int>(dm.type_of(i));
      (t < 3 ? u : rot)[dm.node_of(i)][t % 3] = modes.modes(i, k);
    }
    for (const Eigen::Vector3d& v : u) umax = std::max(umax, std::hypot(v[ax.first], v[ax.second]));
    Panel p;
    p.title = "Mode " + std::to_string(elastic) + ": " + hz(modes.frequencies_hz[k]);
    frame_panel(model, ax, 0.18, &p);
    Series s = members(model, ax, u, rot, umax > 0 ? 0.12 * size / umax : 0.0);
    s.color = 1;
    s.width = 2.2;
    s.label = "mode shape";
    p.series = {undeformed, s};
    p.legend = f.panels.empty();
    f.panels.push_back(p);
  }
  return f;
}

Panel element_map_panel(const Model& model, const std::vector<std::pair<int, double>>& values,
                        const std::vector<int>& highlight, const std::string& title) {
  Panel p;
  p.title = title;
  const auto ax = drawing_plane(model);
  frame_panel(model, ax, 0.08, &p);
  std::map<int, double> v(values.begin(), values.end());
  double vmax = 0;
  for (const auto& [id, x] : values)
    if (std::isfinite(x)) vmax = std::max(vmax, x);
  // Five classes of value (line width and colour), highlighted elements on top.
  Series base = members(model, ax, {}, {}, 0);
  base.x.clear(), base.y.clear();
  base.color = 7;
  base.width = 0.8;
  std::vector<Series> bands(5, base), hit(1, base);
  static const double widths[] = {1.2, 2.0, 3.0, 4.2, 5.6};
  for (int b = 0; b < 5; ++b) bands[b].color = 0, bands[b].width = widths[b];
  bands[4].label = "large share";
  hit[0].color = 3, hit[0].width = 6.0, hit[0].label = "flagged";
  Series none = base;
  none.label = "";
  for (int e = 0; e < model.num_elements(); ++e) {
    const Element& el = model.elements()[e];
    if (el.num_nodes != 2) continue;
    Series* s = &none;
    if (std::find(highlight.begin(), highlight.end(), el.id) != highlight.end()) {
      s = &hit[0];
    } else if (auto it = v.find(el.id); it != v.end() && vmax > 0 && std::isfinite(it->second) && it->second > 0) {
      s = &bands[std::min(4, static_cast<int>(5.0 * it->second / vmax))];
    }
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d& x = model.nodes()[model.element_nodes(e)[k]].x;
      s->x.push_back(x[ax.first]);
      s->y.push_back(x[ax.second]);
    }
  }
  p.series = {none};
  for (const Series& s : bands)
    if (!s.x.empty()) p.series.push_back(s);
  if (!hit[0].x.empty()) p.series.push_back(hit[0]);
  return p;
}

}  // namespace dynid::plot
