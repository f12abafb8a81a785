// dynid/io/output.hpp -- writing result files safely, and JSON for results.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>
#include <string>

#include "dynid/engine/modal.hpp"
#include "dynid/io/case_file.hpp"

namespace dynid {

/// Writes `content` to `path` atomically (a temporary file in the same folder, then rename), so an interrupted
/// run never leaves a half-written file. Refuses to replace an existing file unless `overwrite` is set.
/// Throws InputError naming the path.
void write_file_atomic(const std::string& path, const std::string& content, bool overwrite);

/// Checks every output of a command before any is written (no partial results): throws InputError for the first
/// path that exists, unless `overwrite`.
void refuse_existing(const std::vector<std::string>& paths, bool overwrite);

/// The modal results as JSON: {"case", "dofs", "nonzeros", "modes": [{"index", "frequency_hz", "eigenvalue",
/// "rigid_body", "description"?, "residual"}], "solver": {...}}. See docs/results-json.md.
nlohmann::json modal_json(const Case& c, const ModalResult& r);
/// The same for a model without a case file; `name` goes to "case".
nlohmann::json modal_json(const std::string& name, const ModalResult& r);

}  // namespace dynid
