// Discovery, stages 2-3: where the residual forces are, and a linearised screening of every candidate.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "discovery/stages.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/engine/residual_force.hpp"
#include "dynid/engine/serep.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid::internal {

Localization locate(const Problem& p) {
  const Model& model = *p.model;
  const ModalData& meas = p.data;
  Localization L;
  L.dofs = meas.dofs;
  const std::vector<int> rows = measured_equations(model, meas.dofs);
  const int a = static_cast<int>(rows.size());
  EigenOptions eo;
  const int n = model.num_dofs();
  eo.num_modes = std::min(n, a + 6 + 10);
  if (n <= 400) eo.method = EigenOptions::Method::kDense;
  const ModalResult mr = modal_analysis(model, eo);
  if (!mr.ok()) throw NumericalError("discover: modal analysis of the model failed: " + mr.summary.message);
  // Few modes in the SEREP basis: the measured ones and a margin. With as many modes as masters the reduced
  // stiffness carries the highest modes, which amplify every bit of shape noise into residual force.
  const int m = std::min<int>({a, static_cast<int>(mr.eigenvalues.size()), meas.num_modes() + 4});
  const SerepReduction sr = serep_reduce(mr.modes.leftCols(m), mr.eigenvalues.head(m), rows);
  const int pm = meas.num_modes();
  Eigen::MatrixXd U = meas.shapes;
  Eigen::VectorXd lam(pm);
  for (int k = 0; k < pm; ++k) {
    const double mm = U.col(k).dot(sr.M * U.col(k));
    if (mm > 0) U.col(k) /= std::sqrt(mm);  // mass-normalised on the reduced model
    lam[k] = hz_to_eigenvalue(meas.frequencies_hz[k]);
  }
  L.residuals = residual_forces(sr.K, sr.M, lam, U);  // eq. (6)
  L.pseudo = pseudo_residual_force(L.residuals);       // eqs. (7)-(8)
  double align = 0;
  for (int k = 0; k < pm; ++k) {
    const Eigen::VectorXd f = lam[k] * (sr.M * U.col(k));  // inertia forces of the measured mode
    const double rn = L.residuals.col(k).norm(), fn = f.norm();
    if (rn > 0 && fn > 0) align += std::abs(L.residuals.col(k).dot(f)) / (rn * fn);
  }
  L.mass_alignment = pm ? align / pm : 0.0;
  const double tot = L.pseudo.squaredNorm();
  std::map<int, Localization::NodeShare> by;
  for (int d = 0; d < a; ++d) {
    const double s = tot > 0 ? L.pseudo[d] * L.pseudo[d] / tot : 0.0;
    auto& ns = by[meas.dofs[d].node];
    ns.node = meas.dofs[d].node;
    ns.share += s;
    const int t = static_cast<int>(meas.dofs[d].dof);
    if (t == 0) ns.x += s;
    if (t == 1) ns.y += s;
    if (t == 2) ns.z += s;
    if (t < 3) L.direction_share[t] += s;
  }
  for (auto& [id, ns] : by) L.nodes.push_back(ns);
  std::stable_sort(L.nodes.begin(), L.nodes.end(), [](const auto& x, const auto& y) { return x.share > y.share; });
  const int top = std::max(1, static_cast<int>(std::ceil(0.2 * static_cast<double>(L.nodes.size()))));
  for (int k = 0; k < top && k < static_cast<int>(L.nodes.size()); ++k) L.concentration += L.nodes[k].share;
  L.localized = L.nodes.size() >= 3 && L.concentration > 0.5;
  return L;
}

Screening screen(const Problem& p) {
  ParametricModel pm(*p.model);
  std::vector<const Candidate*> all;
  for (const auto& c : p.library) all.push_back(c.get());
  const std::vector<int> first = install_candidates(&pm, all);
  Linearization lin = linearize(pm, p.data, pm.nominal(), p.fit);
  Screening s;
  s.model_hz = lin.model_hz;
  s.mac = lin.mac;
  s.paired.resize(lin.forced.size());
  for (std::size_t k = 0; k < lin.forced.size(); ++k) s.paired[k] = !lin.forced[k];
  s.chi2 = lin.r.squaredNorm();
  for (int b : lin.block_start) s.chi2_frequency += lin.r[b] * lin.r[b];
  s.drop.assign(all.size(), 0.0);
  s.column.assign(first.begin(), first.end());
  for (std::size_t k = 0; k < all.size(); ++k) {
    // The magnitude (first) parameter's column: the linearised chi-square drop g^2 / h of a step along it,
    // zero when the step would leave the bounds at once.
    const int col = first[k];
    const Parameter& q = pm.parameter(col);
    const Eigen::VectorXd j = lin.J.col(col);
    const double h = j.squaredNorm();
    if (!(h > 0)) continue;
    const double g = j.dot(lin.r), step = -g / h;
    if ((q.nominal <= q.lower && step < 0) || (q.nominal >= q.upper && step > 0)) continue;
    s.drop[k] = g * g / h;
  }
  s.J = std::move(lin.J);
  return s;
}

std::vector<int> shortlist(const Problem& p, const Screening& s, const Localization& L) {
  const int nc = static_cast<int>(p.library.size());
  std::vector<int> local, out;
  for (int k = 0; k < nc; ++k) (p.library[k]->global() ? out : local).push_back(k);
  std::stable_sort(local.begin(), local.end(), [&](int x, int y) { return s.drop[x] > s.drop[y]; });
  std::vector<char> chosen(static_cast<std::size_t>(nc), 0);
  auto take = [&](int k) {
    if (!chosen[k]) chosen[k] = 1, out.push_back(k);
  };
  // The best screened overall, and the best few of every kind: the linearisation at the nominal model ranks
  // kinds unevenly (a release's effect is far from linear), so each kind keeps its own best sites.
  for (int k = 0; k < static_cast<int>(local.size()) && k < p.options.screen_fit; ++k) take(local[k]);
  std::map<std::string, int> per;
  for (int k : local)
    if (per[p.library[k]->kind()]++ < 3) take(k);
  // Candidates at a few nodes the data point at, whatever the screening says (it linearises at the model as
  // given, which misleads when a mode changes a lot): the three carrying most residual force, and where each
  // mode the model lacks moves most (a local mode of what is missing shows where it is).
  std::vector<int> nodes;
  for (std::size_t t = 0; t < L.nodes.size() && t < 3; ++t) nodes.push_back(L.nodes[t].node);
  for (int m = 0; m < p.unpartnered.num_modes(); ++m) {
    std::vector<std::pair<double, int>> amp;
    for (std::size_t r = 0; r < p.unpartnered.dofs.size(); ++r)
      amp.push_back({std::abs(p.unpartnered.shapes(static_cast<Eigen::Index>(r), m)), p.unpartnered.dofs[r].node});
    std::stable_sort(amp.begin(), amp.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t t = 0, got = 0; t < amp.size() && got < 2; ++t)
      if (std::find(nodes.begin(), nodes.end(), amp[t].second) == nodes.end()) nodes.push_back(amp[t].second), ++got;
  }
  for (int node : nodes)
    for (int k : local)
      if (p.library[k]->site().nodes.size() == 1 && p.library[k]->site().elements.empty() && p.library[k]->site().nodes[0] == node)
        take(k);
  return out;
}

}  // namespace dynid::internal
