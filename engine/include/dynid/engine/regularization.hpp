// dynid/engine/regularization.hpp -- the weight of Tikhonov regularisation toward nominal chosen by a stated
// rule: the L-curve (Hansen), traced by continuation over a path of weights.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dynid/engine/model_fit.hpp"

namespace dynid {

/// The path of weights: from the top weight, at which the prior's curvature is 100 times the data's largest
/// (w_top = 100 max eig(D J^T J D) at the initial values, D = the free parameters' scales: the fit stays at the
/// nominal values), down `decades` decades in `points_per_decade` steps per decade.
struct LCurveOptions {
  int points_per_decade = 2;
  double decades = 8;
  bool IsValid(std::string* why) const;
};

struct LCurvePoint {
  double weight = 0;
  double misfit = 0;     ///< ||r||: the whitened data residuals at the solution (sqrt(chi^2))
  double size = 0;       ///< ||(theta - nominal) / scale|| over the free parameters
  double curvature = 0;  ///< of (log misfit, log size) against log weight (0 at the ends)
  Eigen::VectorXd theta;
  bool converged = false;
};

struct LCurveSummary {
  std::vector<LCurvePoint> points;  ///< smallest weight first (the path ran from the largest)
  int corner = -1;                  ///< index of the chosen point
  double weight = 0;                ///< the chosen weight (FitOptions::regularization)
  int evaluations = 0;              ///< model evaluations along the path
  std::vector<std::string> warnings;
};

/// Traces the L-curve: one fit per weight, largest first, each started where the previous one ended
/// (continuation from the regularised, nearly unique solution toward the data's), and chooses the corner
/// (l_curve_corner). `options.regularization` is ignored. Throws as fit_parameters does; NumericalError when the
/// path cannot be traced (a fit fails) or the curve has no corner (fewer than 3 points, or no change).
LCurveSummary l_curve(const ParametricModel& pm, const ModalData& measured, const Eigen::VectorXd& theta0,
                      const std::vector<char>& free, const FitOptions& options, const LCurveOptions& lo = {});

/// The corner of a discrete L-curve given at weights equally spaced in log, smallest first: the interior point of
/// largest curvature kappa = (x' y'' - x'' y') / (x'^2 + y'^2)^(3/2) of x = log misfit, y = log size against
/// t = log weight (central differences; kappa does not depend on the step), positive where the curve turns from
/// steep (small weights: the size falls, the misfit barely grows) to flat (large weights). Fills `curvature` (0
/// at the ends) when not null. Returns -1 when no interior point has positive curvature.
int l_curve_corner(const std::vector<double>& misfit, const std::vector<double>& size,
                   std::vector<double>* curvature = nullptr);

}  // namespace dynid
