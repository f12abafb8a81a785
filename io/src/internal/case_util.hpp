// Helpers shared by the case-file sections (internal to io).
#pragma once

#include <string>
#include <vector>

#include "dynid/engine/modal_data.hpp"
#include "dynid/io/mat_file.hpp"
#include "dynid/io/point_map.hpp"
#include "internal/yaml_util.hpp"

namespace dynid::internal {

/// measured_dofs: all | translations | {types: [ux, uy], nodes: [...]} | [13ux, 13uy, ...]
std::vector<MeasuredDof> parse_dof_selection(const YAML::Node& n, const YamlCtx& ctx, const Model& model,
                                             const std::string& what);
/// A path relative to the case file's folder (absolute paths unchanged).
std::string resolve(const std::string& dir, const std::string& file);
/// The `geometry:` of a section (`detect`, `update`, `discover`): FILE | {file: FILE, match: position | id,
/// tolerance: T}, only beside measured:. None given: an empty GeometrySpec.
GeometrySpec parse_geometry(const YAML::Node& section, const std::string& name, const YamlCtx& ctx, const std::string& dir);
/// The `measured:` file of a section: FILE, or {mat: FILE, frequency_hz | eigenvalues: VAR, shapes: VAR, dofs: VAR,
/// damping: VAR, frequency_std | eigenvalue_std: VAR, shape_std: VAR} (a MATLAB file, whose variable names
/// parse_measured_mat() returns; dofs: {mat: FILE, var: VAR} takes the DOFs from another file, resolved against `dir`).
std::string parse_measured(const YAML::Node& n, const YamlCtx& ctx, const std::string& dir, const std::string& what);
MatModalNames parse_measured_mat(const YAML::Node& section, const std::string& name, const YamlCtx& ctx, const std::string& dir);

}  // namespace dynid::internal

#include "dynid/io/case_file.hpp"

namespace dynid::internal {

/// The `update:` section (io/src/case_update.cpp).
UpdateSpec parse_update(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& dir);
/// The `test:` section (io/src/case_test.cpp).
TestSpec parse_test(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& dir);
/// The `discover:` section (io/src/case_discover.cpp).
DiscoverSpec parse_discover(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& dir,
                            const ReaderLimits& limits);
/// The model section of `root` (root["model"]), following model: {include: FILE}; ctx->file and *dir follow it.
YAML::Node model_node(const YAML::Node& root, YamlCtx* ctx, std::string* dir, int depth);

}  // namespace dynid::internal
