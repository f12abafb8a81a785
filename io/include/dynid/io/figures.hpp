// dynid/io/figures.hpp -- the result figures of dynid's steps, built as plot::Figure (dynid/io/plot.hpp) and saved
// by the caller with plot::save. Every figure is built in io; the command line only chooses the file:
//   detect_figure, update_figure, mode_comparison_panels (here);
//   mode_shape_figure, element_map_panel (figures drawn on the structure: dynid/io/model_plots.hpp);
//   discovery_figure (dynid/io/discover_io.hpp), stabilization_figure (dynid/io/identify_io.hpp).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dynid/engine/detect.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/parametric.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/model_plots.hpp"
#include "dynid/io/plot.hpp"

namespace dynid::plot {

/// One model state compared mode by mode with reference modes (measured data, or the model before a change).
struct ModeComparison {
  std::string label;                 ///< legend of its bars and MAC line ("" : none)
  int color = 0;                     ///< palette index
  Eigen::VectorXd hz, reference_hz;  ///< per mode: the state's frequency and the reference one [Hz]
  Eigen::VectorXd mac;               ///< per mode: MAC of the pair
  std::vector<char> paired;          ///< per mode, optional: 0 = no plausible partner (an x at 0 instead of a bar)
};

struct ModeComparisonPanels {
  Panel frequency, mac;
};

/// The "frequency difference and MAC per mode" pair of panels of the detect, update and discover figures. For
/// each state and mode k (drawn at x = k + 1, over the modes both `hz` and `reference_hz` have): a bar of
/// 100 (f - f_ref) / f_ref [%] (states side by side, `bar_width` wide, 0.4 apart) and a MAC point (line and
/// markers, at the mode). Titles, axis labels other than "MAC", ranges and reference lines are the caller's.
ModeComparisonPanels mode_comparison_panels(const std::vector<ModeComparison>& states, double bar_width = 0.8);

/// dynid detect's figure: the pseudo residual per DOF, the localization on the structure, the paper's element
/// mapping and dynid's per-element scores, and the frequency change and MAC of the changed state per mode.
Figure detect_figure(const Case& c, const DetectSummary& S);

/// dynid update's figure: frequency error and MAC against the measured modes, initial and updated, and the
/// parameters (updated with one standard deviation).
Figure update_figure(const Case& c, const ParametricModel& pm, const UpdateSpec& u, const FitSummary& f);

}  // namespace dynid::plot
