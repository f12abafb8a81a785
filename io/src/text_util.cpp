#include "internal/text_util.hpp"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <cctype>
#include <climits>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "dynid/mesh/error.hpp"

namespace dynid::internal {

std::string read_file_bytes(const std::string& path, std::size_t max_bytes) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": is a folder, not a file");
  // Only regular files: a device (/dev/zero) or a FIFO named by a hostile input would never end.
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw InputError(path + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file (does it exist and is it readable?)");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(path + ": cannot determine the file size");
  if (static_cast<unsigned long long>(size) > max_bytes)
    throw InputError(path + ": file of " + std::to_string(size) + " bytes is larger than the " +
                     std::to_string(max_bytes) + " bytes dynid reads; split it");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.seekg(0, std::ios::beg);
  in.read(bytes.data(), size);
  if (!in) throw InputError(path + ": read failed");
  return bytes;
}

static bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

std::string_view rtrim(std::string_view s) {
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  return rtrim(s);
}

std::vector<std::string_view> split_fields(std::string_view line, bool commas) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  auto sep = [&](char c) { return is_blank(c) || (commas && c == ','); };
  while (i < line.size()) {
    while (i < line.size() && sep(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !sep(line[i])) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

bool parse_double(std::string_view s, double* out) {
  s = trim(s);
  if (s.empty() || s.size() > 64) return false;
  char buf[72];
  std::size_t n = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    char c = s[i];
    if (c == 'D' || c == 'd') c = 'E';  // Fortran double-precision exponent
    if (c == '+' && i == 0) continue;   // from_chars does not take a leading '+'
    buf[n++] = c;
  }
  if (n == 0) return false;
  const auto r = std::from_chars(buf, buf + n, *out);
  return r.ec == std::errc() && r.ptr == buf + n;
}

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string o;
  o.reserve((in.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(in[i]) << 16) | (static_cast<unsigned char>(in[i + 1]) << 8) |
                       static_cast<unsigned char>(in[i + 2]);
    o += t[v >> 18], o += t[(v >> 12) & 63], o += t[(v >> 6) & 63], o += t[v & 63];
  }
  if (i < in.size()) {
    unsigned v = static_cast<unsigned char>(in[i]) << 16;
    if (i + 1 < in.size()) v |= static_cast<unsigned char>(in[i + 1]) << 8;
    o += t[v >> 18], o += t[(v >> 12) & 63];
    o += i + 1 < in.size() ? t[(v >> 6) & 63] : '=';
    o += '=';
  }
  return o;
}

std::string format_number(double v, int digits) {
  char b[40];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

bool parse_int(std::string_view s, int* out) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

bool record_numbers(std::string_view line, const std::vector<int>& widths, std::vector<double>* out) {
  out->clear();
  bool ok = true;
  for (std::string_view f : split_fields(line)) {
    double v;
    if (!parse_double(f, &v)) {
      ok = false;
      break;
    }
    out->push_back(v);
  }
  if (ok) return true;
  out->clear();
  line = rtrim(line);
  if (!widths.empty()) {
    std::size_t pos = 0;
    ok = true;
    for (std::size_t k = 0; ok && pos < line.size(); ++k) {
      const std::size_t w = static_cast<std::size_t>(widths[k % widths.size()]);
      const std::string_view field = line.substr(pos, w);
      pos += w;
      double v;
      if (trim(field).empty()) continue;
      ok = parse_double(field, &v);
      out->push_back(v);
    }
    if (ok) return true;
    out->clear();
  }
  // Narrower fields than the format says, run together: split before a sign that follows a digit or '.'.
  for (std::string_view f : split_fields(line)) {
    std::size_t start = 0;
    for (std::size_t i = 1; i <= f.size(); ++i) {
      const bool cut = i == f.size() || ((f[i] == '-' || f[i] == '+') &&
                                         (std::isdigit(static_cast<unsigned char>(f[i - 1])) || f[i - 1] == '.'));
      if (!cut) continue;
      double v;
      if (!parse_double(f.substr(start, i - start), &v)) return false;
      out->push_back(v);
      start = i;
    }
  }
  return true;
}

bool LineReader::next(std::string_view* line) {
  if (pos_ >= buf_.size()) return false;
  std::size_t end = buf_.find('\n', pos_);
  std::size_t next = end == std::string::npos ? buf_.size() : end + 1;
  if (end == std::string::npos) end = buf_.size();
  std::size_t stop = end;
  if (stop > pos_ && buf_[stop - 1] == '\r') --stop;
  *line = std::string_view(buf_).substr(pos_, stop - pos_);
  pos_ = next;
  if (!mid_line_) ++line_;
  mid_line_ = false;
  return true;
}

std::string_view LineReader::take_bytes(std::size_t n) {
  const std::string_view bytes = std::string_view(buf_).substr(pos_, n);
  line_ += static_cast<int>(std::count(bytes.begin(), bytes.end(), '\n'));
  pos_ += bytes.size();
  mid_line_ = !bytes.empty() && bytes.back() != '\n';
  return bytes;
}

}  // namespace dynid::internal
