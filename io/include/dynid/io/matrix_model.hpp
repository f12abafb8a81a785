// dynid/io/matrix_model.hpp -- models given as matrices exported from another FE code (docs/matrix-input.md):
// the DOF table, the node table, element matrices (or group matrices) and optionally the assembled K and M as
// Matrix Market files. The reader turns them into a dynid Model of Matrix elements, so that every engine step
// (modal, detect, update, discover) runs on them; the writer exports any dynid model in the same format.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dynid/io/limits.hpp"
#include "dynid/mesh/model.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// The files of a matrix model. Paths as given (the case reader resolves them against the case folder).
struct MatrixModelFiles {
  std::string dofs;      ///< DOF table: row i = equation i: "node, dof" (dof: ux..rz or 1..6)   (required)
  std::string nodes;     ///< node table: "id, x, y, z" (optional: without it the nodes have no coordinates)
  std::string elements;  ///< element matrices (the "%%dynid element-matrices" format)
  struct Group {
    std::string name, K, M;  ///< a group's stiffness and mass matrices on the global equations (Matrix Market);
                             ///< one of them may be empty (a stiffness-only or mass-only group)
  };
  std::vector<Group> groups;  ///< group matrices, each one Matrix element (in addition to `elements`)
  std::string K, M;  ///< assembled matrices (Matrix Market), optional: checked against the sum of the elements;
                     ///< what they hold beyond it becomes a "remainder" element
};

/// One row of a DOF table: equation i is DOF `dof` of node `node` (user id).
struct DofRow {
  int node = 0;
  Dof dof = Dof::UX;
};

/// Parses a DOF table held in memory ("node, dof" per line, blanks or commas; dof ux..rz or 1..6; an optional
/// header line; '#' and '%' lines are comments). `name` names it in messages.
std::vector<DofRow> parse_dof_table(const std::string& text, const std::string& name);
/// Parses a node table held in memory ("id, x, y[, z]" per line; an optional header line).
std::vector<Node> parse_node_table(const std::string& text, const std::string& name);

/// One element of an element-matrices file.
struct ElementMatrices {
  int id = 0;
  std::string group;
  std::vector<int> nodes;      ///< optional "nodes" record: the nodes it connects (for geometry)
  std::vector<int> equations;  ///< 0-based global equations, in matrix order
  Eigen::MatrixXd K, M;        ///< full symmetric storage
  int line = 0;                ///< line of its "element" record
};

/// Parses an element-matrices file held in memory; `name` names it in messages ("file:line: ...").
/// `num_equations` bounds the equation numbers (rows of the DOF table).
std::vector<ElementMatrices> parse_element_matrices(const std::string& text, const std::string& name, int num_equations,
                                                    const ReaderLimits& limits = {});

/// A matrix model held in memory: what the files of MatrixModelFiles hold once read, and what a MATLAB file
/// (dynid/io/mat_file.hpp) or a Python host gives. Names in the `*_name` fields say where each part came from
/// in messages ("dofs.csv", "bridge.mat: variable K0").
struct MatrixModelData {
  std::vector<DofRow> dofs;     ///< equation i -> (node, DOF type)  (required)
  std::string dofs_name = "the DOF table";
  std::vector<Node> nodes;      ///< every node a DOF names (empty: nodes at the origin, without coordinates)
  std::string nodes_name = "the node table";
  std::vector<ElementMatrices> elements;  ///< element matrices on 0-based equations
  struct Group {
    std::string name;           ///< the group (element group name)
    std::string K_name, M_name; ///< where K and M came from
    SparseMatrix K, M;          ///< on the global equations; M (or K) 0 x 0 = none (zero)
  };
  std::vector<Group> groups;    ///< one Matrix element each, on the equations it touches
  bool has_assembled = false;   ///< K and M below are given (checked against the sum of the elements)
  SparseMatrix K, M;
  std::string K_name = "K", M_name = "M";
};

/// Adds the nodes and Matrix elements of an in-memory matrix model to `model` (not finalized), as
/// add_matrix_model(files) does: groups become dense elements on the equations they touch (at most
/// ReaderLimits::max_element_dofs), and what K and M hold beyond the elements becomes a "remainder" element.
void add_matrix_model(const MatrixModelData& data, Model* model, std::vector<std::string>* notes = nullptr,
                      const ReaderLimits& limits = {});

/// Adds the nodes and Matrix elements of a matrix model to `model` (not finalized: the caller may add supports,
/// springs, point masses, then finalize). Remarks (e.g. a remainder element) go to `notes` if not null. Throws
/// InputError naming file and line for anything malformed or inconsistent.
void add_matrix_model(const MatrixModelFiles& files, Model* model, std::vector<std::string>* notes = nullptr,
                      const ReaderLimits& limits = {});

/// Writes `model` (finalized) as a matrix model into folder `dir` (created if missing): K.mtx, M.mtx (assembled,
/// symmetric), dofs.csv, nodes.csv, elements.txt (one record per element) and model.yaml (the case-file model
/// section that reads them back). Refuses to replace existing files unless `overwrite`. Returns the paths written.
std::vector<std::string> write_matrix_model(const Model& model, const std::string& dir, bool overwrite);

}  // namespace dynid
