#include "dynid/io/matrix_market.hpp"
#include "dynid/io/limits.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "dynid/io/output.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/text_util.hpp"

namespace dynid {

void write_matrix_market(const std::string& path, const SparseMatrix& A, bool symmetric, bool overwrite) {
  std::string out;
  long long count = 0;
  for (int j = 0; j < A.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(A, j); it; ++it)
      if (!symmetric || it.row() >= j) ++count;
  out.reserve(static_cast<std::size_t>(count) * 40 + 200);
  out += symmetric ? "%%MatrixMarket matrix coordinate real symmetric\n" : "%%MatrixMarket matrix coordinate real general\n";
  out += "% written by dynid\n";
  out += std::to_string(A.rows()) + " " + std::to_string(A.cols()) + " " + std::to_string(count) + "\n";
  char buf[64];
  for (int j = 0; j < A.outerSize(); ++j)
    for (SparseMatrix::InnerIterator it(A, j); it; ++it) {
      if (symmetric && it.row() < j) continue;
      const int len = std::snprintf(buf, sizeof(buf), "%d %d %.17g\n", static_cast<int>(it.row()) + 1, j + 1, it.value());
      out.append(buf, static_cast<std::size_t>(len));
    }
  write_file_atomic(path, out, overwrite);
}

SparseMatrix read_matrix_market(const std::string& path, const ReaderLimits& limits) {
  return parse_matrix_market(internal::read_file_bytes(path), path, limits);
}

SparseMatrix parse_matrix_market(const std::string& text, const std::string& path, const ReaderLimits& limits) {
  std::istringstream in(text);
  std::string line;
  long long lineno = 0;
  auto fail = [&](const std::string& what) -> void {
    throw InputError(path + ":" + std::to_string(lineno) + ": " + what);
  };
  if (!std::getline(in, line)) {
    lineno = 1;
    fail("empty file; expected a '%%MatrixMarket matrix coordinate ...' header");
  }
  ++lineno;
  std::string lower = line;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  std::istringstream hs(lower);
  std::string banner, object, format, field, symmetry;
  hs >> banner >> object >> format >> field >> symmetry;
  if (banner != "%%matrixmarket" || object != "matrix") fail("not a Matrix Market file (first line: '" + line + "')");
  if (format != "coordinate") fail("only the sparse 'coordinate' format is supported, not '" + format + "'");
  if (field != "real" && field != "integer" && field != "double")
    fail("only real matrices are supported, not '" + field + "'");
  const bool sym = symmetry == "symmetric";
  if (!sym && symmetry != "general") fail("symmetry '" + symmetry + "' is not supported (use general or symmetric)");
  long long rows = -1, cols = -1, nnz = -1;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line[0] == '%') continue;
    std::istringstream ss(line);
    if (!(ss >> rows >> cols >> nnz)) fail("expected 'rows cols entries'");
    break;
  }
  if (rows < 0) fail("missing size line 'rows cols entries'");
  // The sparse matrix allocates per column whatever the entries, so the declared size must be bounded.
  const long long max_dimension = limits.max_matrix_dimension;
  if (rows <= 0 || cols <= 0 || nnz < 0 || rows > max_dimension || cols > max_dimension)
    fail("invalid sizes " + std::to_string(rows) + " x " + std::to_string(cols) + ", " + std::to_string(nnz) +
         " entries (at most " + std::to_string(max_dimension) + " rows and columns)");
  if (sym && rows != cols)
    fail("a symmetric matrix must be square, not " + std::to_string(rows) + " x " + std::to_string(cols));
  if (nnz > rows * cols) fail("more entries (" + std::to_string(nnz) + ") than a " + std::to_string(rows) + " x " + std::to_string(cols) + " matrix holds");
  std::vector<Eigen::Triplet<double, int>> t;
  // The declared count is not trusted for the allocation: an entry needs at least 6 bytes ("1 1 1\n").
  t.reserve(static_cast<std::size_t>(std::min<long long>(nnz, static_cast<long long>(text.size() / 6))) * (sym ? 2 : 1));
  long long read = 0;
  while (read < nnz && std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line[0] == '%') continue;
    const char* p = line.c_str();
    char* end = nullptr;
    const long long i = std::strtoll(p, &end, 10);
    if (end == p) fail("expected 'row col value'");
    p = end;
    const long long j = std::strtoll(p, &end, 10);
    if (end == p) fail("expected 'row col value'");
    p = end;
    const double v = std::strtod(p, &end);
    if (end == p) fail("expected 'row col value'");
    if (i < 1 || i > rows || j < 1 || j > cols) fail("entry (" + std::to_string(i) + ", " + std::to_string(j) + ") is outside the " + std::to_string(rows) + " x " + std::to_string(cols) + " matrix");
    if (!std::isfinite(v)) fail("non-finite value");
    if (sym && i < j) fail("a symmetric file must list the lower triangle only (row >= col)");
    t.emplace_back(static_cast<int>(i - 1), static_cast<int>(j - 1), v);
    if (sym && i != j) t.emplace_back(static_cast<int>(j - 1), static_cast<int>(i - 1), v);
    ++read;
  }
  if (read < nnz) fail("file ends after " + std::to_string(read) + " of " + std::to_string(nnz) + " entries");
  SparseMatrix A(static_cast<int>(rows), static_cast<int>(cols));
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

}  // namespace dynid
