// The `discover:` section of a case file, and the measured data it names.
#include <filesystem>

#include "dynid/engine/identify.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/discover_io.hpp"
#include "dynid/io/mat_file.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/results_json.hpp"
#include "dynid/io/test_data.hpp"
#include "dynid/io/test_layout.hpp"
#include "dynid/io/uff.hpp"
#include "dynid/mesh/units.hpp"
#include "internal/case_util.hpp"
#include "internal/model_yaml.hpp"
#include "internal/text_util.hpp"

namespace fs = std::filesystem;

namespace dynid::internal {

namespace {
std::vector<int> ints(const YAML::Node& n, const YamlCtx& ctx, const std::string& what) {
  ctx.require_sequence(n, what);
  std::vector<int> out;
  for (const auto& v : n) out.push_back(ctx.integer(v, what));
  return out;
}

DiscoverSpec::Expect parse_expect(const YAML::Node& n, const YamlCtx& ctx, bool top) {
  ctx.require_map(n, "discover expect");
  if (top) ctx.only_keys(n, "discover expect", {"kind", "nodes", "elements", "parameter", "value", "tolerance", "verdict", "also"});
  else ctx.only_keys(n, "discover expect also", {"kind", "nodes", "elements", "parameter", "value", "tolerance"});
  DiscoverSpec::Expect e;
  if (n["verdict"]) e.verdict = ctx.string(n["verdict"], "expect verdict");
  if (e.verdict != "missing_physics" && e.verdict != "consistent" && e.verdict != "inconclusive")
    ctx.fail(n["verdict"], "expect: verdict must be missing_physics, consistent or inconclusive");
  if (e.verdict == "missing_physics" && !n["kind"]) ctx.fail(n, "expect: kind is missing (e.g. kind: semi_rigid_joint)");
  if (n["kind"] && n["kind"].IsSequence())
    for (const auto& k : n["kind"]) e.kinds.push_back(ctx.string(k, "expect kind"));
  else if (n["kind"])
    e.kinds.push_back(ctx.string(n["kind"], "expect kind"));
  if (n["nodes"]) e.nodes = ints(n["nodes"], ctx, "expect nodes");
  if (n["elements"]) e.elements = ints(n["elements"], ctx, "expect elements");
  if (n["parameter"]) e.parameter = ctx.string(n["parameter"], "expect parameter");
  if (n["value"]) e.value = ctx.number(n["value"], "expect value");
  if (n["tolerance"]) e.tolerance = ctx.number(n["tolerance"], "expect tolerance");
  if (n["parameter"] && !n["value"]) ctx.fail(n, "expect: parameter without value");
  if (n["also"]) {
    ctx.require_sequence(n["also"], "expect also");
    for (const auto& a : n["also"]) e.also.push_back(parse_expect(a, ctx, false));
  }
  return e;
}
}  // namespace

DiscoverSpec parse_discover(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& dir,
                            const ReaderLimits& limits) {
  ctx.require_map(n, "discover");
  ctx.only_keys(n, "discover",
                {"measured", "geometry", "recordings", "identify", "truth", "modes", "min_mpc", "frequency_noise",
                 "shape_noise", "kinds", "sensor_nodes", "suspension_nodes", "max_effects", "screen", "seeds", "expect",
                 "units", "gravity", "gravity_acceleration"});
  DiscoverSpec d;
  const int sources = !!n["measured"] + !!n["recordings"] + !!n["truth"];
  if (sources != 1) ctx.fail(n, "discover: give exactly one of measured: FILE (modal data), recordings: [FILES] or truth: {model:, test:}");
  if (n["measured"]) d.measured_file = parse_measured(n["measured"], ctx, dir, "discover measured");
  d.measured_mat = parse_measured_mat(n, "discover", ctx, dir);
  d.geometry = parse_geometry(n, "discover", ctx, dir);
  if (n["recordings"]) {
    const YAML::Node& r = n["recordings"];
    // FILE, or {mat: FILE, data: VAR, sample_rate: VAR | sample_rate_hz: NUMBER, channels: VAR | [labels], inputs:
    // [labels], quantity: acceleration} (a MATLAB file's variables).
    auto one = [&](const YAML::Node& f) {
      MatRecordingNames m;
      if (f.IsMap()) {
        ctx.only_keys(f, "discover recording", {"mat", "data", "sample_rate", "sample_rate_hz", "channels", "inputs", "quantity"});
        if (!f["mat"]) ctx.fail(f, "discover recording: mat (the .mat file) is missing");
        m.file = resolve(dir, ctx.string(f["mat"], "recording mat"));
        if (f["data"]) m.data = ctx.string(f["data"], "recording data");
        if (f["sample_rate"]) m.sample_rate = ctx.string(f["sample_rate"], "recording sample_rate");
        if (f["sample_rate_hz"]) m.sample_rate_hz = ctx.number(f["sample_rate_hz"], "recording sample_rate_hz");
        if (f["channels"]) {
          if (f["channels"].IsSequence()) {
            for (const auto& c : f["channels"]) m.channel_labels.push_back(ctx.string(c, "recording channel"));
          } else {
            m.channels = ctx.string(f["channels"], "recording channels");
          }
        }
        if (f["inputs"]) {
          ctx.require_sequence(f["inputs"], "recording inputs");
          for (const auto& c : f["inputs"]) m.inputs.push_back(ctx.string(c, "recording input"));
        }
        if (f["quantity"]) m.quantity = ctx.string(f["quantity"], "recording quantity");
        d.recordings.push_back(m.file);
      } else {
        d.recordings.push_back(resolve(dir, ctx.string(f, "discover recordings")));
      }
      d.recording_mat.push_back(m);
    };
    if (r.IsScalar() || r.IsMap()) one(r);
    else {
      ctx.require_sequence(r, "discover recordings");
      for (const auto& f : r) one(f);
    }
  }
  if (n["identify"]) {
    const YAML::Node& id = n["identify"];
    ctx.require_map(id, "discover identify");
    ctx.only_keys(id, "discover identify", {"method", "band_hz", "orders"});
    if (id["method"]) {
      d.method = ctx.string(id["method"], "identify method");
      if (d.method != "lscf" && d.method != "ssi") ctx.fail(id["method"], "identify: method must be lscf or ssi");
    }
    if (id["band_hz"]) {
      const std::vector<double> b = ctx.numbers(id["band_hz"], "identify band_hz");
      if (b.size() != 2 || !(b[0] >= 0 && b[1] > b[0])) ctx.fail(id["band_hz"], "identify band_hz: expected [lo, hi] with 0 <= lo < hi (Hz)");
      d.identify.band_lo_hz = b[0];
      d.identify.band_hi_hz = b[1];
    }
    if (id["orders"]) {
      const std::vector<double> o = ctx.numbers(id["orders"], "identify orders");
      if (o.size() != 2) ctx.fail(id["orders"], "identify: orders must be [min, max]");
      d.identify.min_order = static_cast<int>(o[0]);
      d.identify.max_order = static_cast<int>(o[1]);
    }
    std::string why;
    if (!d.identify.IsValid(&why)) ctx.fail(id, "identify: " + why);
  }
  if (n["truth"]) {
    const YAML::Node& t = n["truth"];
    ctx.require_map(t, "discover truth");
    ctx.only_keys(t, "discover truth", {"model", "test"});
    if (!t["model"] || !t["test"]) ctx.fail(t, "discover truth: needs model: (the structure as it really is) and test: (the virtual test)");
    YamlCtx tctx = ctx;
    std::string tdir = dir;
    const YAML::Node m = model_node(t, &tctx, &tdir, 0);
    d.truth = std::make_shared<Model>(parse_model(m, tctx, tdir, nullptr, limits));
    d.truth_test = std::make_shared<TestSpec>(parse_test(t["test"], ctx, *d.truth, dir));
    // The analysis model must know every sensor (the recordings are labelled with the truth's node ids).
    for (const MeasuredDof& s : d.truth_test->options.sensors)
      if (model.node_index(s.node) < 0)
        ctx.fail(t["test"], "discover truth: sensor " + to_string(s) + " is on a node the analysis model does not have");
  }
  if (n["modes"]) d.modes = ctx.integer(n["modes"], "discover modes");
  if (n["min_mpc"]) d.min_mpc = ctx.number(n["min_mpc"], "discover min_mpc");
  DiscoveryOptions& o = d.options;
  // Both are fractions. A frequency known to 20 % or a shape entry to 100 % of the mode's largest says nothing
  // discovery could use; such a value is most likely a percentage (1 meant as 1 %).
  if (n["frequency_noise"]) {
    o.frequency_noise = ctx.number(n["frequency_noise"], "discover frequency_noise");
    if (!(o.frequency_noise > 0 && o.frequency_noise < 0.2))
      ctx.fail(n["frequency_noise"],
               "discover frequency_noise: the frequencies' relative std, a fraction in (0, 0.2): 0.01 for 1 %");
  }
  if (n["shape_noise"]) {
    o.shape_noise = ctx.number(n["shape_noise"], "discover shape_noise");
    if (!(o.shape_noise > 0 && o.shape_noise < 1))
      ctx.fail(n["shape_noise"],
               "discover shape_noise: the shape entries' std relative to each mode's largest entry, a fraction in (0, "
               "1): 0.05 for 5 %");
  }
  if (n["kinds"]) {
    ctx.require_sequence(n["kinds"], "discover kinds");
    for (const auto& k : n["kinds"]) {
      const std::string name = ctx.string(k, "discover kinds");
      std::string known;
      bool ok = false;
      for (const CandidateKind& r : builtin_candidate_kinds()) {
        ok = ok || r.name == name;
        known += (known.empty() ? "" : ", ") + r.name;
      }
      if (!ok) ctx.fail(k, "discover kinds: unknown candidate kind '" + name + "' (known kinds: " + known + ")");
      o.kinds.push_back(name);
    }
  }
  if (n["gravity"]) {
    const std::vector<double> g = ctx.numbers(n["gravity"], "discover gravity");
    if (g.size() != 3 || Eigen::Vector3d(g[0], g[1], g[2]).norm() == 0)
      ctx.fail(n["gravity"], "discover gravity: expected a direction [x, y, z] (e.g. [0, -1, 0])");
    o.gravity = Eigen::Vector3d(g[0], g[1], g[2]);
  }
  if (n["sensor_nodes"]) o.sensor_nodes = ints(n["sensor_nodes"], ctx, "discover sensor_nodes");
  if (n["suspension_nodes"]) o.suspension_nodes = ints(n["suspension_nodes"], ctx, "discover suspension_nodes");
  if (n["max_effects"]) o.max_effects = ctx.integer(n["max_effects"], "discover max_effects");
  if (n["screen"]) o.screen_fit = ctx.integer(n["screen"], "discover screen");
  if (n["seeds"]) d.seeds = ctx.integer(n["seeds"], "discover seeds");
  if (n["gravity_acceleration"]) {
    o.gravity_acceleration = ctx.number(n["gravity_acceleration"], "discover gravity_acceleration");
    if (!(o.gravity_acceleration > 0))
      ctx.fail(n["gravity_acceleration"],
               "discover gravity_acceleration: expected the acceleration of gravity in the model's units (> 0; 9.81 in "
               "m/s^2, 9810 in mm/s^2)");
  }
  if (n["units"]) {
    const std::string u = ctx.string(n["units"], "discover units");
    if (u != "si" && u != "other") ctx.fail(n["units"], "discover: units must be si (values labelled kg, N, m) or other (model units)");
    o.si_units = u == "si";
  } else {
    // Not stated: SI unless the materials put the model in millimetres or its masses in tonnes (mesh/units.hpp).
    const LengthUnit unit = length_unit(model);
    o.si_units = !(unit.known && (unit.per_metre != 1 || (unit.mass_known && unit.kilogram != 1)));
  }
  if (d.seeds < 1) ctx.fail(n["seeds"], "discover: seeds must be >= 1");
  if (d.seeds > 1 && !d.truth) ctx.fail(n["seeds"], "discover: seeds (a robustness study) needs a truth: model");
  std::string why;
  if (!o.IsValid(&why)) ctx.fail(n, "discover: " + why);
  if (n["expect"]) d.expect = parse_expect(n["expect"], ctx, true);
  return d;
}

}  // namespace dynid::internal

namespace dynid {

namespace {
using internal::format_number;

// expected: per mode, whether the identification reported it as a mode the model predicts (its shape carries no
// weight, so its MPC is no reason to leave it out); empty = none.
ModalData keep_modes(ModalData m, const DiscoverSpec& d, const std::string& source, std::vector<std::string>* notes,
                     const std::vector<char>& expected = {}) {
  std::vector<int> keep;
  std::string left_out;
  for (int k = 0; k < m.num_modes(); ++k) {
    const bool exempt = static_cast<std::size_t>(k) < expected.size() && expected[static_cast<std::size_t>(k)];
    if (!exempt && m.mpc.size() == m.frequencies_hz.size() && m.mpc[k] < d.min_mpc) {
      const std::string what = format_number(m.frequencies_hz[k], 5) + " Hz (MPC " + format_number(m.mpc[k], 3) + ")";
      if (notes)
        notes->push_back("identified mode at " + what + " left out: MPC < " + format_number(d.min_mpc, 3) +
                         " (not a normal mode)");
      left_out += (left_out.empty() ? "" : ", ") + what;
      continue;
    }
    keep.push_back(k);
  }
  if (m.num_modes() >= 1 && keep.empty())
    throw InputError(source + ": discover: none of the " + std::to_string(m.num_modes()) +
                     " modes is a normal mode; their shapes are complex (MPC below discover: min_mpc = " +
                     format_number(d.min_mpc, 3) + "): " + left_out +
                     ". Discovery needs at least 1. Close modes or too few sensors make identified "
                     "shapes complex: more sensors or another band (discover: identify: band_hz) would help, or a "
                     "lower min_mpc if these are real modes.");
  if (d.modes > 0 && static_cast<int>(keep.size()) > d.modes) keep.resize(static_cast<std::size_t>(d.modes));
  return modes_subset(m, keep);
}
}  // namespace

namespace {
// Per identified mode, whether it was reported as a mode the model predicts (keep_modes).
std::vector<char> expected_flags(const DiscoveryData& out) {
  std::vector<char> e;
  if (out.identified)
    for (const IdentifiedMode& m : out.identification.modes) e.push_back(m.expected_hz > 0);
  return e;
}

// Identification of the recordings of a discover: case (the band the model implies unless the case gives one).
void identify_recordings_for(const Case& c, std::vector<Recording> recs, DiscoveryData* out) {
  const DiscoverSpec& d = *c.discover;
  const std::string method = d.truth ? (d.method.empty() ? d.truth_test->method : d.method) : d.method;
  IdentificationOptions io = d.identify;
  if (d.truth && d.identify.band_hi_hz == 0 && d.identify.max_order == 0) io = d.truth_test->identify;
  std::string band_words = "in the band the case gives";
  if (d.identify.band_hi_hz == 0 && !recs.empty()) {
    // One rule for every case: the band the analysis model implies for these sensors (band_from_model).
    std::vector<MeasuredDof> sensors;
    for (const Recording& r : recs)
      for (int ch : r.output_channels()) sensors.push_back(r.channels[static_cast<std::size_t>(ch)].dof);
    const ModelBand b = band_from_model(c.model, sensors, recs[0].sample_rate_hz / 2);
    io.band_lo_hz = b.lo_hz;
    io.band_hi_hz = b.hi_hz;
    io.expected_modes = b.expected;
    out->notes.push_back("identification band " + format_number(b.lo_hz, 4) + " to " + format_number(b.hi_hz, 4) + " Hz, from the " +
                         std::to_string(b.visible_hz.size()) + " lowest modes of the model the sensors see (" +
                         format_number(b.visible_hz.front(), 4) + " to " + format_number(b.visible_hz.back(), 4) + " Hz)");
    band_words = "in " + format_number(b.lo_hz, 4) + " to " + format_number(b.hi_hz, 4) + " Hz, where the model has " +
                 std::to_string(b.visible_hz.size()) + " modes the sensors see";
  }
  out->identification = identify_recordings(std::move(recs), method, io);
  out->identified = true;
  for (const IdentifiedMode& m : out->identification.modes) {
    if (!(m.expected_hz > 0)) continue;
    const std::string weak = m.expected_because == Rejection::kComplexShape
                                 ? "its shape complex when fitted beside the other modes (MPC < " +
                                       format_number(io.min_mpc, 2) + "; its own fit's shape kept)"
                                 : "stable over " + format_number(m.support, 2) + " of the orders (< " +
                                       format_number(io.min_cluster_fraction, 2) + ")";
    out->notes.push_back("identified mode at " + format_number(m.frequency_hz, 5) + " Hz: " + weak +
                         ", reported because its shape matches the model's mode at " + format_number(m.expected_hz, 5) +
                         " Hz (MAC >= " + format_number(io.expected_mac, 2) + ")");
  }
  out->measured = out->identification.modal_data("identified from " + out->source);
  const Eigen::Index found = out->measured.num_modes();
  if (found < 1)
    throw InputError(out->source + ": discover: identification (" + out->identification.method + ") found no mode " +
                     band_words +
                     "; discovery needs at least 1. Longer records, more or "
                     "better-placed sensors, or another band (discover: identify: band_hz: [lo, hi]) would help; "
                     "`dynid identify` on the same files lists the rejected poles and why.");
}
}  // namespace

DiscoveryData discovery_data(const Case& c, int seed_offset) {
  require_section(c, c.discover.has_value(), "discover");
  const DiscoverSpec& d = *c.discover;
  DiscoveryData out;
  if (!d.measured_file.empty()) {
    out.measured = read_measured_modal_data(d.measured_file, d.geometry, c.model, &out.notes, d.measured_mat, c.limits);
    out.source = d.measured_file;
  } else {
    std::vector<Recording> recs;
    if (d.truth) {
      VirtualTest vt = run_test_spec(*d.truth, *d.truth_test, EigenOptions{}, static_cast<std::uint64_t>(seed_offset),
                                     c.path + ": modal analysis of the truth model ");
      recs = std::move(vt.recordings);
      out.truth_modes = std::move(vt.modes);
      out.source = "virtual test of the truth model (seed " + std::to_string(d.truth_test->options.seed + static_cast<std::uint64_t>(seed_offset)) + ")";
    } else {
      // .mat files by their named variables; every other file in any layout (one file per channel, per test,
      // per hit), grouped into tests (io/test_layout.hpp).
      std::vector<std::string> files;
      for (std::size_t k = 0; k < d.recordings.size(); ++k) {
        if (k < d.recording_mat.size() && !d.recording_mat[k].file.empty())
          recs.push_back(read_mat_recording(d.recording_mat[k], c.limits));
        else files.push_back(d.recordings[k]);
      }
      if (!files.empty()) {
        TestSetOptions read_options;
        read_options.limits = c.limits;
        const TestSet set = read_test_set(files, read_options);
        if (set.kind != TestSet::Kind::kRecordings)
          throw InputError(files[0] + (files.size() > 1 ? " ..." : "") + ": discover: recordings: needs time recordings (UFF 58 type 1, text or LabVIEW time tables); these hold " +
                           (set.kind == TestSet::Kind::kFrf ? "FRFs" : "a spectrum"));
        set.require_consistent();
        for (Recording& r : set.recordings()) recs.push_back(std::move(r));
        out.notes.insert(out.notes.end(), set.notes.begin(), set.notes.end());
      }
      out.source = d.recordings[0] + (d.recordings.size() > 1 ? " ..." : "");
    }
    identify_recordings_for(c, std::move(recs), &out);
  }
  out.measured = keep_modes(std::move(out.measured), d, out.source, &out.notes, expected_flags(out));
  return out;
}

DiscoveryData discovery_data(const Case& c, ModalData measured, const std::string& source) {
  require_section(c, c.discover.has_value(), "discover");
  DiscoveryData out;
  out.source = source;
  out.measured = keep_modes(std::move(measured), *c.discover, source, &out.notes);
  return out;
}

DiscoveryData discovery_data(const Case& c, std::vector<Recording> recordings, const std::string& source) {
  require_section(c, c.discover.has_value(), "discover");
  if (recordings.empty()) throw InputError(c.path + ": discover: no recordings given");
  DiscoveryData out;
  out.source = source;
  identify_recordings_for(c, std::move(recordings), &out);
  out.measured = keep_modes(std::move(out.measured), *c.discover, source, &out.notes, expected_flags(out));
  return out;
}

}  // namespace dynid
