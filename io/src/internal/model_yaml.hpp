// Parsing of the `model:` section of a case file (internal to io; shared by every case kind).
#pragma once

#include <string>
#include <vector>

#include "dynid/io/limits.hpp"
#include "dynid/mesh/model.hpp"
#include "internal/yaml_util.hpp"

namespace dynid::internal {

/// Builds and finalizes a Model from a `model:` mapping; mesh files (model.file) resolve against `dir`, and
/// what they hold but the model does not use is described in `notes`; files are read within `limits`. Errors
/// carry file:line:col.
Model parse_model(const YAML::Node& node, const YamlCtx& ctx, const std::string& dir, std::vector<std::string>* notes,
                  const ReaderLimits& limits);

}  // namespace dynid::internal
