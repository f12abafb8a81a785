// dynid's own reader of MATLAB v5 (v6, v7 compressed) files (io/src/mat_v5_reader.cpp), and the array both it and
// libmatio's v4 / v7.3 path hand to MatFile (io/src/mat_file.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dynid::internal {

/// One MATLAB array as dynid reads it. Every size here was counted from the bytes the file holds, never taken from a
/// declared size alone.
struct MatArray {
  std::string name;
  /// MatFile::Info::type: "double", "single", "int8" ... "uint64", "logical", "sparse", "char", "cell", "struct",
  /// "object", "function" or "opaque".
  std::string type;
  std::vector<std::size_t> dims;
  bool complex = false;
  std::vector<double> values;       ///< numeric / logical: the real part, column-major; sparse: the nonzeros' values
  std::vector<std::uint32_t> ir;    ///< sparse: 0-based row of each nonzero
  std::vector<std::uint32_t> jc;    ///< sparse: column pointers (columns + 1)
  std::vector<std::uint32_t> text;  ///< char: UTF-16 code units, column-major
  std::vector<MatArray> cells;      ///< cell: the cells, column-major
  bool numeric() const;             ///< a numeric class or logical, not sparse
};

/// A MATLAB v5 file (a 128-byte header with version 0x0100 and the endian indicator "IM" or "MI"), read without
/// libmatio: libmatio sizes its allocations by the tags a file declares (fuzz_mat, 2026-11-28: one damaged tag is a
/// 4 GB allocation from a 364-byte file), this reader by the bytes the file holds. It reads numeric, logical,
/// sparse, char and cell arrays (nested at most 64 levels); structs, objects, function handles and opaque arrays are
/// listed with their headers, their content not read. Variables are miMATRIX elements, stored or deflated
/// (miCOMPRESSED); any other element is skipped.
class MatV5Reader {
 public:
  /// Whether `path` starts with a v5 header.
  static bool is_v5(const std::string& path);
  /// Lists the variables of `path`, reading each one's flags, dimensions and name (inflating only the first bytes
  /// of a compressed one). Throws InputError naming the file and the variable at the first damaged header.
  explicit MatV5Reader(std::string path);
  /// The variables' headers (name, type, dims, complex; no data), in file order.
  const std::vector<MatArray>& variables() const { return headers_; }
  /// Variable `k` of variables() with its data. Throws InputError naming the file, the variable and the cell
  /// where the data do not hold what the headers declare.
  MatArray read(std::size_t k) const;

 private:
  struct Entry {
    std::uint64_t offset = 0;  // of the element's data in the file
    std::uint64_t bytes = 0;   // of the element's data that the file holds
    bool compressed = false;
  };
  std::string path_;
  bool swap_ = false;
  std::vector<Entry> entries_;
  std::vector<MatArray> headers_;
};

}  // namespace dynid::internal
