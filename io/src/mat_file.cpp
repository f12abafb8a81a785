// MATLAB .mat files (dynid/io/mat_file.hpp): v5/v7 through dynid's own reader (internal/mat_reader.hpp), v4 and
// v7.3 (HDF5) through libmatio.
#include "dynid/io/mat_file.hpp"

#include <matio.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <mutex>
#include <new>

#include "dynid/io/limits.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/mat_reader.hpp"
#include "internal/mat_v5_check.hpp"
#include "internal/text_util.hpp"

namespace dynid {

using internal::dims_text;
using internal::MatArray;

namespace {

// matio reports problems through a log function; the default one prints. dynid's libraries never print, so the
// last message is kept (per thread) and goes into the InputError instead.
thread_local std::string g_last_message;
void log_to_buffer(int, char* message) { g_last_message = message ? message : ""; }
void quiet_matio() {
  static std::once_flag once;
  std::call_once(once, [] { Mat_LogInitFunc("dynid", log_to_buffer); });
}
std::string matio_says() {
  std::string m = g_last_message;
  g_last_message.clear();
  return m.empty() ? "" : " (" + m + ")";
}

struct VarDeleter {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using Var = std::unique_ptr<matvar_t, VarDeleter>;

const char* class_name(const matvar_t* v) {
  if (v->isLogical) return "logical";
  switch (v->class_type) {
    case MAT_C_EMPTY: return "empty";
    case MAT_C_CELL: return "cell";
    case MAT_C_STRUCT: return "struct";
    case MAT_C_OBJECT: return "object";
    case MAT_C_CHAR: return "char";
    case MAT_C_SPARSE: return "sparse";
    case MAT_C_DOUBLE: return "double";
    case MAT_C_SINGLE: return "single";
    case MAT_C_INT8: return "int8";
    case MAT_C_UINT8: return "uint8";
    case MAT_C_INT16: return "int16";
    case MAT_C_UINT16: return "uint16";
    case MAT_C_INT32: return "int32";
    case MAT_C_UINT32: return "uint32";
    case MAT_C_INT64: return "int64";
    case MAT_C_UINT64: return "uint64";
    case MAT_C_FUNCTION: return "function";
    default: return "opaque";
  }
}

std::vector<std::size_t> dims_of(const matvar_t* v) {
  std::vector<std::size_t> d;
  for (int k = 0; k < v->rank && v->dims; ++k) d.push_back(v->dims[k]);
  return d;
}

// Number of elements, or -1 when the product exceeds `max` (ReaderLimits::max_mat_elements), or one dimension does:
// an empty array's other dimensions are sizes too (fuzz_mat, 2026-11-28: a v4 file's 0 x -1560281086 array read as
// 0 x 18446744072149270530, which a matrix cannot be resized to).
long long numel(const std::vector<std::size_t>& dims, long long max) {
  long double n = 1;
  for (std::size_t d : dims) {
    if (d > static_cast<std::size_t>(max)) return -1;
    n *= static_cast<long double>(d);
  }
  if (n > static_cast<long double>(max)) return -1;
  return static_cast<long long>(n);
}

int type_size(matio_types t) {
  switch (t) {
    case MAT_T_INT8: case MAT_T_UINT8: return 1;
    case MAT_T_INT16: case MAT_T_UINT16: return 2;
    case MAT_T_INT32: case MAT_T_UINT32: case MAT_T_SINGLE: return 4;
    case MAT_T_DOUBLE: case MAT_T_INT64: case MAT_T_UINT64: return 8;
    default: return 0;
  }
}

// Element k of a numeric buffer of type t, as a double.
double element(const void* p, matio_types t, std::size_t k) {
  switch (t) {
    case MAT_T_INT8: return static_cast<const std::int8_t*>(p)[k];
    case MAT_T_UINT8: return static_cast<const std::uint8_t*>(p)[k];
    case MAT_T_INT16: return static_cast<const std::int16_t*>(p)[k];
    case MAT_T_UINT16: return static_cast<const std::uint16_t*>(p)[k];
    case MAT_T_INT32: return static_cast<const std::int32_t*>(p)[k];
    case MAT_T_UINT32: return static_cast<const std::uint32_t*>(p)[k];
    case MAT_T_SINGLE: return static_cast<const float*>(p)[k];
    case MAT_T_DOUBLE: return static_cast<const double*>(p)[k];
    case MAT_T_INT64: return static_cast<double>(static_cast<const std::int64_t*>(p)[k]);
    case MAT_T_UINT64: return static_cast<double>(static_cast<const std::uint64_t*>(p)[k]);
    default: return std::numeric_limits<double>::quiet_NaN();
  }
}

std::string int_text(double v) { return internal::format_number(v, 17); }

// A variable libmatio read (v7.3) as dynid's array: numeric data as doubles, sparse structure, char codes and
// cells, each checked against the bytes libmatio holds (complex data are not copied: dynid refuses them).
MatArray from_matio(const matvar_t* v, const std::string& who, long long max, int depth) {
  MatArray a;
  a.name = v->name ? v->name : "";
  a.type = class_name(v);
  a.dims = dims_of(v);
  a.complex = v->isComplex != 0;
  const long long n = numel(a.dims, max);
  if (n < 0) throw InputError(who + ": a " + dims_text(a.dims) + " array is larger than dynid reads");
  const int ts = type_size(v->data_type);
  if (a.complex) return a;
  if (v->class_type == MAT_C_SPARSE) {
    const auto* s = static_cast<const mat_sparse_t*>(v->data);
    if (!s || !s->jc || (s->nir > 0 && !s->ir) || (s->ndata > 0 && (!s->data || ts == 0)))
      throw InputError(who + ": inconsistent sparse structure");
    a.ir.assign(s->ir, s->ir + s->nir);
    a.jc.assign(s->jc, s->jc + s->njc);
    a.values.resize(s->ndata);
    for (std::size_t k = 0; k < a.values.size(); ++k) a.values[k] = element(s->data, v->data_type, k);
  } else if (v->class_type >= MAT_C_DOUBLE && v->class_type <= MAT_C_UINT64) {
    if (n > 0 && (!v->data || ts == 0 || v->nbytes < static_cast<std::size_t>(n) * static_cast<std::size_t>(ts)))
      throw InputError(who + ": its data is incomplete (" + std::to_string(v->nbytes) + " bytes for " +
                       std::to_string(n) + " values)");
    a.values.resize(static_cast<std::size_t>(n));
    for (std::size_t k = 0; k < a.values.size(); ++k) a.values[k] = element(v->data, v->data_type, k);
  } else if (v->class_type == MAT_C_CHAR) {
    const int size = v->data_size > 0 ? v->data_size : 1;
    if (n > 0 && (!v->data || v->nbytes < static_cast<std::size_t>(n) * static_cast<std::size_t>(size)))
      throw InputError(who + ": its text is incomplete");
    a.text.resize(static_cast<std::size_t>(n));
    for (std::size_t k = 0; k < a.text.size(); ++k)
      a.text[k] = size == 1   ? static_cast<const unsigned char*>(v->data)[k]
                  : size == 2 ? static_cast<const std::uint16_t*>(v->data)[k]
                              : static_cast<const std::uint32_t*>(v->data)[k];
  } else if (v->class_type == MAT_C_CELL) {
    if (depth >= 64) throw InputError(who + " is nested more than 64 levels deep (dynid reads at most that)");
    for (long long k = 0; k < n; ++k) {
      const std::string cell = who + " cell " + std::to_string(k + 1);
      const matvar_t* c = Mat_VarGetCell(const_cast<matvar_t*>(v), static_cast<int>(k));
      if (!c) throw InputError(cell + " is missing");
      a.cells.push_back(from_matio(c, cell, max, depth + 1));
    }
  }
  return a;
}

}  // namespace

struct MatFile::Handle {
  mat_t* mat = nullptr;                      // v7.3 (HDF5): libmatio
  std::unique_ptr<internal::MatReader> own;  // v5 / v7 and v4: dynid's readers
  ~Handle() {
    if (mat) Mat_Close(mat);
  }
  [[noreturn]] void fail(const std::string& path, const std::string& name, const std::string& what) const {
    throw InputError(path + ": variable '" + name + "': " + what);
  }
  [[noreturn]] void missing(const std::string& path, const std::string& name, const std::string& what,
                            const MatFile& file) const {
    g_last_message.clear();
    throw InputError(path + ": no variable '" + name + "' (" + what + "); the file holds: " + file.listing());
  }
  // The variable with its data, checked for a consistent size; throws naming it.
  MatArray read(const std::string& path, const std::string& name, const std::string& what, const MatFile& file) const {
    const long long max = file.limits().max_mat_elements;
    // A dense array's elements count against max_mat_elements; a sparse matrix's rows and columns against
    // max_matrix_dimension, as a Matrix Market file's do (its nonzeros are counted from the data).
    const auto check_size = [&](const std::string& type, const std::vector<std::size_t>& dims) {
      const auto largest = static_cast<double>(dims.empty() ? 0 : *std::max_element(dims.begin(), dims.end()));
      if (type == "sparse" && largest > static_cast<double>(file.limits().max_matrix_dimension))
        fail(path, name,
             "a sparse " + dims_text(dims) + " matrix is larger than dynid reads (" +
                 limit_text(static_cast<double>(file.limits().max_matrix_dimension)) + " rows or columns)");
      if (type != "sparse" && numel(dims, max) < 0)
        fail(path, name,
             "a " + dims_text(dims) + " array is larger than dynid reads (" + limit_text(static_cast<double>(max)) +
                 " elements)");
    };
    if (own) {
      const std::vector<MatArray>& vars = own->variables();
      for (std::size_t k = 0; k < vars.size(); ++k) {
        if (vars[k].name != name) continue;
        check_size(vars[k].type, vars[k].dims);
        return own->read(k);
      }
      missing(path, name, what, file);
    }
    Mat_Rewind(mat);
    Var info(Mat_VarReadInfo(mat, name.c_str()));
    if (!info) missing(path, name, what, file);
    const std::vector<std::size_t> dims = dims_of(info.get());
    check_size(class_name(info.get()), dims);
    // A damaged header can declare far more data than the file holds, and libmatio allocates what it declares
    // before reading. Data never exceeds the file by more than zlib's largest ratio (about 1032:1); sparse arrays
    // hold fewer values than their dimensions.
    if (info->class_type != MAT_C_SPARSE) {
      std::error_code ec;
      const double file_bytes = static_cast<double>(std::filesystem::file_size(path, ec));
      const double bytes =
          static_cast<double>(numel(dims, max)) * static_cast<double>(Mat_SizeOfClass(info->class_type));
      if (!ec && bytes > internal::max_inflated_bytes(file_bytes))
        fail(path, name,
             "declares a " + dims_text(dims) + " array (" + limit_text(bytes) + " bytes) in a file of " +
                 limit_text(file_bytes) + " bytes: the file is damaged; save it again from MATLAB or SciPy");
    }
    info.reset();
    Mat_Rewind(mat);
    Var v(Mat_VarRead(mat, name.c_str()));
    if (!v) fail(path, name, "cannot be read; the file is damaged or uses a feature dynid does not read" + matio_says());
    return from_matio(v.get(), path + ": variable '" + name + "'", max, 0);
  }
};

MatFile::MatFile(const std::string& path, const ReaderLimits& limits)
    : path_(path), limits_(limits), h_(std::make_unique<Handle>()) {
  quiet_matio();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": cannot open the file (no such file)");
  const unsigned version = internal::mat_header_version(path);
  if (version == 0x0100) {
    // The walk names what is wrong with a damaged variable before anything is listed (internal/mat_v5_check.hpp);
    // the reader then reads only what the file holds.
    bool unsupported = false;
    const std::string why = internal::v5_damage(path, &unsupported);
    if (!why.empty())
      throw InputError(
          path + ": " + why +
          (unsupported ? "; save the file without it" : ": the file is damaged; save it again from MATLAB or SciPy"));
    h_->own = std::make_unique<internal::MatV5Reader>(path);
    return;
  }
  if (version != 0x0200) {  // no v5 / v7.3 header: a v4 file, or no MAT-file (the reader says which)
    h_->own = std::make_unique<internal::MatV4Reader>(path);
    return;
  }
  h_->mat = Mat_Open(path.c_str(), MAT_ACC_RDONLY);
  if (!h_->mat || Mat_GetVersion(h_->mat) != MAT_FT_MAT73)
    throw InputError(path + ": not a MATLAB .mat file (v4, v5/v7 or v7.3)" + matio_says() +
                     "; save it from MATLAB with save(..., '-v7') or '-v7.3', or from Python with scipy.io.savemat");
}

MatFile::~MatFile() = default;

std::string MatFile::version() const {
  if (h_->own) return h_->own->version();
  return "MATLAB 7.3 (HDF5)";
}

std::vector<MatFile::Info> MatFile::variables() const {
  std::vector<Info> out;
  if (h_->own) {
    for (const MatArray& a : h_->own->variables()) out.push_back({a.name, a.type, a.dims, a.complex});
    return out;
  }
  Mat_Rewind(h_->mat);
  // Bounded: a damaged file must not list forever.
  for (int k = 0; k < 1000000; ++k) {
    Var v(Mat_VarReadNextInfo(h_->mat));
    if (!v) break;
    out.push_back({v->name ? v->name : "", class_name(v.get()), dims_of(v.get()), v->isComplex != 0});
  }
  g_last_message.clear();
  return out;
}

bool MatFile::has(const std::string& name) const {
  for (const Info& i : variables())
    if (i.name == name) return true;
  return false;
}

std::string MatFile::listing() const {
  std::string s;
  const std::vector<Info> vars = variables();
  for (std::size_t k = 0; k < vars.size() && k < 40; ++k)
    s += (k ? ", " : "") + vars[k].name + " (" + dims_text(vars[k].dims) + " " + vars[k].type +
         (vars[k].complex ? " complex" : "") + ")";
  if (vars.size() > 40) s += ", ... (" + std::to_string(vars.size()) + " variables)";
  return s.empty() ? "no variables" : s;
}

namespace {

// The column pointers and row indices of sparse array `a` (rows x cols), checked: throws naming `who`.
void check_sparse(const MatArray& a, std::size_t rows, std::size_t cols, const std::string& who) {
  const std::size_t nnz = std::min(a.ir.size(), a.values.size());
  if (a.jc.size() != cols + 1)
    throw InputError(who + ": inconsistent sparse structure (column pointers " + std::to_string(a.jc.size()) + " for " +
                     std::to_string(cols) + " columns)");
  for (std::size_t j = 0; j < cols; ++j) {
    if (a.jc[j] > a.jc[j + 1] || a.jc[j + 1] > nnz)
      throw InputError(who + ": inconsistent sparse structure (column " + std::to_string(j + 1) + ")");
    for (std::uint32_t k = a.jc[j]; k < a.jc[j + 1]; ++k)
      if (a.ir[k] >= rows)
        throw InputError(who + ": sparse row index " + std::to_string(a.ir[k] + 1ull) + " outside " +
                         std::to_string(rows) + " rows");
  }
}

// An array's real numeric content as a dense matrix (rows x cols), checked; `who` names it; `max`: numel's.
Eigen::MatrixXd dense_of(const MatArray& v, const std::string& who, long long max) {
  if (v.complex) throw InputError(who + " is complex; real values are needed");
  if (v.dims.size() > 2) throw InputError(who + " is a " + dims_text(v.dims) + " array; a matrix (2-D) is needed");
  if (v.type != "sparse" && !v.numeric())
    throw InputError(who + " is a " + v.type + " (" + dims_text(v.dims) + "); a numeric matrix is needed");
  if (numel(v.dims, max) < 0) throw InputError(who + ": a " + dims_text(v.dims) + " array is larger than dynid reads");
  const std::size_t rows = v.dims.size() >= 1 ? v.dims[0] : 0, cols = v.dims.size() >= 2 ? v.dims[1] : 1;
  Eigen::MatrixXd A;
  try {
    A.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
  } catch (const std::bad_alloc&) {
    throw InputError(who + " is a " + dims_text(v.dims) + " matrix; held dense it does not fit in memory");
  }
  if (v.type == "sparse") {
    check_sparse(v, rows, cols, who);
    A.setZero();
    for (std::size_t j = 0; j < cols; ++j)
      for (std::uint32_t k = v.jc[j]; k < v.jc[j + 1]; ++k) A(v.ir[k], static_cast<Eigen::Index>(j)) += v.values[k];
    return A;
  }
  if (v.values.size() != rows * cols)
    throw InputError(who + ": its data is incomplete (" + std::to_string(v.values.size()) + " values for " +
                     std::to_string(rows * cols) + ")");
  std::copy(v.values.begin(), v.values.end(), A.data());
  return A;
}

void require_finite(const Eigen::MatrixXd& A, const std::string& who) {
  for (Eigen::Index j = 0; j < A.cols(); ++j)
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      if (!std::isfinite(A(i, j)))
        throw InputError(who + ": entry (" + std::to_string(i + 1) + ", " + std::to_string(j + 1) + ") is not finite");
}

std::string who(const std::string& path, const std::string& name, const std::string& what) {
  return path + ": variable '" + name + "' (" + what + ")";
}

std::vector<std::string> strings_of(const MatArray& v, const std::string& w, long long max) {
  std::vector<std::string> out;
  if (v.type == "char") {
    if (v.dims.size() != 2)
      throw InputError(w + " is a " + dims_text(v.dims) + " char array; one string per row is needed");
    const std::size_t rows = v.dims[0], cols = v.dims[1];
    // Each row is a string even when the text has no columns: a row counts as one element at least (fuzz_mat,
    // 2026-11-28: a cell holding a 10^8 x 0 char array, 3.2 GB of empty strings).
    if (numel(v.dims, max) < 0 ||
        static_cast<long double>(rows) * static_cast<long double>(std::max<std::size_t>(cols, 1)) >
            static_cast<long double>(max))
      throw InputError(w + " is a " + dims_text(v.dims) + " char array, larger than dynid reads (" +
                       limit_text(static_cast<double>(max)) + " elements)");
    if (v.text.size() != rows * cols) throw InputError(w + ": its text is incomplete");
    for (std::size_t i = 0; i < rows; ++i) {
      std::string s;
      for (std::size_t j = 0; j < cols; ++j) {
        const std::uint32_t code = v.text[i + j * rows];
        s += code < 128 ? static_cast<char>(code) : '?';
      }
      while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
      out.push_back(s);
    }
    return out;
  }
  if (v.type == "cell") {
    for (std::size_t k = 0; k < v.cells.size(); ++k) {
      const std::vector<std::string> s = strings_of(v.cells[k], w + " cell " + std::to_string(k + 1), max);
      out.push_back(s.empty() ? std::string() : s[0]);
    }
    return out;
  }
  throw InputError(w + " is a " + v.type + "; text is needed (a char array or a cell array of strings)");
}

}  // namespace

Eigen::MatrixXd MatFile::matrix(const std::string& name, const std::string& what) const {
  const MatArray v = h_->read(path_, name, what, *this);
  Eigen::MatrixXd A = dense_of(v, who(path_, name, what), limits_.max_mat_elements);
  require_finite(A, who(path_, name, what));
  return A;
}

Eigen::VectorXd MatFile::vector(const std::string& name, const std::string& what) const {
  const Eigen::MatrixXd A = matrix(name, what);
  if (A.rows() != 1 && A.cols() != 1)
    throw InputError(who(path_, name, what) + " is " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                     "; a vector (1 x n or n x 1) is needed");
  return A.rows() == 1 ? Eigen::VectorXd(A.row(0).transpose()) : Eigen::VectorXd(A.col(0));
}

SparseMatrix MatFile::sparse(const std::string& name, const std::string& what) const {
  const MatArray x = h_->read(path_, name, what, *this);
  const std::string w = who(path_, name, what);
  if (x.dims.size() != 2 || x.dims[0] != x.dims[1])
    throw InputError(w + " is " + dims_text(x.dims) + "; a square matrix is needed");
  if (x.type != "sparse") {
    const Eigen::MatrixXd D = dense_of(x, w, limits_.max_mat_elements);
    require_finite(D, w);
    SparseMatrix A = D.sparseView();
    A.makeCompressed();
    return A;
  }
  if (x.complex) throw InputError(w + " is complex; real values are needed");
  const std::size_t n = x.dims[0];
  check_sparse(x, n, n, w);
  std::vector<Eigen::Triplet<double, int>> t;
  t.reserve(x.jc[n]);
  for (std::size_t j = 0; j < n; ++j)
    for (std::uint32_t k = x.jc[j]; k < x.jc[j + 1]; ++k) {
      if (!std::isfinite(x.values[k]))
        throw InputError(w + ": entry (" + std::to_string(x.ir[k] + 1ull) + ", " + std::to_string(j + 1) +
                         ") is not finite");
      t.emplace_back(static_cast<int>(x.ir[k]), static_cast<int>(j), x.values[k]);
    }
  SparseMatrix A(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

double MatFile::scalar(const std::string& name, const std::string& what) const {
  const Eigen::MatrixXd A = matrix(name, what);
  if (A.size() != 1)
    throw InputError(who(path_, name, what) + " is " + std::to_string(A.rows()) + " x " + std::to_string(A.cols()) + "; a number is needed");
  return A(0, 0);
}

std::vector<std::string> MatFile::strings(const std::string& name, const std::string& what) const {
  return strings_of(h_->read(path_, name, what, *this), who(path_, name, what), limits_.max_mat_elements);
}

std::vector<Eigen::MatrixXd> MatFile::matrices(const std::string& name, const std::string& what) const {
  const MatArray v = h_->read(path_, name, what, *this);
  const std::string w = who(path_, name, what);
  if (v.type != "cell") throw InputError(w + " is a " + v.type + "; a cell array of matrices is needed");
  std::vector<Eigen::MatrixXd> out;
  for (std::size_t k = 0; k < v.cells.size(); ++k) {
    const std::string wc = w + " cell " + std::to_string(k + 1);
    out.push_back(dense_of(v.cells[k], wc, limits_.max_mat_elements));
    require_finite(out.back(), wc);
  }
  return out;
}

// ---- the three things dynid reads from .mat files ---------------------------------------------------------------

namespace {

// DOF rows from an n x 2 numeric table [node, dof 1..6] or from labels.
std::vector<DofRow> dof_rows(const MatFile& f, const std::string& var, const std::string& what) {
  const Eigen::MatrixXd D = f.matrix(var, what);
  const std::string w = who(f.path(), var, what);
  if (D.cols() != 2) throw InputError(w + " is " + std::to_string(D.rows()) + " x " + std::to_string(D.cols()) + "; n x 2 [node, dof 1..6] is needed");
  std::vector<DofRow> rows;
  for (Eigen::Index i = 0; i < D.rows(); ++i) {
    const double node = D(i, 0), dof = D(i, 1);
    if (node != std::floor(node) || std::abs(node) > 2e9)
      throw InputError(w + ": row " + std::to_string(i + 1) + ": node " + int_text(node) + " is not an integer id");
    if (dof != std::floor(dof) || dof < 1 || dof > 6)
      throw InputError(w + ": row " + std::to_string(i + 1) + ": DOF " + int_text(dof) + " is not 1..6 (ux, uy, uz, rx, ry, rz)");
    rows.push_back({static_cast<int>(node), static_cast<Dof>(static_cast<int>(dof) - 1)});
  }
  return rows;
}

}  // namespace

MatrixModelData read_mat_matrix_model(const MatModelNames& n, std::vector<std::string>* notes,
                                      const ReaderLimits& limits) {
  const MatFile f(n.file, limits);
  MatrixModelData d;
  if (n.K.empty() != n.M.empty())
    throw InputError(n.file + ": give both K and M (the assembled matrices), or neither");
  if (n.groups.empty() && n.element_K.empty())
    throw InputError(n.file + ": name group matrices (groups:) or element matrices (elements:) of the model");
  if (n.K.empty() && n.element_M.empty() && std::all_of(n.groups.begin(), n.groups.end(), [](const auto& g) { return g.M.empty(); }))
    throw InputError(n.file + ": no mass: name the assembled M (with K), group masses or element masses");
  // Size of the system: from the DOF table, else the first matrix.
  std::vector<SparseMatrix> group_K(n.groups.size()), group_M(n.groups.size());
  for (std::size_t g = 0; g < n.groups.size(); ++g) {
    if (n.groups[g].K.empty() && n.groups[g].M.empty())
      throw InputError(n.file + ": group '" + n.groups[g].name + "' names neither a stiffness nor a mass variable");
    if (!n.groups[g].K.empty()) group_K[g] = f.sparse(n.groups[g].K, "stiffness of group '" + n.groups[g].name + "'");
    if (!n.groups[g].M.empty()) group_M[g] = f.sparse(n.groups[g].M, "mass of group '" + n.groups[g].name + "'");
  }
  if (!n.K.empty()) {
    d.has_assembled = true;
    d.K = f.sparse(n.K, "the assembled stiffness matrix K");
    d.M = f.sparse(n.M, "the assembled mass matrix M");
    d.K_name = n.file + ": variable '" + n.K + "'";
    d.M_name = n.file + ": variable '" + n.M + "'";
  }
  Eigen::Index size = -1;
  std::vector<Eigen::MatrixXd> element_eqs;  // read first: without a DOF table they give the number of equations
  if (!n.element_dofs.empty()) element_eqs = f.matrices(n.element_dofs, "element equations (1-based)");
  if (!n.dofs.empty()) {
    d.dofs = dof_rows(f, n.dofs, "the DOF table: [node, dof 1..6] per equation");
    d.dofs_name = n.file + ": variable '" + n.dofs + "'";
  } else {
    size = d.has_assembled ? d.K.rows() : !n.groups.empty() ? std::max(group_K[0].rows(), group_M[0].rows()) : -1;
    for (const Eigen::MatrixXd& q : element_eqs)
      if (q.size() > 0 && size < 0) size = 0;
    if (size == 0)
      for (const Eigen::MatrixXd& q : element_eqs)
        for (Eigen::Index k = 0; k < q.size(); ++k)
          if (q.data()[k] >= 1 && q.data()[k] <= 2e9) size = std::max<Eigen::Index>(size, static_cast<Eigen::Index>(q.data()[k]));
    if (size <= 0) throw InputError(n.file + ": name the DOF table (dofs:), or K and M or groups (their size gives the equations)");
    for (Eigen::Index i = 0; i < size; ++i) d.dofs.push_back({static_cast<int>(i + 1), Dof::UX});
    d.dofs_name = n.file + " (no DOF table: equation i is ux of node i)";
    if (notes)
      notes->push_back(n.file + ": no DOF table (dofs:): each of the " + std::to_string(size) +
                       " equations is DOF ux of its own node (ids 1..n)");
  }
  if (!n.nodes.empty()) {
    const Eigen::MatrixXd N = f.matrix(n.nodes, "the node table: [id, x, y(, z)] per node");
    const std::string w = who(n.file, n.nodes, "the node table");
    if (N.cols() != 3 && N.cols() != 4)
      throw InputError(w + " is " + std::to_string(N.rows()) + " x " + std::to_string(N.cols()) + "; [id, x, y] or [id, x, y, z] per row is needed");
    for (Eigen::Index i = 0; i < N.rows(); ++i) {
      if (N(i, 0) != std::floor(N(i, 0)) || std::abs(N(i, 0)) > 2e9)
        throw InputError(w + ": row " + std::to_string(i + 1) + ": id " + int_text(N(i, 0)) + " is not an integer");
      Node nd;
      nd.id = static_cast<int>(N(i, 0));
      nd.x = Eigen::Vector3d(N(i, 1), N(i, 2), N.cols() == 4 ? N(i, 3) : 0.0);
      d.nodes.push_back(nd);
    }
    d.nodes_name = n.file + ": variable '" + n.nodes + "'";
  }
  for (std::size_t g = 0; g < n.groups.size(); ++g)
    d.groups.push_back({n.groups[g].name, n.groups[g].K.empty() ? "" : n.file + ": variable '" + n.groups[g].K + "'",
                        n.groups[g].M.empty() ? "" : n.file + ": variable '" + n.groups[g].M + "'", std::move(group_K[g]),
                        std::move(group_M[g])});
  if (!n.element_K.empty()) {
    if (n.element_dofs.empty()) throw InputError(n.file + ": element matrices need their equations (elements: dofs: VAR, a cell array)");
    const std::vector<Eigen::MatrixXd> Ke = f.matrices(n.element_K, "element stiffness matrices");
    const std::vector<Eigen::MatrixXd> Me = n.element_M.empty() ? std::vector<Eigen::MatrixXd>() : f.matrices(n.element_M, "element mass matrices");
    const std::vector<Eigen::MatrixXd>& De = element_eqs;
    std::vector<std::string> groups;
    if (!n.element_groups.empty()) groups = f.strings(n.element_groups, "element groups");
    if (De.size() != Ke.size() || (!Me.empty() && Me.size() != Ke.size()) || (!groups.empty() && groups.size() != Ke.size()))
      throw InputError(n.file + ": element variables disagree: " + std::to_string(Ke.size()) + " stiffness, " + std::to_string(Me.size()) +
                       " mass matrices, " + std::to_string(De.size()) + " equation lists, " + std::to_string(groups.size()) + " groups");
    const auto neq = static_cast<double>(d.dofs.size());
    for (std::size_t e = 0; e < Ke.size(); ++e) {
      ElementMatrices em;
      em.id = static_cast<int>(e + 1);
      const std::string w = n.file + ": element " + std::to_string(e + 1);
      const Eigen::MatrixXd& q = De[e];
      if (q.rows() != 1 && q.cols() != 1) throw InputError(w + ": its equations ('" + n.element_dofs + "') must be a vector");
      for (Eigen::Index k = 0; k < q.size(); ++k) {
        const double x = q.data()[k];
        if (x != std::floor(x) || x < 1 || x > neq)
          throw InputError(w + ": equation " + int_text(x) + " is not 1.." + std::to_string(d.dofs.size()));
        em.equations.push_back(static_cast<int>(x) - 1);
      }
      const auto m = static_cast<Eigen::Index>(em.equations.size());
      if (Ke[e].rows() != m || Ke[e].cols() != m || (!Me.empty() && (Me[e].rows() != m || Me[e].cols() != m)))
        throw InputError(w + ": K and M must be " + std::to_string(m) + " x " + std::to_string(m) + " for its " + std::to_string(m) + " equations");
      if (m > limits.max_element_dofs)
        throw InputError(w + ": " + std::to_string(m) + " DOFs; an element has at most " +
                         limit_text(limits.max_element_dofs));
      em.K = Ke[e];
      em.M = Me.empty() ? Eigen::MatrixXd::Zero(m, m) : Me[e];
      if (!groups.empty()) em.group = groups[e];
      d.elements.push_back(std::move(em));
    }
  }
  return d;
}

Recording read_mat_recording(const MatRecordingNames& n, const ReaderLimits& limits) {
  const MatFile f(n.file, limits);
  Recording r;
  r.source = n.file;
  r.sample_rate_hz = n.sample_rate_hz > 0 ? n.sample_rate_hz : f.scalar(n.sample_rate, "the sampling rate in Hz");
  if (!(r.sample_rate_hz > 0))
    throw InputError(who(n.file, n.sample_rate, "the sampling rate") + " is " + int_text(r.sample_rate_hz) + "; it must be > 0 (Hz)");
  std::vector<Eigen::MatrixXd> records;
  bool cell = false;
  for (const MatFile::Info& i : f.variables())
    if (i.name == n.data) cell = i.type == "cell";
  if (cell) records = f.matrices(n.data, "records: channels x samples each");
  else records.push_back(f.matrix(n.data, "the recording: channels x samples"));
  std::vector<std::string> labels = n.channel_labels;
  if (labels.empty() && f.has(n.channels)) labels = f.strings(n.channels, "channel DOF labels");
  const Eigen::Index channels = records.empty() ? 0 : records[0].rows();
  if (labels.empty()) {
    throw InputError(n.file + ": name the channels' DOFs (a variable '" + n.channels + "' with one label such as 13uy per row of '" +
                     n.data + "', or channels: in the case file)");
  }
  if (static_cast<Eigen::Index>(labels.size()) != channels) {
    const bool transposed = !records.empty() && static_cast<Eigen::Index>(labels.size()) == records[0].cols();
    throw InputError(who(n.file, n.data, "the recording") + " has " + std::to_string(channels) + " rows but " +
                     std::to_string(labels.size()) + " channel labels are given" +
                     (transposed ? "; dynid reads channels x samples: transpose it (data.')" : ""));
  }
  Quantity q = Quantity::kAcceleration;
  for (Quantity x : {Quantity::kDisplacement, Quantity::kVelocity, Quantity::kAcceleration, Quantity::kOther})
    if (n.quantity == to_string(x)) q = x;
  for (const std::string& l : labels) {
    Channel c;
    double sign = 1;
    if (!parse_dof_label(l, &c.dof, &sign))
      throw InputError(n.file + ": channel label '" + l + "' is not a DOF label (e.g. 13uy, 13+Y)");
    c.name = l;
    c.input = std::find(n.inputs.begin(), n.inputs.end(), l) != n.inputs.end();
    c.quantity = c.input ? Quantity::kForce : q;
    r.channels.push_back(c);
  }
  for (const std::string& in : n.inputs)
    if (std::find(labels.begin(), labels.end(), in) == labels.end())
      throw InputError(n.file + ": input channel '" + in + "' is not one of the channel labels");
  for (std::size_t k = 0; k < records.size(); ++k) {
    if (records[k].rows() != channels)
      throw InputError(who(n.file, n.data, "records") + ": record " + std::to_string(k + 1) + " has " + std::to_string(records[k].rows()) +
                       " channels, the first " + std::to_string(channels));
    r.records.push_back(records[k].transpose());  // dynid stores samples x channels
  }
  r.validate(n.file);
  return r;
}

ModalData read_mat_modal_data(const MatModalNames& n, const ReaderLimits& limits) {
  const MatFile f(n.file, limits);
  ModalData m;
  m.source = n.file;
  if (!n.eigenvalues.empty()) {
    const Eigen::VectorXd lambda = f.vector(n.eigenvalues, "eigenvalues (rad/s)^2");
    m.frequencies_hz.resize(lambda.size());
    for (Eigen::Index k = 0; k < lambda.size(); ++k) {
      if (!(lambda[k] > 0)) throw InputError(who(n.file, n.eigenvalues, "eigenvalues") + ": mode " + std::to_string(k + 1) + " has eigenvalue " + int_text(lambda[k]) + "; it must be > 0");
      m.frequencies_hz[k] = eigenvalue_to_hz(lambda[k]);
    }
  } else {
    m.frequencies_hz = f.vector(n.frequency_hz, "natural frequencies in Hz");
  }
  m.shapes = f.matrix(n.shapes, "mode shapes: DOFs x modes");
  if (m.shapes.cols() != m.frequencies_hz.size()) {
    const bool transposed = m.shapes.rows() == m.frequencies_hz.size();
    throw InputError(who(n.file, n.shapes, "mode shapes") + " is " + std::to_string(m.shapes.rows()) + " x " + std::to_string(m.shapes.cols()) +
                     " for " + std::to_string(m.frequencies_hz.size()) + " modes; DOFs x modes is needed" +
                     (transposed ? " (it looks transposed)" : ""));
  }
  const std::unique_ptr<MatFile> other = n.dofs_file.empty() ? nullptr : std::make_unique<MatFile>(n.dofs_file, limits);
  const MatFile& fd = other ? *other : f;
  bool text = false, vector = false;
  for (const MatFile::Info& i : fd.variables())
    if (i.name == n.dofs) {
      text = i.type == "char" || i.type == "cell";
      vector = !text && i.dims.size() == 2 && (i.dims[0] == 1 || i.dims[1] == 1) && i.dims[0] * i.dims[1] == static_cast<std::size_t>(m.shapes.rows());
    }
  if (text) {
    for (const std::string& l : fd.strings(n.dofs, "DOF labels, one per shape row")) {
      MeasuredDof d;
      double sign = 1;
      if (!parse_dof_label(l, &d, &sign)) throw InputError(who(fd.path(), n.dofs, "DOF labels") + ": '" + l + "' is not a DOF label (e.g. 13uy)");
      m.dofs.push_back(d);
    }
  } else if (vector) {  // equation numbers of a matrix model without a DOF table
    const Eigen::VectorXd q = fd.vector(n.dofs, "equation numbers (1-based) of the shape rows");
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      if (q[i] != std::floor(q[i]) || q[i] < 1 || q[i] > 2e9)
        throw InputError(who(fd.path(), n.dofs, "equation numbers") + ": entry " + std::to_string(i + 1) + " is " + int_text(q[i]) +
                         "; 1-based equation numbers are needed");
      m.dofs.push_back({static_cast<int>(q[i]), Dof::UX});
    }
  } else {
    for (const DofRow& r : dof_rows(fd, n.dofs, "DOFs of the shape rows: [node, dof 1..6], labels, or equation numbers")) m.dofs.push_back({r.node, r.dof});
  }
  if (static_cast<Eigen::Index>(m.dofs.size()) != m.shapes.rows())
    throw InputError(who(fd.path(), n.dofs, "DOFs") + " lists " + std::to_string(m.dofs.size()) + " DOFs for " +
                     std::to_string(m.shapes.rows()) + " shape rows");
  auto per_mode = [&](const std::string& var, const char* what) {
    Eigen::VectorXd v = f.vector(var, what);
    if (v.size() != m.frequencies_hz.size())
      throw InputError(who(n.file, var, what) + " has " + std::to_string(v.size()) + " values for " + std::to_string(m.frequencies_hz.size()) + " modes");
    return v;
  };
  if (!n.frequency_std.empty()) m.frequency_std_hz = per_mode(n.frequency_std, "frequency standard deviations (Hz)");
  if (!n.eigenvalue_std.empty()) {  // lambda = (2 pi f)^2: std f = std lambda / (8 pi^2 f)
    const Eigen::VectorXd s = per_mode(n.eigenvalue_std, "eigenvalue standard deviations ((rad/s)^2)");
    m.frequency_std_hz = s.array() / (8.0 * M_PI * M_PI * m.frequencies_hz.array());
  }
  if (!n.shape_std.empty()) {
    const Eigen::MatrixXd S = f.matrix(n.shape_std, "shape standard deviations: DOFs x modes, or one per mode");
    if (S.rows() == m.shapes.rows() && S.cols() == m.shapes.cols()) m.shape_entry_std = S;
    else if (S.size() == m.frequencies_hz.size() && (S.rows() == 1 || S.cols() == 1)) m.shape_std = S.reshaped();
    else
      throw InputError(who(n.file, n.shape_std, "shape standard deviations") + " is " + std::to_string(S.rows()) + " x " +
                       std::to_string(S.cols()) + "; " + std::to_string(m.shapes.rows()) + " x " + std::to_string(m.shapes.cols()) +
                       " (one per shape entry) or one per mode is needed");
  }
  if (!n.damping.empty()) {
    m.damping_ratios = f.vector(n.damping, "damping ratios");
    if (m.damping_ratios.size() != m.frequencies_hz.size())
      throw InputError(who(n.file, n.damping, "damping ratios") + " has " + std::to_string(m.damping_ratios.size()) + " values for " +
                       std::to_string(m.frequencies_hz.size()) + " modes");
  }
  m.validate(n.file);
  return m;
}

}  // namespace dynid
