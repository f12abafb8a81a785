// Low-level text helpers shared by the test-data readers (UFF, CSV, LVM); internal to io.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace dynid::internal {

/// Reads a whole file as bytes (every reader goes through it). Throws InputError naming the path if it cannot
/// be opened, is a folder, a device or a FIFO (which would never end), or is larger than `max_bytes`.
std::string read_file_bytes(const std::string& path, std::size_t max_bytes = std::size_t(1) << 31);

std::string_view trim(std::string_view s);
std::string_view rtrim(std::string_view s);
/// Fields separated by blanks, tabs (and commas when `commas`).
std::vector<std::string_view> split_fields(std::string_view line, bool commas = false);

/// A real number, Fortran style allowed ("1.5D+03", "+2.", "-1.e-5"), surrounding blanks ignored; the whole
/// field must be the number.
bool parse_double(std::string_view s, double* out);
/// An integer (the whole field, blanks ignored), within int range.
bool parse_int(std::string_view s, int* out);

/// Base64 (RFC 4648, with padding) of arbitrary bytes: images and compressed scripts embedded in a report.
std::string base64(const std::string& bytes);

/// A number for messages and reports, `digits` significant digits ("%.*g": 0.0123, 1.5e+07).
std::string format_number(double v, int digits = 4);

/// The numbers of a Fortran record: split on blanks first; if a field is not a number (fields run together,
/// e.g. "-1.23456E+100-2.34567E+100"), by the fixed column `widths` of the record's format instead, repeated
/// cyclically to the end of the line (blank fixed fields are skipped); if that fails too (narrower fields than
/// the format, e.g. "-1.23456E+00-2.34567E+00"), by cutting before each sign that follows a digit or '.'.
/// Returns false if none works.
bool record_numbers(std::string_view line, const std::vector<int>& widths, std::vector<double>* out);

/// Sequential line reader over a byte buffer: strips "\n" / "\r\n", counts lines (1-based).
class LineReader {
 public:
  explicit LineReader(const std::string& bytes) : buf_(bytes) {}
  /// The next line (without its end); false at the end of the buffer.
  bool next(std::string_view* line);
  int line() const { return line_; }       ///< number of the line last returned
  std::size_t pos() const { return pos_; }  ///< byte offset of the next line
  std::size_t remaining() const { return buf_.size() - pos_; }
  /// Takes `n` raw bytes at the current position (caller checked remaining()); line numbers follow the
  /// newlines inside them.
  std::string_view take_bytes(std::size_t n);

 private:
  const std::string& buf_;
  std::size_t pos_ = 0;
  int line_ = 0;
  bool mid_line_ = false;  ///< take_bytes stopped inside a line
};

}  // namespace dynid::internal
