// dynid/io/identify_io.hpp -- identification results: JSON, the stabilization diagram, and reading recordings.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "dynid/engine/identify.hpp"
#include "dynid/io/plot.hpp"

namespace dynid {

/// {"method", "dofs", "orders": [min, max], "band_hz": [lo, hi], "band_from_data", "resolution_hz", "seconds",
///  "window_decay_removed",
///  "uncertainty": {"halves", "pooled_frequency_std" (x f zeta), "pooled_shape_std"} (when estimated),
///  "modes": [{"frequency_hz", "damping_ratio", "frequency_std_hz", "damping_std", "shape_std" (when estimated),
///             "mpc", "shape": {dof: value}, "contribution", "poles", "support", "indicator_db",
///             "order_frequency_std_hz", "same_shape_as" (twins)}],
///  "rejected": [{"frequency_hz", "damping_ratio", "poles", "support", "reason" ("few orders", "complex shape",
///               "no indicator peak", "spectral edge", "split"), "value", "limit", "merged_into" (split: mode number)}],
///  "stabilization": {"poles": [[order, frequency_hz, damping_ratio, class, mode]], "frequency_hz", "background",
///                    "background_label"},
///  "notes": [...]}; the modes array reads back with read_modal_data.
nlohmann::ordered_json identification_json(const IdentificationSummary& s);

/// The stabilization diagram: model order against frequency, each pole marked by what it is stable in
/// (frequency, damping, vector), the selected modes as vertical lines, and the mode indicator (CMIF for LSCF, the
/// first singular value of the output spectra for SSI) behind it on a log axis at the right.
plot::Figure stabilization_figure(const IdentificationSummary& s, const std::string& title);

}  // namespace dynid
