// dynid/io/point_map.hpp -- tying measurement points to model nodes: the test geometry of a UFF file (datasets
// 15 or 2411) matched to the model's nodes by id or by nearest position within a tolerance, and measured modal
// data relabelled from test point ids to model node ids.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "dynid/engine/modal_data.hpp"
#include "dynid/io/mat_file.hpp"
#include "dynid/io/uff.hpp"
#include "dynid/mesh/model.hpp"

namespace dynid {

/// How a case ties its measured data to the model (`geometry:` beside `measured:`, docs/case-file.md).
struct GeometrySpec {
  std::string file;        ///< UFF file with dataset 15 or 2411; "" = the data's node ids are model node ids
  bool by_position = true; ///< match: position (nearest model node) or id (same id)
  double tolerance = 0;    ///< largest distance point - node, model units; 0 = 1 % of the model's largest extent
};

/// Test point id -> model node id. Coordinates are converted to SI with the file's dataset 164 length factor
/// when it has one (the model is then taken to be in metres). By position: each point goes to its nearest model
/// node, which must lie within the tolerance, and no two points may share a node. By id: each point id must be a
/// model node (and its position within the tolerance of that node's, else the mismatch is named). Throws
/// InputError naming the point, its coordinates, the nearest node and the distance. `notes` (if not null)
/// receives a one-line summary (points matched, largest distance).
std::map<int, int> map_test_points(const Model& model, const UffFile& geometry, const GeometrySpec& spec,
                                   std::vector<std::string>* notes = nullptr);

/// Replaces the node ids of `d`'s DOFs (test points) by model node ids. Throws InputError for a DOF whose point
/// is not in `map` (naming it and `source`).
void relabel_points(const std::map<int, int>& map, const std::string& source, ModalData* d);

/// Measured modal data from a .json, UFF 55/2414 or .mat file (the variables `mat` names; UFF shape directions
/// turned to global by the geometry file's coordinate systems); with a geometry file, relabelled to model nodes.
ModalData read_measured_modal_data(const std::string& file, const GeometrySpec& geometry, const Model& model,
                                   std::vector<std::string>* notes = nullptr,
                                   const MatModalNames& mat = MatModalNames(), const ReaderLimits& limits = {});

}  // namespace dynid
