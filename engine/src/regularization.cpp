#include "dynid/engine/regularization.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "dynid/mesh/error.hpp"
#include "internal/free_parameters.hpp"

namespace dynid {

bool LCurveOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (points_per_decade < 1) return fail("points_per_decade must be >= 1");
  if (!(decades > 0 && decades <= 20)) return fail("decades must be in (0, 20]");
  if (std::lround(decades * points_per_decade) < 2) return fail("the path needs at least 3 weights");
  return true;
}

int l_curve_corner(const std::vector<double>& misfit, const std::vector<double>& size, std::vector<double>* curvature) {
  if (misfit.size() != size.size()) throw InputError("l_curve_corner: as many misfits as sizes are needed");
  const int n = static_cast<int>(misfit.size());
  std::vector<double> x(n), y(n), k(n, 0.0);
  for (int i = 0; i < n; ++i) {
    x[i] = std::log(std::max(misfit[i], 1e-300));
    y[i] = std::log(std::max(size[i], 1e-300));
  }
  int best = -1;
  for (int i = 1; i + 1 < n; ++i) {
    const double dx = 0.5 * (x[i + 1] - x[i - 1]), dy = 0.5 * (y[i + 1] - y[i - 1]);
    const double ddx = x[i + 1] - 2 * x[i] + x[i - 1], ddy = y[i + 1] - 2 * y[i] + y[i - 1];
    const double den = std::pow(dx * dx + dy * dy, 1.5);
    k[i] = den > 0 ? (dx * ddy - ddx * dy) / den : 0.0;
    if (!std::isfinite(k[i])) k[i] = 0;
    if (k[i] > 0 && (best < 0 || k[i] > k[best])) best = i;
  }
  if (curvature) *curvature = k;
  return best;
}

LCurveSummary l_curve(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta0,
                      const std::vector<char>& is_free, const FitOptions& options, const LCurveOptions& lo) {
  std::string why;
  if (!lo.IsValid(&why)) throw InputError("l-curve options: " + why);
  FitOptions o = options;
  o.regularization = 0;
  o.covariance = false;
  const std::vector<int> free = internal::free_parameters(pm, is_free, o);
  // The top weight: 100 times the data's largest curvature in the scaled parameters at the initial values.
  const Linearization L = linearize(pm, measured, theta0, o);
  Eigen::MatrixXd JD(L.J.rows(), static_cast<Eigen::Index>(free.size()));
  for (std::size_t k = 0; k < free.size(); ++k)
    JD.col(static_cast<Eigen::Index>(k)) = L.J.col(free[k]) * pm.parameter(free[k]).scale;
  const double top = 100.0 * Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(JD.transpose() * JD, Eigen::EigenvaluesOnly)
                                 .eigenvalues()
                                 .maxCoeff();
  if (!(top > 0) || !std::isfinite(top))
    throw NumericalError("l-curve: the data do not depend on the free parameters at the initial values");

  LCurveSummary out;
  const int n = static_cast<int>(std::lround(lo.decades * lo.points_per_decade)) + 1;
  Eigen::VectorXd x = theta0;
  for (int j = 0; j < n; ++j) {  // largest weight first, each fit from the previous one's end
    o.regularization = top * std::pow(10.0, -static_cast<double>(j) / lo.points_per_decade);
    const FitSummary f = fit_parameters(pm, measured, x, is_free, o);
    LCurvePoint p;
    p.weight = o.regularization;
    p.misfit = f.final_residuals.norm();
    double s2 = 0;
    for (int q : free) s2 += std::pow((f.theta[q] - pm.parameter(q).nominal) / pm.parameter(q).scale, 2);
    p.size = std::sqrt(s2);
    p.theta = f.theta;
    p.converged = f.converged;
    out.evaluations += f.evaluations;
    out.points.push_back(std::move(p));
    x = f.theta;
  }
  std::reverse(out.points.begin(), out.points.end());
  std::vector<double> misfit, size, kappa;
  for (const LCurvePoint& p : out.points) misfit.push_back(p.misfit), size.push_back(p.size);
  out.corner = l_curve_corner(misfit, size, &kappa);
  for (int j = 0; j < n; ++j) out.points[static_cast<std::size_t>(j)].curvature = kappa[static_cast<std::size_t>(j)];
  if (out.corner < 0)
    throw NumericalError("l-curve: the curve has no corner (no point where it turns from steep to flat) over " +
                         std::to_string(lo.decades) + " decades of weight below " + std::to_string(top) +
                         "; give a fixed regularization weight");
  out.weight = out.points[static_cast<std::size_t>(out.corner)].weight;
  const int unconverged = static_cast<int>(
      std::count_if(out.points.begin(), out.points.end(), [](const LCurvePoint& p) { return !p.converged; }));
  if (unconverged > 0)
    out.warnings.push_back("l-curve: " + std::to_string(unconverged) + " of " + std::to_string(n) +
                           " fits along the path stopped without converging");
  return out;
}

}  // namespace dynid
