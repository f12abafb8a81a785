// dynid/io/model_plots.hpp -- figures drawn on the structure's geometry (PLplot, through dynid/io/plot.hpp):
// mode shapes over the undeformed structure, and per-element values (residual-force localization scores)
// as a map on the structure.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "dynid/engine/modal.hpp"
#include "dynid/io/plot.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid::plot {

/// The two global axes (0 x, 1 y, 2 z) along which the nodes spread most: the plane a structure is drawn in.
std::pair<int, int> drawing_plane(const Model& model);

/// Mode shapes on the structure: one panel per mode (at most `max_modes`, rigid-body modes skipped), the
/// undeformed members in grey and the deformed ones (translations of the free DOFs, scaled to 12 % of the
/// structure's size) in colour, titled with the frequency.
Figure mode_shape_figure(const Model& model, const ModalResult& modes, int max_modes, const std::string& title);

/// A panel drawing the structure with each element's value (e.g. a localization score in [0, 1]) as line width
/// and colour: elements in `highlight` in red, others from light grey (0) to blue (max). Elements without a
/// value are thin grey. Element values are keyed by user element id.
Panel element_map_panel(const Model& model, const std::vector<std::pair<int, double>>& values,
                        const std::vector<int>& highlight, const std::string& title);

}  // namespace dynid::plot
