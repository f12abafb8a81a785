// The API guide's complete example (docs/api.md), built against an installed dynid by ctest (install.consumer).
// A host FE code hands dynid its own elements, then uses a dynid model built in memory; no file is read.
//   1. Host elements through dynid::ElementSource: a fixed-free chain of masses and springs, assembled sparse,
//      solved by shift-invert Lanczos, reduced by SEREP, and a stiffness loss located by residual forces.
//   2. A model built in memory: modal analysis, detection and quantification of a damaged element, updating.
//   3. The distributed backend (one process here; `mpirun -n N consumer` for N): the host elements' solve again.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <dynid/engine/detect.hpp>
#include <dynid/engine/modal.hpp>
#include <dynid/engine/model_fit.hpp>
#include <dynid/engine/serep.hpp>
#include <dynid/mesh/element_source.hpp>
#include <dynid/mesh/generators.hpp>
#include <dynid/solvers/eigen.hpp>
#include <dynid/solvers/sparse.hpp>
#include <exception>
#include <fstream>
#include <string>
#include <vector>

namespace {

// The host code's elements: spring e joins mass e-1 and mass e (mass -1 is the ground), each mass m on its own
// DOF. Element e carries the spring and, lumped, mass e.
class SpringChain : public dynid::ElementSource {
 public:
  SpringChain(int n, double k, double m) : k_(n, k), m_(m) {}
  std::vector<double>& springs() { return k_; }
  int num_dofs() const override { return static_cast<int>(k_.size()); }
  int num_elements() const override { return static_cast<int>(k_.size()); }
  void element_dofs(int e, std::vector<int>* dofs) const override { *dofs = {e - 1, e}; }  // -1: the ground
  void element_matrices(int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const override {
    if (K) *K = k_[e] * (Eigen::Matrix2d() << 1, -1, -1, 1).finished();
    if (M) *M = (Eigen::Matrix2d() << 0, 0, 0, m_).finished();
  }

 private:
  std::vector<double> k_;
  double m_;
};

int host_elements() {
  const int n = 200;
  const double k = 1e6, m = 2.0, pi = 3.14159265358979323846;
  SpringChain chain(n, k, m);
  const dynid::AssembledSystem sys = dynid::assemble_system(chain);
  dynid::EigenOptions eo;
  eo.num_modes = 6;
  const dynid::EigenSolution s = dynid::solve_eigen(sys.K, sys.M, eo);
  if (!s.summary.ok()) return std::printf("eigen-solve failed: %s\n", s.summary.message.c_str()), 1;
  // Analytic: omega_j = 2 sqrt(k/m) sin((2j - 1) pi / (2 (2n + 1))).
  double worst = 0;
  for (int j = 1; j <= 6; ++j) {
    const double w = 2 * std::sqrt(k / m) * std::sin((2 * j - 1) * pi / (2 * (2 * n + 1)));
    worst = std::max(worst, std::abs(std::sqrt(s.eigenvalues[j - 1]) - w) / w);
  }
  std::printf("host elements: %d DOFs, 6 modes, worst frequency error vs analytic %.1e\n", n, worst);

  // SEREP to 6 sensors (as many as modes): the reduced 6 x 6 model keeps the 6 eigenvalues exactly.
  const std::vector<int> sensors = {29, 59, 89, 119, 149, 199};
  const dynid::SerepReduction red = dynid::serep_reduce(s.modes, s.eigenvalues, sensors);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> reduced(red.K, red.M);
  const double serep_error = ((reduced.eigenvalues() - s.eigenvalues).array() / s.eigenvalues.array()).abs().maxCoeff();
  std::printf("SEREP to %d sensors: reduced eigenvalues within %.1e\n", static_cast<int>(sensors.size()), serep_error);

  // The "measured" structure: spring 125 lost 40 % of its stiffness. Its modes (all DOFs, a simulation) on the
  // intact K and M: the residual forces (K - lambda M) phi (eq. 6 of the paper) vanish except at the DOFs the
  // damaged spring joins.
  SpringChain damaged(n, k, m);
  damaged.springs()[125] *= 0.6;
  const dynid::AssembledSystem dsys = dynid::assemble_system(damaged);
  const dynid::EigenSolution d = dynid::solve_eigen(dsys.K, dsys.M, eo);
  Eigen::MatrixXd R;
  dynid::residual_forces(sys.K, sys.M, d.modes, d.eigenvalues, &R);
  Eigen::Index peak = 0;
  const Eigen::VectorXd size = R.rowwise().norm();
  size.maxCoeff(&peak);
  double elsewhere = 0;
  for (Eigen::Index i = 0; i < size.size(); ++i)
    if (i != 124 && i != 125) elsewhere = std::max(elsewhere, size[i]);
  std::printf("residual force peaks at DOF %d (the damaged spring joins DOFs 124 and 125); elsewhere < %.1e of it\n",
              static_cast<int>(peak), elsewhere / size[peak]);
  return (worst < 1e-8 && serep_error < 1e-8 && (peak == 124 || peak == 125) && elsewhere < 1e-6 * size[peak]) ? 0 : 1;
}

int model_in_memory() {
  // A clamped steel cantilever, 20 elements; element 8 (index 7) loses 30 % of its stiffness.
  dynid::BeamSpec spec;
  spec.length = 2.0;
  spec.elements = 20;
  spec.material = {"steel", 2.1e11, 0, 0.3, 7800};
  spec.section = {"flat", 6e-4, 0, 1.8e-9, 0};
  spec.support = dynid::BeamSupport::Cantilever;
  const dynid::Model model = dynid::make_beam(spec);
  const dynid::Model damaged = dynid::changed_model(model, {{8, {-0.3, 0.0}}});
  dynid::EigenOptions eo;
  eo.num_modes = 5;
  const dynid::ModalResult truth = dynid::modal_analysis(damaged, eo);
  const std::vector<dynid::MeasuredDof> dofs = dynid::dofs_of_types(model, dynid::dof_bit(dynid::Dof::UY));
  const dynid::ModalData data = dynid::sample_modes(damaged, truth, dofs, 0, 5, "host test");

  dynid::DetectOptions o;
  o.candidates = {};
  const dynid::DetectSummary S = dynid::detect(model, data, o);
  std::printf("detect: element %d ranked first", S.elements.front().element);
  if (!S.amounts.empty()) std::printf(", dk = %+.3f", S.amounts.front().dk);
  std::printf("\n");

  // Updating: the stiffness factor of elements 7, 8 and 9 from the same data.
  dynid::ParametricModel pm(model);
  for (int e : {6, 7, 8}) {
    dynid::Parameter p;
    p.name = "E:" + std::to_string(e + 1);
    p.kind = dynid::ParameterKind::kStiffness;
    p.elements = {e};
    p.lower = 0.2;
    p.upper = 2.0;
    pm.add(p);
  }
  const dynid::FitSummary f = dynid::fit_parameters(pm, data, Eigen::Vector3d::Ones(), {}, dynid::FitOptions{});
  std::printf("update: E factors %.3f %.3f %.3f (%s)\n", f.theta[0], f.theta[1], f.theta[2], f.termination.c_str());
  const bool ok = S.elements.front().element == 8 && !S.amounts.empty() && std::abs(S.amounts.front().dk + 0.3) < 0.01 &&
                  std::abs(f.theta[1] - 0.7) < 0.01 && std::abs(f.theta[0] - 1) < 0.01 && std::abs(f.theta[2] - 1) < 0.01;
  return ok ? 0 : 1;
}

// The file a shared library was mapped from ("" if it is not loaded).
std::string mapped_file(const std::string& name) {
  std::ifstream maps("/proc/self/maps");
  for (std::string line; std::getline(maps, line);) {
    const std::size_t at = line.find('/');
    if (at != std::string::npos && line.find(name, at) != std::string::npos) return line.substr(at);
  }
  return "";
}

int distributed() {
  // backend = kDistributed: dynid::solvers opens its plugin lib/libdynid_distributed.so (MPI, PETSc, SLEPc) on this
  // first use, found through the run path the installed package gives this program; until now none was loaded.
  const bool loaded_before = !mapped_file("libdynid_distributed.so").empty() || !mapped_file("libmpi").empty();
  SpringChain chain(200, 1e6, 2.0);
  const dynid::AssembledSystem sys = dynid::assemble_system(chain);
  dynid::EigenOptions eo;
  eo.num_modes = 6;
  const dynid::EigenSolution local = dynid::solve_eigen(sys.K, sys.M, eo);
  eo.backend = dynid::EigenOptions::Backend::kDistributed;
  try {
    const dynid::EigenSolution d = dynid::solve_eigen(sys.K, sys.M, eo);
    if (!d.summary.ok()) return std::printf("distributed solve failed: %s\n", d.summary.message.c_str()), 1;
    const double diff = ((d.eigenvalues - local.eigenvalues).array() / local.eigenvalues.array()).abs().maxCoeff();
    std::printf("distributed backend (%d rank, from %s): 6 eigenvalues within %.1e of the local solve\n",
                d.summary.ranks, mapped_file("libdynid_distributed.so").c_str(), diff);
    return !loaded_before && diff < 1e-8 ? 0 : 1;
  } catch (const std::exception& e) {
    return std::printf("distributed backend: %s\n", e.what()), 1;
  }
}

}  // namespace

int main() {
  const int a = host_elements();
  const int b = model_in_memory();
  const int c = distributed();
  std::printf("%s\n", a == 0 && b == 0 && c == 0 ? "dynid consumer: ok" : "dynid consumer: FAILED");
  return a | b | c;
}
