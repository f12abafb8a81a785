// Google Benchmark: element matrices and sparse assembly (symbolic pattern + numeric), over DOF counts.
#include <benchmark/benchmark.h>

#include "bench_common.hpp"
#include "dynid/solvers/sparse.hpp"

namespace {

void BM_ElementMatrices3D(benchmark::State& state) {
  const dynid::Model m = dynid::bench::Frame3D(4, 2);
  Eigen::MatrixXd K, M;
  int e = 0;
  for (auto _ : state) {
    m.element_matrices(e, &K, &M);
    benchmark::DoNotOptimize(K.data());
    e = (e + 1) % m.num_elements();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ElementMatrices3D);

void BM_AssemblySymbolic2D(benchmark::State& state) {
  const dynid::Model m = dynid::bench::Frame2D(static_cast<int>(state.range(0)), 10);
  for (auto _ : state) {
    dynid::Assembler a(m);
    benchmark::DoNotOptimize(a.nonzeros());
  }
  state.counters["DOF"] = m.num_dofs();
  state.counters["DOF/s"] = benchmark::Counter(m.num_dofs(), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_AssemblySymbolic2D)->Arg(10)->Arg(30)->Arg(60)->Unit(benchmark::kMillisecond);

void Numeric(benchmark::State& state, const dynid::Model& m) {
  const dynid::Assembler a(m);
  dynid::SparseMatrix K, M;
  for (auto _ : state) {
    a.assemble(&K, &M);
    benchmark::DoNotOptimize(K.valuePtr());
  }
  state.counters["DOF"] = m.num_dofs();
  state.counters["DOF/s"] = benchmark::Counter(m.num_dofs(), benchmark::Counter::kIsIterationInvariantRate);
}
void BM_AssemblyNumeric2D(benchmark::State& state) { Numeric(state, dynid::bench::Frame2D(static_cast<int>(state.range(0)), 10)); }
void BM_AssemblyNumeric3D(benchmark::State& state) { Numeric(state, dynid::bench::Frame3D(static_cast<int>(state.range(0)), 2)); }
BENCHMARK(BM_AssemblyNumeric2D)->Arg(10)->Arg(30)->Arg(60)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AssemblyNumeric3D)->Arg(4)->Arg(8)->Arg(12)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
