// Test files as acquisition systems write them, assembled into tests (io/test_layout.hpp), made with dynid's own
// virtual test (never with the files of an outside report): a force channel in its own UFF 58 file, one file per
// channel; FRF text tables recognised by their content; a spurious mode left without a partner.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "dynid/engine/correlation.hpp"
#include "dynid/engine/discovery.hpp"
#include "dynid/engine/frf.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/engine/virtual_test.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/test_layout.hpp"
#include "dynid/io/uff.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

// The paper beam hit at node 1 (uy), 5 impacts, accelerometers at every uy, 2 % noise, 1 % damping.
VirtualTest beam_impact(const Model& m) {
  VirtualTestOptions o;
  for (const MeasuredDof& d : dofs_of_types(m, kTranslations))
    if (d.dof == Dof::UY) o.sensors.push_back(d);
  o.inputs = {{1, Dof::UY}};
  o.sample_rate_hz = 2048;
  o.duration_s = 4;
  o.impacts = 5;
  o.band_hz_hi = 800;
  o.noise = 0.02;
  o.force_noise = 0.02;
  EigenOptions eo;
  eo.num_modes = std::min(m.dof_map().num_free(), 60);
  eo.method = EigenOptions::Method::kDense;
  return simulate_test(m, modal_analysis(m, eo), o);
}

// One channel of a recording as a recording of its own (what a per-channel export holds).
Recording channel_of(const Recording& r, int ch) {
  Recording one;
  one.sample_rate_hz = r.sample_rate_hz;
  one.channels = {r.channels[static_cast<std::size_t>(ch)]};
  for (const Eigen::MatrixXd& rec : r.records) one.records.push_back(rec.col(ch));
  return one;
}

// The force channel in its own file, every response in its own file: one test, the force its input, and the
// same modes as from the recording written whole. Tolerance: frequencies within 1e-6 relative (the files hold
// the samples in binary double precision; only the channel order may differ).
TEST(TestLayout, ForceChannelInItsOwnFileMakesOneTest) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  const VirtualTest t = beam_impact(c.model);
  ASSERT_EQ(t.recordings.size(), 1u);
  const Recording& r = t.recordings[0];
  test::ScratchDir dir("layout");
  std::vector<std::string> files;
  for (int ch = 0; ch < r.num_channels(); ++ch) {
    files.push_back(dir.path("ch" + std::to_string(ch) + ".uff"));
    write_uff58_recording(files.back(), channel_of(r, ch), true, false);
  }
  const std::string whole = dir.path("whole.uff");
  write_uff58_recording(whole, r, true, false);

  const TestSet split = read_test_set(files);
  ASSERT_EQ(split.kind, TestSet::Kind::kRecordings);
  ASSERT_EQ(split.tests.size(), 1u) << "one test expected from one file per channel";
  split.require_consistent();
  const std::vector<Recording> recs = split.recordings();
  ASSERT_EQ(recs.size(), 1u);
  EXPECT_EQ(recs[0].input_channels().size(), 1u);
  EXPECT_EQ(recs[0].output_channels().size(), r.output_channels().size());
  EXPECT_EQ(recs[0].records.size(), r.records.size());

  const IdentificationSummary a = identify_recordings(recs, "", test::Band(20, 700));
  const IdentificationSummary b = identify_recordings(read_test_set({whole}).recordings(), "", test::Band(20, 700));
  ASSERT_GE(a.modes.size(), 3u);
  ASSERT_EQ(a.modes.size(), b.modes.size());
  for (std::size_t k = 0; k < a.modes.size(); ++k) EXPECT_TRUE(test::RelClose(a.modes[k].frequency_hz, b.modes[k].frequency_hz, 1e-6));
}

// Text tables of frequency, real and imaginary part are FRFs: read as such without being told.
TEST(TestLayout, FrfTextIsRecognisedByItsColumns) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  const VirtualTest t = beam_impact(c.model);
  FrfOptions fo;
  fo.max_frequency_hz = 800;
  const FrfData h = estimate_frf(t.recordings, fo);
  test::ScratchDir dir("frftext");
  std::vector<std::string> files;
  for (int o = 0; o < 3; ++o) {
    files.push_back(dir.path("frf" + std::to_string(o) + ".txt"));
    std::ofstream f(files.back());
    f.precision(17);
    for (Eigen::Index k = 0; k < h.frequency_hz.size(); ++k) f << h.frequency_hz[k] << " " << h.H(k, o).real() << " " << h.H(k, o).imag() << "\n";
  }
  TestSetOptions to;
  to.frf_outputs = {h.outputs[0].dof, h.outputs[1].dof, h.outputs[2].dof};
  to.frf_inputs = {h.inputs[0].dof};
  const TestSet s = read_test_set(files, to);
  EXPECT_EQ(s.kind, TestSet::Kind::kFrf);
  EXPECT_EQ(s.frf.num_outputs(), 3);
}

// A measured "mode" of no physical partner (a shape like no model mode) is set aside by discovery, never paired
// with a model mode twice its frequency; the real modes stay paired and the model is consistent.
TEST(TestLayout, SpuriousModeIsNotPairedWithADistantPartner) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  EigenOptions eo;
  eo.num_modes = 6;
  eo.method = EigenOptions::Method::kDense;
  const ModalResult r = modal_analysis(c.model, eo);
  const std::vector<MeasuredDof> dofs = dofs_of_types(c.model, kTranslations);
  ModalData m = sample_modes(c.model, r, dofs, 0, 6, "exact");
  // A seventh "mode" at 1.5 x mode 6's frequency whose shape alternates sign sensor by sensor.
  const Eigen::Index n = static_cast<Eigen::Index>(m.dofs.size());
  ModalData s = m;
  s.frequencies_hz.conservativeResize(7);
  s.frequencies_hz[6] = 1.5 * m.frequencies_hz[5];
  s.damping_ratios.conservativeResize(7);
  s.damping_ratios[6] = 0.01;
  s.shapes.conservativeResize(n, 7);
  for (Eigen::Index i = 0; i < n; ++i) s.shapes(i, 6) = (i % 2 ? 1.0 : -1.0) * (1 + 0.1 * static_cast<double>(i % 3));
  DiscoveryOptions o;
  o.frequency_noise = 1e-3;
  o.shape_noise = 0.01;
  const DiscoverySummary d = discover(c.model, s, o);
  ASSERT_EQ(d.set_aside.size(), 1u);
  EXPECT_EQ(d.set_aside[0].mode, 6);
  EXPECT_EQ(d.set_aside[0].reason, SetAside::Reason::kNoPartner);
  EXPECT_EQ(d.verdict, Verdict::kConsistent);
}

}  // namespace
}  // namespace dynid
