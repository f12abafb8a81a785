// Virtual tests and modal identification: FRF estimation (H1/H2, windows) against analytic FRFs, and round trips
// (simulate a test of a model, identify the modes back, compare with the model's modes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "dynid/engine/correlation.hpp"
#include "dynid/engine/frf.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/engine/virtual_test.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/test_data.hpp"
#include "dynid/mesh/generators.hpp"
#include "internal/identify_select.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

using Opt = VirtualTestOptions;

struct RoundTrip {
  ModalData truth;
  IdentificationSummary id;
};

// Every mode of these small models (up to 60; dense solver): the virtual test keeps those below Nyquist and
// refuses a basis that stops short of it.
ModalResult all_modes(const Model& model) {
  EigenOptions eo;
  eo.num_modes = std::min(model.dof_map().num_free(), 60);
  eo.method = EigenOptions::Method::kDense;
  return modal_analysis(model, eo);
}

// The identified mode nearest in frequency to f (nullptr when none was identified).
const IdentifiedMode* nearest_mode(const IdentificationSummary& id, double f) {
  const IdentifiedMode* best = nullptr;
  for (const IdentifiedMode& m : id.modes)
    if (!best || std::abs(m.frequency_hz - f) < std::abs(best->frequency_hz - f)) best = &m;
  return best;
}

// Every truth mode in the band must be found: frequency within ftol, damping within ztol (relative), MAC >= mac.
void expect_identified(const ModalData& truth, const IdentificationSummary& id, double lo, double hi, double ftol, double ztol, double mac) {
  for (int k = 0; k < truth.num_modes(); ++k) {
    const double f = truth.frequencies_hz[k];
    if (f < lo || f > hi) continue;
    const IdentifiedMode* best = nearest_mode(id, f);
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

// A 1.5 m steel strip of 50 x 10 mm in 30 elements, bending about its weak axis; clamped (the default): f1 = 3.7 Hz.
Model flat_steel_strip(BeamSupport support = BeamSupport::Cantilever) {
  BeamSpec b;
  b.length = 1.5;
  b.elements = 30;
  b.material.E = 210e9;
  b.material.rho = 7850;
  b.section.A = 0.05 * 0.01;
  b.section.Iz = 0.05 * 1e-6 / 12;
  b.section.Iy = 0.01 * 1.25e-4 / 12;
  b.section.J = b.section.Iy + b.section.Iz;
  b.support = support;
  return make_beam(b);
}

// The acceptance setting: every translation measured, 2 % sensor (and force) noise, 1 % modal damping (the
// default), the force band up to `band_hi`. Tolerances: 0.5 % frequency, 20 % damping, MAC 0.99 (the issue's).
Opt plan(const Model& m, Opt::Excitation e, double fs, double duration, double band_hi) {
  Opt o;
  o.sensors = dofs_of_types(m, kTranslations);
  o.excitation = e;
  o.sample_rate_hz = fs;
  o.duration_s = duration;
  o.noise = 0.02;
  o.force_noise = 0.02;
  o.band_hz_hi = band_hi;
  return o;
}
constexpr double kFreqTol = 0.005, kDampTol = 0.2, kMinMac = 0.99;

// z^2 of each truth mode in [lo, hi] against the nearest identified mode's frequency and its reported std.
void add_frequency_z2(const ModalData& truth, const IdentificationSummary& id, double lo, double hi,
                      std::vector<double>& z2) {
  for (int k = 0; k < truth.num_modes(); ++k) {
    const double f = truth.frequencies_hz[k];
    if (f < lo || f > hi) continue;
    const IdentifiedMode* best = nearest_mode(id, f);
    ASSERT_NE(best, nullptr);
    ASSERT_GT(best->frequency_std_hz, 0);
    const double z = (best->frequency_hz - f) / best->frequency_std_hz;
    z2.push_back(z * z);
  }
}

// The reported std within a factor 1.6 of the actual error either way: rms z between 0.6 and 1.6.
void expect_rms_z_near_one(const std::vector<double>& z2) {
  ASSERT_FALSE(z2.empty());
  double sum = 0;
  for (double v : z2) sum += v;
  const double rms = std::sqrt(sum / static_cast<double>(z2.size()));
  std::printf("  %zu estimates, rms z %.3f\n", z2.size(), rms);
  EXPECT_GE(rms, 0.6);
  EXPECT_LE(rms, 1.6);
}

// The calibration check over independent realisations: virtual tests of `c` with seeds 1..8 (`options` gives
// everything but the seed), identified by `method` in [lo, hi]; each identification is passed to `check` (seed,
// summary; a fatal failure there ends the test), then every truth mode's z joins the rms-z bounds above.
template <class Check>
void expect_frequency_std_calibrated(const Case& c, Opt options, const std::string& method, double lo, double hi,
                                     Check check) {
  const ModalResult modes = all_modes(c.model);
  std::vector<double> z2;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    options.seed = seed;
    const VirtualTest t = simulate_test(c.model, modes, options);
    const IdentificationSummary id = identify_recordings(t.recordings, method, test::Band(lo, hi));
    check(seed, id);
    if (::testing::Test::HasFatalFailure()) return;
    add_frequency_z2(t.modes, id, lo, hi, z2);
  }
  expect_rms_z_near_one(z2);
}

TEST(VirtualTest, BeamImpactRoundTrip) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  Opt o = plan(c.model, Opt::Excitation::kImpact, 2048, 4, 800);
  o.inputs = {{1, Dof::UY}};
  o.impacts = 5;
  const VirtualTest t = simulate_test(c.model, all_modes(c.model), o);
  FrfOptions fo;
  fo.max_frequency_hz = 800;
  const IdentificationOptions io = test::Band(20, 700);
  expect_identified(t.modes, identify_lscf(estimate_frf(t.recordings, fo), io), 20, 700, kFreqTol, kDampTol, kMinMac);
  // An exponential window ending at 1 % adds 1.15 1/s of decay (40 % of the 45 Hz mode's own 2.86 1/s);
  // identification must take it off again: damping back within the same 20 %.
  fo.exponential_end = 0.01;
  const FrfData windowed = estimate_frf(t.recordings, fo);
  EXPECT_NEAR(windowed.window_decay, -std::log(0.01) / (o.duration_s - 1.0 / o.sample_rate_hz), 1e-9);
  expect_identified(t.modes, identify_lscf(windowed, io), 20, 700, kFreqTol, kDampTol, kMinMac);
  // H2 (noise on the input) on the same data finds the same modes.
  fo.exponential_end = 0;
  fo.estimator = FrfOptions::Estimator::kH2;
  expect_identified(t.modes, identify_lscf(estimate_frf(t.recordings, fo), io), 20, 700, kFreqTol, kDampTol, kMinMac);
}

TEST(VirtualTest, FrameImpactRoundTrip) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  Opt o = plan(c.model, Opt::Excitation::kImpact, 25.6, 240, 10);
  o.inputs = {{17, Dof::UX}, {20, Dof::UX}};  // fifth floor: every mode in the band moves there (the roof moves only in the symmetric ones)
  o.impacts = 5;
  const VirtualTest t = simulate_test(c.model, all_modes(c.model), o);
  FrfOptions fo;
  fo.max_frequency_hz = 10;
  expect_identified(t.modes, identify_lscf(estimate_frf(t.recordings, fo), test::Band(0.3, 8)), 0.3, 8, kFreqTol, kDampTol, kMinMac);
}

// LSCF's automatic orders: up to max(10, kLscfOrders / inputs), 30 with two references (every mode of the band
// found), or max(10, budget / inputs) when the options give a pole budget (120: 60), never past the band's lines.
TEST(VirtualTest, LscfAutomaticOrdersWithTwoReferences) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  Opt o = plan(c.model, Opt::Excitation::kImpact, 25.6, 240, 10);
  o.inputs = {{17, Dof::UX}, {20, Dof::UX}};
  o.impacts = 3;
  const VirtualTest t = simulate_test(c.model, all_modes(c.model), o);
  FrfOptions fo;
  fo.max_frequency_hz = 10;
  const FrfData frf = estimate_frf(t.recordings, fo);
  ASSERT_EQ(frf.num_inputs(), 2);
  const IdentificationSummary full = identify_lscf(frf, test::Band(0.3, 8));
  EXPECT_EQ(full.max_order, kLscfOrders / 2);
  expect_identified(t.modes, full, 0.3, 8, kFreqTol, kDampTol, kMinMac);
  IdentificationOptions budget = test::Band(0.3, 8);
  budget.lscf_pole_budget = 120;
  EXPECT_EQ(identify_lscf(frf, budget).max_order, 60);
  budget.lscf_pole_budget = -1;
  std::string why;
  EXPECT_FALSE(budget.IsValid(&why));
  EXPECT_NE(why.find("pole budget"), std::string::npos) << why;
}

// Two hammer locations, one of which excites nothing the sensors record (a hit on a support, or on a stiff
// anchorage): the second location's hits have the first's force records and responses at rounding level (1e-14
// of the live ones, random). Identified with the defaults: every mode in the band as from the live location
// alone, and a note naming the dead reference. Before the dead reference was left out, its numerically zero FRF
// columns made LSCF's poly-reference normal equations rank-deficient and no pole was stable over the orders.
TEST(VirtualTest, FrameImpactWithAHammerThatExcitesNothing) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  Opt o = plan(c.model, Opt::Excitation::kImpact, 25.6, 240, 10);
  o.inputs = {{17, Dof::UX}};
  o.impacts = 3;
  const VirtualTest t = simulate_test(c.model, all_modes(c.model), o);
  ASSERT_EQ(t.recordings.size(), 1u);
  Recording dead = t.recordings[0];
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  for (std::size_t k = 0; k < dead.channels.size(); ++k) {
    if (dead.channels[k].input) {
      dead.channels[k].dof = {21, Dof::UX};
      continue;
    }
    for (Eigen::MatrixXd& x : dead.records) {
      const double rms = std::sqrt(x.col(static_cast<Eigen::Index>(k)).squaredNorm() / static_cast<double>(x.rows()));
      for (Eigen::Index i = 0; i < x.rows(); ++i) x(i, static_cast<Eigen::Index>(k)) = 1e-14 * rms * g(rng);
    }
  }
  const IdentificationSummary s = identify_recordings({t.recordings[0], dead}, "", IdentificationOptions{});
  EXPECT_EQ(s.method, "lscf");
  expect_identified(t.modes, s, 0.3, 8, kFreqTol, kDampTol, kMinMac);
  EXPECT_TRUE(std::any_of(s.notes.begin(), s.notes.end(), [](const std::string& n) {
    return n.find("reference 21ux left out") != std::string::npos;
  })) << "no note on the dead reference";
}

TEST(VirtualTest, BeamAmbientRoundTrip) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  const VirtualTest t = simulate_test(c.model, all_modes(c.model), plan(c.model, Opt::Excitation::kAmbient, 2048, 120, 800));
  expect_identified(t.modes, identify_ssi(t.recordings[0], test::Band(20, 700)), 20, 700, kFreqTol, kDampTol, kMinMac);
}

TEST(VirtualTest, FrameAmbientRoundTrip) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  const VirtualTest t = simulate_test(c.model, all_modes(c.model), plan(c.model, Opt::Excitation::kAmbient, 25.6, 3600, 10));
  expect_identified(t.modes, identify_ssi(t.recordings[0], test::Band(0.3, 8)), 0.3, 8, kFreqTol, kDampTol, kMinMac);
}

// The frequency std that identify_recordings reports for continuous records (identify.hpp: sqrt(zeta / (pi f T)),
// sqrt(2) times the Cramer-Rao bound, widened where a neighbour overlaps) against the scatter of the estimates
// over independent realisations: the paper frame's ambient response, 300 s at 25.6 Hz, 8 seeds, every mode in
// 0.3-8 Hz. z = (f - f_true) / sigma over all modes and seeds (truth known: bias counts as error) must have an
// rms between 0.6 and 1.6, i.e. the reported std within a factor 1.6 of the actual error either way (sampling
// error of the rms over 8 x 9 values: ~8 %): understated, discovery would call random error missing physics;
// overstated, it would miss real physics. The split-data spread's ratio per mode ranged 0.46-2.7x on the dev split.
TEST(Uncertainty, ContinuousRecordsFrequencyStdMatchesTheScatterOverRealisations) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  expect_frequency_std_calibrated(c, plan(c.model, Opt::Excitation::kAmbient, 25.6, 300, 10), "ssi", 0.3, 8,
                                  [](std::uint64_t, const IdentificationSummary& id) {
                                    EXPECT_NEAR(id.stationary_record_s, 300,
                                                1 / 25.6);  // one record of 300 s (to a sample)
                                  });
}

// The same for a random-force test identified with the defaults (identify_recordings: SSI's selection, each
// mode's frequency and damping from LSCF on the H1 FRFs where LSCF has it): the std is the stationary
// response's for the modes SSI alone gives, and LSCF's own split-data scatter for the refined ones (their errors
// are 0.47 times the stationary value here: rms z 0.47 with it). The paper frame, a random force at node 17 ux,
// 300 s at 25.6 Hz, 8 seeds; the same bounds. Seed 1 has 8 of its 9 modes refined; the lowest, whose half-power
// bandwidth is half a Welch line of these records, keeps SSI's values.
// The damping of the modes below 5 Hz, whose half-power bandwidth (1 % damping) spans fewer than 4 of the records'
// 0.025 Hz Welch lines, stays SSI's with SSI's std: LSCF's is biased high there (1.21-1.43 % for 1.0 % at 1.5-3.3 Hz,
// seed 1) with a halves' std of 0.02 % (z about 20). Their damping z over the 8 seeds: rms 0.5 to 2 (SSI's damping
// scatters by about 30 % at 1.5 Hz; its std follows: rms z 0.9).
TEST(Uncertainty, RandomForceFrequencyStdMatchesTheScatterWithLscfRefinement) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  Opt o = plan(c.model, Opt::Excitation::kRandom, 25.6, 300, 10);
  o.inputs = {{17, Dof::UX}};
  std::vector<double> damping_z2;
  expect_frequency_std_calibrated(c, o, "", 0.3, 8, [&](std::uint64_t seed, const IdentificationSummary& id) {
    EXPECT_EQ(id.method, "ssi");
    const std::string refined = "of " + std::to_string(id.modes.size()) + " SSI modes from LSCF";
    EXPECT_TRUE(std::any_of(id.notes.begin(), id.notes.end(),
                            [&](const std::string& n) { return n.find(refined) != std::string::npos; }))
        << "no LSCF refinement (seed " << seed << "): " << ::testing::PrintToString(id.notes);
    for (const IdentifiedMode& m : id.modes) {
      if (m.frequency_hz >= 5) continue;
      ASSERT_GT(m.damping_std, 0);
      const double z = (m.damping_ratio - o.damping_ratio) / m.damping_std;
      damping_z2.push_back(z * z);
    }
  });
  ASSERT_FALSE(damping_z2.empty());
  const double rms =
      std::sqrt(std::accumulate(damping_z2.begin(), damping_z2.end(), 0.0) / static_cast<double>(damping_z2.size()));
  std::printf("  damping below 5 Hz: %zu estimates, rms z %.3f\n", damping_z2.size(), rms);
  EXPECT_GE(rms, 0.5);
  EXPECT_LE(rms, 2.0);
}

// The same for impacts (identify.hpp: the halves' spread, alternate hits, combined with a quarter of the spread
// over orders): the paper beam, 5 hits at node 1, 4 s records at 2048 Hz, 8 seeds, every mode in 20-700 Hz.
// The halves share what the hits have in common (the record's truncation, the fitted model's order), so their
// spread alone understated the error (rms z 2.4 here, median |z| 1.8 on the dev split's impact tests); the
// same bounds as above, 0.6 to 1.6.
TEST(Uncertainty, ImpactFrequencyStdMatchesTheErrorOverRealisations) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  Opt o = plan(c.model, Opt::Excitation::kImpact, 2048, 4, 800);
  o.inputs = {{1, Dof::UY}};
  o.impacts = 5;
  expect_frequency_std_calibrated(c, o, "lscf", 20, 700, [](std::uint64_t, const IdentificationSummary& id) {
    ASSERT_EQ(id.uncertainty_halves, 2);
  });
}

// Issue 16, item 3: a cantilever over a wide band (the band top ~100x its first mode) identified with the
// defaults (no band, no orders: the band rule from the data). Its two lowest modes, a decade below the rest,
// must be found. Tolerances: 0.5 % in frequency and MAC 0.99, as for the other round trips (2 % noise); damping
// within 30 %, not 20 %: the impact record (decay to 1 %) gives the first mode's half-power bandwidth only 1.5
// lines. The band rule must not cut them off and the selection must not lose them among the wide band's poles.
TEST(VirtualTest, WideBandCantileverLowestModesWithTheDefaultBandRule) {
  const Model m = flat_steel_strip();
  const ModalResult modes = all_modes(m);
  double f1 = 0;
  for (Eigen::Index j = 0; j < modes.frequencies_hz.size() && f1 == 0; ++j)
    if (!modes.rigid_body[j]) f1 = modes.frequencies_hz[j];
  ASSERT_GT(f1, 3);
  // Band to 100 f1 (the force's and the anti-alias band: 0.4 fs); impacts decaying to 1 % within the record.
  Opt o = plan(m, Opt::Excitation::kImpact, 1024, 4.6 / (0.01 * 2 * 3.14159265358979 * f1), 100 * f1);
  o.sensors.clear();
  int tip = 0;
  for (const MeasuredDof& d : dofs_of_types(m, kTranslations))
    if (d.dof == Dof::UY) {
      if (d.node % 3 == 0) o.sensors.push_back(d);  // every third node, in the bending plane
      tip = std::max(tip, d.node);
    }
  o.inputs = {{tip, Dof::UY}};
  o.impacts = 3;
  const VirtualTest t = simulate_test(m, modes, o);
  const IdentificationSummary s = identify_recordings(t.recordings, "", IdentificationOptions{});
  EXPECT_EQ(s.method, "lscf");
  std::printf("  band %.4g-%.4g Hz (f1 %.4g Hz), lines %.4g Hz\n", s.band_lo_hz, s.band_hi_hz, f1, s.resolution_hz);
  expect_identified(t.modes, s, 0, 1.01 * t.modes.frequencies_hz[1], kFreqTol, 0.3, kMinMac);
}

// Issue 16: impacts plan their band from the outputs' |FRF|^2, whose 10th percentile is no noise floor: the |FRF|^2
// of accelerations falls to nothing below the first mode and rises where the hits are weak. A simply supported
// strip hit next to a support (where its first mode moves least) at 3 % damping and 4 % noise: its first mode
// stood well out of its surroundings but within 10 dB of that percentile, the band started at half the second
// mode, and the first was lost (three of 56 impact tests of the identification benchmark: dev seeds, one block). The
// outputs' own energy shows it far above the sensors' noise: it is in the band and identified.
TEST(VirtualTest, ImpactNearASupportKeepsTheFirstModeInTheBand) {
  const Model m = flat_steel_strip(BeamSupport::SimplySupported);
  const ModalResult modes = all_modes(m);
  const double f1 = modes.frequencies_hz[0];
  ASSERT_GT(f1, 5);
  Opt o = plan(m, Opt::Excitation::kImpact, 1024, 4.6 / (0.03 * 2 * 3.14159265358979 * f1), 40 * f1);
  o.damping_ratio = 0.03;
  o.noise = o.force_noise = 0.04;
  o.sensors.clear();
  for (const MeasuredDof& d : dofs_of_types(m, kTranslations))
    if (d.dof == Dof::UY && d.node % 2 == 0) o.sensors.push_back(d);
  o.inputs = {{2, Dof::UY}};
  o.impacts = 5;
  const VirtualTest t = simulate_test(m, modes, o);
  const IdentificationSummary s = identify_recordings(t.recordings, "", IdentificationOptions{});
  std::printf("  band %.4g-%.4g Hz (f1 %.4g Hz), lines %.4g Hz\n", s.band_lo_hz, s.band_hi_hz, f1, s.resolution_hz);
  EXPECT_LT(s.band_lo_hz, f1);
  expect_identified(t.modes, s, 0, 1.01 * t.modes.frequencies_hz[1], kFreqTol, 0.3, kMinMac);
}

// Two clusters with one shape: the mode indicator's power response |H|^2 of 1 % damped modes on lines 0.0005
// apart, and two candidates at 1 and 1.04 (4 % apart: beyond the half-power merge window max(3 %, zeta)).
struct SplitPair {
  Eigen::VectorXd f, power;
  std::vector<internal::Candidate> cands;
  std::vector<internal::IndicatorEvidence> ev;
  IdentificationSummary s;
  explicit SplitPair(bool second_resonance, double apart = 0.04, double zeta = 0.01) {
    f = Eigen::VectorXd::LinSpaced(801, 0.8, 1.2);
    power.resize(f.size());
    auto resonance = [&](double x, double fr) {
      return 1 / (std::pow(1 - x * x / (fr * fr), 2) + std::pow(2 * zeta * x / fr, 2));
    };
    for (Eigen::Index k = 0; k < f.size(); ++k)
      power[k] = resonance(f[k], 1.0) + (second_resonance ? resonance(f[k], 1 + apart) : 0.0);
    s.frequency_hz = f;
    Eigen::VectorXcd shape(5);
    shape << 1, 0.8, -0.3, 0.5, -1;
    for (const auto& [fr, orders] : {std::pair<double, int>{1.0, 10}, std::pair<double, int>{1 + apart, 6}}) {
      internal::Candidate c;
      c.cluster.frequency_hz = fr;
      c.cluster.damping_ratio = zeta;
      for (int j = 0; j < orders; ++j) c.cluster.members.emplace_back(j, 0), c.cluster.member_weight.push_back(1.0);
      c.cluster.poles = orders;
      c.cluster.support = orders / 10.0;
      c.strength = c.cluster.support;
      c.shape = shape;
      cands.push_back(c);
      ev.push_back(internal::indicator_evidence(f, power, fr, zeta));
    }
  }
  std::vector<std::vector<std::size_t>> check() {
    return internal::check_evidence(cands, ev, {power, power}, IdentificationOptions{}, 10, s);
  }
};

TEST(Selection, SecondReportOfAModeOnItsFlankIsMerged) {
  // Issue 16: SSI reported some modes twice, 3-8 % apart with the same shape. One resonance: the indicator falls
  // monotonically from the mode to the second report (no dip), so the second is a split of the first, merged.
  SplitPair one(false);
  const auto kept = one.check();
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0], (std::vector<std::size_t>{0, 1}));
  ASSERT_EQ(one.s.rejected.size(), 1u);
  EXPECT_EQ(one.s.rejected[0].reason, Rejection::kSplit);
  EXPECT_NEAR(one.s.rejected[0].frequency_hz, 1.04, 1e-12);
  // Two resonances 4 % apart (4 half-power half-bandwidths): the indicator dips 4.2 dB between them, beyond
  // min_peak_db (3 dB), so two modes with one shape at these sensors stay two.
  SplitPair two(true);
  EXPECT_GT(internal::indicator_dip_db(two.f, two.power, 1.0, 1.04, 0.005), 3.5);
  EXPECT_EQ(two.check().size(), 2u);
  // Inside the half-power merge window (2.5 % < 3 %) too: two 0.5 % damped resonances dip 5.8 dB between them,
  // so a close pair whose local shapes look alike (LSCF's local residues near a stronger neighbour) stays two.
  SplitPair close(true, 0.025, 0.005);
  EXPECT_GT(internal::indicator_dip_db(close.f, close.power, 1.0, 1.025, 0.0025), 3.5);
  EXPECT_EQ(close.check().size(), 2u);
}

// The band rule counts the model's modes until `modes` of them are visible at the sensors. Here 80 oscillators the
// sensors cannot see (point masses on grounded springs, 0.5-2.1 Hz) lie below the cantilever's first mode (3.7 Hz),
// as a frame's member modes can: the first 48 modes (the rule's first count for 8 wanted) hold none the sensors see.
TEST(BandRule, CountsModesUntilEnoughAreVisible) {
  const Model beam = flat_steel_strip();
  Model m = test::UnsupportedCopy(beam);
  m.restrain(1, kAllDofs);
  std::vector<MeasuredDof> sensors;
  for (const Node& n : beam.nodes())
    if (n.id % 3 == 0) sensors.push_back({n.id, Dof::UY});
  ASSERT_GE(sensors.size(), 8u);
  for (int i = 0; i < 80; ++i) {
    const int id = 1000 + i;
    m.add_node(id, Eigen::Vector3d(0.01 * i, -1.0, 0.0));
    const double f = 0.5 + 0.02 * i, mass = 1.0;
    m.add_element(test::PointMass(5000 + i, id, mass));
    m.add_element(test::GroundedSpring(6000 + i, id, Dof::UY, mass * std::pow(2 * M_PI * f, 2)));
    m.restrain(id, static_cast<DofMask>(kAllDofs & ~dof_bit(Dof::UY)));
  }
  m.finalize();
  const ModelBand band = band_from_model(m, sensors, 5000, 8);
  const ModelBand alone = band_from_model(beam, sensors, 5000, 8);
  ASSERT_EQ(band.visible_hz.size(), 8u);
  for (std::size_t k = 0; k < 8; ++k) EXPECT_TRUE(test::RelClose(band.visible_hz[k], alone.visible_hz[k], 1e-9)) << k;
  EXPECT_NEAR(band.lo_hz, alone.lo_hz, 1e-9 * alone.lo_hz);
  EXPECT_NEAR(band.hi_hz, alone.hi_hz, 1e-9 * alone.hi_hz);
}

// Issue 16: hits end where their spectrum falls 20 dB below its median, not 10. A half-sine hammer pulse of
// 1.6 / B seconds (the identification benchmark's, for a band B = 0.4 fs) falls 10 dB below its median at about
// 0.8 B and has its first zero at 0.94 B: the modes between were in the test's band but outside the one analysed
// (four of 40 impact tests on the benchmark's dev seeds). Here a pulse of 1.2 / B (three samples; its first zero
// beyond 0.45 fs, where a zero of the hits would make a peak of its own in the |FRF|^2) and two modes (60 and 150
// Hz, 2 % damping, 1 % noise) whose peaks set the band to 187.5 Hz; the hits reach further, and the top follows
// them to where they carry a hundredth of their median power (computed here from the hits' own spectrum, within
// two lines; here that is the whole analysable range, 0.45 fs, where 10 dB stopped at 422.5 Hz).
TEST(BandRule, ImpactBandReachesWhereTheHitsFall20dB) {
  const double fs = 1000, B = 0.4 * fs, tp = 1.2 / B;
  const int n = 2000;
  Recording r;
  r.sample_rate_hz = fs;
  r.channels.resize(3);
  r.channels[0].input = true;
  r.channels[0].quantity = Quantity::kForce;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int hit = 0; hit < 3; ++hit) {
    Eigen::MatrixXd x = Eigen::MatrixXd::Zero(n, 3);
    const int p = static_cast<int>(std::lround(tp * fs));
    for (int i = 0; i <= p; ++i) x(10 + i, 0) = std::sin(M_PI * i / p);
    // Outputs: the pulse through two modes (unit-impulse acceleration responses), 1 % noise.
    for (const auto& [f, zeta] : {std::pair<double, double>{60, 0.02}, std::pair<double, double>{150, 0.02}}) {
      const double w = 2 * M_PI * f, wd = w * std::sqrt(1 - zeta * zeta);
      for (int i = 0; i < n; ++i)
        for (int j = 10; j <= 10 + p && j <= i; ++j) {
          const double t = (i - j) / fs;
          const double h = std::exp(-zeta * w * t) * std::sin(wd * t) / fs;
          x(i, 1) += x(j, 0) * h * (f < 100 ? 1.0 : 0.7);
          x(i, 2) += x(j, 0) * h * (f < 100 ? 0.5 : -1.0);
        }
    }
    for (int c = 1; c < 3; ++c) {
      const double rms = std::sqrt(x.col(c).squaredNorm() / n);
      for (int i = 0; i < n; ++i) x(i, c) += 0.01 * rms * noise(rng);
    }
    r.records.push_back(x);
  }
  const IdentificationPlan plan = plan_identification({r}, IdentificationOptions{});
  // The hits' energy spectrum (summed over the records, as the plan sums them), its median over (0, 0.45 fs] and
  // where it last stands within 10 and 20 dB of it.
  const double df = fs / n;
  std::vector<double> levels;
  for (int k = 1; k * df <= 0.45 * fs; ++k) {
    double e = 0;
    for (const Eigen::MatrixXd& x : r.records) {
      std::complex<double> X = 0;
      for (int i = 0; i < n; ++i) X += x(i, 0) * std::polar(1.0, -2 * M_PI * k * i / n);
      e += std::norm(X);
    }
    levels.push_back(e);
  }
  std::vector<double> sorted = levels;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[(sorted.size() - 1) / 2];
  double end10 = 0, end20 = 0;
  for (std::size_t k = 0; k < levels.size(); ++k) {
    if (levels[k] >= 0.1 * median) end10 = (static_cast<double>(k) + 1) * df;
    if (levels[k] >= 0.01 * median) end20 = (static_cast<double>(k) + 1) * df;
  }
  std::printf("  band %.4g-%.4g Hz; the hits fall 10 dB below their median at %.4g Hz, 20 dB at %.4g Hz\n",
              plan.band_lo_hz, plan.band_hi_hz, end10, end20);
  ASSERT_GT(end20, end10 + 10 * df);
  EXPECT_NEAR(plan.band_hi_hz, end20, 2 * df);
}

// IdentificationOptions::expected_modes: one resonance at 1 with a clear indicator peak, its cluster stable over
// 30 % of the orders (below min_cluster_fraction 0.45, above expected_fraction 0.2). On its own it is rejected for
// few orders; with a model mode predicted at 1.05 (within expected_ratio 1.15) of the same shape it is a mode, at
// its own frequency, and make_modes says which model mode it was reported as. Not with a predicted shape of MAC
// 0.01 (< expected_mac 0.9), nor at 1.2 (beyond 1.15), nor when the cluster holds 10 % of the orders (< 0.2).
TEST(Selection, WeakClusterShapedLikeAnExpectedModeIsReported) {
  SplitPair one(false);
  std::vector<internal::Candidate> weak{one.cands[0]};
  const std::vector<internal::IndicatorEvidence> ev{one.ev[0]};
  auto with_orders = [&](int n) {
    weak[0].cluster.members.clear();
    for (int j = 0; j < n; ++j) weak[0].cluster.members.emplace_back(j, 0);
    weak[0].cluster.member_weight.assign(static_cast<std::size_t>(n), 1.0);
  };
  with_orders(3);
  for (int i = 0; i < 5; ++i) one.s.dofs.push_back({i + 1, Dof::UY});
  const Eigen::VectorXd shape = weak[0].shape.real();
  auto check = [&](std::vector<ExpectedMode> expected, IdentificationSummary* out = nullptr) {
    IdentificationOptions o;
    o.expected_modes = std::move(expected);
    IdentificationSummary s = one.s;
    const auto kept = internal::check_evidence(weak, ev, {one.power}, o, 10, s);
    if (out) {
      *out = s;
      internal::make_modes(weak, ev, kept, 10, o, *out);
    }
    return kept.size();
  };
  EXPECT_EQ(check({}), 0u);
  IdentificationSummary s;
  EXPECT_EQ(check({{1.05, one.s.dofs, shape}}, &s), 1u);
  ASSERT_EQ(s.modes.size(), 1u);
  EXPECT_DOUBLE_EQ(s.modes[0].expected_hz, 1.05);
  EXPECT_NEAR(s.modes[0].frequency_hz, 1.0, 1e-12);  // the data's frequency, not the model's
  EXPECT_NEAR(s.modes[0].support, 0.3, 1e-12);
  Eigen::VectorXd other(5);
  other << 1, 0.8, 0.3, -0.5, 1;
  EXPECT_LT(test::Mac(other, shape), 0.02);
  EXPECT_EQ(check({{1.05, one.s.dofs, other}}), 0u);
  EXPECT_EQ(check({{1.2, one.s.dofs, shape}}), 0u);
  with_orders(1);
  EXPECT_EQ(check({{1.05, one.s.dofs, shape}}), 0u);
}

}  // namespace
}  // namespace dynid

// Real measurements (../shared/data/real, made by others): the tool impact test and the USC cantilever.
namespace dynid {
namespace {

// Published beside the data (PROVENANCE.md): peak picking gave 1074, 1961, 2617 Hz with these shapes.
TEST(RealData, ToolImpactLscfFindsThePublishedModes) {
  DYNID_REQUIRE_SHARED();
  const std::string dir = test::SharedDir() + "/data/real/tool-impact-test/";
  std::vector<std::string> files;
  std::vector<MeasuredDof> outs;
  for (int p = 1; p <= 5; ++p) {
    files.push_back(dir + "frf_point_" + std::to_string(p) + ".txt");
    outs.push_back({p, Dof::UX});  // H_1p = H_p1 (reciprocity): one reference (point 1), five responses
  }
  const FrfData frf = read_frf_text_set(files, outs, std::vector<MeasuredDof>(5, MeasuredDof{1, Dof::UX}));
  IdentificationOptions o;
  o.band_lo_hz = 500;
  o.band_hi_hz = 3500;
  const IdentificationSummary s = identify_lscf(frf, o);
  const double published[3] = {1074, 1961, 2617};
  const std::vector<std::vector<double>> shapes = {{1.4111, 0.9608, 0.6749, 0.4734, 0.3435},
                                                   {1.7165, 0.7057, 0.1830, -0.1333, -0.2136},
                                                   {2.0023, 0.4510, -0.1414, -0.2755, -0.3013}};
  // The three strongest modes that are not twins of a stronger one (split pairs share a shape) and have a
  // normal-mode shape (MPC >= 0.5): the dominant modes.
  std::vector<const IdentifiedMode*> dominant;
  for (const IdentifiedMode& m : s.modes)
    if (m.twin_of < 0 && m.mpc >= 0.5) dominant.push_back(&m);
  std::sort(dominant.begin(), dominant.end(), [](auto* a, auto* b) { return a->contribution > b->contribution; });
  ASSERT_GE(dominant.size(), 3u);
  dominant.resize(3);
  std::sort(dominant.begin(), dominant.end(), [](auto* a, auto* b) { return a->frequency_hz < b->frequency_hz; });
  for (int k = 0; k < 3; ++k) {
    // 1.5 %: the tolerance (peak picking on a 1 Hz grid against a fitted pole).
    EXPECT_TRUE(test::RelClose(dominant[k]->frequency_hz, published[k], 0.015)) << "mode near " << published[k];
    const Eigen::Map<const Eigen::VectorXd> p(shapes[k].data(), 5);
    EXPECT_GE(test::Mac(dominant[k]->real_shape, p), 0.9) << "mode near " << published[k];
    std::printf("  published %.0f Hz: identified %.1f Hz, zeta %.2f %%, MAC %.4f, MPC %.3f\n", published[k], dominant[k]->frequency_hz,
                100 * dominant[k]->damping_ratio, test::Mac(dominant[k]->real_shape, p), dominant[k]->mpc);
  }
}

// H1 from the raw impact record (force + acceleration at 51.2 kHz) against the supplied point-1 FRF: the
// strongest peaks of |H| agree within 2 % (the tolerance; the supplied FRF is a receptance averaged
// over impacts, ours one impact, converted from accelerance).
TEST(RealData, ToolImpactH1MatchesSuppliedFrf) {
  DYNID_REQUIRE_SHARED();
  const std::string dir = test::SharedDir() + "/data/real/tool-impact-test/";
  Recording r = read_time_text(dir + "impact_point1_time.txt");
  ASSERT_EQ(r.num_channels(), 2);
  r.channels[0].input = true;
  r.channels[0].quantity = Quantity::kForce;
  r.channels[0].dof = {1, Dof::UX};
  r.channels[1].input = false;
  r.channels[1].quantity = Quantity::kAcceleration;
  r.channels[1].dof = {1, Dof::UX};
  FrfOptions fo;
  fo.max_frequency_hz = 5000;
  const FrfData h = convert_frf(estimate_frf({r}, fo), Quantity::kDisplacement);
  const FrfData ref = read_frf_text(dir + "frf_point_1.txt", {1, Dof::UX}, {1, Dof::UX});
  auto peaks = [](const FrfData& d) {
    Eigen::VectorXd db(d.frequency_hz.size());
    for (Eigen::Index k = 0; k < db.size(); ++k) db[k] = 20 * std::log10(std::abs(d.H(k, 0)) + 1e-300);
    std::vector<SpectrumPeak> p = spectrum_peaks(d.frequency_hz, db, 500, 3500, 3.0);
    std::sort(p.begin(), p.end(), [](auto& a, auto& b) { return a.level_db > b.level_db; });
    p.resize(std::min<std::size_t>(p.size(), 3));
    std::sort(p.begin(), p.end(), [](auto& a, auto& b) { return a.frequency_hz < b.frequency_hz; });
    return p;
  };
  const std::vector<SpectrumPeak> a = peaks(h), b = peaks(ref);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(test::RelClose(a[k].frequency_hz, b[k].frequency_hz, 0.02)) << "peak " << k + 1;
    std::printf("  peak %d: H1 from the raw record %.1f Hz, supplied FRF %.1f Hz\n", k + 1, a[k].frequency_hz, b[k].frequency_hz);
  }
}

// The USC cantilever's impulse spectrum (LabVIEW, dB, 0.0853 Hz lines): its three strongest peaks are the
// documented 6.6, 41.4 and 117.9 Hz within 1 % (the tolerance; parabolic interpolation on the dB lines).
TEST(RealData, CantileverSpectrumPeaks) {
  DYNID_REQUIRE_SHARED();
  const LvmFile f = read_lvm(test::SharedDir() + "/data/real/usc-cantilever-ds4/FFT_data.lvm");
  ASSERT_TRUE(f.spectrum);
  std::vector<SpectrumPeak> p = spectrum_peaks(f.table.x, f.table.columns.col(0), 1, 200, 20.0);
  std::sort(p.begin(), p.end(), [](auto& a, auto& b) { return a.level_db > b.level_db; });
  ASSERT_GE(p.size(), 3u);
  p.resize(3);
  std::sort(p.begin(), p.end(), [](auto& a, auto& b) { return a.frequency_hz < b.frequency_hz; });
  const double documented[3] = {6.6, 41.4, 117.9};
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(test::RelClose(p[k].frequency_hz, documented[k], 0.01)) << p[k].frequency_hz;
}

}  // namespace
}  // namespace dynid
