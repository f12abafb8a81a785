// Plain-text test data readers (see dynid/io/test_data.hpp).
#include "dynid/io/test_data.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>

#include "dynid/io/mat_file.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/solvers/signal.hpp"
#include "internal/text_util.hpp"

namespace dynid {

using internal::parse_double;
using internal::split_fields;
using internal::trim;

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool contains(const std::string& s, const char* what) { return lower(s).find(what) != std::string::npos; }

std::string where(const std::string& path, int line) { return path + ":" + std::to_string(line); }

/// Rows of numbers, with the line of each row; `names` from a header row if there is one.
struct Rows {
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  std::vector<int> line_of;
};

// NaN and Inf parse as numbers (from_chars reads "nan", "inf"), but no measurement holds them: an error naming
// the line and column.
template <class Fields>
void require_finite(const std::vector<double>& v, const Fields& f, const std::string& at) {
  for (std::size_t k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]))
      throw InputError(at + ": column " + std::to_string(k + 1) + ": '" + std::string(f[k]) +
                       "' is not a finite number (mark a missing sample by leaving the row out)");
}

Rows parse_rows(const std::string& bytes, const std::string& path) {
  internal::LineReader in(bytes);
  Rows r;
  std::string_view l;
  std::size_t width = 0;
  while (in.next(&l)) {
    const std::string_view t = trim(l);
    if (t.empty() || t.front() == '#') continue;
    const auto f = split_fields(t, true);
    std::vector<double> v(f.size());
    std::size_t bad = f.size();
    for (std::size_t k = 0; k < f.size() && bad == f.size(); ++k)
      if (!parse_double(f[k], &v[k])) bad = k;
    if (bad < f.size()) {
      if (r.rows.empty() && r.names.empty()) {  // the header row
        for (auto s : f) r.names.emplace_back(s);
        continue;
      }
      throw InputError(where(path, in.line()) + ": column " + std::to_string(bad + 1) + ": '" + std::string(f[bad]) +
                       "' is not a number");
    }
    require_finite(v, f, where(path, in.line()));
    if (r.rows.empty()) width = v.size();
    if (v.size() != width)
      throw InputError(where(path, in.line()) + ": " + std::to_string(v.size()) + " fields, the first data row (line " +
                       std::to_string(r.line_of[0]) + ") has " + std::to_string(width));
    r.rows.push_back(std::move(v));
    r.line_of.push_back(in.line());
  }
  if (r.rows.empty()) throw InputError(path + ": no rows of numbers");
  return r;
}

TextTable to_table(const Rows& r, const std::string& path, bool x_column) {
  TextTable t;
  t.source = path;
  const auto n = static_cast<Eigen::Index>(r.rows.size());
  const std::size_t width = r.rows[0].size();
  const std::size_t first = x_column ? 1 : 0;
  if (width <= first) throw InputError(path + ": no data columns besides the first (time or frequency) column");
  t.x.resize(n);
  t.columns.resize(n, static_cast<Eigen::Index>(width - first));
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& row = r.rows[static_cast<std::size_t>(i)];
    t.x[i] = x_column ? row[0] : static_cast<double>(i);
    for (std::size_t c = first; c < width; ++c) t.columns(i, static_cast<Eigen::Index>(c - first)) = row[c];
  }
  std::vector<std::string> names = r.names;
  if (names.size() == width + 1 && lower(names.back()) == "comment") names.pop_back();
  if (!names.empty() && names.size() != width)
    throw InputError(path + ": the header names " + std::to_string(names.size()) + " columns, the rows have " +
                     std::to_string(width));
  if (x_column) t.x_name = names.empty() ? "" : names[0];
  for (std::size_t c = first; c < width; ++c)
    t.names.push_back(names.empty() ? "ch" + std::to_string(c - first + 1) : names[c]);
  t.units.assign(t.names.size(), "");
  t.dx = n > 1 ? (t.x[n - 1] - t.x[0]) / static_cast<double>(n - 1) : 0.0;
  return t;
}

Channel guess_channel(const std::string& name, const std::string& unit) {
  Channel c;
  c.name = name;
  c.unit = unit;
  c.quantity = Quantity::kOther;
  const std::string both = name + " " + unit;
  if (contains(both, "force") || contains(unit, "lbf") || lower(unit) == "n" || contains(unit, "pound")) {
    c.quantity = Quantity::kForce;
    c.input = true;
  } else if (contains(name, "acc") || lower(unit) == "g" || contains(unit, "m/s^2") || contains(unit, "m/s2")) {
    c.quantity = Quantity::kAcceleration;
  } else if (contains(name, "vel")) {
    c.quantity = Quantity::kVelocity;
  } else if (contains(name, "disp")) {
    c.quantity = Quantity::kDisplacement;
  }
  // A DOF label among the name's words ("5uy", "acc 5uy", "17ux force", "acc_5uy").
  std::string words = name;
  for (char& ch : words)
    if (ch == '_' || ch == ',' || ch == ';' || ch == '(' || ch == ')' || ch == '[' || ch == ']') ch = ' ';
  for (std::string_view w : split_fields(words)) {
    MeasuredDof d;
    double sign = 1;
    if (parse_dof_label(std::string(w), &d, &sign) && d.node > 0 && sign > 0) {
      c.dof = d;
      break;
    }
  }
  return c;
}

Recording recording_of(const TextTable& t, double sample_rate_hz) {
  Recording r;
  r.source = t.source;
  r.sample_rate_hz = sample_rate_hz;
  for (std::size_t c = 0; c < t.names.size(); ++c) r.channels.push_back(guess_channel(t.names[c], t.units[c]));
  r.records.push_back(t.columns);
  r.validate(t.source);
  return r;
}

bool same_grid(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() != b.size()) return false;
  for (Eigen::Index k = 0; k < a.size(); ++k)
    if (std::abs(a[k] - b[k]) > 1e-9 * std::max(std::abs(a[k]), std::abs(b[k]))) return false;
  return true;
}

bool any_of_words(const std::string& name, std::initializer_list<const char*> words) {
  std::string n = lower(name);
  for (char& ch : n)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = ' ';
  for (std::string_view w : split_fields(n))
    for (const char* x : words)
      if (w == x) return true;
  return false;
}
bool starts_with_any(const std::string& name, std::initializer_list<const char*> prefixes) {
  const std::string n = lower(std::string(trim(name)));
  for (const char* p : prefixes)
    if (n.rfind(p, 0) == 0) return true;
  return false;
}

// The complex inverse DFT of re + i im (length n), from two real forward FFTs:
// idft(x)[t] = conj(dft(conj(x)))[t] / n, dft(a - i b) = dft(a) - i dft(b), each real-input DFT completed by its
// conjugate symmetry.
Eigen::VectorXcd inverse_dft(const Eigen::VectorXd& re, const Eigen::VectorXd& im) {
  const int n = static_cast<int>(re.size());
  RealFft fft(n);
  std::vector<std::complex<double>> A(static_cast<std::size_t>(n / 2 + 1)), B(A.size());
  Eigen::VectorXd a = re, b = im;
  fft.forward(a.data(), A.data());
  fft.forward(b.data(), B.data());
  auto full = [&](const std::vector<std::complex<double>>& X, int k) { return k <= n / 2 ? X[static_cast<std::size_t>(k)] : std::conj(X[static_cast<std::size_t>(n - k)]); };
  Eigen::VectorXcd out(n);
  for (int k = 0; k < n; ++k) out[k] = std::conj(full(A, k) - std::complex<double>(0, 1) * full(B, k)) / static_cast<double>(n);
  return out;
}

}  // namespace

const char* to_string(TableKind k) {
  switch (k) {
    case TableKind::kTimeHistory: return "time history";
    case TableKind::kFrf: return "FRF";
    case TableKind::kSpectrum: return "spectrum";
    case TableKind::kAuto: return "auto";
  }
  return "?";
}

double frf_causality(const Eigen::VectorXd& re, const Eigen::VectorXd& im) {
  if (re.size() != im.size() || re.size() < 8) return 0;
  // (i k)^p H for p = 0, 1, 2 (receptance, mobility, accelerance up to a scale of the lines): causal whatever
  // the response quantity, and one of them keeps a measured FRF's low-frequency blow-up (receptance from
  // accelerance) or high-frequency noise from swamping the rest.
  double best = 0;
  for (int p = 0; p <= 2; ++p) {
    Eigen::VectorXd a(re.size()), b(re.size());
    for (Eigen::Index k = 0; k < re.size(); ++k) {
      const std::complex<double> z = std::complex<double>(re[k], im[k]) * std::pow(std::complex<double>(0, static_cast<double>(k)), p);
      a[k] = z.real(), b[k] = z.imag();
    }
    const Eigen::VectorXcd g = inverse_dft(a, b);
    const Eigen::Index n = g.size(), half = n / 2;
    double ep = 0, em = 0;
    for (Eigen::Index t = 1; t < half; ++t) ep += std::norm(g[t]), em += std::norm(g[n - t]);
    if (ep + em > 0) best = std::max(best, std::abs(ep - em) / (ep + em));
  }
  return best;
}

TableKind classify_text_table(const TextTable& t, std::string* why) {
  auto say = [&](TableKind k, const std::string& w) {
    if (why) *why = w;
    return k;
  };
  const Eigen::Index nc = t.columns.cols();
  // 1. The header, when it names the columns.
  bool re_im = nc >= 2 && nc % 2 == 0;
  for (Eigen::Index c = 0; re_im && c < nc; ++c) {
    const std::string& nm = t.names[static_cast<std::size_t>(c)];
    re_im = c % 2 == 0 ? starts_with_any(nm, {"re", "real"}) : starts_with_any(nm, {"im", "imag"});
  }
  bool spectral_names = false;
  for (const std::string& nm : t.names) spectral_names = spectral_names || contains(nm, "fft") || contains(nm, "spectrum") || contains(nm, "psd") || any_of_words(nm, {"db", "magnitude", "mag", "amplitude"});
  const bool time_axis = any_of_words(t.x_name, {"time", "t", "s", "sec", "seconds"});
  const bool freq_axis = starts_with_any(t.x_name, {"freq"}) || any_of_words(t.x_name, {"hz", "f"});
  if (re_im && !time_axis) return say(TableKind::kFrf, "the header names real and imaginary columns");
  if (spectral_names && !time_axis) return say(TableKind::kSpectrum, "the header names a spectrum");
  if (time_axis) return say(TableKind::kTimeHistory, "the first column is named '" + t.x_name + "' (time)");
  // 2. Numbers: (re, im) pairs of one causal function.
  if (nc >= 2 && nc % 2 == 0 && t.x.size() >= 16 && t.x[0] >= 0) {
    double worst = 1;
    for (Eigen::Index c = 0; c < nc; c += 2) worst = std::min(worst, frf_causality(t.columns.col(c), t.columns.col(c + 1)));
    if (worst >= 0.5)
      return say(TableKind::kFrf, "columns 2 and 3 are the real and imaginary parts of one causal function (causality " +
                                      std::to_string(worst).substr(0, 4) + " >= 0.5)" + (freq_axis ? "" : ", read as an FRF"));
  }
  // 3. One-signed columns: magnitudes or levels, not a signal about zero.
  bool one_signed = nc >= 1;
  for (Eigen::Index c = 0; c < nc && one_signed; ++c) one_signed = t.columns.col(c).minCoeff() >= 0 || t.columns.col(c).maxCoeff() <= 0;
  if (one_signed) return say(TableKind::kSpectrum, "every data column keeps one sign (magnitudes or dB levels, not a vibration signal)");
  if (freq_axis) return say(TableKind::kSpectrum, "the first column is named '" + t.x_name + "' (frequency)");
  return say(TableKind::kTimeHistory, "columns that change sign and are not real/imaginary pairs: time histories");
}

FrfData frf_of_tables(const std::vector<TextTable>& tables, const std::vector<MeasuredDof>& outputs, const std::vector<MeasuredDof>& inputs) {
  if (tables.empty()) throw InputError("FRF text files: none given");
  std::size_t total = 0;
  for (const TextTable& t : tables) {
    if (t.columns.cols() < 2 || t.columns.cols() % 2 != 0)
      throw InputError(t.source + ": expected columns frequency, then real and imaginary parts (an odd number of columns), found " +
                       std::to_string(t.columns.cols() + 1));
    total += static_cast<std::size_t>(t.columns.cols() / 2);
  }
  auto dof_at = [&](const std::vector<MeasuredDof>& l, std::size_t k, const char* what) {
    if (l.size() == 1) return l[0];
    if (l.size() != total)
      throw InputError("FRF text files: " + std::to_string(total) + " FRFs need as many " + what + " DOFs (or one for all); got " + std::to_string(l.size()));
    return l[k];
  };
  FrfData h;
  h.source = tables[0].source + (tables.size() > 1 ? " and " + std::to_string(tables.size() - 1) + " more" : "");
  auto index_of = [](std::vector<Channel>& list, const MeasuredDof& d, bool input) {
    for (std::size_t k = 0; k < list.size(); ++k)
      if (list[k].dof == d) return static_cast<int>(k);
    Channel c;
    c.dof = d;
    c.name = to_string(d);
    c.input = input;
    c.quantity = input ? Quantity::kForce : Quantity::kOther;
    list.push_back(c);
    return static_cast<int>(list.size()) - 1;
  };
  struct Pair {
    int o, i;
    std::size_t table;
    Eigen::Index col;
    MeasuredDof od, id;
  };
  std::vector<Pair> pairs;
  std::size_t k = 0;
  for (std::size_t t = 0; t < tables.size(); ++t) {
    if (t > 0 && !same_grid(tables[0].x, tables[t].x))
      throw InputError(tables[t].source + ": its frequencies (" + std::to_string(tables[t].x.size()) + " lines) differ from those of " +
                       tables[0].source + " (" + std::to_string(tables[0].x.size()) + " lines); FRFs identified together need one grid");
    for (Eigen::Index c = 0; c < tables[t].columns.cols(); c += 2, ++k) {
      const MeasuredDof od = dof_at(outputs, k, "output"), id = dof_at(inputs, k, "input");
      pairs.push_back({index_of(h.outputs, od, false), index_of(h.inputs, id, true), t, c, od, id});
    }
  }
  const int no = h.num_outputs(), ni = h.num_inputs();
  h.frequency_hz = tables[0].x;
  h.H.setZero(h.frequency_hz.size(), no * ni);
  std::vector<int> from(static_cast<std::size_t>(no * ni), -1);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const Pair& q = pairs[p];
    const int col = q.o + q.i * no;
    if (from[static_cast<std::size_t>(col)] >= 0)
      throw InputError(tables[q.table].source + ": FRF " + to_string(q.od) + "/" + to_string(q.id) + " already read from " +
                       tables[pairs[static_cast<std::size_t>(from[static_cast<std::size_t>(col)])].table].source +
                       " (give each FRF its own output/input DOFs)");
    from[static_cast<std::size_t>(col)] = static_cast<int>(p);
    h.H.col(col).real() = tables[q.table].columns.col(q.col);
    h.H.col(col).imag() = tables[q.table].columns.col(q.col + 1);
  }
  std::string missing;
  for (int i = 0; i < ni; ++i)
    for (int o = 0; o < no; ++o)
      if (from[static_cast<std::size_t>(o + i * no)] < 0)
        missing += (missing.empty() ? "" : ", ") + to_string(h.outputs[o].dof) + "/" + to_string(h.inputs[i].dof);
  if (!missing.empty()) throw InputError(h.source + ": missing FRFs for output/input pairs " + missing);
  h.validate(h.source);
  return h;
}

TextTable parse_text_table(const std::string& text, const std::string& name, bool x_column) {
  return to_table(parse_rows(text, name), name, x_column);
}
TextTable read_text_table(const std::string& path, bool x_column) {
  return parse_text_table(internal::read_file_bytes(path), path, x_column);
}

double check_even_steps(const Eigen::VectorXd& x, const std::vector<int>& line_of, const std::string& what) {
  const Eigen::Index n = x.size();
  if (n < 2) throw InputError(what + ": fewer than 2 samples");
  const double first = x[1] - x[0];
  for (Eigen::Index k = 1; k < n; ++k) {
    const double step = x[k] - x[k - 1];
    if (!(first > 0) || std::abs(step - first) > 0.02 * first) {
      const std::string line = k < static_cast<Eigen::Index>(line_of.size()) ? std::to_string(line_of[k]) : "?";
      throw InputError(what + ":" + line + ": the step changes to " + std::to_string(step) + " (it is " +
                       std::to_string(first) + " at the start); samples must be evenly spaced and increasing");
    }
  }
  return (x[n - 1] - x[0]) / static_cast<double>(n - 1);
}

Recording read_time_text(const std::string& path, double sample_rate_hz) {
  const Rows rows = parse_rows(internal::read_file_bytes(path), path);
  const TextTable t = to_table(rows, path, sample_rate_hz <= 0);
  const double fs = sample_rate_hz > 0 ? sample_rate_hz : 1.0 / check_even_steps(t.x, rows.line_of, path);
  return recording_of(t, fs);
}

FrfData read_frf_text(const std::string& path, const MeasuredDof& output, const MeasuredDof& input) {
  return read_frf_text_set({path}, {output}, {input});
}

FrfData read_frf_text_set(const std::vector<std::string>& paths, const std::vector<MeasuredDof>& outputs,
                          const std::vector<MeasuredDof>& inputs) {
  if (paths.empty()) throw InputError("FRF text files: none given");
  if (outputs.size() != paths.size() || inputs.size() != paths.size())
    throw InputError("FRF text files: " + std::to_string(paths.size()) + " files need as many output and input DOFs (got " +
                     std::to_string(outputs.size()) + " and " + std::to_string(inputs.size()) + ")");
  std::vector<TextTable> tables;
  for (const std::string& p : paths) {
    tables.push_back(read_text_table(p, true));
    if (tables.back().columns.cols() != 2)
      throw InputError(p + ": expected 3 columns (frequency, real, imaginary), found " + std::to_string(tables.back().columns.cols() + 1));
  }
  return frf_of_tables(tables, outputs, inputs);
}

LvmFile read_lvm(const std::string& path) { return parse_lvm(internal::read_file_bytes(path), path); }

LvmFile parse_lvm(const std::string& bytes, const std::string& path) {
  internal::LineReader in(bytes);
  std::string_view l;
  if (!in.next(&l) || trim(l).substr(0, 19) != "LabVIEW Measurement")
    throw InputError(path + ":1: not a LabVIEW measurement file (the first line must be 'LabVIEW Measurement')");
  std::map<std::string, std::vector<std::string>> header;  // key -> values (per channel in the segment header)
  int ends = 0;
  while (ends < 2 && in.next(&l)) {
    const auto f = split_fields(l);
    if (f.empty()) continue;
    if (f[0] == "***End_of_Header***") {
      ++ends;
      continue;
    }
    std::vector<std::string>& v = header[std::string(f[0])];
    v.clear();
    for (std::size_t k = 1; k < f.size(); ++k) v.emplace_back(f[k]);
  }
  if (ends < 2) throw InputError(path + ": the file ends inside its header (two ***End_of_Header*** lines expected)");
  auto value = [&](const char* key) { return header.count(key) && !header[key].empty() ? header[key][0] : ""; };
  if (value("Separator") != "" && value("Separator") != "Tab")
    throw InputError(path + ": separator '" + value("Separator") + "' is not supported (only Tab)");
  const bool comma = value("Decimal_Separator") == ",";
  const std::string xcols = value("X_Columns").empty() ? "One" : value("X_Columns");
  LvmFile out;
  parse_double(value("Delta_X"), &out.header_delta_x);
  std::vector<std::string> names;
  std::vector<std::vector<double>> rows;
  std::vector<int> line_of;
  while (in.next(&l)) {
    if (trim(l).empty()) continue;
    // Fields are tab separated; names may hold blanks.
    std::vector<std::string> f;
    std::size_t start = 0;
    while (start <= l.size()) {
      const std::size_t tab = std::min(l.find('\t', start), l.size());
      f.emplace_back(trim(l.substr(start, tab - start)));
      start = tab + 1;
    }
    while (!f.empty() && f.back().empty()) f.pop_back();
    if (f.empty()) continue;
    std::vector<double> v(f.size());
    bool numeric = true;
    for (std::size_t k = 0; k < f.size() && numeric; ++k) {
      if (comma) std::replace(f[k].begin(), f[k].end(), ',', '.');
      numeric = parse_double(f[k], &v[k]);
    }
    if (!numeric) {
      if (rows.empty() && names.empty()) {
        names = f;
        continue;
      }
      if (f[0] == "***End_of_Header***" || f[0] == "Channels")
        throw InputError(where(path, in.line()) + ": a second segment; dynid reads single-segment LVM files");
      throw InputError(where(path, in.line()) + ": '" + f[0] + "...' is not a row of numbers");
    }
    require_finite(v, f, where(path, in.line()));
    if (!rows.empty() && v.size() != rows[0].size())
      throw InputError(where(path, in.line()) + ": " + std::to_string(v.size()) + " fields, the first row has " +
                       std::to_string(rows[0].size()));
    rows.push_back(std::move(v));
    line_of.push_back(in.line());
  }
  if (rows.empty()) throw InputError(path + ": no data rows after the header");
  const std::size_t width = rows[0].size();
  if (names.size() > width) names.resize(width);  // the trailing "Comment" column
  // Which columns are X and which are channels.
  std::vector<std::size_t> ycols;
  int xcol = -1;
  for (std::size_t c = 0; c < width; ++c) {
    const bool is_x = (xcols == "One" && c == 0) || (xcols == "Multi" && c % 2 == 0);
    if (is_x && xcol < 0) xcol = static_cast<int>(c);
    if (!is_x) ycols.push_back(c);
  }
  if (ycols.empty()) throw InputError(path + ": no channel columns");
  TextTable& t = out.table;
  t.source = path;
  const auto n = static_cast<Eigen::Index>(rows.size());
  t.x.resize(n);
  t.columns.resize(n, static_cast<Eigen::Index>(ycols.size()));
  double x0 = 0;
  parse_double(value("X0"), &x0);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& row = rows[static_cast<std::size_t>(i)];
    t.x[i] = xcol >= 0 ? row[static_cast<std::size_t>(xcol)] : x0 + static_cast<double>(i) * out.header_delta_x;
    for (std::size_t c = 0; c < ycols.size(); ++c) t.columns(i, static_cast<Eigen::Index>(c)) = row[ycols[c]];
  }
  t.x_name = xcol >= 0 && static_cast<std::size_t>(xcol) < names.size() ? names[static_cast<std::size_t>(xcol)] : "X";
  const std::vector<std::string> units = header.count("Y_Unit_Label") ? header["Y_Unit_Label"] : std::vector<std::string>{};
  for (std::size_t c = 0; c < ycols.size(); ++c) {
    t.names.push_back(ycols[c] < names.size() ? names[ycols[c]] : "ch" + std::to_string(c + 1));
    t.units.push_back(c < units.size() ? units[c] : "");
  }
  t.dx = check_even_steps(t.x, line_of, path);
  out.spectrum = lower(value("X_Dimension")) == "frequency";
  for (const std::string& name : t.names)
    out.spectrum = out.spectrum || contains(name, "fft") || contains(name, "spectrum") || contains(name, "psd");
  if (!out.spectrum) out.recording = recording_of(t, 1.0 / t.dx);
  return out;
}

TestData read_test_data(const std::string& path, double sample_rate_hz, TableKind kind, const ReaderLimits& limits) {
  std::string ext = lower(std::filesystem::path(path).extension().string());
  if (ext == ".mat") {  // a MATLAB recording: data (channels x samples), fs, channels (dynid/io/mat_file.hpp)
    MatRecordingNames names;
    names.file = path;
    names.sample_rate_hz = sample_rate_hz;
    TestData d;
    d.kind = TestData::Kind::kTimeHistory;
    d.recording = read_mat_recording(names, limits);
    return d;
  }
  if (ext != ".uff" && ext != ".unv" && ext != ".lvm" && ext != ".txt" && ext != ".csv" && ext != ".dat" && ext != ".tsv") {
    // By content: the first non-blank line.
    const std::string head = internal::read_file_bytes(path).substr(0, 4096);
    internal::LineReader in(head);
    std::string_view l;
    while (in.next(&l) && trim(l).empty()) {
    }
    ext = trim(l) == "-1" ? ".uff" : trim(l).substr(0, 19) == "LabVIEW Measurement" ? ".lvm" : ".txt";
  }
  TestData d;
  if (ext == ".uff" || ext == ".unv") {
    d.kind = TestData::Kind::kUff;
    d.uff = read_uff(path);
  } else if (ext == ".lvm") {
    LvmFile f = read_lvm(path);
    d.kind = f.spectrum ? TestData::Kind::kSpectrum : TestData::Kind::kTimeHistory;
    if (kind == TableKind::kSpectrum && !f.spectrum) d.kind = TestData::Kind::kSpectrum;
    d.how = f.spectrum ? "LabVIEW spectrum (channel name or X_Dimension)" : "LabVIEW time data";
    d.table = std::move(f.table);
    d.recording = std::move(f.recording);
  } else if (sample_rate_hz > 0 || kind == TableKind::kTimeHistory) {
    d.kind = TestData::Kind::kTimeHistory;
    d.recording = read_time_text(path, sample_rate_hz);
    d.how = sample_rate_hz > 0 ? "time history (a sampling rate was given: every column a channel)" : "time history (as told)";
  } else {
    const Rows rows = parse_rows(internal::read_file_bytes(path), path);
    TextTable t = to_table(rows, path, true);
    const TableKind k = kind != TableKind::kAuto ? kind : classify_text_table(t, &d.how);
    if (kind != TableKind::kAuto) d.how = std::string(to_string(kind)) + " (as told)";
    if (k == TableKind::kTimeHistory) {
      d.kind = TestData::Kind::kTimeHistory;
      d.recording = recording_of(t, 1.0 / check_even_steps(t.x, rows.line_of, path));
    } else {
      d.kind = k == TableKind::kFrf ? TestData::Kind::kFrf : TestData::Kind::kSpectrum;
      if (k == TableKind::kFrf && (t.columns.cols() % 2 != 0))
        throw InputError(path + ": an FRF table needs frequency, then real and imaginary columns (an odd number of columns); it has " +
                         std::to_string(t.columns.cols() + 1));
      t.dx = t.x.size() > 1 ? (t.x[t.x.size() - 1] - t.x[0]) / static_cast<double>(t.x.size() - 1) : 0.0;
    }
    d.table = std::move(t);
  }
  return d;
}

}  // namespace dynid
