// dynid/io/identify_io.hpp -- identification results: JSON, the stabilization diagram, and reading recordings.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "dynid/engine/identify.hpp"
#include "dynid/io/plot.hpp"

namespace dynid {

/// {"method", "dofs", "orders": [min, max], "seconds", "window_decay_removed",
///  "modes": [{"frequency_hz", "damping_ratio", "frequency_std_hz", "damping_std", "mpc", "contribution",
///             "poles", "shape": {dof: value}}],
///  "stabilization": {"poles": [[order, frequency_hz, damping_ratio, class, mode]], "frequency_hz", "background",
///                    "background_label"}}; the modes array reads back with read_modal_data.
nlohmann::ordered_json identification_json(const IdentificationSummary& s);

/// The stabilization diagram: model order against frequency, each pole marked by what it is stable in
/// (frequency, damping, vector), the selected modes as vertical lines, and the FRF sum (LSCF) or the first
/// singular value of the output spectra (SSI) behind it on a log axis at the right.
plot::Figure stabilization_figure(const IdentificationSummary& s, const std::string& title);

}  // namespace dynid
