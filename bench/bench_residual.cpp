// Google Benchmark: residual forces R = (-K + lambda M) Phi for 20 modes (OpenMP over rows), over DOF counts up
// to 1e6; compare with the eigen-solve of the same model in bench/README.md (scaling table).
#include <benchmark/benchmark.h>

#include "bench_common.hpp"
#include "dynid/engine/modal.hpp"

namespace {

void BM_ResidualForces20(benchmark::State& state) {
  const dynid::Model m = dynid::bench::Frame2D(static_cast<int>(state.range(0)), 17);
  const dynid::AssembledSystem s = dynid::assemble_system(m);
  const Eigen::MatrixXd Phi = Eigen::MatrixXd::Random(s.K.rows(), 20);
  const Eigen::VectorXd lam = Eigen::VectorXd::LinSpaced(20, 1, 300);
  Eigen::MatrixXd R;
  for (auto _ : state) {
    dynid::residual_forces(s.K, s.M, Phi, lam, &R);
    benchmark::DoNotOptimize(R.data());
  }
  state.counters["DOF"] = static_cast<double>(s.K.rows());
  state.counters["DOF/s"] = benchmark::Counter(static_cast<double>(s.K.rows()), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ResidualForces20)->Arg(10)->Arg(30)->Arg(100)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
