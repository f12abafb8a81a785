// The `test:` section of a case file: a virtual test plan and how to identify its recordings.
#include <cmath>

#include "dynid/io/modal_data_io.hpp"
#include "internal/case_util.hpp"

namespace dynid::internal {

namespace {
std::vector<MeasuredDof> dof_list(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& what) {
  ctx.require_sequence(n, what);
  std::vector<MeasuredDof> out;
  for (const auto& q : n) {
    MeasuredDof d;
    const std::string lab = ctx.string(q, what);
    if (!parse_dof_label(lab, &d)) ctx.fail(q, what + ": '" + lab + "' is not a DOF label (e.g. 13ux)");
    try {
      measured_equations(model, {d});
    } catch (const InputError& e) {
      ctx.fail(q, what + ": " + e.what());
    }
    out.push_back(d);
  }
  return out;
}

std::pair<double, double> band(const YAML::Node& n, const YamlCtx& ctx, const std::string& what) {
  const std::vector<double> b = ctx.numbers(n, what);
  if (b.size() != 2 || !(b[0] >= 0 && b[1] > b[0])) ctx.fail(n, what + ": expected [lo, hi] with 0 <= lo < hi (Hz)");
  return {b[0], b[1]};
}
}  // namespace

TestSpec parse_test(const YAML::Node& n, const YamlCtx& ctx, const Model& model, const std::string& dir) {
  using Opt = VirtualTestOptions;
  ctx.require_map(n, "test");
  ctx.only_keys(n, "test", {"sensors", "response", "excitation", "inputs", "sample_rate_hz", "duration_s", "impacts", "band_hz",
                            "pulse_s", "force", "damping", "noise", "force_noise", "seed", "output", "format", "max_frequency_hz",
                            "identify"});
  TestSpec t;
  Opt& o = t.options;
  if (!n["sensors"]) ctx.fail(n, "test: sensors is missing (e.g. sensors: translations, or [13ux, 13uy])");
  o.sensors = parse_dof_selection(n["sensors"], ctx, model, "test sensors");
  if (n["response"]) {
    const std::string r = ctx.string(n["response"], "test response");
    if (r == "displacement") o.response = Quantity::kDisplacement;
    else if (r == "velocity") o.response = Quantity::kVelocity;
    else if (r == "acceleration") o.response = Quantity::kAcceleration;
    else ctx.fail(n["response"], "test: response must be displacement, velocity or acceleration");
  }
  const std::string ex = n["excitation"] ? ctx.string(n["excitation"], "test excitation") : "impact";
  if (ex == "impact") o.excitation = Opt::Excitation::kImpact;
  else if (ex == "random") o.excitation = Opt::Excitation::kRandom;
  else if (ex == "ambient") o.excitation = Opt::Excitation::kAmbient;
  else ctx.fail(n["excitation"], "test: excitation must be impact, random or ambient");
  if (n["inputs"]) o.inputs = dof_list(n["inputs"], ctx, model, "test inputs");
  if (o.excitation != Opt::Excitation::kAmbient && o.inputs.empty()) ctx.fail(n, "test: " + ex + " excitation needs inputs: [DOF, ...]");
  if (o.excitation == Opt::Excitation::kAmbient && n["inputs"]) ctx.fail(n["inputs"], "test: ambient tests have no measured inputs");
  if (!n["sample_rate_hz"]) ctx.fail(n, "test: sample_rate_hz is missing");
  o.sample_rate_hz = ctx.number(n["sample_rate_hz"], "test sample_rate_hz");
  if (!n["duration_s"]) ctx.fail(n, "test: duration_s is missing (seconds per record)");
  o.duration_s = ctx.number(n["duration_s"], "test duration_s");
  if (n["impacts"]) o.impacts = ctx.integer(n["impacts"], "test impacts");
  if (n["band_hz"]) std::tie(o.band_hz_lo, o.band_hz_hi) = band(n["band_hz"], ctx, "test band_hz");
  if (n["pulse_s"]) o.pulse_s = ctx.number(n["pulse_s"], "test pulse_s");
  if (n["force"]) o.force_rms = ctx.number(n["force"], "test force");
  if (n["damping"]) {
    const YAML::Node d = n["damping"];
    ctx.require_map(d, "test damping");
    ctx.only_keys(d, "test damping", {"modal", "rayleigh"});
    if (d["modal"] && d["rayleigh"]) ctx.fail(d, "test damping: give modal: ZETA or rayleigh: [alpha, beta], not both");
    if (d["modal"]) o.damping_ratio = ctx.number(d["modal"], "test damping modal");
    if (d["rayleigh"]) {
      const std::vector<double> ab = ctx.numbers(d["rayleigh"], "test damping rayleigh");
      if (ab.size() != 2) ctx.fail(d["rayleigh"], "test damping: rayleigh: expected [alpha, beta] (C = alpha M + beta K)");
      o.damping = Opt::Damping::kRayleigh;
      o.rayleigh_alpha = ab[0];
      o.rayleigh_beta = ab[1];
    }
  }
  if (n["noise"]) o.noise = ctx.number(n["noise"], "test noise");
  if (n["force_noise"]) o.force_noise = ctx.number(n["force_noise"], "test force_noise");
  if (n["seed"]) o.seed = static_cast<std::uint64_t>(ctx.integer(n["seed"], "test seed"));
  std::string why;
  if (!o.IsValid(&why)) ctx.fail(n, "test: " + why);
  if (n["output"]) t.output = resolve(dir, ctx.string(n["output"], "test output"));
  if (n["format"]) {
    const std::string f = ctx.string(n["format"], "test format");
    if (f != "binary" && f != "ascii") ctx.fail(n["format"], "test: format must be binary (58b) or ascii (58)");
    t.binary = f == "binary";
  }
  if (n["max_frequency_hz"]) t.max_frequency_hz = ctx.number(n["max_frequency_hz"], "test max_frequency_hz");
  if (n["identify"]) {
    const YAML::Node id = n["identify"];
    ctx.require_map(id, "test identify");
    ctx.only_keys(id, "test identify", {"method", "band_hz", "orders"});
    if (id["method"]) {
      t.method = ctx.string(id["method"], "identify method");
      if (t.method != "lscf" && t.method != "ssi") ctx.fail(id["method"], "identify: method must be lscf or ssi");
      if (t.method == "lscf" && o.excitation == Opt::Excitation::kAmbient) ctx.fail(id["method"], "identify: LSCF needs measured inputs; ambient tests use ssi");
    }
    if (id["band_hz"]) std::tie(t.identify.band_lo_hz, t.identify.band_hi_hz) = band(id["band_hz"], ctx, "identify band_hz");
    if (id["orders"]) {
      const std::vector<double> ord = ctx.numbers(id["orders"], "identify orders");
      if (ord.size() != 2) ctx.fail(id["orders"], "identify: orders must be [min, max]");
      t.identify.min_order = static_cast<int>(ord[0]);
      t.identify.max_order = static_cast<int>(ord[1]);
    }
    if (!t.identify.IsValid(&why)) ctx.fail(id, "identify: " + why);
  }
  return t;
}

}  // namespace dynid::internal

namespace dynid {

VirtualTest run_test_spec(const Model& model, const TestSpec& t, EigenOptions eo, std::uint64_t seed_offset,
                          const std::string& what) {
  VirtualTestOptions vo = t.options;
  vo.seed += seed_offset;
  eo.band_lo = 0;
  eo.band_hi = hz_to_eigenvalue(t.max_frequency_hz > 0 ? t.max_frequency_hz : 1.2 * vo.sample_rate_hz / 2);
  const ModalResult modes = modal_analysis(model, eo);
  if (!modes.ok()) throw NumericalError(what + "failed: " + modes.summary.message);
  return simulate_test(model, modes, vo);
}

}  // namespace dynid
