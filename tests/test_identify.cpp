// Virtual tests and modal identification: FRF estimation (H1/H2, windows) against analytic FRFs, and round trips
// (simulate a test of a model, identify the modes back, compare with the model's modes).
#include <gtest/gtest.h>

#include <cmath>

#include "dynid/engine/correlation.hpp"
#include "dynid/engine/frf.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/engine/virtual_test.hpp"
#include "dynid/io/case_file.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

using Opt = VirtualTestOptions;

struct RoundTrip {
  ModalData truth;
  IdentificationSummary id;
};

ModalResult modes_to_nyquist(const Model& model, double nyquist) {
  EigenOptions eo;
  eo.num_modes = std::min(model.dof_map().num_free(), 60);
  eo.method = EigenOptions::Method::kDense;
  return modal_analysis(model, eo);
}

// Every truth mode in the band must be found: frequency within ftol, damping within ztol (relative), MAC >= mac.
void expect_identified(const ModalData& truth, const IdentificationSummary& id, double lo, double hi, double ftol, double ztol, double mac) {
  for (int k = 0; k < truth.num_modes(); ++k) {
    const double f = truth.frequencies_hz[k];
    if (f < lo || f > hi) continue;
    const IdentifiedMode* best = nullptr;
    for (const IdentifiedMode& m : id.modes)
      if (!best || std::abs(m.frequency_hz - f) < std::abs(best->frequency_hz - f)) best = &m;
    ASSERT_NE(best, nullptr) << "no mode identified near " << f << " Hz";
    EXPECT_TRUE(test::RelClose(best->frequency_hz, f, ftol)) << "mode " << k + 1 << " (" << f << " Hz)";
    EXPECT_TRUE(test::RelClose(best->damping_ratio, truth.damping_ratios[k], ztol)) << "mode " << k + 1 << " damping";
    EXPECT_GE(test::Mac(best->real_shape, truth.shapes.col(k)), mac) << "mode " << k + 1 << " shape";
    std::printf("  truth %9.4f Hz zeta %.4f | found %9.4f Hz (+-%.4f) zeta %.4f (+-%.4f) MAC %.5f MPC %.4f contrib %.3f poles %d\n", f,
                truth.damping_ratios[k], best->frequency_hz, best->frequency_std_hz, best->damping_ratio, best->damping_std,
                test::Mac(best->real_shape, truth.shapes.col(k)), best->mpc, best->contribution, best->poles);
  }
  std::printf("  %zu modes identified in %.3f s\n", id.modes.size(), id.seconds);
}

TEST(VirtualTest, BeamImpactRoundTrip) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  Opt o;
  o.sensors = dofs_of_types(c.model, kTranslations);
  o.inputs = {{1, Dof::UY}};
  o.sample_rate_hz = 2048;
  o.duration_s = 4;
  o.impacts = 5;
  o.noise = 0.02;
  o.force_noise = 0.02;
  o.band_hz_hi = 800;
  const VirtualTest t = simulate_test(c.model, modes_to_nyquist(c.model, 1024), o);
  FrfOptions fo;
  fo.max_frequency_hz = 800;
  const FrfData frf = estimate_frf(t.recordings, fo);
  IdentificationOptions io;
  io.band_lo_hz = 20;
  io.band_hi_hz = 700;
  const IdentificationSummary id = identify_lscf(frf, io);
  expect_identified(t.modes, id, 20, 700, 0.005, 0.2, 0.99);
}

TEST(VirtualTest, FrameImpactRoundTrip) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  Opt o;
  o.sensors = dofs_of_types(c.model, kTranslations);
  o.inputs = {{17, Dof::UX}, {20, Dof::UX}};  // fifth floor: every mode in the band moves there (the roof moves only in the symmetric ones)
  o.sample_rate_hz = 25.6;
  o.duration_s = 240;
  o.impacts = 5;
  o.noise = 0.02;
  o.force_noise = 0.02;
  o.band_hz_hi = 10;
  const VirtualTest t = simulate_test(c.model, modes_to_nyquist(c.model, 12.8), o);
  FrfOptions fo;
  fo.max_frequency_hz = 10;
  const FrfData frf = estimate_frf(t.recordings, fo);
  IdentificationOptions io;
  io.band_lo_hz = 0.3;
  io.band_hi_hz = 8;
  const IdentificationSummary id = identify_lscf(frf, io);
  expect_identified(t.modes, id, 0.3, 8, 0.005, 0.2, 0.99);
}

TEST(VirtualTest, BeamAmbientRoundTrip) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  Opt o;
  o.sensors = dofs_of_types(c.model, kTranslations);
  o.excitation = Opt::Excitation::kAmbient;
  o.sample_rate_hz = 2048;
  o.duration_s = 120;
  o.noise = 0.02;
  o.band_hz_hi = 800;
  const VirtualTest t = simulate_test(c.model, modes_to_nyquist(c.model, 1024), o);
  IdentificationOptions io;
  io.band_lo_hz = 20;
  io.band_hi_hz = 700;
  const IdentificationSummary id = identify_ssi(t.recordings[0], io);
  expect_identified(t.modes, id, 20, 700, 0.005, 0.2, 0.99);
}

TEST(VirtualTest, FrameAmbientRoundTrip) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  Opt o;
  o.sensors = dofs_of_types(c.model, kTranslations);
  o.excitation = Opt::Excitation::kAmbient;
  o.sample_rate_hz = 25.6;
  o.duration_s = 3600;
  o.noise = 0.02;
  o.band_hz_hi = 10;
  const VirtualTest t = simulate_test(c.model, modes_to_nyquist(c.model, 12.8), o);
  IdentificationOptions io;
  io.band_lo_hz = 0.3;
  io.band_hi_hz = 8;
  const IdentificationSummary id = identify_ssi(t.recordings[0], io);
  expect_identified(t.modes, id, 0.3, 8, 0.005, 0.2, 0.99);
}

}  // namespace
}  // namespace dynid
