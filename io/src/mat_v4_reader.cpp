// dynid's MATLAB v4 reader (internal/mat_reader.hpp).
//
// v4 layout (MathWorks, "MAT-File Format", Level 4): each variable is a header of five 32-bit integers (type MOPT,
// rows, columns, imaginary flag, name length), the name (NUL included), the real data (rows x columns values of
// precision P, column-major) and, when the flag is set, the imaginary data. Text (T = 1) holds character codes;
// a sparse matrix (T = 2) is stored as a (nonzeros + 1) x 3 (or x 4, complex) matrix of rows [i j value] whose
// last row is [rows columns 0]. Every size is checked against the bytes the file holds before anything is read.
#include <algorithm>
#include <cstdint>
#include <fstream>
#include <tuple>
#include <utility>

#include "dynid/mesh/error.hpp"
#include "internal/mat_reader.hpp"

namespace dynid::internal {

namespace {

// Value k of data of precision `p` (0..5), as a double.
double value(const unsigned char* data, int p, std::uint64_t k, bool swap) {
  const unsigned char* at = data + k * v4_value_bytes(p);
  switch (p) {
    case 0:
      return load_as_double<double>(at, swap);
    case 1:
      return load_as_double<float>(at, swap);
    case 2:
      return load_as_double<std::int32_t>(at, swap);
    case 3:
      return load_as_double<std::int16_t>(at, swap);
    case 4:
      return load_as_double<std::uint16_t>(at, swap);
    default:
      return load_as_double<std::uint8_t>(at, swap);
  }
}

// A sparse matrix's size from its last stored row [rows columns 0]: a non-negative integer below 2^31.
bool sparse_size(double x, std::size_t* out) {
  if (!(x >= 0 && x < 2147483648.0) || x != static_cast<double>(static_cast<std::int64_t>(x))) return false;
  *out = static_cast<std::size_t>(x);
  return true;
}

}  // namespace

std::uint64_t v4_value_bytes(int p) {
  static const std::uint64_t bytes[] = {8, 4, 4, 2, 2, 1};
  return p >= 0 && p < 6 ? bytes[p] : 0;
}

bool read_v4_header(const unsigned char* h, V4Header* out) {
  auto mopt = static_cast<std::int32_t>(load_u32(h, false));
  if (mopt < 0 || mopt > 4052) mopt = static_cast<std::int32_t>(load_u32(h, true));
  if (mopt < 0 || mopt > 4052) return false;
  const int machine = mopt / 1000, o = (mopt / 100) % 10;
  out->type = static_cast<std::uint32_t>(mopt);
  out->precision = (mopt / 10) % 10;
  out->kind = mopt % 10;
  if (machine > 1 || o != 0 || out->kind > 2) return false;  // VAX and Cray formats, or no v4 type word
  constexpr bool kHostBigEndian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;
  out->swap = (machine == 1) != kHostBigEndian;
  out->rows = static_cast<std::int32_t>(load_u32(h + 4, out->swap));
  out->cols = static_cast<std::int32_t>(load_u32(h + 8, out->swap));
  out->imaginary = load_u32(h + 12, false) != 0;
  out->name_length = static_cast<std::int32_t>(load_u32(h + 16, out->swap));
  return !(out->imaginary && out->kind == 1) && out->name_length >= 1;
}

MatV4Reader::MatV4Reader(std::string path) : path_(std::move(path)) {
  std::ifstream in(path_, std::ios::binary);
  in.seekg(0, std::ios::end);
  const auto file_size = static_cast<std::uint64_t>(in.tellg());
  for (std::uint64_t pos = 0; pos + 20 <= file_size;) {
    in.clear();
    in.seekg(static_cast<std::streamoff>(pos));
    unsigned char h[20];
    V4Header v;
    if (!in.read(reinterpret_cast<char*>(h), 20) || !read_v4_header(h, &v)) break;
    const std::string where = path_ + ": the variable at byte " + std::to_string(pos);
    const auto damaged = [&where](const std::string& what) {
      throw InputError(where + ": " + what + ": the file is damaged; save it again from MATLAB or SciPy");
    };
    if (v.precision > 5) damaged("its type " + std::to_string(v.type) + " names no MAT-file v4 precision");
    // Signed 32-bit sizes, as libmatio reads them (fuzz_mat, 2026-11-28: a 0 x -1560281086 array). Every size is
    // checked against the bytes the file holds before anything is read (fuzz_mat, 2026-11-28: names of 1 to 1.7 GB
    // declared in files of 91 to 400 bytes, which libmatio allocated).
    if (v.rows < 0 || v.cols < 0)
      damaged("its dimensions " + std::to_string(v.rows) + " x " + std::to_string(v.cols) + " are negative");
    const std::uint64_t left = file_size - pos - 20, name_length = static_cast<std::uint64_t>(v.name_length);
    if (name_length > left)
      damaged("its name declares " + std::to_string(name_length) + " bytes where the file holds " +
              std::to_string(left));
    const std::uint64_t values = static_cast<std::uint64_t>(v.rows) * static_cast<std::uint64_t>(v.cols);
    const long double data = static_cast<long double>(values) * v4_value_bytes(v.precision) * (v.imaginary ? 2 : 1);
    if (data > static_cast<long double>(left - name_length))
      damaged("its data declare " + std::to_string(v.rows) + " x " + std::to_string(v.cols) +
              (v.imaginary ? " complex" : "") + " values where the file holds " + std::to_string(left - name_length) +
              " bytes");
    MatArray a;
    a.name.resize(name_length);
    in.read(a.name.data(), static_cast<std::streamsize>(name_length));
    a.name.resize(std::min(a.name.size(), a.name.find('\0')));
    a.type = v.kind == 1 ? "char" : v.kind == 2 ? "sparse" : "double";
    a.dims = {static_cast<std::size_t>(v.rows), static_cast<std::size_t>(v.cols)};
    a.complex = v.imaginary;
    const std::uint64_t offset = pos + 20 + name_length;
    if (v.kind == 2) {  // the matrix's size is its last row's first two values
      if (v.rows < 1 || (v.cols != 3 && v.cols != 4))
        damaged("its sparse data are " + std::to_string(v.rows) + " x " + std::to_string(v.cols) +
                ", not (nonzeros + 1) x 3 (or x 4)");
      const std::uint64_t size = v4_value_bytes(v.precision), last = static_cast<std::uint64_t>(v.rows) - 1;
      unsigned char m[8], n[8];
      in.seekg(static_cast<std::streamoff>(offset + last * size));
      in.read(reinterpret_cast<char*>(m), static_cast<std::streamsize>(size));
      in.seekg(static_cast<std::streamoff>(offset + (last + static_cast<std::uint64_t>(v.rows)) * size));
      in.read(reinterpret_cast<char*>(n), static_cast<std::streamsize>(size));
      if (!in || !sparse_size(value(m, v.precision, 0, v.swap), &a.dims[0]) ||
          !sparse_size(value(n, v.precision, 0, v.swap), &a.dims[1]))
        damaged("its last row does not hold the sparse matrix's size (two non-negative integers)");
      a.complex = v.cols == 4;
    }
    headers_.push_back(std::move(a));
    entries_.push_back({offset, v});
    pos = offset + static_cast<std::uint64_t>(data);
  }
  if (headers_.empty())
    throw InputError(path_ +
                     ": not a MATLAB .mat file (v4, v5/v7 or v7.3); save it from MATLAB with save(..., '-v7') or "
                     "'-v7.3', or from Python with scipy.io.savemat");
}

MatArray MatV4Reader::read(std::size_t k) const {
  const Entry& e = entries_.at(k);
  const V4Header& v = e.header;
  MatArray a = headers_[k];
  const std::string who = path_ + ": variable '" + a.name + "'";
  const auto rows = static_cast<std::uint64_t>(v.rows), cols = static_cast<std::uint64_t>(v.cols);
  std::vector<unsigned char> raw(rows * cols * v4_value_bytes(v.precision));  // fits in the file: checked on listing
  std::ifstream in(path_, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(e.data));
  if (!in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(raw.size())))
    throw InputError(who + ": cannot be read (the file changed or ends early)");
  const auto at = [&](std::uint64_t i) { return value(raw.data(), v.precision, i, v.swap); };
  if (v.kind == 0 && !a.complex) {
    a.values.resize(rows * cols);
    for (std::uint64_t i = 0; i < a.values.size(); ++i) a.values[i] = at(i);
  } else if (v.kind == 1) {
    a.text.resize(rows * cols);
    for (std::uint64_t i = 0; i < a.text.size(); ++i) {
      const double c = at(i);
      a.text[i] = c >= 0 && c <= 0xFFFF ? static_cast<std::uint32_t>(c) : 0xFFFD;
    }
  } else if (v.kind == 2 && !a.complex) {
    // Rows [i j value], 1-based, in any order: sorted by column, then row, into compressed columns.
    const std::uint64_t nnz = rows - 1;
    std::vector<std::tuple<std::uint32_t, std::uint32_t, double>> entries(nnz);
    for (std::uint64_t q = 0; q < nnz; ++q) {
      const double i = at(q), j = at(rows + q);
      std::size_t r = 0, c = 0;
      if (!sparse_size(i, &r) || !sparse_size(j, &c) || r < 1 || r > a.dims[0] || c < 1 || c > a.dims[1])
        throw InputError(who + ": sparse entry " + std::to_string(q + 1) + " is at (" + std::to_string(i) + ", " +
                         std::to_string(j) + "), outside its " + std::to_string(a.dims[0]) + " x " +
                         std::to_string(a.dims[1]) +
                         " matrix: the file is damaged; save it again from MATLAB or SciPy");
      entries[q] = {static_cast<std::uint32_t>(c - 1), static_cast<std::uint32_t>(r - 1), at(2 * rows + q)};
    }
    std::stable_sort(entries.begin(), entries.end(), [](const auto& x, const auto& y) {
      return std::tie(std::get<0>(x), std::get<1>(x)) < std::tie(std::get<0>(y), std::get<1>(y));
    });
    a.jc.assign(a.dims[1] + 1, 0);
    for (const auto& [c, r, x] : entries) {
      ++a.jc[c + 1];
      a.ir.push_back(r);
      a.values.push_back(x);
    }
    for (std::size_t c = 0; c < a.dims[1]; ++c) a.jc[c + 1] += a.jc[c];
  }
  return a;
}

}  // namespace dynid::internal
