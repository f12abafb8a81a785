// Universal File Format reader and writer (see dynid/io/uff.hpp for the formats).
#include "dynid/io/uff.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cstdarg>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <tuple>

#include "dynid/io/output.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/text_util.hpp"

namespace dynid {

using internal::parse_double;
using internal::parse_int;
using internal::record_numbers;
using internal::rtrim;
using internal::trim;

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
constexpr long long kMaxPoints = 1LL << 30;  // no UFF function holds a billion points

/// Abscissa of point k of an evenly spaced function; the reader and the writer's "is it even?" test both use it.
double even_abscissa(double x0, double dx, Eigen::Index k) { return x0 + static_cast<double>(k) * dx; }

/// Where we are in a file, for error messages: "file: dataset 58 starting at line 120, record 7 (line 127): ...".
struct Ctx {
  const std::string& file;
  std::string type;
  int first_line;
  [[noreturn]] void fail(const std::string& record, int line, const std::string& what) const {
    std::string m = file + ": dataset " + type + " starting at line " + std::to_string(first_line);
    if (!record.empty()) m += ", " + record;
    if (line > 0) m += " (line " + std::to_string(line) + ")";
    throw InputError(m + ": " + what);
  }
};

/// The lines of an ASCII dataset between its type line and the closing "-1".
struct Block {
  std::vector<std::string_view> lines;
  std::vector<int> line_no;
  bool closed = false;  ///< the closing "-1" was found
  int last_line = 0;
};

bool is_delimiter(std::string_view l) { return trim(l) == "-1"; }

Block read_block(internal::LineReader& in) {
  Block b;
  std::string_view l;
  while (in.next(&l)) {
    if (is_delimiter(l)) {
      b.closed = true;
      break;
    }
    b.lines.push_back(l);
    b.line_no.push_back(in.line());
  }
  b.last_line = in.line();
  return b;
}

std::string record_name(int r) { return "record " + std::to_string(r); }

/// A dataset's header must have its n records; `line` is where the file or block ended.
void require_header(const Ctx& c, std::size_t have, std::size_t n, int line) {
  if (have < n)
    c.fail(record_name(static_cast<int>(have) + 1), line,
           "the header has " + std::to_string(have) + " of its " + std::to_string(n) + " records (file truncated?)");
}

/// Integer fields of a record: by blanks, else by fixed widths. At least `min_fields` are required; missing
/// optional ones are 0.
std::vector<int> int_record(const Ctx& c, std::string_view line, int line_no, int record,
                            const std::vector<int>& widths, std::size_t min_fields, const std::string& what) {
  std::vector<double> v;
  if (!record_numbers(line, widths, &v) || v.size() < min_fields)
    c.fail(record_name(record), line_no,
           "expected " + std::to_string(min_fields) + " integer fields (" + what + "), found '" +
               std::string(rtrim(line)) + "'");
  std::vector<int> out;
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (v[k] != std::floor(v[k]) || std::abs(v[k]) > 2147483647.0)
      c.fail(record_name(record), line_no, "field " + std::to_string(k + 1) + " (" + what + ") must be an integer, found " +
                                               std::to_string(v[k]));
    out.push_back(static_cast<int>(v[k]));
  }
  return out;
}

/// The five ID lines of a dataset of nodal values (55, 2414) from line `first`, then the record of six integers
/// after them: model type, analysis type, data characteristic (stored), the dataset's own type (`fourth`), data
/// type and values per node (returned with the others, for the caller to check).
std::vector<int> ids_and_types(const Ctx& c, const Block& b, std::size_t first, const std::string& fourth,
                               std::array<std::string, 5>* id, int* model_type, int* analysis_type,
                               int* data_characteristic) {
  for (std::size_t k = 0; k < 5; ++k) (*id)[k] = std::string(rtrim(b.lines[first + k]));
  const std::size_t r = first + 5;
  const auto v =
      int_record(c, b.lines[r], b.line_no[r], static_cast<int>(r) + 1, {10}, 6,
                 "model type, analysis type, data characteristic, " + fourth + ", data type, values per node");
  *model_type = v[0];
  *analysis_type = v[1];
  *data_characteristic = v[2];
  return v;
}

std::string field_text(std::string_view line, std::size_t begin, std::size_t width) {
  if (begin >= line.size()) return "";
  return std::string(trim(line.substr(begin, width)));
}

// ---- 58 -------------------------------------------------------------------------------------------------------

/// Record 6 of a 58: fixed columns (the entity names may contain blanks), else free format with 10 fields.
void parse58_record6(const Ctx& c, std::string_view l, int ln, Uff58* d) {
  static const std::size_t col[8] = {0, 5, 15, 20, 41, 51, 66, 76};
  static const std::size_t wid[8] = {5, 10, 5, 10, 10, 4, 10, 4};
  int v[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  bool fixed = true;
  for (int k = 0; k < 8 && fixed; ++k) {
    const std::string f = field_text(l, col[k], wid[k]);
    if (f.empty() && k > 0) continue;  // optional trailing fields
    fixed = parse_int(f, &v[k]);
  }
  if (fixed) {
    d->response_name = field_text(l, 31, 10);
    d->reference_name = field_text(l, 56, 10);
  } else {
    const auto t = internal::split_fields(l);
    const int idx[8] = {0, 1, 2, 3, 5, 6, 8, 9};
    bool ok = t.size() == 10;
    for (int k = 0; k < 8 && ok; ++k) ok = parse_int(t[idx[k]], &v[k]);
    if (!ok)
      c.fail(record_name(6), ln,
             "expected function type, function id, version, load case, response name, node, direction, reference "
             "name, node, direction (I5,I10,I5,I10,1X,A10,I10,I4,1X,A10,I10,I4), found '" + std::string(rtrim(l)) + "'");
    d->response_name = std::string(t[4]);
    d->reference_name = std::string(t[7]);
  }
  d->function_type = v[0];
  d->function_id = v[1];
  d->version = v[2];
  d->load_case = v[3];
  d->response_node = v[4];
  d->response_direction = v[5];
  d->reference_node = v[6];
  d->reference_direction = v[7];
  if (std::abs(d->response_direction) > 6 || std::abs(d->reference_direction) > 6)
    c.fail(record_name(6), ln, "directions must be -6..6, found " + std::to_string(d->response_direction) + " and " +
                                   std::to_string(d->reference_direction));
}

void parse58_record7(const Ctx& c, std::string_view l, int ln, Uff58* d, long long* num_points) {
  std::vector<double> v;
  if (!record_numbers(l, {10, 10, 10, 13, 13, 13}, &v) || v.size() < 3)
    c.fail(record_name(7), ln, "expected ordinate data type, number of points, abscissa spacing, minimum, increment, "
                               "z value (3I10,3E13.5), found '" + std::string(rtrim(l)) + "'");
  if (v[0] != 2 && v[0] != 4 && v[0] != 5 && v[0] != 6)  // compared as doubles: no out-of-range cast
    c.fail(record_name(7), ln, "ordinate data type must be 2 (real single), 4 (real double), 5 (complex single) or "
                               "6 (complex double), found " + std::to_string(v[0]));
  if (!(v[1] >= 1 && v[1] <= static_cast<double>(kMaxPoints)) || v[1] != std::floor(v[1]))
    c.fail(record_name(7), ln, "number of points must be an integer in 1.." + std::to_string(kMaxPoints) + ", found " +
                                   std::to_string(v[1]));
  if (v[2] != 0 && v[2] != 1)
    c.fail(record_name(7), ln, "abscissa spacing must be 0 (uneven) or 1 (even), found " + std::to_string(v[2]));
  d->ordinate_type = static_cast<int>(v[0]);
  *num_points = static_cast<long long>(v[1]);
  d->even = v[2] == 1;
  if (d->even && v.size() < 5)
    c.fail(record_name(7), ln, "even abscissa spacing needs the abscissa minimum and increment (fields 4 and 5)");
  d->x_min = v.size() > 3 ? v[3] : 0;
  d->dx = v.size() > 4 ? v[4] : 0;
  d->z_value = v.size() > 5 ? v[5] : 0;
  if (d->even && !(std::isfinite(d->x_min) && std::isfinite(d->dx) && d->dx > 0))
    c.fail(record_name(7), ln, "abscissa increment must be > 0 for even spacing, found " + std::to_string(d->dx));
}

/// Records 8-11: I10,3I5,2(1X,A20); free format (4 integers, label, unit) if the columns do not fit.
UffAxis parse58_axis(const Ctx& c, std::string_view l, int ln, int record) {
  UffAxis a;
  int v[4] = {0, 0, 0, 0};
  static const std::size_t col[4] = {0, 10, 15, 20}, wid[4] = {10, 5, 5, 5};
  bool fixed = true;
  for (int k = 0; k < 4 && fixed; ++k) {
    const std::string f = field_text(l, col[k], wid[k]);
    fixed = f.empty() ? k > 0 : parse_int(f, &v[k]);
  }
  if (fixed) {
    a.label = field_text(l, 26, 20);
    a.unit = field_text(l, 47, 20);
  } else {
    const auto t = internal::split_fields(l);
    bool ok = t.size() >= 4;
    for (int k = 0; k < 4 && ok; ++k) ok = parse_int(t[k], &v[k]);
    if (!ok)
      c.fail(record_name(record), ln, "expected specific data type, 3 unit exponents, axis label and units label "
                                      "(I10,3I5,2(1X,A20)), found '" + std::string(rtrim(l)) + "'");
    a.label = t.size() > 4 ? std::string(t[4]) : "";
    a.unit = t.size() > 5 ? std::string(t[5]) : "";
  }
  a.data_type = v[0];
  a.length_exp = v[1];
  a.force_exp = v[2];
  a.temperature_exp = v[3];
  return a;
}

int values_per_point(const Uff58& d) { return (d.is_complex() ? 2 : 1) + (d.even ? 0 : 1); }

/// Fills x and y from the flat values (y, re im, x y, or x re im per point).
void unpack58(const std::vector<double>& v, Uff58* d) {
  const int per = values_per_point(*d);
  const Eigen::Index n = static_cast<Eigen::Index>(v.size()) / per;
  d->x.resize(n);
  d->y.resize(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double* p = &v[static_cast<std::size_t>(k * per)];
    int j = 0;
    d->x[k] = d->even ? even_abscissa(d->x_min, d->dx, k) : p[j++];
    const double re = p[j++];
    d->y[k] = std::complex<double>(re, d->is_complex() ? p[j] : 0.0);
  }
  if (!d->even && n > 0) {
    d->x_min = d->x[0];
    d->dx = 0;
  }
}

/// ASCII record 12 widths by type (the fallback when numbers run together), as pyuff reads them.
std::vector<int> data_widths(const Uff58& d) {
  if (!d.is_double()) return {13};
  if (d.even) return {20};
  return d.is_complex() ? std::vector<int>{13, 20, 20} : std::vector<int>{13, 20};
}

void parse58_header(const Ctx& c, const std::vector<std::string_view>& lines, const std::vector<int>& ln, Uff58* d,
                    long long* num_points) {
  for (int k = 0; k < 5; ++k) d->id[k] = std::string(rtrim(lines[k]));
  parse58_record6(c, lines[5], ln[5], d);
  parse58_record7(c, lines[6], ln[6], d, num_points);
  d->abscissa = parse58_axis(c, lines[7], ln[7], 8);
  d->ordinate = parse58_axis(c, lines[8], ln[8], 9);
  d->denominator = parse58_axis(c, lines[9], ln[9], 10);
  d->z_axis = parse58_axis(c, lines[10], ln[10], 11);
}

Uff58 read58_ascii(const Ctx& c, const Block& b) {
  require_header(c, b.lines.size(), 11, b.last_line);
  Uff58 d;
  long long n = 0;
  parse58_header(c, b.lines, b.line_no, &d, &n);
  const long long expected = n * values_per_point(d);
  const std::vector<int> widths = data_widths(d);
  std::vector<double> values, line_values;
  for (std::size_t k = 11; k < b.lines.size(); ++k) {
    if (!record_numbers(b.lines[k], widths, &line_values)) {
      if (!b.closed && k + 1 == b.lines.size())  // cut inside a number
        c.fail(record_name(12), b.line_no[k], "found about " + std::to_string(values.size()) + " of the " +
                                                  std::to_string(expected) + " values declared; the file ends inside "
                                                  "the data without the closing -1 (truncated?)");
      c.fail(record_name(12), b.line_no[k], "value " + std::to_string(values.size() + 1) + ": not a number in '" +
                                                std::string(rtrim(b.lines[k])) + "'");
    }
    values.insert(values.end(), line_values.begin(), line_values.end());
    if (static_cast<long long>(values.size()) > expected)
      c.fail(record_name(12), b.line_no[k], "more values than the " + std::to_string(expected) + " declared (" +
                                                std::to_string(n) + " points in record 7)");
  }
  if (static_cast<long long>(values.size()) < expected)
    c.fail(record_name(12), b.last_line, "found " + std::to_string(values.size()) + " of the " + std::to_string(expected) +
                                             " values declared (" + std::to_string(n) + " points in record 7)" +
                                             (b.closed ? "" : "; the file ends without the closing -1 (truncated?)"));
  if (!b.closed) c.fail(record_name(12), b.last_line, "the file ends without the closing -1 line (truncated?)");
  unpack58(values, &d);
  return d;
}

double decode_float(const unsigned char* p, int size, bool big_endian) {
  std::uint64_t u = 0;
  for (int k = 0; k < size; ++k) {
    const int byte = big_endian ? k : size - 1 - k;
    u = (u << 8) | p[byte];
  }
  if (size == 4) {
    const auto u32 = static_cast<std::uint32_t>(u);
    float f;
    std::memcpy(&f, &u32, 4);
    return f;
  }
  double v;
  std::memcpy(&v, &u, 8);
  return v;
}

Uff58 read58_binary(const Ctx& c, internal::LineReader& in, std::string_view type_line, int type_ln) {
  // Type line: 58b, byte order, floating-point format, number of ASCII lines, number of bytes, 4 unused.
  std::string_view rest = trim(type_line);
  rest = rest.substr(std::min(rest.size(), rest.find_first_of("bB") + 1));
  std::vector<double> h;
  if (!record_numbers(rest, {6, 6, 12, 12, 6, 6, 12, 12}, &h) || h.size() < 4)
    c.fail("header line", type_ln, "expected '58b byte_order fp_format num_ascii_lines num_bytes ...', found '" +
                                       std::string(rtrim(type_line)) + "'");
  if (h[0] != 1 && h[0] != 2)
    c.fail("header line", type_ln, "byte order must be 1 (little endian) or 2 (big endian), found " + std::to_string(h[0]));
  if (h[1] != 2)
    c.fail("header line", type_ln, "floating-point format " + std::to_string(h[1]) +
                                       " is not supported (only 2, IEEE 754); convert the file to IEEE or ASCII");
  if (h[2] != 11)
    c.fail("header line", type_ln, "expected 11 ASCII header lines, the file says " + std::to_string(h[2]));
  if (!(h[3] >= 0 && h[3] <= 8.0 * 3 * kMaxPoints))
    c.fail("header line", type_ln, "number of bytes " + std::to_string(h[3]) + " is out of range");
  Block head;
  std::string_view l;
  while (head.lines.size() < 11 && in.next(&l)) {
    if (is_delimiter(l))
      c.fail(record_name(static_cast<int>(head.lines.size()) + 1), in.line(), "-1 inside the 11 header records");
    head.lines.push_back(l);
    head.line_no.push_back(in.line());
  }
  require_header(c, head.lines.size(), 11, in.line());
  Uff58 d;
  d.binary = true;
  d.big_endian = h[0] == 2;
  long long n = 0;
  parse58_header(c, head.lines, head.line_no, &d, &n);
  const int size = d.is_double() ? 8 : 4;
  const long long count = n * values_per_point(d);
  const long long need = count * size;
  const long long declared = static_cast<long long>(h[3]);
  const int data_line = in.line() + 1;
  if (static_cast<long long>(in.remaining()) < need)
    c.fail(record_name(12), data_line, "binary data: " + std::to_string(need) + " bytes needed for " + std::to_string(n) +
                                           " points, the file has " + std::to_string(in.remaining()) + " left (truncated?)");
  const std::string_view bytes = in.take_bytes(static_cast<std::size_t>(need));
  if (declared > need && static_cast<long long>(in.remaining()) >= declared - need)
    in.take_bytes(static_cast<std::size_t>(declared - need));  // padding some writers add
  std::vector<double> values(static_cast<std::size_t>(count));
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  for (long long k = 0; k < count; ++k) values[static_cast<std::size_t>(k)] = decode_float(p + k * size, size, d.big_endian);
  bool closed = false;
  while (in.next(&l)) {
    if (is_delimiter(l)) {
      closed = true;
      break;
    }
    if (!trim(l).empty())
      c.fail(record_name(12), in.line(), "the binary data (" + std::to_string(need) +
                                             " bytes) is not followed by the closing -1 (header says " +
                                             std::to_string(declared) + " bytes)");
  }
  if (!closed) c.fail(record_name(12), in.line(), "the file ends without the closing -1 line (truncated?)");
  unpack58(values, &d);
  return d;
}

// ---- 55 -------------------------------------------------------------------------------------------------------

/// Numbers from the lines of a block starting at line k until `count` are read; returns the next line index. A
/// short count is reported at `count_line` (default: the first line read).
std::size_t read_values(const Ctx& c, const Block& b, std::size_t k, std::size_t count, int record, const std::string& who,
                        std::vector<double>* out, int count_line = -1) {
  std::vector<double> v;
  std::size_t got = 0;
  const int first = count_line >= 0 ? count_line : k < b.line_no.size() ? b.line_no[k] : b.last_line;
  while (got < count && k < b.lines.size()) {
    if (!record_numbers(b.lines[k], {13}, &v))
      c.fail(record_name(record), b.line_no[k], who + ": not a number in '" + std::string(rtrim(b.lines[k])) + "'");
    got += v.size();
    out->insert(out->end(), v.begin(), v.end());
    ++k;
  }
  if (got != count)
    c.fail(record_name(record), first, who + ": expected " + std::to_string(count) + " values, found " + std::to_string(got) +
                                           (b.closed ? "" : " (file truncated?)"));
  return k;
}

/// The node records of a 55 or 2414 data set from line k to the block's end: a node number (record
/// `node_record`, I10) followed by `per_node` values (record node_record + 1; a short count is reported at the node
/// line when `count_at_node`). Fills the node numbers and the values in file order.
void read_node_values(const Ctx& c, const Block& b, std::size_t k, std::size_t per_node, int node_record,
                      bool count_at_node, std::vector<int>* nodes, std::vector<double>* vals) {
  while (k < b.lines.size()) {
    if (trim(b.lines[k]).empty()) {
      ++k;
      continue;
    }
    int node = 0;
    if (!parse_int(b.lines[k], &node))
      c.fail(record_name(node_record), b.line_no[k],
             "expected a node number (I10), found '" + std::string(rtrim(b.lines[k])) + "'");
    const int node_line = count_at_node ? b.line_no[k] : -1;
    ++k;
    k = read_values(c, b, k, per_node, node_record + 1, "node " + std::to_string(node), vals, node_line);
    nodes->push_back(node);
  }
}

/// Values (nodes x per node) from the numbers of read_node_values(): per node, real parts or (re, im) pairs.
Eigen::MatrixXcd node_values(const std::vector<double>& vals, Eigen::Index nn, int values_per_node, bool complex) {
  const std::size_t per_node = static_cast<std::size_t>(values_per_node) * (complex ? 2 : 1);
  Eigen::MatrixXcd values(nn, values_per_node);
  for (Eigen::Index i = 0; i < nn; ++i)
    for (int j = 0; j < values_per_node; ++j) {
      const std::size_t at = static_cast<std::size_t>(i) * per_node + static_cast<std::size_t>(complex ? 2 * j : j);
      values(i, j) = std::complex<double>(vals[at], complex ? vals[at + 1] : 0.0);
    }
  return values;
}

Uff55 read55(const Ctx& c, const Block& b) {
  require_header(c, b.lines.size(), 8, b.last_line);
  Uff55 d;
  const auto r6 =
      ids_and_types(c, b, 0, "specific data type", &d.id, &d.model_type, &d.analysis_type, &d.data_characteristic);
  d.data_type_code = r6[3];
  if (r6[4] != 2 && r6[4] != 5)
    c.fail(record_name(6), b.line_no[5], "data type (field 5) must be 2 (real) or 5 (complex), found " + std::to_string(r6[4]));
  d.complex = r6[4] == 5;
  d.values_per_node = r6[5];
  if (d.values_per_node < 1 || d.values_per_node > 6)
    c.fail(record_name(6), b.line_no[5], "values per node (field 6) must be 1..6, found " + std::to_string(d.values_per_node));
  d.record7 = int_record(c, b.lines[6], b.line_no[6], 7, {10}, 2, "number of integers, number of reals, ...");
  std::vector<double> r8;
  if (!record_numbers(b.lines[7], {13}, &r8) || r8.empty())
    c.fail(record_name(8), b.line_no[7], "expected real values (6E13.5), found '" + std::string(rtrim(b.lines[7])) + "'");
  d.record8 = r8;
  const int per_node = d.values_per_node * (d.complex ? 2 : 1);
  std::vector<double> vals;
  read_node_values(c, b, 8, static_cast<std::size_t>(per_node), 9, true, &d.nodes, &vals);
  if (!b.closed) c.fail(record_name(10), b.last_line, "the file ends without the closing -1 line (truncated?)");
  d.values = node_values(vals, static_cast<Eigen::Index>(d.nodes.size()), d.values_per_node, d.complex);
  return d;
}

// ---- 15, 2411, 2412, 164 --------------------------------------------------------------------------------------

void require_closed(const Ctx& c, const Block& b, const std::string& record) {
  if (!b.closed) c.fail(record, b.last_line, "the file ends without the closing -1 line (truncated?)");
}

UffNode node_from(const Ctx& c, const std::vector<double>& v, std::size_t first_real, int ln, int record) {
  UffNode n;
  int ints[4] = {0, 0, 0, 0};
  for (int k = 0; k < 4; ++k) {
    if (v[k] != std::floor(v[k]) || std::abs(v[k]) > 2147483647.0)
      c.fail(record_name(record), ln, "field " + std::to_string(k + 1) + " must be an integer");
    ints[k] = static_cast<int>(v[k]);
  }
  n.id = ints[0];
  n.definition_cs = ints[1];
  n.displacement_cs = ints[2];
  n.colour = ints[3];
  n.x = Eigen::Vector3d(v[first_real], v[first_real + 1], v[first_real + 2]);
  return n;
}

UffNodes read15(const Ctx& c, const Block& b) {
  UffNodes d;
  std::vector<double> v;
  for (std::size_t k = 0; k < b.lines.size(); ++k) {
    if (trim(b.lines[k]).empty()) continue;
    if (!record_numbers(b.lines[k], {10, 10, 10, 10, 13, 13, 13}, &v) || v.size() != 7)
      c.fail(record_name(1), b.line_no[k], "node " + std::to_string(d.nodes.size() + 1) +
                                               ": expected 7 fields (label, 2 coordinate systems, colour, x, y, z; "
                                               "4I10,3E13.5), found '" + std::string(rtrim(b.lines[k])) + "'");
    d.nodes.push_back(node_from(c, v, 4, b.line_no[k], 1));
  }
  require_closed(c, b, record_name(1));
  return d;
}

UffNodes read2411(const Ctx& c, const Block& b) {
  UffNodes d;
  std::vector<double> v, x;
  for (std::size_t k = 0; k < b.lines.size(); k += 2) {
    if (k + 1 >= b.lines.size())
      c.fail(record_name(2), b.last_line, "node " + std::to_string(d.nodes.size() + 1) + ": coordinates missing");
    if (!record_numbers(b.lines[k], {10}, &v) || v.size() != 4)
      c.fail(record_name(1), b.line_no[k], "expected 4 integers (label, export and displacement coordinate systems, "
                                           "colour; 4I10), found '" + std::string(rtrim(b.lines[k])) + "'");
    if (!record_numbers(b.lines[k + 1], {25}, &x) || x.size() != 3)
      c.fail(record_name(2), b.line_no[k + 1], "expected 3 coordinates (3D25.16), found '" +
                                                   std::string(rtrim(b.lines[k + 1])) + "'");
    v.insert(v.end(), x.begin(), x.end());
    d.nodes.push_back(node_from(c, v, 4, b.line_no[k], 1));
  }
  require_closed(c, b, record_name(2));
  return d;
}

bool is_beam_descriptor(int fe) { return fe == 11 || (fe >= 21 && fe <= 24); }

UffElements read2412(const Ctx& c, const Block& b, std::vector<std::string>* notes) {
  UffElements d;
  std::size_t k = 0;
  int higher_order = 0;
  while (k < b.lines.size()) {
    if (trim(b.lines[k]).empty()) {
      ++k;
      continue;
    }
    const auto r1 = int_record(c, b.lines[k], b.line_no[k], 1, {10}, 6,
                               "label, FE descriptor, physical property, material property, colour, number of nodes");
    UffElement e{r1[0], r1[1], r1[2], r1[3], r1[4], {}};
    const int nn = r1[5];
    if (nn < 1 || nn > 64)
      c.fail(record_name(1), b.line_no[k], "element " + std::to_string(e.id) + ": number of nodes must be 1..64, found " +
                                               std::to_string(nn));
    ++k;
    if (is_beam_descriptor(e.fe_descriptor)) ++k;  // record 2: orientation node, cross sections
    while (static_cast<int>(e.nodes.size()) < nn && k < b.lines.size()) {
      const auto ids = int_record(c, b.lines[k], b.line_no[k], 3, {10}, 1, "node labels, 8I10");
      e.nodes.insert(e.nodes.end(), ids.begin(), ids.end());
      ++k;
    }
    if (static_cast<int>(e.nodes.size()) != nn)
      c.fail(record_name(3), b.last_line, "element " + std::to_string(e.id) + ": expected " + std::to_string(nn) +
                                              " node labels, found " + std::to_string(e.nodes.size()));
    if (nn > 4) ++higher_order;
    d.elements.push_back(std::move(e));
  }
  require_closed(c, b, record_name(3));
  if (higher_order > 0)
    notes->push_back(c.file + ": dataset 2412 starting at line " + std::to_string(c.first_line) + ": " +
                     std::to_string(higher_order) + " elements with more than 4 nodes kept as node lists only");
  return d;
}

UffUnits read164(const Ctx& c, const Block& b) {
  if (b.lines.size() < 2)
    c.fail(record_name(static_cast<int>(b.lines.size()) + 1), b.last_line, "units dataset is incomplete (file truncated?)");
  UffUnits u;
  const std::string_view r1 = b.lines[0];
  if (!parse_int(field_text(r1, 0, 10), &u.code))
    c.fail(record_name(1), b.line_no[0], "expected the units code (I10), found '" + std::string(rtrim(r1)) + "'");
  u.description = field_text(r1, 10, 20);
  const std::string tm = field_text(r1, 30, 10);
  u.temperature_mode = 2;
  if (!tm.empty() && !parse_int(tm, &u.temperature_mode))
    c.fail(record_name(1), b.line_no[0], "temperature mode (columns 31-40) must be an integer, found '" + tm + "'");
  std::vector<double> all, v;
  for (std::size_t k = 1; k < b.lines.size(); ++k) {
    if (!record_numbers(b.lines[k], {25}, &v))
      c.fail(record_name(static_cast<int>(k) + 1), b.line_no[k], "not a number in '" + std::string(rtrim(b.lines[k])) + "'");
    all.insert(all.end(), v.begin(), v.end());
  }
  if (all.size() < 3)
    c.fail(record_name(2), b.line_no[1], "expected the length, force and temperature factors (3D25.17)");
  u.length = all[0];
  u.force = all[1];
  u.temperature = all[2];
  u.temperature_offset = all.size() > 3 ? all[3] : 0.0;
  require_closed(c, b, record_name(3));
  return u;
}

// ---- 2414, 18, 2420 (vendor FE results and coordinate systems) ---------------------------------------------------

Uff2414 read2414(const Ctx& c, const Block& b, std::vector<std::string>* notes) {
  require_header(c, b.lines.size(), 13, b.last_line);
  Uff2414 d;
  const auto r1 = int_record(c, b.lines[0], b.line_no[0], 1, {10}, 1, "analysis dataset label");
  d.label = r1[0];
  d.name = std::string(rtrim(b.lines[1]));
  d.location = int_record(c, b.lines[2], b.line_no[2], 3, {10}, 1, "dataset location")[0];
  const auto r9 = ids_and_types(c, b, 3, "result type", &d.id, &d.model_type, &d.analysis_type, &d.data_characteristic);
  d.result_type = r9[3];
  d.data_type = r9[4];
  d.values_per_node = r9[5];
  if (d.data_type != 1 && d.data_type != 2 && d.data_type != 4 && d.data_type != 5 && d.data_type != 6)
    c.fail(record_name(9), b.line_no[8], "data type (field 5) must be 1, 2, 4, 5 or 6, found " + std::to_string(d.data_type));
  if (d.values_per_node < 1 || d.values_per_node > 9)
    c.fail(record_name(9), b.line_no[8], "values per data component (field 6) must be 1..9, found " + std::to_string(d.values_per_node));
  d.integers = int_record(c, b.lines[9], b.line_no[9], 10, {10}, 1, "integer analysis data 1-8");
  const auto r11 = int_record(c, b.lines[10], b.line_no[10], 11, {10}, 1, "integer analysis data 9-10");
  d.integers.resize(8, 0);
  d.integers.insert(d.integers.end(), r11.begin(), r11.end());
  d.integers.resize(10, 0);
  std::vector<double> r12, r13;
  if (!record_numbers(b.lines[11], {13}, &r12) || r12.empty())
    c.fail(record_name(12), b.line_no[11], "expected real values (6E13.5), found '" + std::string(rtrim(b.lines[11])) + "'");
  if (!record_numbers(b.lines[12], {13}, &r13) || r13.empty())
    c.fail(record_name(13), b.line_no[12], "expected real values (6E13.5), found '" + std::string(rtrim(b.lines[12])) + "'");
  r12.resize(6, 0.0);
  r13.resize(6, 0.0);
  d.reals = r12;
  d.reals.insert(d.reals.end(), r13.begin(), r13.end());
  if (d.location != 1) {
    require_closed(c, b, record_name(14));
    notes->push_back(c.file + ": dataset 2414 starting at line " + std::to_string(c.first_line) + ": data " +
                     (d.location == 2 ? "on elements" : d.location == 3 ? "at nodes on elements" : "at points") +
                     " (location " + std::to_string(d.location) + ") kept without values; dynid reads data at nodes");
    return d;
  }
  const std::size_t per_node = static_cast<std::size_t>(d.values_per_node) * (d.complex() ? 2 : 1);
  std::vector<double> vals;
  read_node_values(c, b, 13, per_node, 14, false, &d.nodes, &vals);
  require_closed(c, b, record_name(15));
  d.values = node_values(vals, static_cast<Eigen::Index>(d.nodes.size()), d.values_per_node, d.complex());
  return d;
}

UffCoordinateSystems read18(const Ctx& c, const Block& b) {
  UffCoordinateSystems d;
  std::size_t k = 0;
  std::vector<double> v, w;
  while (k < b.lines.size()) {
    if (trim(b.lines[k]).empty()) {
      ++k;
      continue;
    }
    if (k + 3 >= b.lines.size())
      c.fail(record_name(static_cast<int>(b.lines.size() - k) + 1), b.last_line,
             "coordinate system " + std::to_string(d.systems.size() + 1) + ": expected 4 records (file truncated?)");
    const auto r1 = int_record(c, b.lines[k], b.line_no[k], 1, {10}, 3, "number, type, reference system, colour, method");
    UffCoordinateSystem s;
    s.id = r1[0];
    s.type = r1[1];
    s.reference = r1[2];
    if (s.type < 0 || s.type > 2) c.fail(record_name(1), b.line_no[k], "coordinate system type must be 0, 1 or 2, found " + std::to_string(s.type));
    if (r1.size() > 4 && r1[4] != 1)
      c.fail(record_name(1), b.line_no[k], "method of definition " + std::to_string(r1[4]) + " is not 1 (origin, +x axis, +xz plane)");
    s.name = std::string(trim(b.lines[k + 1]));
    if (!record_numbers(b.lines[k + 2], {13}, &v) || v.size() != 6)
      c.fail(record_name(3), b.line_no[k + 2], "expected the origin and a point on +x (6E13.5), found '" + std::string(rtrim(b.lines[k + 2])) + "'");
    if (!record_numbers(b.lines[k + 3], {13}, &w) || w.size() != 3)
      c.fail(record_name(4), b.line_no[k + 3], "expected a point in the +xz plane (3E13.5), found '" + std::string(rtrim(b.lines[k + 3])) + "'");
    s.definition = {Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Vector3d(v[3], v[4], v[5]), Eigen::Vector3d(w[0], w[1], w[2])};
    d.systems.push_back(s);
    k += 4;
  }
  require_closed(c, b, record_name(4));
  return d;
}

UffCoordinateSystems read2420(const Ctx& c, const Block& b) {
  if (b.lines.size() < 2) c.fail(record_name(static_cast<int>(b.lines.size()) + 1), b.last_line, "the part header is incomplete (file truncated?)");
  UffCoordinateSystems d;
  d.part_uid = int_record(c, b.lines[0], b.line_no[0], 1, {10}, 1, "part UID")[0];
  d.part_name = std::string(trim(b.lines[1]));
  std::size_t k = 2;
  std::vector<double> v;
  while (k < b.lines.size()) {
    if (trim(b.lines[k]).empty()) {
      ++k;
      continue;
    }
    if (k + 5 >= b.lines.size())
      c.fail(record_name(3 + static_cast<int>(b.lines.size() - k)), b.last_line,
             "coordinate system " + std::to_string(d.systems.size() + 1) + ": expected 6 records (file truncated?)");
    const auto r3 = int_record(c, b.lines[k], b.line_no[k], 3, {10}, 2, "label, type, colour");
    UffCoordinateSystem s;
    s.id = r3[0];
    s.type = r3[1];
    if (s.type < 0 || s.type > 2) c.fail(record_name(3), b.line_no[k], "coordinate system type must be 0, 1 or 2, found " + std::to_string(s.type));
    s.name = std::string(trim(b.lines[k + 1]));
    Eigen::Matrix<double, 4, 3> T;
    for (int r = 0; r < 4; ++r) {
      if (!record_numbers(b.lines[k + 2 + r], {25}, &v) || v.size() != 3)
        c.fail(record_name(5 + r), b.line_no[k + 2 + r], "expected row " + std::to_string(r + 1) +
                                                             " of the transformation matrix (3D25.16), found '" + std::string(rtrim(b.lines[k + 2 + r])) + "'");
      T.row(r) << v[0], v[1], v[2];
    }
    const Eigen::Matrix3d A = T.topRows<3>().transpose();  // columns: the local axes
    if (!A.allFinite() || (A.transpose() * A - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || A.determinant() < 0)
      c.fail(record_name(5), b.line_no[k + 2], "coordinate system " + std::to_string(s.id) +
                                                   ": rows 1-3 of its transformation matrix are not a right-handed set of unit axes");
    s.axes = A;
    s.origin = T.row(3).transpose();
    s.resolved = true;
    d.systems.push_back(s);
    k += 6;
  }
  require_closed(c, b, record_name(8));
  return d;
}

constexpr double kDegree = 0.017453292519943295769236907684886;

}  // namespace

Eigen::Vector3d UffCoordinateSystem::to_global(const Eigen::Vector3d& p) const {
  Eigen::Vector3d local = p;
  if (type == 1) {
    const double t = p[1] * kDegree;
    local = Eigen::Vector3d(p[0] * std::cos(t), p[0] * std::sin(t), p[2]);
  } else if (type == 2) {
    const double t = p[1] * kDegree, f = p[2] * kDegree;
    local = Eigen::Vector3d(p[0] * std::sin(t) * std::cos(f), p[0] * std::sin(t) * std::sin(f), p[0] * std::cos(t));
  }
  return origin + axes * local;
}

Eigen::Matrix3d UffCoordinateSystem::directions_at(const Eigen::Vector3d& g) const {
  if (type == 0) return axes;
  const Eigen::Vector3d q = axes.transpose() * (g - origin);  // the point in the local Cartesian frame
  Eigen::Matrix3d local;
  const double phi = std::atan2(q[1], q[0]);
  if (type == 1) {
    local << std::cos(phi), -std::sin(phi), 0, std::sin(phi), std::cos(phi), 0, 0, 0, 1;
  } else {
    const double theta = std::atan2(std::hypot(q[0], q[1]), q[2]);
    const Eigen::Vector3d er(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    const Eigen::Vector3d et(std::cos(theta) * std::cos(phi), std::cos(theta) * std::sin(phi), -std::sin(theta));
    const Eigen::Vector3d ef(-std::sin(phi), std::cos(phi), 0);
    local.col(0) = er;
    local.col(1) = et;
    local.col(2) = ef;
  }
  return axes * local;
}

double Uff2414::frequency_hz() const {
  if ((analysis_type == 3 || analysis_type == 7) && reals.size() >= 8)
    return std::abs(std::complex<double>(reals[6], reals[7])) / kTwoPi;
  return reals.size() > 1 ? reals[1] : 0.0;
}

double Uff2414::damping_ratio() const {
  if ((analysis_type == 3 || analysis_type == 7) && reals.size() >= 8) {
    const double mag = std::abs(std::complex<double>(reals[6], reals[7]));
    return mag > 0 ? -reals[6] / mag : 0.0;
  }
  return analysis_type == 2 && reals.size() > 4 ? reals[4] : 0.0;
}

namespace {

// Every coordinate system of a file by id, resolved to global axes (18's definitions chain through their
// reference systems). Systems that cannot be resolved (a missing or circular reference) stay unresolved, with
// a note.
std::map<int, UffCoordinateSystem> coordinate_systems(UffFile* f) {
  std::map<int, UffCoordinateSystem> cs;
  for (UffDataset& ds : f->datasets)
    if (auto* d = std::get_if<UffCoordinateSystems>(&ds.data))
      for (const UffCoordinateSystem& s : d->systems) cs[s.id] = s;
  for (int pass = 0; pass < static_cast<int>(cs.size()) + 1; ++pass) {
    bool changed = false;
    for (auto& [id, s] : cs) {
      if (s.resolved) continue;
      const UffCoordinateSystem* ref = nullptr;
      UffCoordinateSystem global;
      global.resolved = true;
      if (s.reference == 0) ref = &global;
      else if (auto it = cs.find(s.reference); it != cs.end() && it->second.resolved) ref = &it->second;
      if (!ref) continue;
      const Eigen::Vector3d o = ref->to_global(s.definition[0]), px = ref->to_global(s.definition[1]),
                            pxz = ref->to_global(s.definition[2]);
      const Eigen::Vector3d x = px - o, v = pxz - o;
      const Eigen::Vector3d zdir = v - (v.dot(x) / std::max(x.squaredNorm(), 1e-300)) * x;
      if (!(x.norm() > 0) || !(zdir.norm() > 1e-12 * x.norm())) {
        f->notes.push_back(f->source + ": coordinate system " + std::to_string(id) +
                           ": its origin, +x point and +xz point do not span a plane; it is not applied");
        s.reference = id;  // never resolvable
        continue;
      }
      s.axes.col(0) = x.normalized();
      s.axes.col(2) = zdir.normalized();
      s.axes.col(1) = s.axes.col(2).cross(s.axes.col(0));
      s.origin = o;
      s.resolved = true;
      changed = true;
    }
    if (!changed) break;
  }
  for (const auto& [id, s] : cs)
    if (!s.resolved && s.reference != id)
      f->notes.push_back(f->source + ": coordinate system " + std::to_string(id) + " refers to system " + std::to_string(s.reference) +
                         ", which the file does not define (or which refers back to it); it is not applied");
  // Store the resolved systems back into the datasets (for readers of the datasets).
  for (UffDataset& ds : f->datasets)
    if (auto* d = std::get_if<UffCoordinateSystems>(&ds.data))
      for (UffCoordinateSystem& s : d->systems) s = cs[s.id];
  return cs;
}

// Turns the nodal vectors of `values` (nodes x 3 or 6: translations, then rotations) at nodes with a local
// displacement system into global directions. Returns the number of nodes turned; `missing` collects systems
// that are not defined.
int rotate_to_global(const std::vector<int>& nodes, Eigen::MatrixXcd* values, const std::map<int, UffNode>& node_of,
                     const std::map<int, UffCoordinateSystem>& cs, std::set<int>* missing) {
  int turned = 0;
  const Eigen::Index per = values->cols();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    auto n = node_of.find(nodes[i]);
    if (n == node_of.end() || n->second.displacement_cs == 0) continue;
    auto s = cs.find(n->second.displacement_cs);
    if (s == cs.end() || !s->second.resolved) {
      missing->insert(n->second.displacement_cs);
      continue;
    }
    const Eigen::Matrix3d R = s->second.directions_at(n->second.x);
    const auto row = static_cast<Eigen::Index>(i);
    for (Eigen::Index block = 0; block + 3 <= per; block += 3) {
      const Eigen::Vector3cd v = values->block(row, block, 1, 3).transpose();
      values->block(row, block, 1, 3) = (R.cast<std::complex<double>>() * v).transpose();
    }
    ++turned;
  }
  return turned;
}

// Converts local node coordinates to global and local vectors of 55/2414 to global directions, using the
// coordinate systems and nodes of `geo` (the file itself, or its geometry file).
void apply_coordinate_systems(UffFile* f, UffFile* geo) {
  const std::map<int, UffCoordinateSystem> cs = coordinate_systems(geo);
  if (geo == f) {
    int converted = 0;
    std::set<int> missing;
    for (UffDataset& ds : f->datasets)
      if (auto* d = std::get_if<UffNodes>(&ds.data))
        for (UffNode& n : d->nodes) {
          n.x_file = n.x;
          if (n.definition_cs == 0) continue;
          auto s = cs.find(n.definition_cs);
          if (s == cs.end() || !s->second.resolved) {
            n.global = false;
            missing.insert(n.definition_cs);
            continue;
          }
          n.x = s->second.to_global(n.x_file);
          ++converted;
        }
    if (converted > 0)
      f->notes.push_back(f->source + ": " + std::to_string(converted) + " node coordinates converted from local coordinate systems to global");
    for (int id : missing)
      f->notes.push_back(f->source + ": nodes are defined in coordinate system " + std::to_string(id) +
                         ", which the file does not define (dataset 18 or 2420): their coordinates are as written, not global");
  }
  std::map<int, UffNode> node_of;
  for (const UffDataset& ds : geo->datasets)
    if (const auto* d = std::get_if<UffNodes>(&ds.data))
      for (const UffNode& n : d->nodes) node_of[n.id] = n;
  bool any_local = false;
  for (const auto& [id, n] : node_of) any_local = any_local || n.displacement_cs != 0;
  if (!any_local) return;
  int turned = 0;
  std::set<int> missing;
  for (UffDataset& ds : f->datasets) {
    if (auto* d = std::get_if<Uff55>(&ds.data); d && !d->in_global && (d->values_per_node == 3 || d->values_per_node == 6)) {
      turned += rotate_to_global(d->nodes, &d->values, node_of, cs, &missing);
      d->in_global = true;
    }
    if (auto* d = std::get_if<Uff2414>(&ds.data);
        d && !d->in_global && d->location == 1 && (d->values_per_node == 3 || d->values_per_node == 6)) {
      turned += rotate_to_global(d->nodes, &d->values, node_of, cs, &missing);
      d->in_global = true;
    }
  }
  if (turned > 0)
    f->notes.push_back(f->source + ": nodal vectors at " + std::to_string(turned) +
                       " nodes turned from their local displacement coordinate systems to global directions");
  for (int id : missing)
    f->notes.push_back(f->source + ": nodal vectors refer to displacement coordinate system " + std::to_string(id) +
                       ", which is not defined: they are left in it");
}

}  // namespace

// ---- reading --------------------------------------------------------------------------------------------------

UffFile parse_uff(const std::string& bytes, const std::string& name) {
  UffFile f;
  f.source = name;
  internal::LineReader in(bytes);
  std::string_view l;
  while (in.next(&l)) {
    if (trim(l).empty()) continue;
    if (!is_delimiter(l))
      throw InputError(name + ": line " + std::to_string(in.line()) + ": expected the -1 line that starts a dataset, found '" +
                       std::string(trim(l)).substr(0, 40) + "'" + (f.datasets.empty() ? " (is this a UFF file?)" : ""));
    const int start = in.line();
    std::string_view type_line;
    if (!in.next(&type_line))
      throw InputError(name + ": dataset starting at line " + std::to_string(start) + ": the file ends after its -1 line");
    const std::string_view tok = trim(type_line).substr(0, trim(type_line).find_first_of(" \t"));
    const bool binary = !tok.empty() && (tok.back() == 'b' || tok.back() == 'B');
    int type = 0;
    if (!parse_int(binary ? tok.substr(0, tok.size() - 1) : tok, &type))
      throw InputError(name + ": dataset starting at line " + std::to_string(start) + " (line " + std::to_string(in.line()) +
                       "): expected the dataset number, found '" + std::string(trim(type_line)).substr(0, 40) + "'");
    UffDataset ds;
    ds.type = type;
    ds.first_line = start;
    const Ctx c{name, std::string(tok), start};
    if (binary) {
      if (type != 58) c.fail("", in.line(), "binary datasets other than 58b are not supported; convert it to ASCII");
      ds.data = read58_binary(c, in, type_line, in.line());
    } else {
      const Block b = read_block(in);
      switch (type) {
        case 58: ds.data = read58_ascii(c, b); break;
        case 55: ds.data = read55(c, b); break;
        case 15: ds.data = read15(c, b); break;
        case 2411: ds.data = read2411(c, b); break;
        case 2412: ds.data = read2412(c, b, &f.notes); break;
        case 164: ds.data = read164(c, b); break;
        case 2414: ds.data = read2414(c, b, &f.notes); break;
        case 18: ds.data = read18(c, b); break;
        case 2420: ds.data = read2420(c, b); break;
        default:
          if (!b.closed) c.fail("", b.last_line, "the file ends without the closing -1 line (truncated?)");
          ds.data = UffSkipped{};
      }
    }
    f.datasets.push_back(std::move(ds));
  }
  if (f.datasets.empty()) throw InputError(name + ": no UFF datasets (the file is empty or blank)");
  // Vectors are in global directions unless a node's displacement system says otherwise (applied below).
  for (UffDataset& ds : f.datasets) {
    if (auto* d = std::get_if<Uff55>(&ds.data)) d->in_global = false;
    if (auto* d = std::get_if<Uff2414>(&ds.data)) d->in_global = false;
  }
  apply_coordinate_systems(&f, &f);
  return f;
}

void uff_apply_coordinate_systems(UffFile* data, const UffFile& geometry) {
  UffFile geo = geometry;
  apply_coordinate_systems(data, &geo);
}

UffFile read_uff(const std::string& path) { return parse_uff(internal::read_file_bytes(path), path); }

double Uff55::frequency_hz() const {
  if ((analysis_type == 3 || analysis_type == 7) && record8.size() >= 2)
    return std::abs(std::complex<double>(record8[0], record8[1])) / kTwoPi;
  return record8.empty() ? 0.0 : record8[0];
}

double Uff55::damping_ratio() const {
  if ((analysis_type == 3 || analysis_type == 7) && record8.size() >= 2) {
    const double mag = std::abs(std::complex<double>(record8[0], record8[1]));
    return mag > 0 ? -record8[0] / mag : 0.0;
  }
  return analysis_type == 2 && record8.size() >= 3 ? record8[2] : 0.0;
}

// ---- writing --------------------------------------------------------------------------------------------------

namespace {

/// A real with 17 significant digits (reads back to the same double), 25 characters wide.
void put_real(std::string* s, double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%25.16E", v);
  *s += b;
}

/// printf-formatted text appended to s.
void put_text(std::string* s, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
void put_text(std::string* s, const char* fmt, ...) {
  char b[256];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(b, sizeof b, fmt, ap);
  va_end(ap);
  *s += b;
}

/// The "-1" and type lines that open an ASCII dataset.
std::string open_dataset(int type) {
  std::string s;
  put_text(&s, "%6d\n", -1);
  put_text(&s, "%6d\n", type);
  return s;
}

/// Text fields are cut to their width and must not hold line breaks.
std::string text_field(const std::string& s, std::size_t width) {
  std::string t = s.substr(0, width);
  for (char& ch : t)
    if (ch == '\n' || ch == '\r') ch = ' ';
  return t.empty() ? "NONE" : t;
}

void put_ids(std::string* s, const std::array<std::string, 5>& id) {
  for (const std::string& l : id) put_text(s, "%-80s\n", text_field(l, 80).c_str());
}

/// Values in lines of 3.
void put_values(std::string* s, const std::vector<double>& v) {
  for (std::size_t k = 0; k < v.size(); ++k) {
    put_real(s, v[k]);
    if (k % 3 == 2 || k + 1 == v.size()) *s += '\n';
  }
}

void put_axis(std::string* s, const UffAxis& a) {
  put_text(s, "%10d%5d%5d%5d %-20s %-20s\n", a.data_type, a.length_exp, a.force_exp, a.temperature_exp,
           text_field(a.label, 20).c_str(), text_field(a.unit, 20).c_str());
}

void put_le_double(std::string* s, double v) {
  std::uint64_t u;
  std::memcpy(&u, &v, 8);
  for (int k = 0; k < 8; ++k) s->push_back(static_cast<char>((u >> (8 * k)) & 0xFF));
}

}  // namespace

std::string format_uff58(const Uff58& d) {
  const auto n = d.y.size();
  if (n < 1) throw InputError("UFF 58 '" + d.id[0] + "': no points to write");
  if (!d.even && d.x.size() != n)
    throw InputError("UFF 58 '" + d.id[0] + "': uneven abscissa needs one x per point");
  Uff58 w = d;
  w.ordinate_type = d.is_complex() ? 6 : 4;  // dynid writes double precision
  std::vector<double> v;
  v.reserve(static_cast<std::size_t>(n * values_per_point(w)));
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!w.even) v.push_back(d.x[k]);
    v.push_back(d.y[k].real());
    if (w.is_complex()) v.push_back(d.y[k].imag());
  }
  std::string s = d.binary ? "" : open_dataset(58);
  if (d.binary) {
    put_text(&s, "%6d\n", -1);
    put_text(&s, "%6db%6d%6d%12d%12lld%6d%6d%12d%12d\n", 58, 1, 2, 11, static_cast<long long>(v.size() * 8), 0, 0, 0, 0);
  }
  put_ids(&s, d.id);
  put_text(&s, "%5d%10d%5d%10d %-10s%10d%4d %-10s%10d%4d\n", d.function_type, d.function_id, d.version, d.load_case,
           text_field(d.response_name, 10).c_str(), d.response_node, d.response_direction,
           text_field(d.reference_name, 10).c_str(), d.reference_node, d.reference_direction);
  put_text(&s, "%10d%10lld%10d", w.ordinate_type, static_cast<long long>(n), w.even ? 1 : 0);
  put_real(&s, w.even ? d.x_min : 0.0);
  put_real(&s, w.even ? d.dx : 0.0);
  put_real(&s, d.z_value);
  s += '\n';
  put_axis(&s, d.abscissa);
  put_axis(&s, d.ordinate);
  put_axis(&s, d.denominator);
  put_axis(&s, d.z_axis);
  if (d.binary)
    for (double x : v) put_le_double(&s, x);
  else
    put_values(&s, v);
  put_text(&s, "%6d\n", -1);
  return s;
}

std::string format_uff55(const Uff55& d) {
  if (d.values.rows() != static_cast<Eigen::Index>(d.nodes.size()) || d.values.cols() != d.values_per_node)
    throw InputError("UFF 55 '" + d.id[0] + "': values must be nodes x values per node");
  std::string s = open_dataset(55);
  put_ids(&s, d.id);
  put_text(&s, "%10d%10d%10d%10d%10d%10d\n", d.model_type, d.analysis_type, d.data_characteristic, d.data_type_code,
           d.complex ? 5 : 2, d.values_per_node);
  for (int i : d.record7) put_text(&s, "%10d", i);
  s += '\n';
  for (double r : d.record8) put_real(&s, r);
  s += '\n';
  for (std::size_t i = 0; i < d.nodes.size(); ++i) {
    put_text(&s, "%10d\n", d.nodes[i]);
    std::vector<double> v;
    for (int j = 0; j < d.values_per_node; ++j) {
      v.push_back(d.values(static_cast<Eigen::Index>(i), j).real());
      if (d.complex) v.push_back(d.values(static_cast<Eigen::Index>(i), j).imag());
    }
    put_values(&s, v);
  }
  put_text(&s, "%6d\n", -1);
  return s;
}

std::string format_uff15(const UffNodes& d) {
  std::string s = open_dataset(15);
  for (const UffNode& n : d.nodes) {
    put_text(&s, "%10d%10d%10d%10d", n.id, n.definition_cs, n.displacement_cs, n.colour);
    for (int k = 0; k < 3; ++k) put_real(&s, n.x[k]);
    s += '\n';
  }
  put_text(&s, "%6d\n", -1);
  return s;
}

std::string format_uff164(const UffUnits& u) {
  std::string s = open_dataset(164);
  put_text(&s, "%10d%-20s%10d\n", u.code, text_field(u.description, 20).c_str(), u.temperature_mode);
  put_real(&s, u.length);
  put_real(&s, u.force);
  put_real(&s, u.temperature);
  s += '\n';
  put_real(&s, u.temperature_offset);
  s += '\n';
  put_text(&s, "%6d\n", -1);
  return s;
}

void write_uff(const std::string& path, const std::vector<UffDataset>& datasets, bool overwrite) {
  std::string s;
  for (const UffDataset& d : datasets) {
    if (const auto* p = std::get_if<Uff58>(&d.data)) s += format_uff58(*p);
    else if (const auto* q = std::get_if<Uff55>(&d.data)) s += format_uff55(*q);
    else if (const auto* r = std::get_if<UffNodes>(&d.data)) s += format_uff15(*r);
    else if (const auto* u = std::get_if<UffUnits>(&d.data)) s += format_uff164(*u);
    else throw InputError(path + ": dynid cannot write UFF dataset " + std::to_string(d.type));
  }
  write_file_atomic(path, s, overwrite);
}

std::string uff_function_type_name(int t) {
  static const char* names[] = {"general",         "time response",     "auto spectrum",       "cross spectrum",
                                "FRF",             "transmissibility",  "coherence",           "auto correlation",
                                "cross correlation", "PSD",             "ESD",                 "probability density",
                                "spectrum",        "cumulative frequency distribution", "peaks valley", "stress/cycles",
                                "strain/cycles",   "orbit",             "mode indicator function", "force pattern",
                                "partial power",   "partial coherence", "eigenvalue",          "eigenvector",
                                "shock response spectrum", "finite impulse response filter", "multiple coherence",
                                "order function"};
  return t >= 0 && t < static_cast<int>(std::size(names)) ? names[t] : "type " + std::to_string(t);
}

std::string uff_data_type_name(int t) {
  static const std::map<int, const char*> names = {
      {0, "unknown"},        {1, "general"},      {2, "stress"},          {3, "strain"},   {5, "temperature"},
      {6, "heat flux"},      {8, "displacement"}, {9, "reaction force"},  {11, "velocity"}, {12, "acceleration"},
      {13, "excitation force"}, {15, "pressure"}, {16, "mass"},           {17, "time"},     {18, "frequency"},
      {19, "rpm"},           {20, "order"},       {21, "sound pressure"}, {22, "sound intensity"}, {23, "sound power"}};
  const auto it = names.find(t);
  return it != names.end() ? it->second : "type " + std::to_string(t);
}

// ---- conversions ----------------------------------------------------------------------------------------------

namespace {

struct Located {
  const Uff58* d;
  int line;
};

std::vector<Located> functions_of_type(const UffFile& f, int type) {
  std::vector<Located> out;
  for (const UffDataset& ds : f.datasets)
    if (const auto* p = std::get_if<Uff58>(&ds.data))
      if (p->function_type == type) out.push_back({p, ds.first_line});
  return out;
}

std::string at(const UffFile& f, int line) { return f.source + ": dataset 58 starting at line " + std::to_string(line); }

/// The DOF of a UFF node/direction pair and the sign that makes it positive.
MeasuredDof uff_dof(int node, int direction, double* sign) {
  MeasuredDof m;
  m.node = node;
  *sign = direction < 0 ? -1.0 : 1.0;
  if (direction != 0) m.dof = static_cast<Dof>(std::abs(direction) - 1);
  return m;
}

int uff_direction(const MeasuredDof& m) { return static_cast<int>(m.dof) + 1; }

Quantity quantity_of(int data_type) {
  switch (data_type) {
    case 8: return Quantity::kDisplacement;
    case 11: return Quantity::kVelocity;
    case 12: return Quantity::kAcceleration;
    case 9:
    case 13: return Quantity::kForce;
    default: return Quantity::kOther;
  }
}

int data_type_of(const Channel& c) {
  switch (c.quantity) {
    case Quantity::kDisplacement: return 8;
    case Quantity::kVelocity: return 11;
    case Quantity::kAcceleration: return 12;
    case Quantity::kForce: return c.input ? 13 : 9;
    case Quantity::kOther: return 1;
  }
  return 1;
}

std::string unit_of(const std::string& label) { return label == "NONE" ? "" : label; }

Channel response_channel(const Uff58& d, double* sign) {
  Channel c;
  c.dof = uff_dof(d.response_node, d.response_direction, sign);
  c.quantity = quantity_of(d.ordinate.data_type);
  c.input = d.ordinate.data_type == 13;
  c.unit = unit_of(d.ordinate.unit);
  c.name = d.id[0] != "NONE" && !d.id[0].empty() ? d.id[0] : d.response_name != "NONE" ? d.response_name : "";
  return c;
}

void require_same_grid(const UffFile& f, const Located& a, const Located& b, const char* what) {
  bool same = a.d->x.size() == b.d->x.size();
  for (Eigen::Index k = 0; same && k < a.d->x.size(); ++k)
    same = std::abs(a.d->x[k] - b.d->x[k]) <= 1e-9 * std::max(std::abs(a.d->x[k]), std::abs(b.d->x[k]));
  if (!same)
    throw InputError(at(f, b.line) + ": its " + what + " (" + std::to_string(b.d->x.size()) +
                     " points) differs from that of the dataset at line " + std::to_string(a.line) + " (" +
                     std::to_string(a.d->x.size()) + " points); dynid needs one common " + what);
}

Uff58 function_base(int type, const std::string& name, const MeasuredDof& rsp, int ref_node, int ref_dir) {
  Uff58 d;
  d.function_type = type;
  d.id[0] = name.empty() ? "NONE" : name;
  d.response_name = name.empty() ? "NONE" : name.substr(0, 10);
  d.response_node = rsp.node;
  d.response_direction = uff_direction(rsp);
  d.reference_node = ref_node;
  d.reference_direction = ref_dir;
  return d;
}

UffAxis axis(int type, const std::string& label, const std::string& unit) {
  UffAxis a;
  a.data_type = type;
  a.label = label;
  a.unit = unit.empty() ? "NONE" : unit;
  return a;
}

/// Even spacing if x_k == x_0 + k dx reproduces every abscissa exactly, else uneven.
void set_abscissa(Uff58* d, const Eigen::VectorXd& x) {
  d->x = x;
  d->x_min = x[0];
  d->dx = x.size() > 1 ? x[1] - x[0] : 1.0;
  d->even = d->dx > 0;
  for (Eigen::Index k = 0; d->even && k < x.size(); ++k) d->even = even_abscissa(d->x_min, d->dx, k) == x[k];
}

UffDataset dataset58(Uff58 d) {
  UffDataset ds;
  ds.type = 58;
  ds.data = std::move(d);
  return ds;
}

}  // namespace

Channel uff_channel(const Uff58& d, double* sign) { return response_channel(d, sign); }

bool uff_reference(const Uff58& d, MeasuredDof* dof) {
  if (d.reference_node == 0 || d.reference_direction == 0 || std::abs(d.reference_direction) > 6) return false;
  double s = 1;
  *dof = uff_dof(d.reference_node, d.reference_direction, &s);
  return true;
}

Recording uff_recording(const UffFile& f) {
  const std::vector<Located> t = functions_of_type(f, 1);
  if (t.empty()) throw InputError(f.source + ": no time responses (dataset 58 with function type 1)");
  Recording r;
  r.source = f.source;
  using Key = std::tuple<int, int, std::string>;
  std::map<Key, int> seen;  // occurrences of each channel: the n-th occurrence belongs to record n
  std::vector<std::vector<std::pair<Key, const Located*>>> recs;
  for (const Located& l : t) {
    if (!l.d->even)
      throw InputError(at(f, l.line) + ": time response with uneven abscissa; dynid needs evenly sampled data");
    if (l.d->is_complex()) throw InputError(at(f, l.line) + ": time response with complex values");
    require_same_grid(f, t[0], l, "sampling (start, interval and length)");
    const Key key{l.d->response_node, std::abs(l.d->response_direction), l.d->id[0] + "|" + l.d->response_name};
    const int rec = seen[key]++;
    if (rec >= static_cast<int>(recs.size())) recs.resize(static_cast<std::size_t>(rec) + 1);
    recs[static_cast<std::size_t>(rec)].push_back({key, &l});
  }
  const std::size_t nc = recs[0].size();
  std::vector<double> sign(nc);
  for (std::size_t c = 0; c < nc; ++c) r.channels.push_back(response_channel(*recs[0][c].second->d, &sign[c]));
  const Eigen::Index ns = t[0].d->y.size();
  for (std::size_t k = 0; k < recs.size(); ++k) {
    if (recs[k].size() != nc)
      throw InputError(f.source + ": record " + std::to_string(k + 1) + " has " + std::to_string(recs[k].size()) +
                       " channels, the first has " + std::to_string(nc) + " (channel repeated at line " +
                       std::to_string(recs[k][0].second->line) + "); every record needs the same channels");
    Eigen::MatrixXd m(ns, static_cast<Eigen::Index>(nc));
    for (std::size_t c = 0; c < nc; ++c) {
      if (recs[k][c].first != recs[0][c].first)
        throw InputError(at(f, recs[k][c].second->line) + ": record " + std::to_string(k + 1) +
                         " lists its channels in another order than record 1");
      m.col(static_cast<Eigen::Index>(c)) = sign[c] * recs[k][c].second->d->y.real();
    }
    r.records.push_back(std::move(m));
  }
  r.sample_rate_hz = 1.0 / t[0].d->dx;
  r.validate(f.source);
  return r;
}

FrfData uff_frf(const UffFile& f) { return uff_frf(std::vector<const UffFile*>{&f}); }

FrfData uff_frf(const std::vector<const UffFile*>& files) {
  struct At {
    const UffFile* f;
    Located l;
  };
  std::vector<At> t;
  for (const UffFile* f : files)
    for (const Located& l : functions_of_type(*f, 4)) t.push_back({f, l});
  if (t.empty()) throw InputError((files.empty() ? std::string("UFF") : files[0]->source) + (files.size() > 1 ? " and the other files" : "") +
                                  ": no FRFs (dataset 58 with function type 4)");
  FrfData h;
  h.source = files[0]->source + (files.size() > 1 ? " and " + std::to_string(files.size() - 1) + " more" : "");
  auto index_of = [](std::vector<Channel>& list, const Channel& c) {
    for (std::size_t k = 0; k < list.size(); ++k)
      if (list[k].dof == c.dof) return static_cast<int>(k);
    list.push_back(c);
    return static_cast<int>(list.size()) - 1;
  };
  struct Entry {
    int o, i;
    std::complex<double> sign;
    const At* a;
  };
  std::vector<Entry> entries;
  for (const At& a : t) {
    if (a.f == t[0].f) require_same_grid(*a.f, t[0].l, a.l, "frequency grid");
    else {
      bool same = a.l.d->x.size() == t[0].l.d->x.size();
      for (Eigen::Index k = 0; same && k < a.l.d->x.size(); ++k)
        same = std::abs(a.l.d->x[k] - t[0].l.d->x[k]) <= 1e-9 * std::max(std::abs(a.l.d->x[k]), std::abs(t[0].l.d->x[k]));
      if (!same)
        throw InputError(at(*a.f, a.l.line) + ": its frequency grid (" + std::to_string(a.l.d->x.size()) + " points) differs from that of " +
                         at(*t[0].f, t[0].l.line) + " (" + std::to_string(t[0].l.d->x.size()) + " points); FRFs identified together need one grid");
    }
    double so = 1, si = 1;
    Channel out = response_channel(*a.l.d, &so);
    out.input = false;
    Channel in;
    in.dof = uff_dof(a.l.d->reference_node, a.l.d->reference_direction, &si);
    in.quantity = Quantity::kForce;
    in.input = true;
    in.unit = unit_of(a.l.d->denominator.unit);
    in.name = a.l.d->reference_name != "NONE" ? a.l.d->reference_name : "";
    entries.push_back({index_of(h.outputs, out), index_of(h.inputs, in), so * si, &a});
  }
  const int no = h.num_outputs(), ni = h.num_inputs();
  const Eigen::Index nf = t[0].l.d->x.size();
  h.frequency_hz = t[0].l.d->x;
  h.H.setZero(nf, no * ni);
  std::vector<const At*> from(static_cast<std::size_t>(no * ni), nullptr);
  for (const Entry& e : entries) {
    const At*& first = from[static_cast<std::size_t>(e.o + e.i * no)];
    if (first)
      throw InputError(at(*e.a->f, e.a->l.line) + ": FRF " + to_string(h.outputs[e.o].dof) + "/" + to_string(h.inputs[e.i].dof) +
                       " already given by " + at(*first->f, first->l.line));
    first = e.a;
    h.H.col(e.o + e.i * no) = e.sign * e.a->l.d->y;
  }
  std::string missing;
  for (int i = 0; i < ni; ++i)
    for (int o = 0; o < no; ++o)
      if (!from[static_cast<std::size_t>(o + i * no)])
        missing += (missing.empty() ? "" : ", ") + to_string(h.outputs[o].dof) + "/" + to_string(h.inputs[i].dof);
  if (!missing.empty())
    throw InputError(h.source + ": missing FRFs for output/input pairs " + missing +
                     " (every response DOF needs an FRF for every reference DOF)");
  // Coherence in the FRF layout: ordinary coherence (type 6) per output/input pair, or multiple coherence (26)
  // per output repeated over the inputs; kept only if every FRF has one on the same grid.
  Eigen::MatrixXd c = Eigen::MatrixXd::Constant(nf, static_cast<Eigen::Index>(no) * ni, std::numeric_limits<double>::quiet_NaN());
  for (int type : {26, 6})
    for (const UffFile* f : files)
      for (const Located& l : functions_of_type(*f, type)) {
        double s = 1;
        const MeasuredDof d = uff_dof(l.d->response_node, l.d->response_direction, &s);
        if (l.d->x.size() != nf) continue;
        for (int o = 0; o < no; ++o) {
          if (!(h.outputs[o].dof == d)) continue;
          for (int i = 0; i < ni; ++i) {
            if (type == 6 && !(h.inputs[i].dof == uff_dof(l.d->reference_node, l.d->reference_direction, &s))) continue;
            c.col(o + i * no) = l.d->y.real();
          }
        }
      }
  if (c.allFinite()) h.coherence = c;
  h.validate(h.source);
  return h;
}

ModalData uff_modal_data(const UffFile& f) {
  // One view per mode: 55 (analysis type 2, 3, 7) and 2414 (data at nodes, analysis type 2, 3, 7, three- or six-DOF
  // vectors).
  struct ModeView {
    const std::vector<int>* nodes;
    const Eigen::MatrixXcd* values;
    int values_per_node;
    bool complex;
    double frequency_hz, damping;
  };
  std::vector<ModeView> modes;
  for (const UffDataset& ds : f.datasets) {
    if (const auto* p = std::get_if<Uff55>(&ds.data))
      if (p->analysis_type == 2 || p->analysis_type == 3 || p->analysis_type == 7)
        modes.push_back({&p->nodes, &p->values, p->values_per_node, p->complex, p->frequency_hz(), p->damping_ratio()});
    if (const auto* q = std::get_if<Uff2414>(&ds.data))
      if ((q->analysis_type == 2 || q->analysis_type == 3 || q->analysis_type == 7) && q->location == 1 &&
          (q->data_characteristic == 2 || q->data_characteristic == 3) && q->values.cols() >= 3)
        modes.push_back({&q->nodes, &q->values, static_cast<int>(q->values.cols()), q->complex(), q->frequency_hz(), q->damping_ratio()});
  }
  if (modes.empty())
    throw InputError(f.source + ": no modes (dataset 55, or 2414 with data at nodes, analysis type 2, 3 or 7)");
  std::vector<int> nodes;
  std::map<int, int> row_of;
  for (const ModeView& m : modes)
    for (int n : *m.nodes)
      if (row_of.emplace(n, static_cast<int>(nodes.size())).second) nodes.push_back(n);
  const auto nm = static_cast<Eigen::Index>(modes.size());
  Eigen::MatrixXd all = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nodes.size()) * kNumDofTypes, nm);
  ModalData out;
  out.source = f.source;
  out.frequencies_hz.resize(nm);
  out.damping_ratios.resize(nm);
  for (Eigen::Index k = 0; k < nm; ++k) {
    const ModeView& m = modes[static_cast<std::size_t>(k)];
    const Eigen::MatrixXcd& values = *m.values;
    std::complex<double> rot = 1.0;
    if (m.complex && values.size() > 0) {
      Eigen::Index i, j;
      values.cwiseAbs().maxCoeff(&i, &j);
      if (std::abs(values(i, j)) > 0) rot = std::conj(values(i, j)) / std::abs(values(i, j));
    }
    for (std::size_t n = 0; n < m.nodes->size(); ++n)
      for (int j = 0; j < std::min(m.values_per_node, kNumDofTypes); ++j)
        all(row_of[(*m.nodes)[n]] * kNumDofTypes + j, k) = (rot * values(static_cast<Eigen::Index>(n), j)).real();
    out.frequencies_hz[k] = m.frequency_hz;
    out.damping_ratios[k] = m.damping;
  }
  std::vector<Eigen::Index> keep;
  for (Eigen::Index r = 0; r < all.rows(); ++r)
    if ((all.row(r).array() != 0.0).any()) {
      keep.push_back(r);
      out.dofs.push_back({nodes[static_cast<std::size_t>(r / kNumDofTypes)], static_cast<Dof>(r % kNumDofTypes)});
    }
  out.shapes.resize(static_cast<Eigen::Index>(keep.size()), nm);
  for (std::size_t r = 0; r < keep.size(); ++r) out.shapes.row(static_cast<Eigen::Index>(r)) = all.row(keep[r]);
  if ((out.damping_ratios.array() == 0.0).all()) out.damping_ratios.resize(0);
  out.validate(f.source);
  return out;
}

std::vector<UffDataset> uff_datasets(const Recording& r, bool binary) {
  r.validate("recording " + r.source);
  std::vector<UffDataset> out;
  // The reference DOF (record 6): the excitation DOF when the recording has one force channel (a hammer location
  // or one shaker), so files of one test can be told apart from those of another.
  const std::vector<int> ins = r.input_channels();
  const MeasuredDof* ref = ins.size() == 1 && r.channels[static_cast<std::size_t>(ins[0])].dof.node != 0 ? &r.channels[static_cast<std::size_t>(ins[0])].dof : nullptr;
  for (std::size_t k = 0; k < r.records.size(); ++k)
    for (int c = 0; c < r.num_channels(); ++c) {
      const Channel& ch = r.channels[static_cast<std::size_t>(c)];
      Uff58 d = function_base(1, ch.name, ch.dof, ref ? ref->node : 0, ref ? uff_direction(*ref) : 0);
      d.load_case = static_cast<int>(k) + 1;
      d.binary = binary;
      d.ordinate_type = 4;
      d.even = true;
      d.x_min = 0;
      d.dx = 1.0 / r.sample_rate_hz;
      d.abscissa = axis(17, "Time", "s");
      d.ordinate = axis(data_type_of(ch), to_string(ch.quantity), ch.unit);
      const Eigen::VectorXd y = r.records[k].col(c);
      d.y = y.cast<std::complex<double>>();
      d.x.resize(y.size());
      for (Eigen::Index i = 0; i < y.size(); ++i) d.x[i] = even_abscissa(0.0, d.dx, i);
      out.push_back(dataset58(std::move(d)));
    }
  return out;
}

std::vector<UffDataset> uff_datasets(const FrfData& h, bool binary) {
  h.validate("FRFs " + h.source);
  std::vector<UffDataset> out;
  for (int i = 0; i < h.num_inputs(); ++i)
    for (int o = 0; o < h.num_outputs(); ++o) {
      const Channel& oc = h.outputs[static_cast<std::size_t>(o)];
      const Channel& ic = h.inputs[static_cast<std::size_t>(i)];
      Uff58 d = function_base(4, oc.name, oc.dof, ic.dof.node, uff_direction(ic.dof));
      d.reference_name = ic.name.empty() ? "NONE" : ic.name.substr(0, 10);
      d.binary = binary;
      d.ordinate_type = 6;
      set_abscissa(&d, h.frequency_hz);
      d.abscissa = axis(18, "Frequency", "Hz");
      d.ordinate = axis(data_type_of(oc), to_string(oc.quantity), oc.unit);
      d.denominator = axis(13, "force", ic.unit);
      d.y = h.H.col(o + i * h.num_outputs());
      out.push_back(dataset58(std::move(d)));
    }
  if (h.coherence.size())
    for (int i = 0; i < h.num_inputs(); ++i)
      for (int o = 0; o < h.num_outputs(); ++o) {
        const Channel& oc = h.outputs[static_cast<std::size_t>(o)];
        const Channel& ic = h.inputs[static_cast<std::size_t>(i)];
        Uff58 d = function_base(6, oc.name, oc.dof, ic.dof.node, uff_direction(ic.dof));
        d.binary = binary;
        d.ordinate_type = 4;
        set_abscissa(&d, h.frequency_hz);
        d.abscissa = axis(18, "Frequency", "Hz");
        d.ordinate = axis(0, "coherence", "");
        d.y = h.coherence.col(o + i * h.num_outputs()).cast<std::complex<double>>();
        out.push_back(dataset58(std::move(d)));
      }
  return out;
}

std::vector<UffDataset> uff_datasets(const ModalData& m) {
  m.validate("modal data " + m.source);
  std::vector<int> nodes;
  std::map<int, int> row_of;
  bool rotations = false;
  for (const MeasuredDof& d : m.dofs) {
    if (row_of.emplace(d.node, static_cast<int>(nodes.size())).second) nodes.push_back(d.node);
    rotations = rotations || is_rotation(d.dof);
  }
  const int per = rotations ? 6 : 3;
  std::vector<UffDataset> out;
  for (int k = 0; k < m.num_modes(); ++k) {
    Uff55 d;
    d.id[0] = "Mode " + std::to_string(k + 1);
    d.data_characteristic = rotations ? 3 : 2;
    d.values_per_node = per;
    d.record7 = {2, 4, 1, k + 1};
    d.record8 = {m.frequencies_hz[k], 0.0, m.damping_ratios.size() > k ? m.damping_ratios[k] : 0.0, 0.0};
    d.nodes = nodes;
    d.values = Eigen::MatrixXcd::Zero(static_cast<Eigen::Index>(nodes.size()), per);
    for (std::size_t r = 0; r < m.dofs.size(); ++r)
      d.values(row_of[m.dofs[r].node], static_cast<int>(m.dofs[r].dof)) = m.shapes(static_cast<Eigen::Index>(r), k);
    UffDataset ds;
    ds.type = 55;
    ds.data = std::move(d);
    out.push_back(std::move(ds));
  }
  return out;
}

void write_uff58_recording(const std::string& path, const Recording& r, bool binary, bool overwrite) {
  write_uff(path, uff_datasets(r, binary), overwrite);
}

void write_uff58_frf(const std::string& path, const FrfData& h, bool binary, bool overwrite) {
  write_uff(path, uff_datasets(h, binary), overwrite);
}

void write_uff55(const std::string& path, const ModalData& m, bool overwrite) {
  write_uff(path, uff_datasets(m), overwrite);
}

}  // namespace dynid
