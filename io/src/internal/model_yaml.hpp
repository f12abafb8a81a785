// Parsing of the `model:` section of a case file (internal to io; shared by every case kind).
#pragma once

#include "dynid/mesh/model.hpp"
#include "internal/yaml_util.hpp"

namespace dynid::internal {

/// Builds and finalizes a Model from a `model:` mapping. Errors carry file:line:col.
Model parse_model(const YAML::Node& node, const YamlCtx& ctx);

}  // namespace dynid::internal
