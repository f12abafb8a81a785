// dynid identify RECORDINGS... : modal identification (LSCF on FRFs or input/output recordings, SSI-cov on
// output-only recordings). dynid simulate-test CASE : a virtual test of a case's model, written as UFF 58.
#include <fmt/core.h>

#include <filesystem>

#include "commands.hpp"
#include "dynid/engine/frf.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/engine/virtual_test.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/identify_io.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/output.hpp"
#include "dynid/io/test_data.hpp"
#include "dynid/io/test_layout.hpp"
#include "dynid/io/uff.hpp"
#include "dynid/mesh/error.hpp"
#include "progress.hpp"

namespace dynid::cli {

namespace {

namespace fs = std::filesystem;

struct IdentifyArgs {
  std::vector<std::string> files;
  std::string method, json, uff, plot, out_stem;
  std::vector<double> band, orders;
  std::vector<std::string> outputs, inputs;  // DOF labels for FRF text files
  bool frf_text = false, force = false;
  std::string as;  // what text tables hold: "" (by content), time, frf, spectrum
  double fs = 0, exponential = 0;
  int segment = -1;
  std::string estimator = "h1";
};

std::vector<MeasuredDof> labels(const std::vector<std::string>& l, const char* what) {
  std::vector<MeasuredDof> out;
  for (const std::string& s : l) {
    MeasuredDof d;
    if (!parse_dof_label(s, &d)) throw InputError(std::string(what) + ": '" + s + "' is not a DOF label (e.g. 13ux, 13+Y)");
    out.push_back(d);
  }
  return out;
}

std::string describe_mode(const IdentificationSummary& s, std::size_t k) {
  const IdentifiedMode& m = s.modes[k];
  if (m.mpc < 0.5) return fmt::format("complex shape (MPC {:.2f}): not a normal mode; noise or a mathematical pole", m.mpc);
  if (m.twin_of >= 0)
    return fmt::format("same shape as mode {} (MAC {:.3f}) at {:+.1f} % frequency: a split pair (the mode in a second plane) or a twin",
                       m.twin_of + 1, m.twin_mac, 100 * (m.frequency_hz / s.modes[m.twin_of].frequency_hz - 1));
  std::string w = m.mpc < 0.9 ? fmt::format(", complex (MPC {:.2f})", m.mpc) : "";
  if (s.method != "lscf") return w.empty() ? "" : w.substr(2);
  if (m.contribution >= 0.1) return "dominant" + w;
  if (m.contribution >= 0.01) return "minor mode" + w;
  return "weakly excited (< 1 % of the strongest peak)" + w;
}

// A magnitude spectrum (e.g. a LabVIEW dB spectrum, no phase): peak picking only.
int report_spectrum_peaks(const TextTable& t, const std::vector<double>& band, const GlobalOptions& g) {
  const double lo = band.empty() ? 0.0 : band[0], hi = band.empty() ? 0.0 : band[1];
  for (Eigen::Index c = 0; c < t.columns.cols(); ++c) {
    Eigen::VectorXd db = t.columns.col(c);
    const bool is_db = db.minCoeff() < 0;  // dB spectra go negative; linear magnitudes do not
    if (!is_db) db = (20 * db.array().max(1e-300).log10()).matrix();
    std::vector<SpectrumPeak> peaks = spectrum_peaks(t.x, db, lo, hi, 20.0);
    if (peaks.size() > 12) peaks.resize(12);
    std::sort(peaks.begin(), peaks.end(), [](const SpectrumPeak& a, const SpectrumPeak& b) { return a.frequency_hz < b.frequency_hz; });
    if (!g.quiet) {
      fmt::print("dynid identify: {} — a magnitude spectrum (no phase): peaks standing >= 20 dB above their surroundings\n", t.source);
      fmt::print("  column '{}' ({} lines, step {:.5g} Hz{})\n", c < static_cast<Eigen::Index>(t.names.size()) ? t.names[c] : "", t.x.size(), t.dx,
                 is_db ? ", dB" : ", converted to dB");
      double top = -1e300;
      for (const SpectrumPeak& p : peaks) top = std::max(top, p.level_db);
      fmt::print("  peak  frequency [Hz]  level [dB]  below strongest [dB]  prominence [dB]\n");
      for (std::size_t k = 0; k < peaks.size(); ++k)
        fmt::print("  {:4d}  {:<14.5g}  {:<10.4g}  {:<20.3g}  {:.4g}{}\n", k + 1, peaks[k].frequency_hz, peaks[k].level_db, top - peaks[k].level_db,
                   peaks[k].prominence_db, top - peaks[k].level_db > 20 ? "  (weak)" : "");
      fmt::print("  (frequencies only: damping and shapes need FRFs or time histories)\n");
    }
  }
  return 0;
}

// Rejected clusters worth a line: those with a quarter of the orders or more, and every split.
void print_rejected(const IdentificationSummary& s) {
  int shown = 0, rest = 0;
  for (const RejectedCluster& r : s.rejected) {
    if (r.support < 0.25 && r.reason != Rejection::kSplit) {
      ++rest;
      continue;
    }
    if (shown++ == 0) fmt::print("  not reported (clusters of poles without the evidence of a mode):\n");
    std::string why;
    switch (r.reason) {
      case Rejection::kFewOrders: why = fmt::format("stable over {:.0f} % of the orders (< {:.0f} %)", 100 * r.value, 100 * r.limit); break;
      case Rejection::kComplexShape: why = fmt::format("complex shape, MPC {:.2f} < {:.2f}: noise or a mathematical pole", r.value, r.limit); break;
      case Rejection::kIndicatorTrough:
        why = fmt::format("the mode indicator stands {:+.1f} dB above its surroundings (< {:.1f} dB): no peak", r.value, r.limit);
        break;
      case Rejection::kSpectralEdge:
        why = fmt::format("the mode indicator falls {:.1f} dB faster than a resonance beside it: a spectral edge (excitation or filter)", r.value);
        break;
      case Rejection::kSplit: why = fmt::format("a split of mode {} (same shape, MAC {:.3f}): merged into it", r.merged_into + 1, r.value); break;
    }
    fmt::print("        {:<14.6g}  {:<11.4g}  {:3d} poles  {}\n", r.frequency_hz, 100 * r.damping_ratio, r.poles, why);
  }
  if (rest > 0) fmt::print("  ({} more clusters stable over fewer than 25 % of the orders: in the JSON)\n", rest);
}

int run_identify(const IdentifyArgs& a, const GlobalOptions& g) {
  set_threads(g.threads);
  Progress progress(!g.quiet);
  progress.update("reading", -1);
  IdentificationOptions io;
  if (!a.band.empty()) io.band_lo_hz = a.band[0], io.band_hi_hz = a.band[1];
  if (!a.orders.empty()) io.min_order = static_cast<int>(a.orders[0]), io.max_order = static_cast<int>(a.orders[1]);
  io.segment = a.segment;
  io.estimator = a.estimator == "h2" ? FrfOptions::Estimator::kH2 : FrfOptions::Estimator::kH1;
  io.exponential_end = a.exponential;
  std::string why;
  if (!io.IsValid(&why)) throw InputError("identify: " + why);

  TestSetOptions to;
  to.limits = g.limits;
  to.sample_rate_hz = a.fs;
  if (a.frf_text || a.as == "frf") to.kind = TableKind::kFrf;
  else if (a.as == "time") to.kind = TableKind::kTimeHistory;
  else if (a.as == "spectrum") to.kind = TableKind::kSpectrum;
  if (!a.outputs.empty()) to.frf_outputs = labels(a.outputs, "--outputs");
  if (!a.inputs.empty()) to.frf_inputs = labels(a.inputs, "--inputs");
  const TestSet set = read_test_set(a.files, to);
  if (set.kind == TestSet::Kind::kSpectrum) return report_spectrum_peaks(set.spectrum, a.band, g);
  set.require_consistent();

  std::string method = a.method;
  IdentificationSummary s;
  if (set.kind == TestSet::Kind::kFrf) {
    if (method == "ssi") throw InputError("identify: SSI works on time recordings (output-only); FRFs go to --method lscf");
    method = "lscf";
    progress.update("identifying (lscf)", -1);
    s = identify_frfs(set.frf, io);
  } else {
    const std::vector<Recording> recs = set.recordings();
    bool has_inputs = false;
    for (const Recording& r : recs) has_inputs = has_inputs || !r.input_channels().empty();
    if (method == "lscf" && !has_inputs) throw InputError("identify: LSCF needs FRFs or recordings with a force channel; these are output-only: use --method ssi");
    progress.update("identifying" + (method.empty() ? std::string() : " (" + method + ")"), -1);
    s = identify_recordings(recs, method, io);  // no method given: the engine's rule (impacts lscf, else ssi)
    method = s.method;
  }
  progress.done();

  const std::string stem = a.out_stem.empty() ? fs::path(a.files[0]).stem().string() + "-" + method : a.out_stem;
  const std::string json = a.json.empty() ? stem + "-modes.json" : a.json;
  const std::string uff = a.uff.empty() ? stem + "-modes.uff" : a.uff;
  const std::string png = a.plot.empty() ? stem + "-stabilization.png" : a.plot;
  const ModalData md = s.modal_data("dynid identify " + method);
  // Refuse before writing anything if an output exists (no partial results).
  refuse_existing({json, uff, png}, a.force);
  if (md.frequencies_hz.size() > 0) write_uff55(uff, md, a.force);
  nlohmann::ordered_json j = identification_json(s);
  nlohmann::ordered_json tests = nlohmann::ordered_json::array();
  for (const TestGroup& t : set.tests) tests.push_back(t.summary());
  if (!tests.empty()) j["tests"] = tests;
  nlohmann::ordered_json notes = nlohmann::ordered_json::array();
  for (const std::string& n : set.read_as) notes.push_back(n);
  for (const std::string& n : set.notes) notes.push_back(n);
  for (const auto& n : j["notes"]) notes.push_back(n);
  j["notes"] = notes;
  write_file_atomic(json, j.dump(1) + "\n", a.force);
  plot::save(stabilization_figure(s, "dynid identify: " + fs::path(a.files[0]).filename().string() + (a.files.size() > 1 ? " ..." : "")), png, a.force);

  if (!g.quiet) {
    for (std::size_t k = 0; k < set.tests.size(); ++k) fmt::print("dynid identify: test {}: {}\n", k + 1, set.tests[k].summary());
    if (set.kind == TestSet::Kind::kFrf)
      fmt::print("dynid identify: FRFs, {} outputs x {} inputs, {} lines\n", set.frf.num_outputs(), set.frf.num_inputs(), set.frf.frequency_hz.size());
    for (const std::string& n : set.notes) fmt::print("  note: {}\n", n);
    fmt::print("dynid identify: {} on {} output DOFs, band {:.5g}-{:.5g} Hz{}, lines {:.4g} Hz, orders {}-{}, {:.2f} s\n", method, s.dofs.size(), s.band_lo_hz,
               s.band_hi_hz, s.band_from_data ? " (from the spectral peaks)" : "", s.resolution_hz, s.min_order, s.max_order, s.seconds);
    for (const std::string& n : s.notes) fmt::print("  {}\n", n);
    if (s.window_decay_removed > 0) fmt::print("  exponential window: {:.4g} 1/s of decay taken off every pole\n", s.window_decay_removed);
    fmt::print("  mode  frequency [Hz]  (std)     damping [%]  (std)    MPC     poles  {}  assessment\n", method == "lscf" ? "contribution" : "");
    for (std::size_t k = 0; k < s.modes.size(); ++k) {
      const IdentifiedMode& m = s.modes[k];
      fmt::print("  {:4d}  {:<14.6g}  ({:<7.2g})  {:<11.4g}  ({:<6.2g})  {:.4f}  {:5d}  {}  {}\n", k + 1, m.frequency_hz, m.frequency_std_hz,
                 100 * m.damping_ratio, 100 * m.damping_std, m.mpc, m.poles, method == "lscf" ? fmt::format("{:12.3f}", m.contribution) : "",
                 describe_mode(s, k));
    }
    if (s.modes.empty()) fmt::print("  no stable physical poles in the band: widen the band or raise the maximum order\n");
    print_rejected(s);
    fmt::print("  wrote {}, {}{}\n", json, md.frequencies_hz.size() ? uff + ", " : "", png);
  }
  return 0;
}

struct SimulateArgs {
  std::string case_path, output;
  bool force = false;
  bool per_channel = false;  ///< one file per channel (as many acquisition systems export) instead of one per test
};

/// Writes the recordings (one file per hit location); their paths go to `written_out` if not null.
int run_simulate(const SimulateArgs& a, const GlobalOptions& g, std::vector<std::string>* written_out = nullptr) {
  set_threads(g.threads);
  const Case c = load_case(a.case_path, g.limits);
  require_section(c, c.test.has_value(), "test");
  const TestSpec& t = *c.test;
  Progress progress(!g.quiet);
  progress.update("modes and simulation", -1);
  const VirtualTest vt = run_test_spec(c.model, t, c.analysis.eigen_options(), 0, "modal analysis ");
  progress.done();
  std::string out = !a.output.empty() ? a.output : !t.output.empty() ? t.output : (fs::path(c.dir) / (c.name + "-test.uff")).string();
  // One file per recording (a roving hammer gives one per hit location: their channel sets differ).
  std::vector<std::string> written;
  std::size_t datasets = 0;
  for (std::size_t k = 0; k < vt.recordings.size(); ++k) {
    const fs::path p(out);
    const std::string stem = (p.parent_path() / p.stem()).string() + (vt.recordings.size() > 1 ? "-" + to_string(t.options.inputs[k]) : "");
    const std::vector<UffDataset> ds = uff_datasets(vt.recordings[k], t.binary);
    datasets += ds.size();
    if (!a.per_channel) {
      const std::string path = stem + p.extension().string();
      write_uff(path, ds, a.force);
      written.push_back(path);
      continue;
    }
    // One file per channel: its datasets (one per record) in order; the reference DOF tells the tests apart.
    const Recording& r = vt.recordings[k];
    for (int c = 0; c < r.num_channels(); ++c) {
      std::vector<UffDataset> mine;
      for (std::size_t d = static_cast<std::size_t>(c); d < ds.size(); d += static_cast<std::size_t>(r.num_channels())) mine.push_back(ds[d]);
      const Channel& ch = r.channels[static_cast<std::size_t>(c)];
      const std::string path = stem + "-" + to_string(ch.dof) + (ch.input ? "-force" : "") + p.extension().string();
      write_uff(path, mine, a.force);
      written.push_back(path);
    }
  }
  const std::string truth = fs::path(out).replace_extension(".truth.json").string();
  write_modal_data(truth, vt.modes, a.force);
  if (!g.quiet) {
    std::size_t records = 0;
    for (const Recording& r : vt.recordings) records += r.records.size();
    fmt::print("dynid simulate-test: {} — {} sensors, {} records of {} samples at {} Hz, {} modes below Nyquist\n", c.name,
               t.options.sensors.size(), records, vt.recordings[0].records[0].rows(), t.options.sample_rate_hz, vt.modes.num_modes());
    if (written.size() <= 6)
      for (const std::string& w : written) fmt::print("  wrote {}\n", w);
    else
      fmt::print("  wrote {} files, one per channel: {} ... {}\n", written.size(), written.front(), written.back());
    fmt::print("  ({} datasets, UFF 58{}); the simulated modes (the truth) in {}\n", datasets, t.binary ? "b" : "", truth);
  }
  if (written_out) *written_out = written;
  return 0;
}

}  // namespace

int test_step(const std::string& case_path, const std::string& dir, bool force, const GlobalOptions& g) {
  const Case c = load_case(case_path, g.limits);
  require_section(c, c.test.has_value(), "test");
  const std::string uff = (fs::path(dir) / "test.uff").string();
  IdentifyArgs a;  // identifies exactly the files simulate-test wrote (test.uff, or test-<input>.uff per hit)
  if (const int rc = run_simulate(SimulateArgs{case_path, uff, force, false}, g, &a.files); rc != 0) return rc;
  const IdentificationOptions& io = c.test->identify;
  if (io.band_hi_hz > 0) a.band = {io.band_lo_hz, io.band_hi_hz};
  if (io.max_order > 0) a.orders = {static_cast<double>(io.min_order), static_cast<double>(io.max_order)};
  a.method = c.test->method;
  a.json = (fs::path(dir) / "identify.json").string();
  a.uff = (fs::path(dir) / "identify-modes.uff").string();
  a.plot = (fs::path(dir) / "identify.png").string();
  a.force = force;
  return run_identify(a, g);
}

void register_identify(CLI::App& app, GlobalOptions& g) {
  auto a = std::make_shared<IdentifyArgs>();
  CLI::App* cmd = app.add_subcommand("identify", "Modal identification from recordings: LSCF + LSFD (FRFs, or force and responses) or SSI-cov (output-only)");
  cmd->add_option("RECORDINGS", a->files,
                  "Test files in any layout (one per channel, per test, per hit...): UFF 58/58b (time or FRF), text/CSV (time histories, FRF "
                  "re/im columns, spectra: recognised by content), LabVIEW .lvm")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--method", a->method, "lscf or ssi (default: lscf for FRFs and impacts, ssi for continuous records)")
      ->check(CLI::IsMember({"lscf", "ssi"}));
  cmd->add_option("--band", a->band, "Analysis band LO HI in Hz (default: from the spectral peaks, 0.5 x the lowest to 1.25 x the highest)")->expected(2);
  cmd->add_option("--orders", a->orders, "Model orders MIN MAX")->expected(2);
  cmd->add_option("--json", a->json, "Modal data JSON (default: <first file>-<method>-modes.json)");
  cmd->add_option("--uff", a->uff, "Modal data UFF 55 (default: <first file>-<method>-modes.uff)");
  cmd->add_option("--plot", a->plot, "Stabilization diagram .png/.svg (default: <first file>-<method>-stabilization.png)");
  cmd->add_option("--out", a->out_stem, "Stem for the default output names");
  cmd->add_flag("--frf", a->frf_text, "The text files are FRFs (frequency, real, imaginary): the same as --as frf");
  cmd->add_option("--as", a->as, "What text tables hold, overriding what their content says: time, frf or spectrum")
      ->check(CLI::IsMember({"time", "frf", "spectrum"}));
  cmd->add_option("--outputs", a->outputs, "FRF text files: output DOF of each FRF (or one for all), e.g. 1ux,2ux (default: point k for FRF k)")->delimiter(',');
  cmd->add_option("--inputs", a->inputs, "FRF text files: input DOF of each FRF (or one for all) (default: one common reference)")->delimiter(',');
  cmd->add_option("--fs", a->fs, "Sampling rate for text files without a time column (Hz)");
  cmd->add_option("--estimator", a->estimator, "FRF estimator for force + response recordings: h1 or h2")->check(CLI::IsMember({"h1", "h2"}));
  cmd->add_option("--segment", a->segment,
                  "FRF / spectrum segment in samples for continuous records (default: from the lowest spectral peak's bandwidth; 0 = whole records; impacts always use whole records)");
  cmd->add_option("--exponential", a->exponential, "Exponential window on impact records: its end value, e.g. 0.05 (its damping is removed)");
  cmd->add_flag("--force", a->force, "Overwrite existing output files");
  cmd->callback([a, &g]() { g.exit_code = run_guarded("identify", [&] { return run_identify(*a, g); }); });

  auto s = std::make_shared<SimulateArgs>();
  CLI::App* sim = app.add_subcommand("simulate-test", "Simulate the vibration test in a case's test: section and write the recordings (UFF 58)");
  sim->add_option("CASE", s->case_path, "Case file or folder with a test: section")->required();
  sim->add_option("-o,--output", s->output, "UFF file to write (default: the case's test output, or <case>-test.uff beside it)");
  sim->add_flag("--force", s->force, "Overwrite existing output files");
  sim->add_flag("--per-channel", s->per_channel, "One UFF file per channel (<output stem>[-<hammer DOF>]-<DOF>[-force].uff), as many acquisition systems export");
  sim->callback([s, &g]() { g.exit_code = run_guarded("simulate-test", [&] { return run_simulate(*s, g); }); });
}

}  // namespace dynid::cli
