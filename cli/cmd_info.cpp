// dynid info FILE... [--fs HZ]: what a test-data file holds (UFF datasets, text / LabVIEW channels).
#include <fmt/core.h>

#include <algorithm>
#include <set>

#include "commands.hpp"
#include "dynid/io/test_data.hpp"
#include "dynid/io/test_layout.hpp"
#include "dynid/io/uff.hpp"

namespace dynid::cli {

namespace {
struct InfoArgs {
  std::vector<std::string> files;
  double fs = 0;
};

/// "13+X", "13-RZ", or "13 (scalar)" for direction 0.
std::string uff_dof_text(int node, int direction) {
  static const char* names[] = {"X", "Y", "Z", "RX", "RY", "RZ"};
  if (direction == 0) return fmt::format("{} (scalar)", node);
  return fmt::format("{}{}{}", node, direction < 0 ? '-' : '+', names[std::abs(direction) - 1]);
}

std::string unit_text(const UffAxis& a) {
  std::string s = a.label == "NONE" || a.label.empty() ? uff_data_type_name(a.data_type) : a.label;
  if (!a.unit.empty() && a.unit != "NONE") s += " [" + a.unit + "]";
  return s;
}

void print_58(const Uff58& d) {
  const char* precision = d.is_double() ? "double" : "single";
  std::string storage = d.binary ? fmt::format("binary 58b {} endian", d.big_endian ? "big" : "little") : "ascii";
  fmt::print("{}, response {}", uff_function_type_name(d.function_type), uff_dof_text(d.response_node, d.response_direction));
  if (d.response_name != "NONE" && !d.response_name.empty()) fmt::print(" '{}'", d.response_name);
  if (d.reference_direction != 0 || d.reference_node != 0)
    fmt::print(", reference {}", uff_dof_text(d.reference_node, d.reference_direction));
  fmt::print(", {} points, ", d.num_points());
  if (d.even) fmt::print("even spacing {:.6g} from {:.6g}", d.dx, d.x_min);
  else fmt::print("uneven spacing");
  fmt::print(", {} vs {}", unit_text(d.ordinate), unit_text(d.abscissa));
  if (d.function_type == 4 || d.denominator.data_type != 0) fmt::print(" per {}", unit_text(d.denominator));
  fmt::print(", {} {}, {}\n", d.is_complex() ? "complex" : "real", precision, storage);
}

void print_uff(const UffFile& f) {
  fmt::print("{}: UFF, {} datasets\n", f.source, f.datasets.size());
  for (const UffDataset& ds : f.datasets) {
    fmt::print("  {:>5}  line {:>7}: ", ds.type, ds.first_line);
    if (const auto* d58 = std::get_if<Uff58>(&ds.data)) {
      print_58(*d58);
    } else if (const auto* d55 = std::get_if<Uff55>(&ds.data)) {
      fmt::print("data at nodes, analysis type {}, mode {}: {:.6g} Hz, damping {:.4g}, {} nodes x {} {} values\n",
                 d55->analysis_type, d55->mode_number(), d55->frequency_hz(), d55->damping_ratio(), d55->nodes.size(),
                 d55->values_per_node, d55->complex ? "complex" : "real");
    } else if (const auto* nodes = std::get_if<UffNodes>(&ds.data)) {
      fmt::print("{} nodes\n", nodes->nodes.size());
    } else if (const auto* el = std::get_if<UffElements>(&ds.data)) {
      std::set<int> fe;
      for (const UffElement& e : el->elements) fe.insert(e.fe_descriptor);
      std::string list;
      for (int t : fe) list += (list.empty() ? "" : ", ") + std::to_string(t);
      fmt::print("{} elements (FE descriptors {})\n", el->elements.size(), list);
    } else if (const auto* u = std::get_if<UffUnits>(&ds.data)) {
      fmt::print("units {} '{}': length factor {:.6g}, force {:.6g}, temperature {:.6g}, offset {:.6g}\n", u->code,
                 u->description, u->length, u->force, u->temperature, u->temperature_offset);
    } else if (const auto* a = std::get_if<Uff2414>(&ds.data)) {
      fmt::print("analysis data, analysis type {}, data characteristic {}, result type {}, mode {}: {:.6g} Hz, {} nodes x {} {} values\n",
                 a->analysis_type, a->data_characteristic, a->result_type, a->mode_number(), a->frequency_hz(), a->nodes.size(),
                 a->values_per_node, a->complex() ? "complex" : "real");
    } else if (const auto* cs = std::get_if<UffCoordinateSystems>(&ds.data)) {
      int resolved = 0;
      for (const UffCoordinateSystem& c : cs->systems) resolved += c.resolved;
      fmt::print("{} coordinate systems ({} resolved to global axes)\n", cs->systems.size(), resolved);
    } else {
      fmt::print("skipped (dataset type not read by dynid)\n");
    }
  }
  for (const std::string& n : f.notes) fmt::print("  note: {}\n", n);
}

void print_recording(const std::string& path, const Recording& r) {
  const auto samples = r.records.empty() ? 0 : r.records[0].rows();
  fmt::print("{}: time history, {} channels, sampling rate {:.8g} Hz, {} samples ({:.6g} s)", path, r.num_channels(),
             r.sample_rate_hz, samples, static_cast<double>(samples) / r.sample_rate_hz);
  if (r.records.size() > 1) fmt::print(", {} records", r.records.size());
  fmt::print("\n");
  for (const Channel& c : r.channels)
    fmt::print("  {:<24} {:<13}{}{}\n", c.name, to_string(c.quantity), c.unit.empty() ? "" : " [" + c.unit + "]",
               c.input ? " (input)" : "");
}

void print_table(const std::string& path, const TextTable& t) {
  const auto n = t.x.size();
  fmt::print("{}: spectrum, {} columns, step {:.6g}, {} lines ({:.6g} .. {:.6g})\n", path, t.columns.cols(), t.dx, n,
             n ? t.x[0] : 0.0, n ? t.x[n - 1] : 0.0);
  for (std::size_t c = 0; c < t.names.size(); ++c)
    fmt::print("  {:<24}{}\n", t.names[c], t.units[c].empty() ? "" : " [" + t.units[c] + "]");
}

void print_frf_table(const std::string& path, const TextTable& t) {
  const auto n = t.x.size();
  fmt::print("{}: FRF table, {} FRF{} (real, imaginary pairs), step {:.6g}, {} lines ({:.6g} .. {:.6g})\n", path, t.columns.cols() / 2,
             t.columns.cols() > 2 ? "s" : "", t.dx, n, n ? t.x[0] : 0.0, n ? t.x[n - 1] : 0.0);
}

int info_file(const std::string& path, const InfoArgs& a, const GlobalOptions& g, std::vector<TestData>* read) {
  TestData d = read_test_data(path, a.fs, TableKind::kAuto, g.limits);
  switch (d.kind) {
    case TestData::Kind::kUff: print_uff(d.uff); break;
    case TestData::Kind::kTimeHistory: print_recording(path, d.recording); break;
    case TestData::Kind::kSpectrum: print_table(path, d.table); break;
    case TestData::Kind::kFrf: print_frf_table(path, d.table); break;
  }
  if (!d.how.empty()) fmt::print("  read as: {}\n", d.how);
  read->push_back(std::move(d));
  return 0;
}

// How the files group into tests (test_layout.hpp): one line per test, then the notes and inconsistencies.
int info_groups(const std::vector<TestData>& files, const std::vector<std::string>& paths, const InfoArgs& a) {
  TestSetOptions o;
  o.sample_rate_hz = a.fs;
  const TestSet s = assemble_test_set(files, paths, o);
  if (s.kind == TestSet::Kind::kRecordings) {
    fmt::print("{} test{} in {} file{}:\n", s.tests.size(), s.tests.size() == 1 ? "" : "s", paths.size(), paths.size() == 1 ? "" : "s");
    for (std::size_t k = 0; k < s.tests.size(); ++k) fmt::print("  test {}: {}\n", k + 1, s.tests[k].summary());
  } else if (s.kind == TestSet::Kind::kFrf) {
    fmt::print("FRFs: {} outputs x {} inputs, {} lines ({:.6g} .. {:.6g} Hz), from {} file{}\n", s.frf.num_outputs(), s.frf.num_inputs(),
               s.frf.frequency_hz.size(), s.frf.frequency_hz[0], s.frf.frequency_hz[s.frf.frequency_hz.size() - 1], paths.size(),
               paths.size() == 1 ? "" : "s");
  }
  for (const std::string& n : s.notes) fmt::print("  note: {}\n", n);
  for (const std::string& p : s.problems) fmt::print("  inconsistent: {}\n", p);
  return s.problems.empty() ? 0 : 2;
}
}  // namespace

void register_info(CLI::App& app, GlobalOptions& g) {
  auto a = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "What test-data files hold: UFF datasets, text and LabVIEW channels, and how they group into tests");
  cmd->add_option("FILE", a->files, "UFF (.uff/.unv), LabVIEW (.lvm) or text (.txt/.csv) files")->required();
  cmd->add_option("--fs", a->fs, "Sampling rate [Hz] of text files without a time column")->check(CLI::PositiveNumber);
  cmd->callback([a, &g]() {
    int rc = 0;
    std::vector<TestData> read;
    std::vector<std::string> paths;
    for (const std::string& f : a->files) {
      const std::size_t before = read.size();
      rc = std::max(rc, run_guarded("info", [&] { return info_file(f, *a, g, &read); }));
      if (read.size() > before) paths.push_back(f);
    }
    // The grouping only when every file was read and they hold test data (not only geometry or modes).
    bool data = false;
    for (const TestData& d : read) {
      if (d.kind != TestData::Kind::kUff) data = true;
      else
        for (const UffDataset& ds : d.uff.datasets)
          if (const Uff58* u = std::get_if<Uff58>(&ds.data)) data = data || u->function_type == 1 || u->function_type == 4;
    }
    if (rc == 0 && data) rc = std::max(rc, run_guarded("info", [&] { return info_groups(read, paths, *a); }));
    g.exit_code = rc;
  });
}

}  // namespace dynid::cli
