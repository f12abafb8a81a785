// Google Benchmark: FRF estimation throughput (Welch H1, 1 force + 15 responses) and SSI-cov identification of
// 16 channels x N samples (a virtual ambient test of the paper frame, 16 of its horizontal translations), up to
// N = 1e6. Results in bench/README.md.
#include <benchmark/benchmark.h>

#include "dynid/engine/frf.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/engine/virtual_test.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/mesh/generators.hpp"

namespace {

// The paper frame's layout is not needed here: a generated 2D frame with similar low modes will do, and keeps
// the benchmark independent of the case files.
dynid::Recording ambient(int samples) {
  dynid::Frame2DSpec spec;
  spec.bays = 3, spec.stories = 5;
  spec.material.E = 210e9, spec.material.rho = 7800;
  spec.column.A = spec.beam.A = 9e-5;
  spec.column.Iz = spec.beam.Iz = 2e-10;
  const dynid::Model m = dynid::make_frame2d(spec);
  dynid::EigenOptions eo;
  eo.num_modes = 30;
  eo.method = dynid::EigenOptions::Method::kDense;
  const dynid::ModalResult r = dynid::modal_analysis(m, eo);
  dynid::VirtualTestOptions o;
  for (const dynid::MeasuredDof& d : dynid::dofs_of_types(m, dynid::dof_bit(dynid::Dof::UX)))
    if (o.sensors.size() < 16) o.sensors.push_back(d);
  o.excitation = dynid::VirtualTestOptions::Excitation::kAmbient;
  o.sample_rate_hz = 2 * r.frequencies_hz[8] / 0.8;  // Nyquist just above the 9th mode
  o.duration_s = samples / o.sample_rate_hz;
  o.noise = 0.02;
  return dynid::simulate_test(m, r, o).recordings[0];
}

void BM_SsiCov16(benchmark::State& state) {
  const dynid::Recording rec = ambient(static_cast<int>(state.range(0)));
  dynid::IdentificationOptions io;
  io.band_hi_hz = 0.4 * rec.sample_rate_hz;
  io.decimate = 1;
  int modes = 0;
  for (auto _ : state) {
    const dynid::IdentificationSummary s = dynid::identify_ssi(rec, io);
    modes = static_cast<int>(s.modes.size());
    benchmark::DoNotOptimize(modes);
  }
  state.counters["modes"] = modes;
  state.counters["samples/s"] = benchmark::Counter(16.0 * state.range(0), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_SsiCov16)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kSecond)->Iterations(1);

void BM_FrfWelch16(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  dynid::Recording rec;
  rec.sample_rate_hz = 1024;
  for (int c = 0; c < 16; ++c)
    rec.channels.push_back({"ch" + std::to_string(c), {c + 1, dynid::Dof::UX}, c == 0 ? dynid::Quantity::kForce : dynid::Quantity::kAcceleration, "", c == 0});
  rec.records.push_back(Eigen::MatrixXd::Random(n, 16));
  dynid::FrfOptions fo;
  fo.segment = 4096;
  for (auto _ : state) benchmark::DoNotOptimize(dynid::estimate_frf({rec}, fo).H.data());
  state.counters["samples/s"] = benchmark::Counter(16.0 * n, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_FrfWelch16)->Arg(16384)->Arg(1000000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
