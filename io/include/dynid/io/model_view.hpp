// dynid/io/model_view.hpp -- the data of the report's animated 3D mode-shape view (docs/report.md): the structure
// as points and segments, and each mode's displacement of every point. `dynid run` writes it beside modal.json
// (modal-view.json); the report draws it with three.js.
#pragma once

#include <nlohmann/json.hpp>

#include "dynid/engine/modal.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

/// {"points": [x0, y0, z0, x1, ...], "segments": [a0, b0, a1, b1, ...] (point indices), "size": structure size,
///  "modes": [{"index", "frequency_hz", "label", "u": [dx0, dy0, dz0, ...]}]}: the first `max_modes` elastic modes,
/// each scaled so that its largest point displacement is 1. Members are sampled along their axis with their
/// shape functions (cubic transverse, linear axial), so the drawn shapes curve as the element's do; other elements
/// are straight lines between their nodes. Large models (more than `curved_limit` members) are drawn straight.
/// Numbers keep 6 significant digits.
nlohmann::json model_view_json(const Model& model, const ModalResult& modes, int max_modes = 6, int curved_limit = 3000);

}  // namespace dynid
