#include "dynid/io/matrix_model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "dynid/io/limits.hpp"
#include "dynid/io/matrix_market.hpp"
#include "dynid/io/output.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/sparse.hpp"
#include "internal/text_util.hpp"

namespace fs = std::filesystem;

namespace dynid {

namespace {

using internal::LineReader;
using internal::parse_double;
using internal::parse_int;
using internal::split_fields;
using internal::trim;

[[noreturn]] void fail_at(const std::string& name, int line, const std::string& what) {
  throw InputError(name + ":" + std::to_string(line) + ": " + what);
}

bool skip_line(std::string_view t) { return t.empty() || t[0] == '#' || t[0] == '%'; }

// A DOF name: ux..rz, or the component numbers 1..6 of Nastran and Abaqus.
bool parse_dof_field(std::string_view f, Dof* d) {
  int c = 0;
  if (parse_int(f, &c)) {
    if (c < 1 || c > 6) return false;
    *d = static_cast<Dof>(c - 1);
    return true;
  }
  return parse_dof(f, d);
}

std::string fmt(double v) { return internal::format_number(v, 3); }

}  // namespace

std::vector<DofRow> parse_dof_table(const std::string& bytes, const std::string& path) {
  LineReader r(bytes);
  std::string_view line;
  std::vector<DofRow> rows;
  std::set<std::pair<int, int>> seen;
  bool first = true;
  while (r.next(&line)) {
    const std::string_view t = trim(line);
    if (skip_line(t)) continue;
    const auto f = split_fields(t, true);
    DofRow row{};
    const bool ok = f.size() == 2 && parse_int(f[0], &row.node) && parse_dof_field(f[1], &row.dof);
    if (!ok && first && f.size() == 2) {  // a header such as "node,dof"
      first = false;
      continue;
    }
    first = false;
    if (!ok)
      fail_at(path, r.line(), "expected 'node, dof' (a node id and ux, uy, uz, rx, ry, rz or 1..6), got '" +
                                  std::string(t) + "'");
    if (!seen.insert({row.node, static_cast<int>(row.dof)}).second)
      fail_at(path, r.line(), std::string(dof_name(row.dof)) + " at node " + std::to_string(row.node) +
                                  " is already equation " + [&] {
                                    for (std::size_t i = 0; i < rows.size(); ++i)
                                      if (rows[i].node == row.node && rows[i].dof == row.dof) return std::to_string(i + 1);
                                    return std::string("?");
                                  }());
    rows.push_back(row);
  }
  if (rows.empty()) throw InputError(path + ": the DOF table lists no DOFs (one line 'node, dof' per equation)");
  return rows;
}

std::vector<Node> parse_node_table(const std::string& bytes, const std::string& path) {
  LineReader r(bytes);
  std::string_view line;
  std::vector<Node> nodes;
  std::set<int> ids;
  bool first = true;
  while (r.next(&line)) {
    const std::string_view t = trim(line);
    if (skip_line(t)) continue;
    const auto f = split_fields(t, true);
    Node n;
    bool ok = (f.size() == 3 || f.size() == 4) && parse_int(f[0], &n.id);
    for (std::size_t k = 1; ok && k < f.size(); ++k) ok = parse_double(f[k], &n.x[static_cast<int>(k) - 1]);
    ok = ok && n.x.allFinite();
    if (!ok && first) {
      first = false;
      continue;
    }
    first = false;
    if (!ok) fail_at(path, r.line(), "expected 'id, x, y, z' (a node id and finite coordinates), got '" + std::string(t) + "'");
    if (!ids.insert(n.id).second) fail_at(path, r.line(), "node " + std::to_string(n.id) + " is listed twice");
    nodes.push_back(n);
  }
  if (nodes.empty()) throw InputError(path + ": the node table lists no nodes (one line 'id, x, y, z' per node)");
  return nodes;
}

namespace {

// The dense matrix of an element record: `count` lines "i j value" (1-based, i >= j), mirrored.
Eigen::MatrixXd read_block(LineReader& r, const std::string& name, const std::string& who, int n, long long count,
                           const char* what) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  std::string_view line;
  long long got = 0;
  while (got < count) {
    if (!r.next(&line)) fail_at(name, r.line(), who + ": file ends after " + std::to_string(got) + " of " +
                                                    std::to_string(count) + " " + what + " entries");
    const std::string_view t = trim(line);
    if (skip_line(t)) continue;
    const auto f = split_fields(t);
    int i = 0, j = 0;
    double v = 0;
    if (f.size() != 3 || !parse_int(f[0], &i) || !parse_int(f[1], &j) || !parse_double(f[2], &v))
      fail_at(name, r.line(), who + ": expected a " + what + " entry 'row col value', got '" + std::string(t) + "'");
    if (i < 1 || i > n || j < 1 || j > n)
      fail_at(name, r.line(), who + ": entry (" + std::to_string(i) + ", " + std::to_string(j) + ") is outside the element's " +
                                  std::to_string(n) + " DOFs");
    if (i < j) fail_at(name, r.line(), who + ": entries are the lower triangle (row >= col); got (" + std::to_string(i) + ", " + std::to_string(j) + ")");
    if (!std::isfinite(v)) fail_at(name, r.line(), who + ": non-finite " + what + " entry");
    A(i - 1, j - 1) += v;
    if (i != j) A(j - 1, i - 1) += v;
    ++got;
  }
  return A;
}

}  // namespace

std::vector<ElementMatrices> parse_element_matrices(const std::string& text, const std::string& name, int num_equations,
                                                    const ReaderLimits& limits) {
  LineReader r(text);
  std::string_view line;
  if (!r.next(&line) || trim(line) != "%%dynid element-matrices 1")
    fail_at(name, 1, "not an element-matrices file: the first line must be '%%dynid element-matrices 1' "
                     "(docs/matrix-input.md)");
  const int max_dofs = limits.max_element_dofs;
  std::vector<ElementMatrices> out;
  std::set<int> ids;
  while (r.next(&line)) {
    const std::string_view t = trim(line);
    if (skip_line(t)) continue;
    auto f = split_fields(t);
    ElementMatrices e;
    e.line = r.line();
    if (f[0] != "element" || f.size() < 2 || f.size() > 3 || !parse_int(f[1], &e.id))
      fail_at(name, r.line(), "expected 'element <id> [group]', got '" + std::string(t) + "'");
    if (!ids.insert(e.id).second) fail_at(name, r.line(), "element " + std::to_string(e.id) + " is defined twice");
    if (f.size() == 3) e.group = std::string(f[2]);
    const std::string who = "element " + std::to_string(e.id);
    // dofs record
    do {
      if (!r.next(&line)) fail_at(name, r.line(), who + ": file ends before its 'dofs' line");
    } while (skip_line(trim(line)));
    f = split_fields(trim(line));
    if (f[0] == "nodes") {  // optional: the nodes it connects (user ids), for geometry
      if (static_cast<long long>(f.size()) - 1 > max_dofs)
        fail_at(name, r.line(), who + ": more than " + limit_text(max_dofs) + " nodes");
      for (std::size_t k = 1; k < f.size(); ++k) {
        int id = 0;
        if (!parse_int(f[k], &id)) fail_at(name, r.line(), who + ": node '" + std::string(f[k]) + "' is not an integer id");
        e.nodes.push_back(id);
      }
      do {
        if (!r.next(&line)) fail_at(name, r.line(), who + ": file ends before its 'dofs' line");
      } while (skip_line(trim(line)));
      f = split_fields(trim(line));
    }
    if (f[0] != "dofs" || f.size() < 2)
      fail_at(name, r.line(), who + ": expected 'dofs <equation> ...' (1-based rows of the DOF table)");
    if (static_cast<long long>(f.size()) - 1 > max_dofs)
      fail_at(name, r.line(), who + ": " + std::to_string(f.size() - 1) + " DOFs; an element or group has at most " +
                                  limit_text(max_dofs) + " (give a large component as several elements)");
    for (std::size_t k = 1; k < f.size(); ++k) {
      int q = 0;
      if (!parse_int(f[k], &q) || q < 1 || q > num_equations)
        fail_at(name, r.line(), who + ": DOF '" + std::string(f[k]) + "' is not an equation number 1.." +
                                    std::to_string(num_equations) + " of the DOF table");
      if (std::find(e.equations.begin(), e.equations.end(), q - 1) != e.equations.end())
        fail_at(name, r.line(), who + ": equation " + std::to_string(q) + " is listed twice");
      e.equations.push_back(q - 1);
    }
    const int n = static_cast<int>(e.equations.size());
    const long long most = static_cast<long long>(n) * (n + 1) / 2;
    for (const char* which : {"K", "M"}) {
      do {
        if (!r.next(&line)) fail_at(name, r.line(), who + ": file ends before its '" + which + " <entries>' line");
      } while (skip_line(trim(line)));
      f = split_fields(trim(line));
      int count = -1;
      if (f.size() != 2 || f[0] != which || !parse_int(f[1], &count) || count < 0)
        fail_at(name, r.line(), who + ": expected '" + which + " <number of entries>', got '" + std::string(trim(line)) + "'");
      if (count > most)
        fail_at(name, r.line(), who + ": " + std::to_string(count) + " " + which + " entries, but a lower triangle of " +
                                    std::to_string(n) + " DOFs has " + std::to_string(most));
      (which[0] == 'K' ? e.K : e.M) = read_block(r, name, who, n, count, which[0] == 'K' ? "stiffness" : "mass");
    }
    out.push_back(std::move(e));
  }
  if (out.empty()) throw InputError(name + ": no element records ('element <id> [group]')");
  return out;
}

void add_matrix_model(const MatrixModelFiles& files, Model* model, std::vector<std::string>* notes,
                      const ReaderLimits& limits) {
  if (files.dofs.empty()) throw InputError("matrix model: the DOF table (dofs:) is required");
  if (files.elements.empty() && files.groups.empty())
    throw InputError("matrix model: give element matrices (elements:) or group matrices (groups:)");
  if (files.K.empty() != files.M.empty()) throw InputError("matrix model: give both K and M, or neither");
  MatrixModelData d;
  d.dofs = parse_dof_table(internal::read_file_bytes(files.dofs), files.dofs);
  d.dofs_name = files.dofs;
  if (!files.nodes.empty()) {
    d.nodes = parse_node_table(internal::read_file_bytes(files.nodes), files.nodes);
    d.nodes_name = files.nodes;
  }
  const int n = static_cast<int>(d.dofs.size());
  if (!files.elements.empty())
    d.elements = parse_element_matrices(internal::read_file_bytes(files.elements), files.elements, n, limits);
  for (const MatrixModelFiles::Group& g : files.groups) {
    if (g.K.empty() && g.M.empty()) throw InputError("matrix model: group '" + g.name + "' names neither a K nor an M file");
    d.groups.push_back({g.name, g.K, g.M, g.K.empty() ? SparseMatrix() : read_matrix_market(g.K, limits),
                        g.M.empty() ? SparseMatrix() : read_matrix_market(g.M, limits)});
  }
  if (!files.K.empty()) {
    d.has_assembled = true;
    d.K = read_matrix_market(files.K, limits);
    d.K_name = files.K;
    d.M = read_matrix_market(files.M, limits);
    d.M_name = files.M;
  }
  add_matrix_model(d, model, notes, limits);
}

void add_matrix_model(const MatrixModelData& data, Model* model, std::vector<std::string>* notes,
                      const ReaderLimits& limits) {
  const std::vector<DofRow>& dofs = data.dofs;
  const int n = static_cast<int>(dofs.size());
  if (n == 0) throw InputError("matrix model: " + data.dofs_name + " lists no DOFs");
  if (data.elements.empty() && data.groups.empty())
    throw InputError("matrix model: give element matrices or group matrices");
  {
    std::set<std::pair<int, int>> seen;
    for (std::size_t i = 0; i < dofs.size(); ++i)
      if (!seen.insert({dofs[i].node, static_cast<int>(dofs[i].dof)}).second)
        throw InputError(data.dofs_name + ": equation " + std::to_string(i + 1) + " is " + std::string(dof_name(dofs[i].dof)) +
                         " at node " + std::to_string(dofs[i].node) + ", which an earlier equation already is");
  }
  std::set<int> node_ids;
  for (const Node& nd : data.nodes) node_ids.insert(nd.id);
  std::vector<Node> origin_nodes;  // no node table: every node the DOF table names, at the origin
  if (data.nodes.empty()) {
    for (const DofRow& r : dofs)
      if (node_ids.insert(r.node).second) origin_nodes.push_back(Node{r.node, Eigen::Vector3d::Zero()});
    if (notes)
      notes->push_back("matrix model: no node table (nodes:): the " + std::to_string(origin_nodes.size()) +
                       " nodes have no coordinates (placed at the origin); modal analysis, detection and updating work, "
                       "but model plots, position mapping of test points and geometric discovery candidates are unavailable");
  }
  for (std::size_t i = 0; i < dofs.size(); ++i)
    if (!node_ids.count(dofs[i].node))
      throw InputError(data.dofs_name + ": equation " + std::to_string(i + 1) + " is at node " + std::to_string(dofs[i].node) +
                       ", which " + data.nodes_name + " does not list");

  std::vector<ElementMatrices> elems = data.elements;
  int next_id = 1;
  for (const ElementMatrices& e : elems) {
    for (int q : e.equations)
      if (q < 0 || q >= n)
        throw InputError("matrix model: element " + std::to_string(e.id) + ": equation " + std::to_string(q + 1) +
                         " is not one of the " + std::to_string(n) + " equations of " + data.dofs_name);
    const auto m = static_cast<Eigen::Index>(e.equations.size());
    if (e.K.rows() != m || e.K.cols() != m || e.M.rows() != m || e.M.cols() != m)
      throw InputError("matrix model: element " + std::to_string(e.id) + ": K and M must be " + std::to_string(m) + " x " +
                       std::to_string(m) + " (one row per DOF)");
    next_id = std::max(next_id, e.id + 1);
  }
  // A sparse matrix on the global equations as one dense element on the equations it touches.
  auto dense_element = [&](const SparseMatrix& K, const SparseMatrix& M, const std::string& what) {
    ElementMatrices e;
    e.id = next_id++;
    std::vector<char> used(n, 0);
    for (const SparseMatrix* A : {&K, &M})
      for (int j = 0; j < A->outerSize(); ++j)
        for (SparseMatrix::InnerIterator it(*A, j); it; ++it)
          if (it.value() != 0.0) used[it.row()] = used[j] = 1;
    for (int i = 0; i < n; ++i)
      if (used[i]) e.equations.push_back(i);
    const int m = static_cast<int>(e.equations.size());
    if (m > limits.max_element_dofs)
      throw InputError(what + " acts on " + std::to_string(m) +
                       " DOFs; a group or remainder is one dense element of at most " +
                       limit_text(limits.max_element_dofs) + " DOFs: export element matrices instead");
    std::vector<int> local(n, -1);
    for (int k = 0; k < m; ++k) local[e.equations[k]] = k;
    e.K = Eigen::MatrixXd::Zero(m, m);
    e.M = e.K;
    for (int j = 0; j < K.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(K, j); it; ++it)
        if (it.value() != 0.0) e.K(local[it.row()], local[j]) += it.value();
    for (int j = 0; j < M.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(M, j); it; ++it)
        if (it.value() != 0.0) e.M(local[it.row()], local[j]) += it.value();
    return e;
  };
  // A square symmetric matrix on the n equations (0 x 0: none, zero).
  auto check_square = [&](const SparseMatrix& A, const std::string& name) {
    if (A.rows() == 0 && A.cols() == 0) return SparseMatrix(n, n);
    if (A.rows() != n || A.cols() != n)
      throw InputError(name + ": a " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                       " matrix, but the DOF table " + data.dofs_name + " has " + std::to_string(n) + " equations");
    const SparseMatrix At = A.transpose();
    const double scale = std::max(1e-300, norm1(A));
    for (int j = 0; j < n; ++j)
      for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
        if (!std::isfinite(it.value()))
          throw InputError(name + ": entry (" + std::to_string(it.row() + 1) + ", " + std::to_string(j + 1) + ") is not finite");
        if (std::abs(it.value() - At.coeff(it.row(), j)) > 1e-12 * scale)
          throw InputError(name + ": not symmetric: entries (" + std::to_string(it.row() + 1) + ", " + std::to_string(j + 1) +
                           ") and (" + std::to_string(j + 1) + ", " + std::to_string(it.row() + 1) + ") differ");
      }
    return A;
  };
  for (const MatrixModelData::Group& g : data.groups) {
    ElementMatrices e = dense_element(check_square(g.K, g.K_name), check_square(g.M, g.M_name),
                                      "group '" + g.name + "' (" + g.K_name + ")");
    e.group = g.name;
    elems.push_back(std::move(e));
  }

  // The assembled matrices, if given: the elements must add up to them; what they hold beyond the elements
  // (entries that differ by more than rounding) becomes one remainder element.
  if (data.has_assembled) {
    const SparseMatrix K = check_square(data.K, data.K_name), M = check_square(data.M, data.M_name);
    std::vector<Eigen::Triplet<double, int>> tk, tm, ta;
    for (const ElementMatrices& e : elems) {
      const int m = static_cast<int>(e.equations.size());
      for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b) {
          tk.emplace_back(e.equations[a], e.equations[b], e.K(a, b));
          tm.emplace_back(e.equations[a], e.equations[b], e.M(a, b));
          ta.emplace_back(e.equations[a], e.equations[b], std::abs(e.K(a, b)) + std::abs(e.M(a, b)));
        }
    }
    SparseMatrix SK(n, n), SM(n, n), SA(n, n);
    SK.setFromTriplets(tk.begin(), tk.end());
    SM.setFromTriplets(tm.begin(), tm.end());
    SA.setFromTriplets(ta.begin(), ta.end());
    // Relative to the entry, to the sum of absolute contributions, and to the largest entries of its row and
    // column (sqrt(s_i s_j)): exporters print 10 to 17 digits, and an entry where large contributions cancel
    // holds rounding of the row's scale, not of its own (SAP2000's influence matrices are full of such noise).
    constexpr double tol = 1e-9;
    auto difference = [&](const SparseMatrix& A, const SparseMatrix& S, double* worst) {
      Eigen::VectorXd s = Eigen::VectorXd::Zero(n);
      for (const SparseMatrix* X : {&A, &S})
        for (int j = 0; j < n; ++j)
          for (SparseMatrix::InnerIterator it(*X, j); it; ++it) s[j] = std::max(s[j], std::abs(it.value()));
      SparseMatrix R = (A - S).pruned();
      *worst = 0;
      for (int j = 0; j < n; ++j)
        for (SparseMatrix::InnerIterator it(R, j); it; ++it) {
          const double scale = std::abs(A.coeff(it.row(), j)) + SA.coeff(it.row(), j) + std::sqrt(s[it.row()] * s[j]);
          if (std::abs(it.value()) <= tol * scale) it.valueRef() = 0.0;
          else *worst = std::max(*worst, std::abs(it.value()) / std::max(scale, 1e-300));
        }
      R.prune(0.0);
      return R;
    };
    double wk = 0, wm = 0;
    const SparseMatrix RK = difference(K, SK, &wk), RM = difference(M, SM, &wm);
    if (RK.nonZeros() + RM.nonZeros() > 0) {
      ElementMatrices e = dense_element(RK, RM, "the part of " + data.K_name + " / " + data.M_name + " that the element matrices do not hold");
      e.group = "remainder";
      if (notes)
        notes->push_back(data.K_name + " / " + data.M_name + " hold more than the element matrices on " +
                         std::to_string(e.equations.size()) + " DOFs (largest relative difference " + fmt(std::max(wk, wm)) +
                         "): added as matrix element " + std::to_string(e.id) + " (group remainder)");
      elems.push_back(std::move(e));
    }
  }

  for (const Node& nd : data.nodes.empty() ? origin_nodes : data.nodes) model->add_node(nd.id, nd.x);
  for (ElementMatrices& e : elems) {
    MatrixElementData d;
    for (int q : e.equations) d.dofs.emplace_back(dofs[q].node, dofs[q].dof);
    d.nodes = std::move(e.nodes);
    d.K = std::move(e.K);
    d.M = std::move(e.M);
    model->add_element(make_matrix_element(e.id, std::move(d), e.group));
  }
}

std::vector<std::string> write_matrix_model(const Model& model, const std::string& dir, bool overwrite) {
  if (!model.finalized()) throw InputError("write_matrix_model: the model is not finalized");
  const fs::path d(dir);
  const std::vector<std::string> paths = {(d / "K.mtx").string(), (d / "M.mtx").string(), (d / "dofs.csv").string(),
                                          (d / "nodes.csv").string(), (d / "elements.txt").string(),
                                          (d / "model.yaml").string()};
  refuse_existing(paths, overwrite);
  std::error_code ec;
  fs::create_directories(d, ec);
  if (ec) throw InputError(dir + ": cannot create the folder (" + ec.message() + ")");

  const Assembler as(model);
  SparseMatrix K, M;
  as.assemble(&K, &M);
  write_matrix_market(paths[0], K, true, overwrite);
  write_matrix_market(paths[1], M, true, overwrite);

  const DofMap& dm = model.dof_map();
  std::string s = "node,dof\n";
  for (int i = 0; i < dm.num_free(); ++i)
    s += std::to_string(model.nodes()[dm.node_of(i)].id) + "," + std::string(dof_name(dm.type_of(i))) + "\n";
  write_file_atomic(paths[2], s, overwrite);

  char b[128];
  s = "id,x,y,z\n";
  for (const Node& nd : model.nodes()) {
    std::snprintf(b, sizeof b, "%d,%.17g,%.17g,%.17g\n", nd.id, nd.x.x(), nd.x.y(), nd.x.z());
    s += b;
  }
  write_file_atomic(paths[3], s, overwrite);

  s = "%%dynid element-matrices 1\n% written by dynid: per element its equations (rows of dofs.csv, 1-based) and the\n"
      "% lower triangles of its stiffness and mass matrices (global coordinates). docs/matrix-input.md\n";
  std::vector<int> eqs;
  Eigen::MatrixXd Ke, Me;
  for (int e = 0; e < model.num_elements(); ++e) {
    model.element_dofs(e, &eqs);
    model.element_matrices(e, &Ke, &Me);
    std::vector<int> keep;  // restrained DOFs (-1) are not in the exported system
    for (int k = 0; k < static_cast<int>(eqs.size()); ++k)
      if (eqs[k] >= 0) keep.push_back(k);
    if (keep.empty()) continue;
    const Element& el = model.elements()[e];
    std::string group = el.group;
    std::replace_if(group.begin(), group.end(), [](unsigned char c) { return std::isspace(c); }, '_');
    s += "element " + std::to_string(el.id) + (group.empty() ? "" : " " + group) + "\nnodes";
    for (int a = 0; a < el.num_nodes; ++a) s += " " + std::to_string(el.node_ids[a]);
    s += "\ndofs";
    for (int k : keep) s += " " + std::to_string(eqs[k] + 1);
    s += "\n";
    for (const Eigen::MatrixXd* A : {&Ke, &Me}) {
      std::string body;
      int count = 0;
      for (std::size_t j = 0; j < keep.size(); ++j)
        for (std::size_t i = j; i < keep.size(); ++i) {
          const double v = (*A)(keep[i], keep[j]);
          if (v == 0.0) continue;
          std::snprintf(b, sizeof b, "%zu %zu %.17g\n", i + 1, j + 1, v);
          body += b;
          ++count;
        }
      s += std::string(A == &Ke ? "K " : "M ") + std::to_string(count) + "\n" + body;
    }
  }
  write_file_atomic(paths[4], s, overwrite);

  s = "# The model section of a case file that reads this folder back (docs/matrix-input.md).\nmodel:\n  matrices:\n"
      "    K: K.mtx\n    M: M.mtx\n    dofs: dofs.csv\n    nodes: nodes.csv\n    elements: elements.txt\n";
  if (model.free_free()) s += "  supports: free\n";
  write_file_atomic(paths[5], s, overwrite);
  return paths;
}

}  // namespace dynid
