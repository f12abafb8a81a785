// The report's 3D mode-shape view data (dynid/io/model_view.hpp).
#include "dynid/io/model_view.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "internal/text_util.hpp"

namespace dynid {

namespace {
double round6(double v) {
  if (!std::isfinite(v) || v == 0) return 0.0;
  return std::strtod(internal::format_number(v, 6).c_str(), nullptr);
}
}  // namespace

nlohmann::json model_view_json(const Model& model, const ModalResult& modes, int max_modes, int curved_limit) {
  const DofMap& dm = model.dof_map();
  int members = 0;
  for (const Element& e : model.elements()) members += is_member(e.type);
  const int pieces = members <= curved_limit ? 6 : 1;
  // Points: every node, then the interior samples of each member (element, xi).
  std::vector<Eigen::Vector3d> points;
  for (const Node& n : model.nodes()) points.push_back(n.x);
  struct Sample {
    int element;
    double xi;
  };
  std::vector<Sample> samples;  // interior member points, in order after the nodes
  std::vector<int> segments;
  for (int e = 0; e < model.num_elements(); ++e) {
    const Element& el = model.elements()[e];
    if (el.num_nodes != 2) continue;
    const int a = model.element_nodes(e)[0], b = model.element_nodes(e)[1];
    if (!is_member(el.type) || pieces == 1) {
      segments.push_back(a);
      segments.push_back(b);
      continue;
    }
    int prev = a;
    for (int k = 1; k < pieces; ++k) {
      const double xi = static_cast<double>(k) / pieces;
      const int p = static_cast<int>(points.size());
      points.push_back((1 - xi) * model.nodes()[a].x + xi * model.nodes()[b].x);
      samples.push_back({e, xi});
      segments.push_back(prev);
      segments.push_back(p);
      prev = p;
    }
    segments.push_back(prev);
    segments.push_back(b);
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const Node& n : model.nodes()) lo = lo.cwiseMin(n.x), hi = hi.cwiseMax(n.x);
  nlohmann::json j;
  std::vector<double> xyz;
  for (const Eigen::Vector3d& p : points)
    for (int c = 0; c < 3; ++c) xyz.push_back(round6(p[c]));
  j["points"] = xyz;
  j["segments"] = segments;
  j["size"] = model.nodes().empty() ? 1.0 : std::max((hi - lo).maxCoeff(), 1e-12);
  nlohmann::json out = nlohmann::json::array();
  int elastic = 0;
  std::vector<int> eq;
  for (Eigen::Index m = 0; m < modes.modes.cols() && static_cast<int>(out.size()) < max_modes; ++m) {
    if (modes.rigid_body[static_cast<std::size_t>(m)]) continue;
    ++elastic;
    const Eigen::VectorXd phi = modes.modes.col(m);
    std::vector<Eigen::Vector3d> u(points.size(), Eigen::Vector3d::Zero());
    for (std::size_t n = 0; n < model.nodes().size(); ++n)
      for (int c = 0; c < 3; ++c) {
        const int q = dm.eq(static_cast<int>(n), static_cast<Dof>(c));
        if (q >= 0) u[n][c] = phi[q];
      }
    for (std::size_t s = 0; s < samples.size(); ++s) {
      model.element_dofs(samples[s].element, &eq);
      Eigen::VectorXd ue(static_cast<Eigen::Index>(eq.size()));
      for (std::size_t k = 0; k < eq.size(); ++k) ue[static_cast<Eigen::Index>(k)] = eq[k] >= 0 ? phi[eq[k]] : 0.0;
      u[model.nodes().size() + s] = model.member_point_interpolation(samples[s].element, samples[s].xi) * ue;
    }
    double top = 0;
    for (const Eigen::Vector3d& v : u) top = std::max(top, v.norm());
    std::vector<double> d;
    for (const Eigen::Vector3d& v : u)
      for (int c = 0; c < 3; ++c) d.push_back(round6(top > 0 ? v[c] / top : 0.0));
    char label[64];
    std::snprintf(label, sizeof label, "mode %d: %.5g Hz", elastic, modes.frequencies_hz[m]);
    out.push_back({{"index", m + 1}, {"elastic_index", elastic}, {"frequency_hz", modes.frequencies_hz[m]}, {"label", label}, {"u", d}});
  }
  j["modes"] = out;
  return j;
}

}  // namespace dynid
