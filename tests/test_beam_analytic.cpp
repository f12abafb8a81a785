// Euler-Bernoulli beams against the analytic frequencies f_n = (beta_n L)^2 / (2 pi L^2) sqrt(EI / (rho A)):
// the error falls at the rate of the cubic Hermite element with consistent mass (h^4) under mesh refinement.
#include <cmath>

#include "dynid/engine/modal.hpp"
#include "dynid/mesh/generators.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Analytic {
  BeamSupport support;
  std::vector<double> beta_L;  // roots of the frequency equation
  int rigid;
};

double Frequency(double betaL, const BeamSpec& b) {
  const double EI = b.material.E * b.section.Iz, rhoA = b.material.rho * b.section.A;
  return betaL * betaL / (2 * kPi * b.length * b.length) * std::sqrt(EI / rhoA);
}

std::vector<double> Errors(const Analytic& a, int elements) {
  BeamSpec b;
  b.length = 2.0;
  b.elements = elements;
  b.material = {"steel", 2.1e11, 0, 0.3, 7850};
  b.section = {"flat", 0.05 * 0.01, 0, 0.05 * 1e-6 / 12, 0};
  b.support = a.support;
  EigenOptions o;
  o.num_modes = a.rigid + static_cast<int>(a.beta_L.size());
  o.method = EigenOptions::Method::kDense;
  const ModalResult r = modal_analysis(make_beam(b), o);
  std::vector<double> e;
  for (std::size_t k = 0; k < a.beta_L.size(); ++k)
    e.push_back(std::abs(r.frequencies_hz[a.rigid + k] - Frequency(a.beta_L[k], b)) / Frequency(a.beta_L[k], b));
  return e;
}

class BeamConvergence : public ::testing::TestWithParam<Analytic> {};

TEST_P(BeamConvergence, ErrorFallsAtFourthOrder) {
  const Analytic a = GetParam();
  const std::vector<int> meshes = {8, 16, 32};  // 4 elements is pre-asymptotic for the third free-free mode
  std::vector<std::vector<double>> err;
  for (int n : meshes) err.push_back(Errors(a, n));
  for (std::size_t k = 0; k < a.beta_L.size(); ++k) {
    for (std::size_t i = 0; i + 1 < meshes.size(); ++i) {
      // Observed order log2(e_h / e_{h/2}); h^4 in theory, measured 3.8-4.1: assert [3.5, 4.5].
      const double order = std::log2(err[i][k] / err[i + 1][k]);
      EXPECT_GT(order, 3.5) << "mode " << k + 1 << " meshes " << meshes[i] << "->" << meshes[i + 1];
      EXPECT_LT(order, 4.5) << "mode " << k + 1 << " meshes " << meshes[i] << "->" << meshes[i + 1];
    }
    EXPECT_LT(err.back()[k], 1e-3);  // and the finest mesh is accurate
  }
}

INSTANTIATE_TEST_SUITE_P(
    Supports, BeamConvergence,
    ::testing::Values(Analytic{BeamSupport::Cantilever, {1.8751040687, 4.6940911330, 7.8547574382}, 0},
                      Analytic{BeamSupport::SimplySupported, {kPi, 2 * kPi, 3 * kPi}, 0},
                      Analytic{BeamSupport::Free, {4.7300407449, 7.8532046241, 10.9956078380}, 2}),
    [](const ::testing::TestParamInfo<Analytic>& i) {
      switch (i.param.support) {
        case BeamSupport::Cantilever: return std::string("Cantilever");
        case BeamSupport::SimplySupported: return std::string("SimplySupported");
        default: return std::string("FreeFree");
      }
    });

}  // namespace
}  // namespace dynid
