// Google Benchmark: the 20 lowest modes (factorization + shift-invert Lanczos) over DOF counts, both
// formulations (Cholesky standard form, generalized M inner product).
#include <benchmark/benchmark.h>

#include "bench_common.hpp"
#include "blas_kernels.hpp"
#include "dynid/engine/modal.hpp"

namespace {

void Run(benchmark::State& state, dynid::EigenOptions::Formulation form, bool three_d) {
  const int n = static_cast<int>(state.range(0));
  const dynid::Model m = three_d ? dynid::bench::Frame3D(n, 1) : dynid::bench::Frame2D(n, 10);
  const dynid::AssembledSystem sys = dynid::assemble_system(m);
  dynid::EigenOptions o;
  o.num_modes = 20;
  o.method = dynid::EigenOptions::Method::kSparse;
  o.formulation = form;
  int solves = 0;
  for (auto _ : state) {
    const dynid::EigenSolution s = dynid::solve_eigen(sys.K, sys.M, o);
    if (!s.summary.ok()) state.SkipWithError(s.summary.message.c_str());
    solves = s.summary.solves;
  }
  state.counters["DOF"] = m.num_dofs();
  state.counters["solves"] = solves;
  state.counters["DOF/s"] = benchmark::Counter(m.num_dofs(), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Eigen20_2D_Standard(benchmark::State& s) { Run(s, dynid::EigenOptions::Formulation::kCholeskyStandard, false); }
void BM_Eigen20_2D_Generalized(benchmark::State& s) { Run(s, dynid::EigenOptions::Formulation::kGeneralized, false); }
void BM_Eigen20_3D_Standard(benchmark::State& s) { Run(s, dynid::EigenOptions::Formulation::kCholeskyStandard, true); }
void BM_Eigen20_3D_Generalized(benchmark::State& s) { Run(s, dynid::EigenOptions::Formulation::kGeneralized, true); }
BENCHMARK(BM_Eigen20_2D_Standard)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Eigen20_2D_Generalized)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Eigen20_3D_Standard)->Arg(6)->Arg(12)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Eigen20_3D_Generalized)->Arg(6)->Arg(12)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  dynid::cli::ensure_blas_kernels(argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
