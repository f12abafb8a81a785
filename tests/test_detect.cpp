// Residual-force detection: the paper's Table 3 (frame) and Table 4 setting (beam), reduced data, noise,
// and mismatched inputs.
#include <cmath>

#include "dynid/engine/detect.hpp"
#include "dynid/io/case_file.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

struct Table3Entry {
  int element, c;
  double dk, dm;            // the change
  double paper_dk, paper_dm;  // Table 3, first order, in %
};

// Table 3 of the paper (percent). Case 1: 15 % stiffness loss; case 2: 15 % mass loss; case 3: both.
const Table3Entry kTable3[] = {
    {9, 1, -0.15, 0.0, -17.1, 0.18},    {9, 2, 0.0, -0.15, 0.09, -15.3},    {9, 3, -0.15, -0.15, -16.9, -15.5},
    {28, 1, -0.15, 0.0, -16.2, 0.04},   {28, 2, 0.0, -0.15, 0.01, -15.04}, {28, 3, -0.15, -0.15, -16.2, -15.1}};

// The case file's simulation: the changed model's exact modes at its measured DOFs.
DetectSummary RunCase(const std::string& file) {
  const Case c = load_case(file);
  Model ch;
  const ModalData data = detect_changed_data(c, &ch);
  DetectOptions o = c.detect->options;
  o.simulated_changed = &ch;
  return detect(c.model, data, o);
}

class Table3 : public ::testing::TestWithParam<Table3Entry> {};

TEST_P(Table3, LocatesAndQuantifies) {
  const Table3Entry t = GetParam();
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  const std::string file = test::CasesDir() + "/paper-frame-damage/element" + std::to_string(t.element) + "-case" +
                           std::to_string(t.c) + ".yaml";
  const DetectSummary s = RunCase(file);
  ASSERT_TRUE(s.full_dofs);
  ASSERT_EQ(s.used_modes.size(), 4u);
  // The pseudo residual force at each DOF of the changed element exceeds every other DOF's by >= 1e6.
  const auto& en = c.model.element_nodes(c.model.element_index(t.element));
  double in_min = INFINITY, out_max = 0;
  for (std::size_t r = 0; r < s.dofs.size(); ++r) {
    const int n = c.model.node_index(s.dofs[r].node);
    if (n == en[0] || n == en[1]) in_min = std::min(in_min, s.delta_pseudo[r]);
    else out_max = std::max(out_max, s.delta_pseudo[r]);
  }
  EXPECT_GE(in_min, 1e6 * out_max) << "in " << in_min << " out " << out_max;
  // Located: the changed element alone is flagged.
  ASSERT_EQ(s.amounts.size(), 1u);
  EXPECT_EQ(s.amounts[0].element, t.element);
  EXPECT_EQ(s.elements[0].element, t.element);
  EXPECT_TRUE(s.elements[0].flagged);
  // First order (eq. 14-21) vs Table 3: within 0.3 percentage points; entries the paper gives below 0.5 % in
  // magnitude must come out below 0.5 % (the reconstruction flips the sign of two of them, see ../shared/cases).
  auto check = [](double ours_pct, double paper_pct) {
    if (std::abs(paper_pct) < 0.5) EXPECT_LT(std::abs(ours_pct), 0.5) << ours_pct << " vs " << paper_pct;
    else EXPECT_NEAR(ours_pct, paper_pct, 0.3);
  };
  check(100 * s.amounts[0].dk_first_order, t.paper_dk);
  check(100 * s.amounts[0].dm_first_order, t.paper_dm);
  // Refined (eigen-solves, Ceres): the exact change within 0.01 percentage point.
  EXPECT_NEAR(100 * s.amounts[0].dk, 100 * t.dk, 0.01);
  EXPECT_NEAR(100 * s.amounts[0].dm, 100 * t.dm, 0.01);
}

INSTANTIATE_TEST_SUITE_P(Paper, Table3, ::testing::ValuesIn(kTable3), [](const auto& i) {
  return "Element" + std::to_string(i.param.element) + "Case" + std::to_string(i.param.c);
});

DetectSummary BeamAddedMass(const std::vector<MeasuredDof>& dofs) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  Model ch = changed_model(c.model, {{6, {0.0, 0.551}}});
  EigenOptions eo;
  eo.num_modes = 7;
  const ModalResult r = modal_analysis(ch, eo);
  const ModalData data = sample_modes(ch, r, dofs.empty() ? all_dofs(ch) : dofs, 2, 5, "test");
  DetectOptions o;
  o.simulated_changed = &ch;
  return detect(c.model, data, o);
}

TEST(PaperBeam, AddedMassOnElement6) {
  // 55.1 % of element 6's mass added (as a density increase), exact modes at every DOF, 5 elastic modes.
  const DetectSummary s = BeamAddedMass({});
  ASSERT_EQ(s.amounts.size(), 1u);
  EXPECT_EQ(s.amounts[0].element, 6);
  EXPECT_EQ(s.elements[0].element, 6);
  // The first-order estimate is only first order: for a 55 % change it misses the mass and shows a spurious
  // stiffness change (like the paper's 6.9 %); reported as it comes out, checked only to be off.
  EXPECT_GT(std::abs(s.amounts[0].dk_first_order), 0.005);
  EXPECT_GT(std::abs(s.amounts[0].dm_first_order - 0.551), 0.05);
  // Refined: within 0.1 point of 55.1 % and 0.
  EXPECT_NEAR(100 * s.amounts[0].dm, 55.1, 0.1);
  EXPECT_NEAR(100 * s.amounts[0].dk, 0.0, 0.1);
}

TEST(PaperBeam, ReducedToTranslationsStillFirst) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  for (const std::vector<int>& nodes : {std::vector<int>{}, std::vector<int>{1, 3, 5, 7, 9, 11}}) {
    const DetectSummary s = BeamAddedMass(dofs_of_types(c.model, dof_bit(Dof::UY), nodes));
    EXPECT_FALSE(s.full_dofs);
    EXPECT_EQ(s.elements[0].element, 6) << nodes.size() << " nodes";
    EXPECT_TRUE(s.elements[0].flagged);
    ASSERT_FALSE(s.amounts.empty());
    EXPECT_NEAR(100 * s.amounts[0].dm, 55.1, 0.1);
    // Blurring by the reduction: residual forces are no longer confined to the element's DOFs.
    int nonzero = 0;
    for (Eigen::Index r = 0; r < s.pseudo.size(); ++r) nonzero += s.pseudo[r] > 1e-6 * s.pseudo.maxCoeff();
    EXPECT_GT(nonzero, 2);
  }
}

TEST(NoiseStudy, DynidLocatesWithinTopThree) {
  // The study, 200 trials per case at 1 % shape noise (the 3 % level runs in `dynid detect --study`):
  // dynid's sensitivity fit puts the changed element in its top 3 in >= 95 % of trials for every case.
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  for (const Table3Entry& t : kTable3) {
    const Model ch = changed_model(c.model, {{t.element, {t.dk, t.dm}}});
    NoiseStudyOptions o;
    o.trials = 200;
    o.shape_noise = {0.01};
    o.dofs = dofs_of_types(c.model, dof_bit(Dof::UX) | dof_bit(Dof::UY));
    ASSERT_EQ(o.dofs.size(), 40u);
    const NoiseStudyRow r = noise_study(c.model, ch, t.element, o)[0];
    EXPECT_GE(r.dynid_top3, 190) << "element " << t.element << " case " << t.c;
    EXPECT_GE(r.dynid_top3, r.pseudo_top3);
  }
}

TEST(DetectErrors, MeasuredDofNotInModel) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  ModalData d;
  d.dofs = {{5, Dof::UX}, {5, Dof::UZ}};
  d.frequencies_hz = Eigen::VectorXd::Constant(1, 1.0);
  d.shapes = Eigen::MatrixXd::Ones(2, 1);
  try {
    detect(c.model, d, DetectOptions{});
    FAIL();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("measured DOF 5uz"), std::string::npos) << m;
    EXPECT_NE(m.find("free DOFs are: ux,uy,rz"), std::string::npos) << m;
  }
  d.dofs = {{1, Dof::UX}, {5, Dof::UX}};
  try {
    detect(c.model, d, DetectOptions{});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is restrained"), std::string::npos) << e.what();
  }
}

TEST(DetectErrors, ModesThatDoNotPairAndTooFewModes) {
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  Model ch = changed_model(c.model, {{9, {-0.15, -0.15}}});
  EigenOptions eo;
  eo.num_modes = 4;
  const ModalResult r = modal_analysis(ch, eo);
  ModalData d = sample_modes(ch, r, all_dofs(ch), 0, 1, "one mode");
  d.frequencies_hz.conservativeResize(2);
  d.shapes.conservativeResize(Eigen::NoChange, 2);
  d.frequencies_hz[1] = 50.0;
  d.shapes.col(1).setZero();
  d.shapes(2, 1) = 1.0;  // a shape like no model mode
  const DetectSummary s = detect(c.model, d, DetectOptions{});
  bool unpaired = false, few = false;
  for (const std::string& w : s.warnings) {
    unpaired = unpaired || w.find("mode 2 (50 Hz) pairs with no model mode") != std::string::npos;
    few = few || w.find("p < 2 n_c") != std::string::npos;
  }
  EXPECT_TRUE(unpaired);
  EXPECT_TRUE(few);  // one mode for two unknowns
  ModalData none = d;
  none.frequencies_hz = Eigen::VectorXd::Constant(1, 50.0);
  none.shapes = d.shapes.rightCols(1);
  EXPECT_THROW(detect(c.model, none, DetectOptions{}), InputError);
}

TEST(DetectPairing, ModeTheSensorsCannotSeeIsNoPartner) {
  // Issue 16: model modes the sensors barely see (mean square at the sensors below kMinPairingVisibility = 1 % of
  // the mode's mean square over all translations, e.g. vertical bending of the floor beams under horizontal
  // sensors) are no pairing partners: their MAC with any measurement is noise. A measured "mode" that is exactly
  // such a mode's trace at the sensors (MAC 1 at its own frequency) is left unpaired with the warning; the sway
  // modes pair. Exact modes, so the decision has no tolerance of its own.
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  const std::vector<MeasuredDof> sensors = dofs_of_types(c.model, dof_bit(Dof::UX));
  EigenOptions eo;
  eo.num_modes = 30;
  const ModalResult r = modal_analysis(c.model, eo);
  const std::vector<int> rows = measured_equations(c.model, sensors), translations = translation_equations(c.model);
  int hidden = -1;
  for (Eigen::Index j = 0; j < r.eigenvalues.size() && hidden < 0; ++j) {
    const double v = sensor_visibility(r.modes.col(j), rows, translations);
    double trace = 0;
    for (int e : rows) trace += r.modes(e, j) * r.modes(e, j);
    if (!r.rigid_body[j] && v > 0 && v < kMinPairingVisibility && std::sqrt(trace) > 1e-6 * r.modes.col(j).norm())
      hidden = static_cast<int>(j);
  }
  ASSERT_GE(hidden, 3) << "the frame has no mode its horizontal sensors barely see";
  ModalData d = sample_modes(c.model, r, sensors, 0, 3, "sway modes");
  const ModalData h = sample_modes(c.model, r, sensors, hidden, 1, "hidden mode");
  d.frequencies_hz.conservativeResize(4);
  d.shapes.conservativeResize(Eigen::NoChange, 4);
  d.frequencies_hz[3] = h.frequencies_hz[0];
  d.shapes.col(3) = h.shapes.col(0);
  const DetectSummary s = detect(c.model, d, DetectOptions{});
  bool unpaired = false;
  for (const std::string& w : s.warnings)
    unpaired = unpaired ||
               (w.find("mode 4 (") != std::string::npos && w.find("pairs with no model mode") != std::string::npos);
  EXPECT_TRUE(unpaired);
  EXPECT_EQ(s.used_modes, (std::vector<int>{0, 1, 2}));
}

}  // namespace
}  // namespace dynid
