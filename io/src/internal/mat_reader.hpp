// dynid's own readers of MATLAB v5 (v6, v7 compressed) and v4 files (io/src/mat_v5_reader.cpp, mat_v4_reader.cpp),
// and the array they and libmatio's v7.3 (HDF5) path hand to MatFile (io/src/mat_file.cpp).
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace dynid::internal {

/// The 32-bit word at `p`, byte-swapped when `swap` (the file's byte order is not this machine's).
inline std::uint32_t load_u32(const unsigned char* p, bool swap) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return swap ? __builtin_bswap32(v) : v;
}

/// The value of type T stored at `p` (byte-swapped when `swap`), as a double.
template <class T>
double load_as_double(const unsigned char* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return static_cast<double>(v);
}

/// "2 x 3" ("0 x 0" for no dimensions): an array's dimensions in messages.
std::string dims_text(const std::vector<std::size_t>& dims);

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

/// The version word of the 128-byte header that v5 (0x0100) and v7.3 (0x0200) files start with (endian indicator
/// "IM" or "MI"); 0 when `path` starts with no such header (a v4 file, or no MAT-file).
unsigned mat_header_version(const std::string& path);

/// The variables of a .mat file, read by dynid (v5, v4).
class MatReader {
 public:
  virtual ~MatReader() = default;
  /// "MATLAB 5.0 (v5/v7)" or "MATLAB 4".
  virtual std::string version() const = 0;
  /// The variables' headers (name, type, dims, complex; no data), in file order.
  const std::vector<MatArray>& variables() const { return headers_; }
  /// Variable `k` of variables() with its data. Throws InputError naming the file, the variable and the cell
  /// where the data do not hold what the headers declare.
  virtual MatArray read(std::size_t k) const = 0;

 protected:
  std::vector<MatArray> headers_;
};

/// A MATLAB v5 file (a 128-byte header with version 0x0100 and the endian indicator "IM" or "MI"), read without
/// libmatio: libmatio sizes its allocations by the tags a file declares (fuzz_mat, 2026-11-28: one damaged tag is a
/// 4 GB allocation from a 364-byte file), this reader by the bytes the file holds. It reads numeric, logical,
/// sparse, char and cell arrays (nested at most 64 levels); structs, objects, function handles and opaque arrays are
/// listed with their headers, their content not read. Variables are miMATRIX elements, stored or deflated
/// (miCOMPRESSED); any other element is skipped.
class MatV5Reader : public MatReader {
 public:
  /// Lists the variables of `path`, reading each one's flags, dimensions and name (inflating only the first bytes
  /// of a compressed one). Throws InputError naming the file and the variable at the first damaged header.
  explicit MatV5Reader(std::string path);
  std::string version() const override { return "MATLAB 5.0 (v5/v7)"; }
  MatArray read(std::size_t k) const override;

 private:
  struct Entry {
    std::uint64_t offset = 0;  // of the element's data in the file
    std::uint64_t bytes = 0;   // of the element's data that the file holds
    bool compressed = false;
  };
  std::string path_;
  bool swap_ = false;
  std::vector<Entry> entries_;
};

/// A MATLAB v4 variable's 20-byte header, read as libmatio's Mat_VarReadNextInfo4 reads it: the type word MOPT as a
/// 32-bit integer, byte-swapped when outside 0..4052; its thousands digit M gives the byte order of the rest (0
/// little-endian, 1 big-endian), whatever order the type word itself was in.
struct V4Header {
  std::uint32_t type = 0;  ///< MOPT
  int precision = 0;       ///< P: 0 double, 1 single, 2 int32, 3 int16, 4 uint16, 5 uint8 (> 5: none)
  int kind = 0;            ///< T: 0 numeric, 1 text, 2 sparse
  std::int32_t rows = 0, cols = 0;
  bool imaginary = false;
  std::int32_t name_length = 0;  ///< bytes of the name, its terminating NUL included
  bool swap = false;             ///< the sizes and data are in the other byte order than this machine's
};
/// Reads `h` (20 bytes); false where libmatio ends a file's variables (M > 1, O != 0, T > 2, a complex text, a name
/// of no byte). The precision is not checked.
bool read_v4_header(const unsigned char* h, V4Header* out);
/// Bytes of one value of v4 precision `p` (0..5).
std::uint64_t v4_value_bytes(int p);

/// A MATLAB v4 file (headers of 20 bytes, then the name and the data of each variable), read without libmatio: numeric
/// matrices (as libmatio, every precision is listed as "double"), text and sparse matrices (stored as rows [i j value
/// (imaginary)] and a last row [rows cols 0], 1-based).
class MatV4Reader : public MatReader {
 public:
  /// Lists the variables of `path`; throws InputError when its first 20 bytes are no v4 header (not a MAT-file) or a
  /// variable's name or data do not fit in the file.
  explicit MatV4Reader(std::string path);
  std::string version() const override { return "MATLAB 4"; }
  MatArray read(std::size_t k) const override;

 private:
  struct Entry {
    std::uint64_t data = 0;  // offset of the data
    V4Header header;
  };
  std::string path_;
  std::vector<Entry> entries_;
};

}  // namespace dynid::internal
