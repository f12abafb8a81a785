#include "dynid/io/point_map.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "dynid/io/mat_file.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/text_util.hpp"

namespace dynid {

namespace {
std::string fmt(double v) { return internal::format_number(v, 4); }
std::string point(const Eigen::Vector3d& x) { return "(" + fmt(x.x()) + ", " + fmt(x.y()) + ", " + fmt(x.z()) + ")"; }
}  // namespace

std::map<int, int> map_test_points(const Model& model, const UffFile& geometry, const GeometrySpec& spec,
                                   std::vector<std::string>* notes) {
  const std::string& src = geometry.source;
  double length = 1.0;
  std::vector<UffNode> points;
  for (const UffDataset& ds : geometry.datasets) {
    if (const auto* u = std::get_if<UffUnits>(&ds.data)) length = u->length;
    if (const auto* n = std::get_if<UffNodes>(&ds.data)) points.insert(points.end(), n->nodes.begin(), n->nodes.end());
  }
  if (points.empty()) throw InputError(src + ": no test geometry (UFF dataset 15 or 2411 with the measurement points)");
  if (!(std::isfinite(length) && length > 0)) throw InputError(src + ": dataset 164 gives a length factor of " + fmt(length));
  if (model.nodes().empty()) throw InputError(src + ": the model has no nodes to map the test points to");
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Node& n : model.nodes()) lo = lo.cwiseMin(n.x), hi = hi.cwiseMax(n.x);
  if (spec.by_position && model.nodes().size() > 1 && (hi - lo).maxCoeff() == 0)
    throw InputError(src + ": test points cannot be matched by position: the model's nodes have no coordinates (all at one "
                     "point; a matrix model without a node table); give the model a node table, or match by id "
                     "(geometry: match: id)");
  const double tol = spec.tolerance > 0 ? spec.tolerance : 0.01 * std::max((hi - lo).maxCoeff(), 1e-300);
  const std::string hint = length != 1.0 ? " (coordinates scaled by the file's length factor " + fmt(length) + " to metres)" : "";

  std::map<int, int> out, taken;  // point -> node id; node id -> point
  double worst = 0;
  for (const UffNode& p : points) {
    if (spec.by_position && !p.global)
      throw InputError(src + ": test point " + std::to_string(p.id) + " is given in coordinate system " + std::to_string(p.definition_cs) +
                       ", which the file does not define (dataset 18 or 2420): its global position is unknown; add the "
                       "coordinate system to the file or match by id (geometry: match: id)");
    const Eigen::Vector3d x = length * p.x;
    int node = -1;
    double dist = std::numeric_limits<double>::infinity();
    if (spec.by_position) {
      for (const Node& n : model.nodes()) {
        const double d = (n.x - x).norm();
        if (d < dist) dist = d, node = n.id;
      }
      if (dist > tol)
        throw InputError(src + ": test point " + std::to_string(p.id) + " at " + point(x) + hint + " is " + fmt(dist) +
                         " from the nearest model node " + std::to_string(node) + ", more than the tolerance " + fmt(tol) +
                         ": check the units and the coordinate system, or set geometry: tolerance");
    } else {
      const int k = model.node_index(p.id);
      if (k < 0) throw InputError(src + ": test point " + std::to_string(p.id) + " is not a model node (geometry: match: id); use match: position");
      node = p.id;
      dist = (model.nodes()[k].x - x).norm();
      if (dist > tol)
        throw InputError(src + ": test point " + std::to_string(p.id) + " at " + point(x) + hint + " is " + fmt(dist) +
                         " from model node " + std::to_string(p.id) + " at " + point(model.nodes()[k].x) +
                         " (tolerance " + fmt(tol) + "): the ids do not name the same places; use match: position");
    }
    if (auto it = taken.find(node); it != taken.end())
      throw InputError(src + ": test points " + std::to_string(it->second) + " and " + std::to_string(p.id) +
                       " both map to model node " + std::to_string(node) + "; lower the tolerance or give match: id");
    if (out.count(p.id)) throw InputError(src + ": test point " + std::to_string(p.id) + " is defined twice");
    taken[node] = p.id;
    out[p.id] = node;
    worst = std::max(worst, dist);
  }
  if (notes)
    notes->push_back(src + ": " + std::to_string(out.size()) + " test points mapped to model nodes by " +
                     (spec.by_position ? "position" : "id") + ", largest distance " + fmt(worst) + " (tolerance " + fmt(tol) + ")" + hint);
  return out;
}

void relabel_points(const std::map<int, int>& map, const std::string& source, ModalData* d) {
  for (MeasuredDof& q : d->dofs) {
    auto it = map.find(q.node);
    if (it == map.end())
      throw InputError(source + ": DOF " + to_string(q) + " is at test point " + std::to_string(q.node) +
                       ", which the test geometry does not define");
    q.node = it->second;
  }
}

ModalData read_measured_modal_data(const std::string& file, const GeometrySpec& geometry, const Model& model,
                                   std::vector<std::string>* notes, const MatModalNames& mat,
                                   const ReaderLimits& limits) {
  const std::string ext = std::filesystem::path(file).extension().string();
  if (ext == ".mat") {
    MatModalNames names = mat;
    names.file = file;
    ModalData d = read_mat_modal_data(names, limits);
    if (!geometry.file.empty()) relabel_points(map_test_points(model, read_uff(geometry.file), geometry, notes), file, &d);
    return d;
  }
  if (ext == ".json") {
    ModalData d = read_modal_data(file);
    if (!geometry.file.empty()) relabel_points(map_test_points(model, read_uff(geometry.file), geometry, notes), file, &d);
    return d;
  }
  UffFile data = read_uff(file);
  if (geometry.file.empty()) {
    if (notes) notes->insert(notes->end(), data.notes.begin(), data.notes.end());
    return uff_modal_data(data);
  }
  const UffFile geo = read_uff(geometry.file);
  uff_apply_coordinate_systems(&data, geo);  // shape directions in the geometry's local systems, turned to global
  if (notes) notes->insert(notes->end(), data.notes.begin(), data.notes.end());
  ModalData d = uff_modal_data(data);
  relabel_points(map_test_points(model, geo, geometry, notes), file, &d);
  return d;
}

}  // namespace dynid
