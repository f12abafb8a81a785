// Google Benchmark: the cost of missing-physics discovery (locate, screen every local candidate, fit the best and
// the global ones, greedy second effect) on a 2-bay, 3-story plane frame with a flexible column base, exact modes
// at the joints' translations (18 DOFs, 6 modes), for members split into d elements (DOFs 27 + 45 (d - 1)).
// Counters: model DOFs, candidates in the library, eigen-solves. The baseline (second argument 1) fits every
// local candidate in full instead of screening them with one linearisation. Results in bench/README.md.
#include <benchmark/benchmark.h>

#include "dynid/engine/discovery.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/mesh/generators.hpp"

namespace {

dynid::Frame2DSpec spec(int d) {
  dynid::Frame2DSpec s;
  s.bays = 2, s.stories = 3, s.divisions = d, s.span = 4, s.height = 3;
  s.material.E = 2.1e11, s.material.rho = 7850;
  s.column.A = 5.38e-3, s.column.Iz = 5.7e-5;
  s.beam.A = 3.91e-3, s.beam.Iz = 5.79e-5;
  return s;
}

// The truth: the frame with node 2's base rotation on a 1.5e7 N m/rad spring.
dynid::Model truth(int d) {
  const dynid::Model a = dynid::make_frame2d(spec(d));
  dynid::Model t;
  for (const dynid::Node& n : a.nodes()) t.add_node(n.id, n.x);
  for (const dynid::Material& m : a.materials()) t.add_material(m);
  for (const dynid::Section& s : a.sections()) t.add_section(s);
  for (const dynid::Element& e : a.elements()) t.add_element(e);
  dynid::Element sp;
  sp.id = 99999, sp.type = dynid::ElementType::Spring, sp.num_nodes = 1, sp.node_ids = {{2, 2}};
  sp.spring_dofs = dynid::dof_bit(dynid::Dof::RZ), sp.stiffness = 1.5e7;
  t.add_element(sp);
  t.restrain(1, dynid::kAllDofs);
  t.restrain(3, dynid::kAllDofs);
  t.restrain(2, dynid::dof_bit(dynid::Dof::UX) | dynid::dof_bit(dynid::Dof::UY));
  t.finalize();
  return t;
}

// state.range(1) = 1: the baseline without screening, every local candidate fitted in full with Ceres.
void BM_Discover(benchmark::State& state) {
  const int d = static_cast<int>(state.range(0));
  const bool brute = state.range(1) != 0;
  const dynid::Model a = dynid::make_frame2d(spec(d));
  const dynid::Model t = truth(d);
  dynid::EigenOptions eo;
  eo.num_modes = 6;
  const dynid::ModalResult r = dynid::modal_analysis(t, eo);
  std::vector<dynid::MeasuredDof> dofs;
  for (int id = 4; id <= 12; ++id)
    for (dynid::Dof q : {dynid::Dof::UX, dynid::Dof::UY}) dofs.push_back({id, q});
  const dynid::ModalData meas = dynid::sample_modes(t, r, dofs, 0, 6, "bench");
  dynid::DiscoveryOptions o;
  if (brute) o.screen_fit = 1 << 20;
  dynid::DiscoverySummary s;
  for (auto _ : state) {
    s = dynid::discover(a, meas, o);
    benchmark::DoNotOptimize(s.seconds);
  }
  state.counters["dofs"] = a.num_dofs();
  state.counters["candidates"] = static_cast<double>(dynid::candidate_library(a, meas, o).size());
  state.counters["eigen_solves"] = s.eigen_solves;
  state.counters["found"] = !s.findings.empty() && s.findings[0].kind == "flexible_support";
}
BENCHMARK(BM_Discover)->Args({2, 0})->Args({4, 0})->Args({8, 0})->Args({16, 0})->Args({2, 1})->Args({4, 1})->Unit(benchmark::kSecond);

}  // namespace
BENCHMARK_MAIN();
