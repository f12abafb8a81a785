// dynid/io/modal_data_io.hpp -- modal data files (measured or identified modes at DOFs).
//
// JSON layout (what `dynid identify` writes, and `detect`/`update`/`discover` read):
//   {"modes": [{"frequency_hz": 45.2, "damping_ratio": 0.012, "mpc": 0.99,
//               "shape": {"1uy": 0.81, "2uy": 0.64, ...}}, ...]}
// DOF labels are node id + direction: "13ux", "13:ux", "13+X" / "13-Z" (UFF style; '-' flips the sign).
// Every mode must give the same DOFs. Extra keys are ignored.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "dynid/engine/modal_data.hpp"

namespace dynid {

/// Parses a DOF label; returns false if it is not one. `sign` (if non-null) receives -1 for "13-X".
bool parse_dof_label(const std::string& label, MeasuredDof* out, double* sign = nullptr);

/// Reads modal data from a .json file (errors name the file and the mode/DOF at fault).
ModalData read_modal_data(const std::string& path);
ModalData parse_modal_data_json(const std::string& text, const std::string& name);

nlohmann::ordered_json modal_data_json(const ModalData& d);
void write_modal_data(const std::string& path, const ModalData& d, bool overwrite);

}  // namespace dynid
