// Missing-physics discovery: the candidates' matrices against explicit models of the same physics, and the
// four steps on exact data where the answer is known. (The concealed-data suite with virtual tests,
// identification and different discretizations is cases/discovery, run by tests/CMakeLists.txt.)
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <map>
#include <set>

#include "candidates/registry.hpp"
#include "discovery/stages.hpp"
#include "dynid/engine/candidate_checks.hpp"
#include "dynid/engine/discovery.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/io/discover_io.hpp"
#include "dynid/mesh/generators.hpp"
#include "dynid/mesh/units.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

Material steel() {
  Material m;
  m.name = "steel";
  m.E = 2.1e11;
  m.rho = 7850;
  return m;
}

// A steel beam of 0.1 m x 0.1 m square section, `length` long.
BeamSpec square_steel_beam(double length) {
  BeamSpec b;
  b.length = length;
  b.material = steel();
  b.section.name = "s";
  b.section.A = 0.01;
  b.section.Iz = 0.1 * 0.1 * 0.1 * 0.1 / 12;
  return b;
}

Frame2DSpec portal() {
  Frame2DSpec s;
  s.bays = 2;
  s.stories = 2;
  s.divisions = 3;
  s.span = 4;
  s.height = 3;
  s.material = steel();
  s.column.name = "col";
  s.column.A = 5.38e-3;
  s.column.Iz = 5.7e-5;
  s.beam.name = "beam";
  s.beam.A = 3.91e-3;
  s.beam.Iz = 5.79e-5;
  return s;
}

// Exact modes of `truth` at the translations of the analysis model's nodes.
ModalData exact_modes(const Model& truth, const Model& analysis, int count) {
  EigenOptions eo;
  eo.num_modes = count;
  eo.method = EigenOptions::Method::kDense;
  const ModalResult r = modal_analysis(truth, eo);
  EXPECT_TRUE(r.ok());
  std::vector<MeasuredDof> dofs;
  for (const MeasuredDof& d : dofs_of_types(analysis, kTranslations))
    if (truth.node_index(d.node) >= 0) dofs.push_back(d);
  return sample_modes(truth, r, dofs, 0, count, "exact");
}

// The portal with node 2's base rotation free on a rotational spring of stiffness k (an explicit DOF and spring
// element); bases 1 and 3 stay fixed.
Model portal_on_base_spring(double k) {
  Model m = test::UnsupportedCopy(make_frame2d(portal()));
  m.add_element(test::GroundedSpring(9001, 2, Dof::RZ, k));
  for (int id : {1, 3}) m.restrain(id, kAllDofs);
  m.restrain(2, dof_bit(Dof::UX) | dof_bit(Dof::UY));
  m.finalize();
  return m;
}

// What a discovery concluded, for failure messages (the words are io's).
std::string said(const DiscoverySummary& s) {
  std::string w = std::string(to_string(s.verdict)) + " (" + to_string(s.reason) + ")";
  for (const ScoredHypothesis& h : s.findings) w += "; " + h.finding;
  if (!s.candidates.empty()) w += "; best single: " + s.candidates[0].description;
  return w;
}

const PhysicalValue* value(const ScoredHypothesis& h, const std::string& name) {
  for (const PhysicalValue& v : h.values)
    if (v.name == name) return &v;
  return nullptr;
}

// A column base on a rotational spring: the truth releases the base rotation and adds a grounded spring (an
// explicit DOF); the candidate condenses the released rotation into the column's first element. Same physics,
// so discovery must name it and recover k to the Guyan condensation's accuracy (the released rotation's mass is
// condensed statically: 1 % here).
// The prediction-error level of a hypothesis (engine/src/discovery/fit.cpp, level()): the closed form against a
// direct numerical maximization of its log likelihood, ln L(u) = -(n/2) ln u - chi2/(2u) - (u - 1)/(2a^2) on
// u >= 1 (golden section on ln u; tolerance 1e-6 relative, the search's own resolution is 1e-9); within the noise
// the level is the noise's.
TEST(Discovery, ErrorLevelMaximizesTheLikelihoodWithTheFormErrorPrior) {
  internal::Problem p;
  p.modes = 5;
  p.n = 5 * (1 + 12);
  p.noise.frequency = 1e-4;
  p.noise.shape = 0.03;
  auto numeric = [](double chi2, int n, double a) {
    auto L = [&](double lu) {
      const double u = std::exp(lu);
      return -0.5 * n * lu - 0.5 * chi2 / u - 0.5 * (u - 1) / (a * a);
    };
    double lo = 0, hi = 40;
    const double g = 0.5 * (std::sqrt(5.0) - 1);
    while (hi - lo > 1e-11) {
      const double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      if (L(x1) < L(x2)) lo = x1;
      else hi = x2;
    }
    return std::exp(0.5 * (lo + hi));
  };
  const DiscoveryOptions& o = p.options;
  for (double chi2f : {1e2, 3e4, 1e6, 1e9})
    for (double chi2s : {30.0, 6e2, 5e4}) {
      const internal::ErrorScale s = internal::error_scale(p, chi2f + chi2s, chi2f);
      const double uf = numeric(chi2f, p.modes, o.form_error_frequency / p.noise.frequency);
      const double us = numeric(chi2s, p.n - p.modes, o.form_error_shape / p.noise.shape);
      EXPECT_NEAR(s.frequency * s.frequency, uf, 1e-6 * uf) << chi2f;
      EXPECT_NEAR(s.shape * s.shape, us, 1e-6 * us) << chi2s;
    }
  const internal::ErrorScale within = internal::error_scale(p, 3.0 + 40.0, 3.0);  // below n in each type
  EXPECT_EQ(within.frequency, 1.0);
  EXPECT_EQ(within.shape, 1.0);
}

TEST(Discovery, FlexibleBaseMatchesAnExplicitSpring) {
  const Model analysis = make_frame2d(portal());
  const double k = 6.0e6;
  const Model t2 = portal_on_base_spring(k);
  const ModalData meas = exact_modes(t2, analysis, 6);
  DiscoveryOptions o;
  const DiscoverySummary s = discover(analysis, meas, o);
  ASSERT_EQ(s.verdict, Verdict::kMissingPhysics) << said(s);
  ASSERT_FALSE(s.findings.empty());
  EXPECT_EQ(s.findings[0].kind, "flexible_support") << said(s);
  EXPECT_EQ(s.findings[0].site.nodes, std::vector<int>{2});
  const PhysicalValue* v = value(s.findings[0], "stiffness");
  ASSERT_NE(v, nullptr);
  EXPECT_TRUE(test::RelClose(v->value, k, 0.02)) << v->value;
  EXPECT_LT(s.after.max_freq_error_pct, 0.05 * s.before.max_freq_error_pct);
  EXPECT_EQ(s.findings.size(), 1u) << said(s);
}

// The chi-square tests are omnibus: the flexible base's misfit, spread over six modes at a stated noise that puts
// the frequencies' chi-square at 20 (the 1 - 5e-4 quantile of chi-square with 6 degrees of freedom is 26.1, so the
// tests alone call the model consistent; shapes at 20 % noise, far inside theirs), is removed by one parameter of
// one candidate, whose evidence is decisive (ln B 9.1) and which lowers the frequencies' chi-square by more than
// 2 (decisive + ln K) = 17.5 for the K = 42 candidates fitted (by 20). The data are then not consistent with the model:
// the spring is named. Before, the verdict was "consistent" (dev-326: 90 % damage in one element, chi-square 23.3 for 6
// modes). The bundled frame-null case (cli.discover_frame-null) is the other side: a local candidate there lowers only
// the shapes' chi-square.
TEST(Discovery, OneDecisiveCandidateOutweighsTheOmnibusTest) {
  const Model analysis = make_frame2d(portal());
  const ModalData meas = exact_modes(portal_on_base_spring(6.0e6), analysis, 6);
  EigenOptions eo;
  eo.num_modes = 6;
  eo.method = EigenOptions::Method::kDense;
  const ModalResult nominal = modal_analysis(analysis, eo);
  ASSERT_TRUE(nominal.ok());
  double sum = 0;  // chi-square of the relative frequency errors at unit noise
  for (int k = 0; k < 6; ++k) {
    const double f = nominal.frequencies_hz[k], g = meas.frequencies_hz[k];
    sum += (f - g) * (f - g) / (g * g);
  }
  DiscoveryOptions o;
  o.frequency_noise = std::sqrt(sum / 20.0);
  o.shape_noise = 0.2;
  const DiscoverySummary s = discover(analysis, meas, o);
  ASSERT_LT(s.chi2_frequency_before * 6, 26.1) << "the omnibus test alone must pass here";
  ASSERT_LT(s.chi2_shape_before, 1.0);
  ASSERT_EQ(s.verdict, Verdict::kMissingPhysics) << said(s);
  EXPECT_EQ(s.findings.at(0).kind, "flexible_support") << said(s);
  EXPECT_EQ(s.findings.at(0).site.nodes, std::vector<int>{2}) << said(s);
}

// The same flexible base, stage by stage (engine/src/discovery/stages.hpp): what each stage hands the next. The
// screen's linearised drop must already rank the spring at node 2 first among the local candidates (the data are
// exact, so nothing but the physics orders them), the shortlist must keep it, its own fit must remove nearly all
// the misfit (1e-2 of chi2_0: the truth's released rotation carries mass that the candidate condenses statically),
// and select() must start from it and stop there.
TEST(DiscoveryStages, FlexibleBaseThroughEachStage) {
  const Model analysis = make_frame2d(portal());
  const Model truth = portal_on_base_spring(6.0e6);
  const ModalData meas = exact_modes(truth, analysis, 6);

  internal::Problem p;
  DiscoverySummary S;
  internal::prepare(analysis, meas, DiscoveryOptions{}, {}, &p, &S);
  ASSERT_EQ(p.modes, 6);
  const auto at_node_2 = [](const Candidate& c) {
    return c.kind() == "flexible_support" && c.site().nodes == std::vector<int>{2};
  };

  const Localization L = internal::locate(p);
  ASSERT_FALSE(L.nodes.empty());
  const internal::Screening sc = internal::screen(p);
  EXPECT_GT(sc.chi2, 0.0);
  int best = -1;
  for (int k = 0; k < static_cast<int>(p.library.size()); ++k)
    if (!p.library[k]->global() && (best < 0 || sc.drop[k] > sc.drop[best])) best = k;
  ASSERT_GE(best, 0);
  EXPECT_TRUE(at_node_2(*p.library[best])) << "screen ranks first: " << p.library[best]->description();

  // The base spring can be modelled through either member at node 2; the screen's choice is the one to follow.
  const int spring = best;
  const std::vector<int> list = internal::shortlist(p, sc, L);
  ASSERT_NE(std::find(list.begin(), list.end(), spring), list.end()) << "the shortlist lost the spring at node 2";

  p.n = p.modes * (1 + static_cast<int>(p.data.dofs.size()));
  p.chi2_0 = sc.chi2;
  p.chi2_0_frequency = sc.chi2_frequency;
  std::vector<internal::SetFit> singles;
  for (int k : list) singles.push_back(internal::fit_set(p, {p.library[k].get()}));
  const internal::SetFit* own = nullptr;
  for (const internal::SetFit& f : singles)
    if (f.set[0] == p.library[spring].get()) own = &f;
  ASSERT_NE(own, nullptr);
  ASSERT_TRUE(own->ok);
  EXPECT_LT(own->chi2, 1e-2 * p.chi2_0) << own->chi2 << " of " << p.chi2_0;

  std::vector<char> forced(sc.paired.size());
  for (std::size_t k = 0; k < sc.paired.size(); ++k) forced[k] = !sc.paired[k];
  const internal::Selection sel =
      internal::select(p, singles, internal::quality_of(p, sc.model_hz, sc.mac, sc.chi2, forced));
  ASSERT_EQ(sel.fit.set.size(), 1u);
  EXPECT_TRUE(at_node_2(*sel.fit.set[0])) << sel.fit.set[0]->description();
  ASSERT_FALSE(sel.steps.empty());
  EXPECT_EQ(sel.steps[0].action, SelectionStep::Action::kStart);
  EXPECT_EQ(sel.importance.size(), 1u);
}

// An effect fitted to nothing is never a finding. The portal's base is flexible (the misfit far above the
// default noise); a global candidate is given the fit of finding nothing: its parameters at their nominal values,
// the misfit the model's own. Its evidence still passes `decisive` (the model as given is scored at the noise alone,
// while this fit is scored at its misfit's level), which once let such fits stand as lone findings (dev split:
// self weight at load factor 0 +- 8, chi2 100.9 -> 100.9). The likelihood ratio against the model as given is 0,
// so the selection must leave it out. Exact comparisons: the rule's inputs are set, not computed.
TEST(DiscoveryStages, AnEffectFittedToNothingIsNoFinding) {
  const Model analysis = make_frame2d(portal());
  const ModalData meas = exact_modes(portal_on_base_spring(6.0e6), analysis, 6);
  internal::Problem p;
  DiscoverySummary S;
  internal::prepare(analysis, meas, DiscoveryOptions{}, {}, &p, &S);
  const internal::Screening sc = internal::screen(p);
  p.n = p.modes * (1 + static_cast<int>(p.data.dofs.size()));
  p.chi2_0 = sc.chi2;
  p.chi2_0_frequency = sc.chi2_frequency;
  ASSERT_GT(p.chi2_0_frequency, 10.0 * p.modes);
  std::vector<char> forced(sc.paired.size());
  for (std::size_t k = 0; k < sc.paired.size(); ++k) forced[k] = !sc.paired[k];
  const FitQuality before = internal::quality_of(p, sc.model_hz, sc.mac, sc.chi2, forced);

  int tested = 0;
  for (const auto& c : p.library) {
    if (!c->global()) continue;
    internal::SetFit f = internal::fit_set(p, {c.get()});
    if (!f.ok || f.at_bound) continue;
    for (std::size_t q = 0; q < c->parameters().size(); ++q)
      f.theta[0][static_cast<Eigen::Index>(q)] = c->parameters()[q].nominal;
    f.chi2 = p.chi2_0;
    f.chi2_frequency = p.chi2_0_frequency;
    f.quality = before;
    if (internal::log_evidence(p, f) < p.options.decisive) continue;  // the old rule would have refused it too
    ++tested;
    const internal::Selection sel = internal::select(p, {f}, before);
    EXPECT_TRUE(sel.fit.set.empty()) << c->description() << " stood as a finding with its parameters at nominal";
  }
  EXPECT_GT(tested, 0) << "no global candidate's nothing-fit passed the evidence test: the case does not test the rule";
}

// The findings' probability among the explanations (internal::story_odds), against hand-computed odds: with
// findings at ln evidence 10, an equivalent site at 10 counts for them, a same-kind site elsewhere at 9 only for
// their kinds, another physics at three sites (10, 10.2, 10) and the recalibration at 8 against. Exact arithmetic
// (1e-12).
TEST(DiscoveryStages, StoryOddsSumAPhysicsOverItsSites) {
  using R = internal::StoryOdds::Relation;
  const std::vector<std::string> spring = {"spring"}, preload = {"preload"};
  std::vector<internal::StoryOdds::Entry> e = {{R::kSameStory, 10, preload}, {R::kSameKinds, 9, preload},
                                               {R::kOther, 10, spring},      {R::kOther, 10.2, spring},
                                               {R::kOther, 10, spring},      {R::kOther, 8, {}}};
  const double same = 1, kind = std::exp(-1.0), sp = 2 + std::exp(0.2), rec = std::exp(-2.0);
  const double total = 1 + same + kind + sp + rec + std::exp(-10.0);
  internal::StoryOdds o = internal::story_odds(10, e);
  EXPECT_NEAR(o.probability, (1 + same) / total, 1e-12);
  EXPECT_NEAR(o.kind_probability, (1 + same + kind) / total, 1e-12);
  EXPECT_EQ(o.other, 3);  // the spring's best site
  EXPECT_NEAR(o.other_probability, sp / total, 1e-12);
  EXPECT_LT(o.kind_probability, 0.5);   // the findings' physics is not the most probable story ...
  EXPECT_GT(o.other_probability, 0.5);  // ... the spring, over its three sites, is: discover() names it
  // A same-kind site more probable than the findings' own: their kinds' probability is their site's.
  e[1].log_evidence = 10.5;
  o = internal::story_odds(10, e);
  EXPECT_NEAR(o.kind_probability, o.probability, 1e-15);
  // The recalibration is no physics: never the other story, however probable.
  e = {{R::kOther, 12, {}}, {R::kOther, 9, spring}};
  o = internal::story_odds(10, e);
  EXPECT_EQ(o.other, 1);
  EXPECT_NEAR(o.other_probability, std::exp(-1.0) / (1 + std::exp(2.0) + std::exp(-1.0) + std::exp(-10.0)), 1e-12);
}

// Nothing missing: the data are the analysis model's own modes.
TEST(Discovery, ExactDataOfTheModelIsConsistent) {
  const Model analysis = make_frame2d(portal());
  const ModalData meas = exact_modes(analysis, analysis, 6);
  const DiscoverySummary s = discover(analysis, meas, DiscoveryOptions{});
  EXPECT_EQ(s.verdict, Verdict::kConsistent) << said(s);
  EXPECT_TRUE(s.findings.empty());
  EXPECT_LT(s.before.max_freq_error_pct, 1e-6);
}

// Repeated modes: a frame square in plan, every section alike about both axes, sways in x and in y at one
// frequency, and any orthonormal pair in their plane is as much a pair of its modes as the one the solver returns.
// Identified data whose pairs are turned by 30 degrees within their plane are the model's own modes: consistent.
// The noise model weighs a misfit along a neighbour's shape by how far the neighbour lies in frequency against the
// identified frequency's uncertainty (docs/method.md, "Closely spaced modes"); without it the turned pairs (MAC 0.93
// with the partners of discover's own solve, whose basis in each plane is its own) made the verdict inconclusive.
TEST(Discovery, TurnedRepeatedPairsAreTheModelsOwnModes) {
  Frame3DSpec spec = test::SteelFrame3D(1, 1, 2);
  spec.span_y = spec.span_x;
  spec.column.Iy = spec.column.Iz = 1e-5;
  spec.beam.Iy = spec.beam.Iz = 7e-6;
  const Model m = make_frame3d(spec);
  EigenOptions eo;
  eo.num_modes = 8;
  eo.method = EigenOptions::Method::kDense;
  ModalResult r = modal_analysis(m, eo);
  ASSERT_TRUE(r.ok());
  int turned = 0;
  const double c = std::cos(M_PI / 6), sn = std::sin(M_PI / 6);
  for (Eigen::Index j = 0; j + 1 < r.frequencies_hz.size(); ++j)
    if (std::abs(r.frequencies_hz[j + 1] - r.frequencies_hz[j]) < 1e-8 * r.frequencies_hz[j]) {
      const Eigen::VectorXd a = r.modes.col(j), b = r.modes.col(j + 1);
      r.modes.col(j) = c * a + sn * b;
      r.modes.col(j + 1) = -sn * a + c * b;
      ++turned;
      ++j;
    }
  ASSERT_GE(turned, 2);  // the first sways of both stories
  ModalData meas = sample_modes(m, r, dofs_of_types(m, kTranslations), 0, 8, "turned");
  meas.frequency_std_hz = 0.005 * meas.frequencies_hz;  // as an identification states them
  meas.shape_std = Eigen::VectorXd::Constant(8, 0.03);
  const DiscoverySummary s = discover(m, meas, DiscoveryOptions{});
  ASSERT_EQ(s.noise.frequency_source, NoiseModel::Source::kData);
  EXPECT_EQ(s.verdict, Verdict::kConsistent) << said(s);
  EXPECT_LT(s.before.mac.minCoeff(), 0.95);  // the turn is seen: a pair's MAC with its partner
  // Each turned mode's partner has a neighbour within the frequency's uncertainty (share 1), said in a warning.
  ASSERT_EQ(s.noise.neighbour_mixing.size(), 8);
  EXPECT_EQ((s.noise.neighbour_mixing.array() == 1.0).count(), 2 * turned);
  EXPECT_EQ(std::count_if(s.warnings.begin(), s.warnings.end(),
                          [](const std::string& w) { return w.find("closely spaced modes") != std::string::npos; }),
            2 * turned);
}

// Two model modes within each other's half-power band (here 0.5 % apart at 1 % damping) may come out of an
// identification as one estimate: its frequency between the two, its shape mostly one's, and the other mode left
// without a measured partner. That is the model's own pair, not missing physics: the estimate's frequency std
// gains the pull toward the unpartnered neighbour (noise.unresolved) and its shape is compared with their
// mixtures. At 0.1 % damping (a test that resolves the 0.5 % spacing: delta > 2 zeta) the same 0.3 % offset at a
// 0.03 % std is evidence, and the model as given is not consistent.
TEST(Discovery, PairMergedByTheIdentificationIsTheModelsOwn) {
  Frame3DSpec spec = test::SteelFrame3D(1, 1, 2);
  spec.span_y = spec.span_x;
  spec.column.Iy = 1e-5;
  spec.column.Iz = 1.02e-5;  // the sways in x and y 0.5 % apart
  spec.beam.Iy = spec.beam.Iz = 7e-6;
  const Model m = make_frame3d(spec);
  EigenOptions eo;
  eo.num_modes = 8;
  eo.method = EigenOptions::Method::kDense;
  const ModalResult r = modal_analysis(m, eo);
  ASSERT_TRUE(r.ok());
  const double delta = (r.frequencies_hz[1] - r.frequencies_hz[0]) / r.frequencies_hz[0];
  ASSERT_GT(delta, 0.004);
  ASSERT_LT(delta, 0.015);
  ModalData all = sample_modes(m, r, dofs_of_types(m, kTranslations), 0, 8, "merged");
  std::vector<int> keep = {0};  // the first pair merged into one estimate: mode 2 is not identified
  for (int k = 2; k < 8; ++k) keep.push_back(k);
  ModalData meas = modes_subset(all, keep);
  meas.frequencies_hz[0] += 0.6 * (r.frequencies_hz[1] - r.frequencies_hz[0]);
  meas.frequency_std_hz = 0.0003 * meas.frequencies_hz;
  meas.shape_std = Eigen::VectorXd::Constant(7, 0.03);
  meas.damping_ratios = Eigen::VectorXd::Constant(7, 0.01);
  const DiscoverySummary s = discover(m, meas, DiscoveryOptions{});
  ASSERT_EQ(s.noise.frequency_source, NoiseModel::Source::kData);
  EXPECT_EQ(s.verdict, Verdict::kConsistent) << said(s);
  ASSERT_EQ(s.noise.unresolved.size(), 7);
  EXPECT_GT(s.noise.unresolved[0], 0.5 * delta);          // the pull s^2 delta, s = min(1, 0.01 / delta) = 1
  EXPECT_EQ(s.noise.unresolved.tail(6).maxCoeff(), 0.0);  // the other modes' neighbours all have partners
  meas.damping_ratios = Eigen::VectorXd::Constant(7, 0.001);
  const DiscoverySummary fine = discover(m, meas, DiscoveryOptions{});
  EXPECT_NE(fine.verdict, Verdict::kConsistent) << said(fine);
  EXPECT_EQ(fine.noise.unresolved.maxCoeff(), 0.0);
}

// One paired mode is a test, not an explanation: the model's own first mode is consistent; a base on a spring
// soft enough to lower that mode by several percent (far beyond the 1 % stated noise) is inconclusive, never a
// named physics (any one-parameter candidate matches one frequency). Both say why in a warning.
TEST(Discovery, OneModeTestsButNamesNothing) {
  const Model analysis = make_frame2d(portal());
  DiscoveryOptions o;
  o.frequency_noise = 0.01;
  o.shape_noise = 0.03;
  const DiscoverySummary same = discover(analysis, exact_modes(analysis, analysis, 1), o);
  EXPECT_EQ(same.verdict, Verdict::kConsistent) << said(same);
  const Model soft = portal_on_base_spring(2e5);
  const ModalData meas = exact_modes(soft, analysis, 1);
  ASSERT_LT(meas.frequencies_hz[0], 0.95 * same.before.measured_hz[0]);  // the test means something
  const DiscoverySummary d = discover(analysis, meas, o);
  EXPECT_EQ(d.verdict, Verdict::kInconclusive) << said(d);
  EXPECT_TRUE(d.findings.empty());
  EXPECT_NE(discovery_explanation(d).find("from one measured mode no physics can be named"), std::string::npos)
      << discovery_explanation(d);
  for (const DiscoverySummary* x : {&same, &d}) {
    bool warned = false;
    for (const std::string& w : x->warnings) warned = warned || w.find("only one measured mode") != std::string::npos;
    EXPECT_TRUE(warned);
  }
}

// A free-free beam (2 m, 100 elements) hung on two vertical springs one element (1 % of its length) in from the
// ends: the truth. Its bounce and pitch modes and four elastic ones are the data; the analysis model's suspension
// candidate holds the end nodes. The elastic modes feel a spring through the motion of the point it holds, at the
// first mode (1 - 4.65 x 0.01)^2 = 0.91 of the end's, so from them alone the stiffness comes out low (0.936 of the
// truth's before the refit existed); bounce measures it exactly and pitch within (1 - 2 x 0.01)^2 = 0.96. Refitted
// with the rigid-body modes it is within 3 % (0.983), and the findings predict both rigid-body modes within 2 %
// (the pitch frequency's bias, sqrt(0.96) = 0.98, at most).
TEST(Discovery, SuspensionStiffnessIsFittedWithTheRigidBodyModes) {
  BeamSpec b = square_steel_beam(2.0);
  b.elements = 100;
  const Model analysis = make_beam(b);
  ASSERT_TRUE(analysis.free_free());
  const double k = 2.2e6;  // bounce near 0.2 of the first elastic frequency (133 Hz)
  Model truth = test::UnsupportedCopy(analysis);
  truth.add_element(test::GroundedSpring(9001, 2, Dof::UY, k));
  truth.add_element(test::GroundedSpring(9002, 100, Dof::UY, k));
  truth.finalize();
  const ModalData meas = exact_modes(truth, analysis, 6);
  DiscoveryOptions o;
  o.frequency_noise = 0.005;
  o.shape_noise = 0.02;
  const DiscoverySummary s = discover(analysis, meas, o);
  ASSERT_EQ(s.verdict, Verdict::kMissingPhysics) << said(s);
  ASSERT_EQ(s.findings[0].kind, "suspension_stiffness") << said(s);
  const PhysicalValue* v = value(s.findings[0], "stiffness per point");
  ASSERT_NE(v, nullptr);
  EXPECT_NEAR(v->value / k, 1.0, 0.03) << said(s);
  std::printf("stiffness per point %.4f of the truth's\n", v->value / k);
  int rigid = 0;
  for (const SetAside& a : s.set_aside) {
    if (a.reason != SetAside::Reason::kRigidBody) continue;
    ++rigid;
    EXPECT_TRUE(a.paired_after);
    EXPECT_NEAR(a.model_hz_after / a.frequency_hz, 1.0, 0.02);
  }
  EXPECT_EQ(rigid, 2);
}

// Sites the data cannot tell apart carry their own values. A simply supported beam braced by a spring at node 8,
// measured in four modes at five nodes that are not its neighbours: the spring at node 7 or 9 predicts the same
// data with another stiffness. Each equivalent site's value is checked by a second method: an explicit spring
// element of that stiffness at that node gives the measured first frequency to 0.5 % (the stated frequency
// noise: the site's fit weighs all four modes and the shapes, so its first frequency may sit anywhere within the
// noise); and the values are not the finding's (a node at the mirror position, 14 for 8, has nearly its value).
TEST(Discovery, EquivalentSitesCarryTheirOwnValues) {
  BeamSpec b = square_steel_beam(2.0);
  b.elements = 20;
  b.support = BeamSupport::SimplySupported;
  const Model analysis = make_beam(b);
  const double k = 2.5e6;  // raises the first mode (58.6 Hz unbraced) by several per cent
  auto braced = [&](int node, double stiffness) {
    Model m = test::UnsupportedCopy(analysis);
    m.add_element(test::GroundedSpring(9001, node, Dof::UY, stiffness));
    for (int id : {1, 21}) m.restrain(id, dof_bit(Dof::UY));  // make_beam's simple supports
    m.finalize();
    return m;
  };
  const Model truth = braced(8, k);
  EigenOptions eo;
  eo.num_modes = 4;
  eo.method = EigenOptions::Method::kDense;
  const ModalResult r = modal_analysis(truth, eo);
  ASSERT_TRUE(r.ok());
  std::vector<MeasuredDof> dofs;
  for (int id : {3, 5, 11, 15, 19}) dofs.push_back({id, Dof::UY});
  const ModalData meas = sample_modes(truth, r, dofs, 0, 4, "exact");
  DiscoveryOptions o;
  o.frequency_noise = 0.005;
  o.shape_noise = 0.03;
  const DiscoverySummary s = discover(analysis, meas, o);
  ASSERT_EQ(s.verdict, Verdict::kMissingPhysics) << said(s);
  const ScoredHypothesis& h = s.findings[0];
  ASSERT_EQ(h.kind, "grounded_spring") << said(s);
  ASSERT_FALSE(h.equivalent.empty()) << said(s);
  ASSERT_EQ(h.equivalent_values.size(), h.equivalent.size());
  ASSERT_EQ(h.site.nodes.size(), h.equivalent.size() + 1);  // one node per spring site, its own first
  const double first = value(h, "stiffness")->value;
  double spread = 0;
  for (std::size_t q = 0; q < h.equivalent.size(); ++q) {
    ASSERT_EQ(h.equivalent_values[q].size(), 1u);
    const PhysicalValue& v = h.equivalent_values[q][0];
    EXPECT_EQ(v.name, "stiffness");
    EXPECT_TRUE(v.value > 0 && std::isfinite(v.std) && v.std > 0) << v.value << " " << v.std;
    const int node = h.site.nodes[q + 1];
    EXPECT_NE(h.equivalent[q].find("node " + std::to_string(node)), std::string::npos) << h.equivalent[q];
    const ModalResult e = modal_analysis(braced(node, v.value), eo);
    ASSERT_TRUE(e.ok());
    const double f1 = std::sqrt(e.eigenvalues[0]) / (2 * M_PI);
    EXPECT_NEAR(f1 / meas.frequencies_hz[0], 1.0, o.frequency_noise) << "node " << node << ": " << v.value;
    spread = std::max(spread, std::abs(v.value / first - 1));
    std::printf("node %d: %.4g N/m (first site, node %d: %.4g)\n", node, v.value, h.site.nodes[0], first);
  }
  EXPECT_GT(spread, 0.2);  // the first site's value does not hold for the others (here 2.0e6 to 5.7e6 N/m)
}

// What the localization's alignment measures: |cos| between each measured mode's residual force and its inertia
// force on the SEREP-reduced model. A change in proportion everywhere (E x 0.95, or rho x 1.05) leaves the shapes
// as they are, so the residual (K - lambda M) u = (lambda_model - lambda) M u is the inertia force itself: 1 to
// rounding (1e-9), whether stiffness or mass changed. A local change of either nature (a point mass at one node,
// one element at half its E) puts the residual where the change is: far from 1 (below 0.9; 0.32 and 0.19 here).
// The number tells proportional from local, not mass from stiffness (the words say so).
TEST(Discovery, AlignmentWithInertiaForcesTellsProportionalFromLocal) {
  const Model analysis = make_frame2d(portal());
  auto alignment = [&](const Model& truth) {
    DiscoveryOptions o;
    o.frequency_noise = 0.005;
    o.shape_noise = 0.02;
    return discover(analysis, exact_modes(truth, analysis, 6), o).localization.mass_alignment;
  };
  auto scaled = [&](double e, double rho) {  // the portal's materials scaled; its bases 1-3 clamped as built
    Model out;
    for (Material x : analysis.materials()) {
      x.E *= e;
      x.rho *= rho;
      out.add_material(x);
    }
    for (const Section& x : analysis.sections()) out.add_section(x);
    for (const Node& n : analysis.nodes()) out.add_node(n.id, n.x);
    for (const Element& x : analysis.elements()) out.add_element(x);
    for (int id : {1, 2, 3}) out.restrain(id, kAllDofs);
    out.finalize();
    return out;
  };
  const double stiffness = alignment(scaled(0.95, 1.0)), mass = alignment(scaled(1.0, 1.05));
  EXPECT_NEAR(stiffness, 1.0, 1e-9);
  EXPECT_NEAR(mass, 1.0, 1e-9);
  Model point = test::UnsupportedCopy(analysis);
  point.add_element(test::PointMass(9001, 8, 40));
  for (int id : {1, 2, 3}) point.restrain(id, kAllDofs);
  point.finalize();
  const double local_mass = alignment(point);
  Model damaged = test::UnsupportedCopy(analysis);
  for (int id : {1, 2, 3}) damaged.restrain(id, kAllDofs);
  damaged.finalize();
  damaged.element(damaged.element_index(analysis.elements()[0].id)).factors.E = 0.5;  // a column's base element
  const double local_stiffness = alignment(damaged);
  std::printf("alignment: E x 0.95 %.12f, rho x 1.05 %.12f, point mass %.3f, one element softer %.3f\n", stiffness,
              mass, local_mass, local_stiffness);
  EXPECT_LT(local_mass, 0.9);
  EXPECT_LT(local_stiffness, 0.9);
}

// Noise taken from the data is floored (split-data estimates see no identification bias); stated noise is kept
// as stated. Exact values: the floors are the DiscoveryOptions defaults, compared exactly.
TEST(Discovery, DataNoiseIsFlooredStatedNoiseIsKept) {
  const Model analysis = make_frame2d(portal());
  ModalData meas = exact_modes(analysis, analysis, 6);
  meas.frequency_std_hz = meas.frequencies_hz * 1e-6;
  meas.shape_std = Eigen::VectorXd::Constant(6, 1e-4);
  const DiscoveryOptions o;
  const DiscoverySummary d = discover(analysis, meas, o);
  EXPECT_EQ(d.noise.frequency_source, NoiseModel::Source::kData);
  EXPECT_EQ(d.noise.frequency, o.min_data_frequency_noise);
  EXPECT_EQ(d.noise.shape, o.min_data_shape_noise);
  DiscoveryOptions stated;
  stated.frequency_noise = 1e-6;
  stated.shape_noise = 1e-4;
  const DiscoverySummary t = discover(analysis, meas, stated);
  EXPECT_EQ(t.noise.frequency_source, NoiseModel::Source::kStated);
  EXPECT_EQ(t.noise.frequency, 1e-6);
  EXPECT_EQ(t.noise.shape, 1e-4);
  EXPECT_EQ(d.verdict, Verdict::kConsistent) << said(d);
}

// An identified mode with a complex shape is a mixture: its out-of-phase energy c (B/A, from MPC = ((A - B)/(A +
// B))^2) adds zeta sqrt(c) to its frequency's relative std, in quadrature; its shape noise and a real shape's
// (MPC 1) frequency noise stay as they were. The shape is built with a known c (in-phase a, out-of-phase b
// orthogonal to a, |b|^2 = c |a|^2) and its MPC taken as identification takes it (modal_phase_collinearity), so
// the test checks the inversion of the MPC too: 1e-12 relative (closed forms, rounding only).
TEST(Discovery, ComplexShapesWidenTheirFrequencyNoise) {
  const int n = 6;
  Eigen::VectorXd a(n), b(n);
  a << 1.0, 0.8, -0.5, 0.3, -0.9, 0.2;
  b << 0.3, -0.2, 0.1, 0.4, 0.0, 0.5;
  b -= a * (a.dot(b) / a.squaredNorm());
  const double c = 0.02;
  b *= std::sqrt(c) * a.norm() / b.norm();
  const Eigen::VectorXcd v = a.cast<std::complex<double>>() + std::complex<double>(0, 1) * b.cast<std::complex<double>>();
  ModalData d;
  for (int k = 0; k < n; ++k) d.dofs.push_back({k + 1, Dof::UX});
  d.frequencies_hz = Eigen::Vector2d(10.0, 20.0);
  d.shapes.resize(n, 2);
  d.shapes.col(0) = a;
  d.shapes.col(1) = a * 2.5;
  d.damping_ratios = Eigen::Vector2d(0.01, 0.03);
  d.mpc = Eigen::Vector2d(1.0, modal_phase_collinearity(v));
  NoiseModel nm;
  nm.frequency = 1e-3;
  nm.shape = 0.02;
  internal::add_contamination(d, &nm);
  ASSERT_EQ(nm.frequency_modes.size(), 2);
  EXPECT_EQ(nm.frequency_modes[0], 1e-3);
  EXPECT_EQ(nm.shape_modes.size(), 0);  // the shapes keep their noise (see add_contamination)
  EXPECT_EQ(nm.shape, 0.02);
  EXPECT_NEAR(nm.frequency_modes[1], std::hypot(1e-3, 0.03 * std::sqrt(c)), 1e-12 * nm.frequency_modes[1]);
  NoiseModel none;  // data without MPC: unchanged
  none.frequency = 1e-3;
  d.mpc.resize(0);
  internal::add_contamination(d, &none);
  EXPECT_EQ(none.frequency_modes.size(), 0);
}

}  // namespace
}  // namespace dynid

namespace dynid {
namespace {

// Eigenvalues of the analysis model with one candidate installed at theta (its own parameters).
Eigen::VectorXd eigen_with(const Model& m, const Candidate& c, const Eigen::VectorXd& theta, int count) {
  ParametricModel pm(m);
  install_candidates(&pm, {&c});
  SparseMatrix K, M;
  pm.matrices(theta, &K, &M);
  const Eigen::MatrixXd Kd(K), Md(M);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Kd, Md);
  return es.eigenvalues().head(count);
}

// Every kind of candidate: eigenvalue derivatives from its terms' derivatives (complex step, analytic) against
// central differences of its eigenvalues. Step 1e-4 of the parameter: truncation ~1e-8 relative; the dense
// solver's rounding (~1e-12 of lambda) over 2e-4 stays below 1e-7 of lambda even for parameters whose unit
// effect is small (a mass of 0.2 % of the structure's moves lambda_1 by 1e-4 of itself).
TEST(Discovery, CandidateDerivativesMatchFiniteDifferences) {
  Frame2DSpec s = portal();
  s.divisions = 2;
  const Model m = make_frame2d(s);
  const ModalData meas = exact_modes(m, m, 4);
  const auto lib = candidate_library(m, meas, DiscoveryOptions{});
  std::set<std::string> seen;
  for (const auto& c : lib) {
    if (!seen.insert(c->kind()).second) continue;
    const std::vector<CandidateParameter> ps = c->parameters();
    Eigen::VectorXd th(static_cast<Eigen::Index>(ps.size()));
    for (std::size_t q = 0; q < ps.size(); ++q) th[static_cast<Eigen::Index>(q)] = ps[q].nominal + 0.2;
    ParametricModel pm(m);
    install_candidates(&pm, {c.get()});
    SparseMatrix K, M;
    pm.matrices(th, &K, &M);
    const Eigen::MatrixXd Kd(K), Md(M);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Kd, Md);
    const Eigen::VectorXd lam = es.eigenvalues().head(4);
    const Eigen::MatrixXd Phi = es.eigenvectors().leftCols(4);
    const Eigen::MatrixXd S = pm.eigenvalue_sensitivities(th, lam, Phi);
    for (Eigen::Index q = 0; q < th.size(); ++q) {
      const double h = 1e-4;
      Eigen::VectorXd tp = th, tm = th;
      tp[q] += h;
      tm[q] -= h;
      const Eigen::VectorXd fd = (eigen_with(m, *c, tp, 4) - eigen_with(m, *c, tm, 4)) / (2 * h);
      EXPECT_LT((fd - S.col(q)).norm(), 1e-5 * std::max(fd.norm(), 1e-6 * lam.norm())) << c->kind() << " parameter " << q;
    }
  }
  EXPECT_GE(seen.size(), 13u);  // lumped mass, mass on an element, spring, release (support and joint), element
                                // E and rho, member damage, shear, preload, self-weight, distributed mass, sensor mass
}

// The units (prior medians) of springs, supports and preloads are physical, never the mesh's: the same on a
// beam meshed with 8 and with 32 elements, and equal to closed forms. Data: each model's own first 4 modes.
// - a spring at a cantilever's tip: 1 / sum_r phi_r^2 / omega_r^2 over the 4 modes = 3 E I / L^3 / 0.99950 (modes
//   5 and up hold 0.05 % of the static tip flexibility: 4 L^3 / (beta_r^4 E I) each, beta_r L the cantilever's
//   roots); tolerance 0.3 %, the 8-element mesh's error in the 4th mode's flexibility share;
// - the support's rotational spring at the prior's median: the member's 4 E I / L (not the element's 4 E I / l);
// - a preload in a simply supported beam: P_E / (1 + 1/4 + 1/9 + 1/16), each mode's eigenvalue moving by
//   P / (r^2 P_E); tolerance 0.3 %, as for the spring.
// Before, the spring's unit was K_ii (64 times larger on the finer mesh) and the support's 4 E I / l.
TEST(Discovery, CandidateUnitsComeFromTheBandNotTheMesh) {
  BeamSpec b = square_steel_beam(2.0);
  const double EI = b.material.E * b.section.Iz, L = b.length;
  const double euler = M_PI * M_PI * EI / (L * L);
  for (int elements : {8, 32}) {
    b.elements = elements;
    for (BeamSupport support : {BeamSupport::Cantilever, BeamSupport::SimplySupported}) {
      b.support = support;
      const Model m = make_beam(b);
      const ModalData meas = exact_modes(m, m, 4);
      int checked = 0;
      for (const auto& c : candidate_library(m, meas, DiscoveryOptions{})) {
        const CandidateParameter q = c->parameters()[0];
        auto value = [&](double th) {
          return c->physical(Eigen::VectorXd::Constant(1, th), Eigen::VectorXd::Zero(1))[0].value;
        };
        const Site site = c->site();
        if (support == BeamSupport::Cantilever && c->kind() == "grounded_spring" &&
            site.nodes == std::vector<int>{elements + 1}) {
          EXPECT_NEAR(value(1.0) / (3 * EI / (L * L * L) / 0.99950), 1.0, 3e-3) << elements << " elements";
          ++checked;
        } else if (support == BeamSupport::Cantilever && c->kind() == "flexible_support" &&
                   c->description().find("rz") != std::string::npos) {
          EXPECT_NEAR(value(q.prior_scale) / (4 * EI / L), 1.0, 1e-9) << elements << " elements";
          ++checked;
        } else if (support == BeamSupport::SimplySupported && c->kind() == "axial_preload") {
          EXPECT_NEAR(value(1.0) / (euler / (1 + 1 / 4.0 + 1 / 9.0 + 1 / 16.0)), 1.0, 3e-3) << elements << " elements";
          EXPECT_NEAR(q.lower, -0.9 * (1 + 1 / 4.0 + 1 / 9.0 + 1 / 16.0), 3e-3) << "compression stops at 0.9 P_E";
          ++checked;
        }
      }
      EXPECT_EQ(checked, support == BeamSupport::Cantilever ? 2 : 1) << elements << " elements";
    }
  }
}

// The Timoshenko candidate at alpha = 1/kappa against the element kernel's shear-deformable beam (an independent
// implementation: the kernel builds the matrix from phi directly), and the preload candidate against elements
// with an axial force: identical matrices, so identical eigenvalues (to rounding). alpha = 3 (kappa = 1/3, a
// thin-walled section) puts the candidate's rotary-inertia weight 1 - exp(-(3/0.45)^2) at 1 to 1e-19.
TEST(Discovery, ShearAndPreloadCandidatesMatchTheElementKernels) {
  BeamSpec b;
  b.length = 2.0;
  b.elements = 8;
  b.material = steel();
  b.section.name = "s";
  b.section.A = 0.04;
  b.section.Iz = 0.04 * 0.4 * 0.4 / 12;
  b.support = BeamSupport::SimplySupported;
  const Model m = make_beam(b);
  const ModalData meas = exact_modes(m, m, 3);
  BeamSpec bt = b;
  bt.section.shear_factor = 1.0 / 3.0;
  Model shear = make_beam(bt);
  Model tmp = shear;  // rotary inertia on
  Model t2;
  for (const Node& n : tmp.nodes()) t2.add_node(n.id, n.x);
  for (const Material& x : tmp.materials()) t2.add_material(x);
  for (const Section& x : tmp.sections()) t2.add_section(x);
  for (const Element& e : tmp.elements()) t2.add_element(e);
  t2.restrain(1, dof_bit(Dof::UY));
  t2.restrain(9, dof_bit(Dof::UY));
  t2.set_rotary_inertia(true);
  t2.finalize();
  Model pre;
  for (const Node& n : m.nodes()) pre.add_node(n.id, n.x);
  for (const Material& x : m.materials()) pre.add_material(x);
  for (const Section& x : m.sections()) pre.add_section(x);
  for (Element e : m.elements()) {
    e.axial_force = 2.0e6;
    pre.add_element(e);
  }
  pre.restrain(1, dof_bit(Dof::UY));
  pre.restrain(9, dof_bit(Dof::UY));
  pre.finalize();
  const auto lib = candidate_library(m, meas, DiscoveryOptions{});
  int checked = 0;
  for (const auto& c : lib) {
    Eigen::VectorXd th(1);
    const Model* ref = nullptr;
    if (c->kind() == "shear_deformation") {
      th[0] = 3.0;  // 1 / kappa
      ref = &t2;
    } else if (c->kind() == "axial_preload") {
      // The candidate's unit is its own (the band's, CandidateUnitsComeFromTheBandNotTheMesh): read it back.
      th[0] = 2.0e6 / c->physical(Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1))[0].value;
      ref = &pre;
    } else {
      continue;
    }
    EigenOptions eo;
    eo.num_modes = 5;
    eo.method = EigenOptions::Method::kDense;
    const Eigen::VectorXd want = modal_analysis(*ref, eo).eigenvalues;
    const Eigen::VectorXd got = eigen_with(m, *c, th, 5);
    EXPECT_LT(((got - want).array() / want.array()).abs().maxCoeff(), 1e-10) << c->kind();
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

// The same on a space frame (1 x 1 bay, 2 stories, members in 2 elements, sections with Iy != Iz): the candidate
// bends each member in both of its planes (local x-y about Iz, x-z about Iy, one kappa) and must give the kernel's
// frame3d Timoshenko members with rotary inertia at alpha = 3, to rounding (1e-10 relative).
TEST(Discovery, ShearCandidateMatchesTheKernelOnASpaceFrame) {
  const Model m = make_frame3d(test::SteelFrame3D(1, 1, 2));
  Model t = [&] {
    Model x;
    for (const Material& y : m.materials()) x.add_material(y);
    for (Section y : m.sections()) {
      y.shear_factor = 1.0 / 3.0;
      x.add_section(y);
    }
    for (const Node& n : m.nodes()) x.add_node(n.id, n.x);
    for (const Element& e : m.elements()) x.add_element(e);
    for (int n = 0; n < static_cast<int>(m.nodes().size()); ++n)
      if (m.dof_map().restrained(n)) x.restrain(m.nodes()[n].id, m.dof_map().restrained(n));
    x.set_rotary_inertia(true);
    x.finalize();
    return x;
  }();
  int found = 0;
  for (const auto& c : candidate_library(m, exact_modes(m, m, 6), DiscoveryOptions{})) {
    if (c->kind() != "shear_deformation") continue;
    ++found;
    EigenOptions eo;
    eo.num_modes = 8;
    eo.method = EigenOptions::Method::kDense;
    const Eigen::VectorXd want = modal_analysis(t, eo).eigenvalues, plain = modal_analysis(m, eo).eigenvalues;
    const Eigen::VectorXd got = eigen_with(m, *c, Eigen::VectorXd::Constant(1, 3.0), 8);
    ASSERT_GT(((plain - want).array() / want.array()).abs().maxCoeff(), 1e-3);  // shear matters here
    EXPECT_LT(((got - want).array() / want.array()).abs().maxCoeff(), 1e-10);
    const CandidateCheck r = check_candidate(m, *c);
    EXPECT_TRUE(r.ok()) << r.report();
  }
  EXPECT_EQ(found, 1);
}

}  // namespace
}  // namespace dynid

namespace dynid {
namespace {

// Every built-in kind, placed on a plane frame (and a free-free beam for the suspension), passes the invariants
// a candidate must satisfy (check_candidate: nominal = the model, derivatives = central differences, bounds).
TEST(Candidates, EveryKindSatisfiesTheInvariants) {
  Frame2DSpec s = portal();
  s.divisions = 2;
  const Model m = make_frame2d(s);
  const ModalData meas = exact_modes(m, m, 4);
  std::set<std::string> seen;
  for (const auto& c : candidate_library(m, meas, DiscoveryOptions{})) {
    if (!seen.insert(c->kind()).second) continue;
    const CandidateCheck r = check_candidate(m, *c);
    EXPECT_TRUE(r.ok()) << r.report();
  }
  EXPECT_GE(seen.size(), 13u);
}

// A semi-rigid joint is where members meet: on the portal (members in 3 elements each) its candidates sit at the
// six joints above the bases and never at a node inside a member, where a hinge would be member damage.
TEST(Candidates, SemiRigidJointsOnlyWhereMembersMeet) {
  const Model m = make_frame2d(portal());
  const ModalData meas = exact_modes(m, m, 4);
  std::set<int> at;
  for (const auto& c : candidate_library(m, meas, DiscoveryOptions{}))
    if (c->kind() == "semi_rigid_joint") at.insert(c->site().nodes.at(0));
  std::set<int> joints;
  for (const Node& n : m.nodes()) {
    const bool grid = std::abs(std::remainder(n.x[0], 4.0)) < 1e-9 && std::abs(std::remainder(n.x[1], 3.0)) < 1e-9;
    if (grid && n.x[1] > 0) joints.insert(n.id);
  }
  EXPECT_EQ(joints.size(), 6u);
  EXPECT_EQ(at, joints);
}

// A plane frame exported by a code that only has space frames: the portal as Frame3D elements with uz, rx and ry
// restrained at every node (the plane held in its plane) and the bases clamped. Restraints that hold a plane model
// in its plane are no supports (support_restraints): the library must place the same candidates as on the Frame2D
// portal, kind by kind, on the same sites, and gravity along -y. Before, every node counted as supported, so
// members split into single elements (member damage per element), support springs and flexible supports went to
// every node.
TEST(Candidates, APlaneFrameGivenAsASpaceFrameGetsThePlaneFramesCandidates) {
  const Model plane = make_frame2d(portal());
  Model space;
  for (const Material& x : plane.materials()) space.add_material(x);
  for (Section x : plane.sections()) {
    x.Iy = x.Iz;  // out of plane: held by the restraints, any value
    x.J = 2 * x.Iz;
    space.add_section(x);
  }
  for (const Node& n : plane.nodes()) space.add_node(n.id, n.x);
  for (Element e : plane.elements()) {
    e.type = ElementType::Frame3D;
    space.add_element(e);
  }
  const DofMask out_of_plane = dof_bit(Dof::UZ) | dof_bit(Dof::RX) | dof_bit(Dof::RY);
  for (int n = 0; n < static_cast<int>(plane.nodes().size()); ++n)
    space.restrain(plane.nodes()[n].id, plane.dof_map().restrained(n) ? kAllDofs : out_of_plane);
  space.finalize();
  const ModalData pm = exact_modes(plane, plane, 4), sm = exact_modes(space, plane, 4);
  for (int k = 0; k < 4; ++k) ASSERT_TRUE(test::RelClose(pm.frequencies_hz[k], sm.frequencies_hz[k], 1e-9)) << k;
  auto sites = [](const Model& m, const ModalData& d) {
    std::map<std::string, std::multiset<std::vector<int>>> out;
    for (const auto& c : candidate_library(m, d, DiscoveryOptions{})) {
      const Site at = c->site();
      std::vector<int> where = at.nodes;
      where.push_back(-1);
      where.insert(where.end(), at.elements.begin(), at.elements.end());
      out[c->kind()].insert(where);
    }
    return out;
  };
  const auto p = sites(plane, pm), s = sites(space, sm);
  for (const auto& [kind, at] : p) {
    EXPECT_TRUE(s.count(kind)) << kind << " is missing on the space frame";
    if (!s.count(kind)) continue;
    EXPECT_EQ(s.at(kind).size(), at.size()) << kind;
    EXPECT_TRUE(s.at(kind) == at) << kind << ": other sites";
  }
  for (const auto& [kind, at] : s)
    EXPECT_TRUE(p.count(kind)) << kind << " (" << at.size() << ") only on the space frame";
  // Gravity as in the plane model, -y, and without the warning a space model drawn with y up gets: it is flat in
  // x-y, so y is up in it.
  bool unconventional = true;
  EXPECT_EQ(internal::default_gravity(space, &unconventional), Eigen::Vector3d(0, -1, 0));
  EXPECT_FALSE(unconventional);
}

// The axial_preload candidates the library places on `m` (data: its own first `modes` modes), by description.
std::set<std::string> preload_groups(const Model& m, int modes = 3) {
  std::set<std::string> g;
  for (const auto& c : candidate_library(m, exact_modes(m, m, modes), DiscoveryOptions{}))
    if (c->kind() == "axial_preload") g.insert(c->description());
  return g;
}

// A preload is a self-stress: only members whose lack of fit meets a restraint can carry one (the axial_preload
// candidate's placement, group_effects.cpp). The groups that get the candidate, by closed-form statics:
// - a vertical mast of frame elements clamped at its base expands freely (none); pinned at its top as well, it
//   carries one (all members);
// - a beam2d line has no axial DOFs: a cantilever (one support) cannot carry one, a simply supported beam (two) can;
// - the portal (2 x 2 bays, equal stories): its beams are held by the columns (all members and 'beam'), while an
//   equal elongation of every column lifts the floors rigidly (no force: 'column' gets none).
TEST(Candidates, PreloadOnlyWhereALackOfFitMeetsARestraint) {
  auto mast = [](bool pinned_top) {
    Model m;
    m.add_material(steel());
    Section s;
    s.name = "s";
    s.A = 5.38e-3;
    s.Iz = 5.7e-5;
    m.add_section(s);
    for (int k = 0; k <= 6; ++k) m.add_node(k + 1, Eigen::Vector3d(0, 0.5 * k, 0));
    for (int k = 1; k <= 6; ++k) {
      Element e;
      e.id = k;
      e.node_ids = {{k, k + 1}};
      e.material = 0;
      e.section = 0;
      m.add_element(e);
    }
    m.restrain(1, dof_bit(Dof::UX) | dof_bit(Dof::UY) | dof_bit(Dof::RZ));
    if (pinned_top) m.restrain(7, dof_bit(Dof::UX) | dof_bit(Dof::UY));
    m.finalize();
    return m;
  };
  const std::set<std::string> none, all = {"axial preload (geometric stiffness) in all members"};
  EXPECT_EQ(preload_groups(mast(false)), none);
  EXPECT_EQ(preload_groups(mast(true)), all);
  BeamSpec b = square_steel_beam(2.0);
  b.elements = 8;
  b.support = BeamSupport::Cantilever;
  EXPECT_EQ(preload_groups(make_beam(b)), none);
  b.support = BeamSupport::SimplySupported;
  EXPECT_EQ(preload_groups(make_beam(b)), all);
  EXPECT_EQ(preload_groups(make_frame2d(portal())),
            (std::set<std::string>{"axial preload (geometric stiffness) in all members",
                                   "axial preload (geometric stiffness) in the members of group 'beam'"}));
}

// A preload is the self-stress of its group's lack of fit, carried by every member it pulls on: a line pinned at
// both ends, a 'tie' of four frame2d elements (1.5 m) in series with a 'beam' of four (2.5 m, three times the tie's
// area). Shortening the tie stretches the beam by as much as the tie's own shortening fails to happen: the same
// tension in all eight elements (equilibrium of a chain, whatever the areas). The tie's candidate at a mean force
// P must give the eigenvalues of the model whose eight elements carry P through the element kernel's own axial
// force (an independent route: no static analysis), to 1e-10. Before, only the tie's elements carried P: the lowest
// eigenvalue came out 3.1 % low.
TEST(Candidates, APreloadLoadsEveryMemberItPullsOn) {
  auto line = [](double force) {
    Model m;
    m.add_material(steel());
    for (int k = 0; k < 2; ++k) {
      Section s;
      s.name = k == 0 ? "tie" : "beam";
      s.A = k == 0 ? 2e-4 : 6e-4;
      s.Iz = k == 0 ? 2e-9 : 6e-9;
      m.add_section(s);
    }
    for (int k = 0; k <= 8; ++k) m.add_node(k + 1, Eigen::Vector3d(k < 4 ? 0.375 * k : 1.5 + 0.625 * (k - 4), 0, 0));
    for (int k = 1; k <= 8; ++k) {
      Element e;
      e.id = k;
      e.node_ids = {{k, k + 1}};
      e.material = 0;
      e.section = k <= 4 ? 0 : 1;
      e.group = k <= 4 ? "tie" : "beam";
      e.axial_force = force;
      m.add_element(e);
    }
    m.restrain(1, dof_bit(Dof::UX) | dof_bit(Dof::UY));
    m.restrain(9, dof_bit(Dof::UX) | dof_bit(Dof::UY));
    m.finalize();
    return m;
  };
  const Model m = line(0.0);
  const double P = 40.0;  // N: the lowest eigenvalue moves by several per cent
  int checked = 0;
  for (const auto& c : candidate_library(m, exact_modes(m, m, 4), DiscoveryOptions{})) {
    if (c->kind() != "axial_preload" || c->description().find("'tie'") == std::string::npos) continue;
    const Eigen::VectorXd th =
        Eigen::VectorXd::Constant(1, P / c->physical(Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1))[0].value);
    EigenOptions eo;
    eo.num_modes = 5;
    eo.method = EigenOptions::Method::kDense;
    const Eigen::VectorXd want = modal_analysis(line(P), eo).eigenvalues;
    const Eigen::VectorXd got = eigen_with(m, *c, th, 5);
    EXPECT_LT(((got - want).array() / want.array()).abs().maxCoeff(), 1e-10)
        << got.transpose() << " vs " << want.transpose();
    ++checked;
  }
  EXPECT_EQ(checked, 1);
}

// The lack of fit sits where its self-stress is largest. Three steel bars meet at node P: 'a' hangs it from a
// support 1 m below, the two bars of 'b' run to supports 2 m either side and 0.2 m up (sin alpha = 0.0995).
// Shortening 'a' pulls P down, and the shallow bars hold it with N = T / (2 sin alpha) = 5 T: the state of a lack
// of fit in 'a' is largest in 'b', so 'a' gets no candidate (that is a lack of fit of 'b', whose own state loads
// 'a' with 2 N sin alpha = 0.2 N). Closed-form statics of a pin-jointed truss; the bars are frame2d members meshed
// in two elements each, whose bending changes these ratios by far less than the factor of 5 the test rests on.
TEST(Candidates, ALackOfFitSitsWhereItsForcesAreLargest) {
  Model m;
  m.add_material(steel());
  Section s;
  s.name = "s";
  s.A = 1e-3;
  s.Iz = 1e-8;
  m.add_section(s);
  const std::vector<Eigen::Vector3d> x = {{0, 0, 0}, {0, -1, 0}, {-2, 0.2, 0}, {2, 0.2, 0}};
  for (int k = 0; k < 4; ++k) m.add_node(k + 1, x[k]);
  int id = 0;
  for (int far = 2; far <= 4; ++far) {  // P -> mid-node -> support
    const int mid = 10 + far;
    m.add_node(mid, 0.5 * (x[0] + x[far - 1]));
    for (const std::array<int, 2>& ends : {std::array<int, 2>{1, mid}, std::array<int, 2>{mid, far}}) {
      Element e;
      e.id = ++id;
      e.node_ids = ends;
      e.material = 0;
      e.section = 0;
      e.group = far == 2 ? "a" : "b";
      m.add_element(e);
    }
    m.restrain(far, kAllDofs);
  }
  m.finalize();
  EXPECT_EQ(preload_groups(m, 4),
            (std::set<std::string>{"axial preload (geometric stiffness) in all members",
                                   "axial preload (geometric stiffness) in the members of group 'b'"}));
}

// A support's stiffness against the model's idealisation is one physics, seen from either side: a clamp less than
// rigid (flexible_support) or a pin more than free (rotational_spring, only at supported nodes). On a simply
// supported beam the rotational springs are the two pins' and share flexible_support's physics; the translational
// springs to ground (bracing anywhere) keep their own.
TEST(Candidates, ASupportsFixityIsOnePhysics) {
  BeamSpec b = square_steel_beam(2.0);
  b.elements = 8;
  b.support = BeamSupport::SimplySupported;
  const Model m = make_beam(b);
  std::set<int> pins;
  std::set<std::string> grounded;
  for (const auto& c : candidate_library(m, exact_modes(m, m, 3), DiscoveryOptions{})) {
    if (c->kind() == "rotational_spring") {
      pins.insert(c->site().nodes.at(0));
      EXPECT_EQ(c->physics(), "flexible_support") << c->description();
    }
    if (c->kind() == "flexible_support") {
      EXPECT_EQ(c->physics(), "flexible_support") << c->description();
    }
    if (c->kind() == "grounded_spring") grounded.insert(c->physics());
  }
  EXPECT_EQ(pins, (std::set<int>{m.nodes().front().id, m.nodes()[static_cast<std::size_t>(b.elements)].id}));
  EXPECT_EQ(grounded, std::set<std::string>{"grounded_spring"});
}

// The sensors' own mass: no sensor weighs more than 2 kg (the heaviest accelerometer with its mount), a limit on
// what is plausible that leaves the bounds (and so the prior) as they are. A 157 kg steel beam measured at its
// nodes: 1.9 kg per sensor is plausible, 2.1 kg is not, in SI (labelled so or not) and in mm, t, s (2e-3 t: the
// mass unit read from the densities, mesh/units.hpp); in a mass unit that is neither, both are. Before, the limit
// held only where values were labelled SI.
TEST(Candidates, SensorMassOfMoreThanTheHeaviestSensorIsImplausible) {
  BeamSpec b = square_steel_beam(2.0);
  b.elements = 8;
  b.support = BeamSupport::SimplySupported;
  BeamSpec mm = b;
  mm.length *= 1e3;
  mm.material.E *= 1e-6;
  mm.material.rho *= 1e-12;
  mm.section.A *= 1e6;
  mm.section.Iz *= 1e12;
  struct Set {
    BeamSpec beam;
    bool si;
    double kg;  // one kg in the model's mass unit; 0: no limit
  };
  BeamSpec odd = b;  // steel's sqrt(E / rho) (metres) at a density of 1: neither kg nor t
  odd.material.E /= odd.material.rho;
  odd.material.rho = 1;
  for (const Set& x :
       {Set{b, true, 1.0}, Set{b, false, 1.0}, Set{mm, false, 1e-3}, Set{mm, true, 1e-3}, Set{odd, false, 0.0}}) {
    const Model m = make_beam(x.beam);
    DiscoveryOptions o;
    o.si_units = x.si;
    int found = 0;
    for (const auto& c : candidate_library(m, exact_modes(m, m, 3), o)) {
      if (c->kind() != "sensor_mass") continue;
      ++found;
      const CandidateParameter q = c->parameters().at(0);
      EXPECT_EQ(q.upper, 20.0);  // 40 % of the structure in all, whatever the units
      const double unit = c->physical(Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1)).at(0).value;
      if (x.kg == 0) {  // no limit: plausible up to the bound
        EXPECT_TRUE(c->plausible(Eigen::VectorXd::Constant(1, q.upper)));
        continue;
      }
      ASSERT_LT(2.1 * x.kg / unit, q.upper);
      EXPECT_TRUE(c->plausible(Eigen::VectorXd::Constant(1, 1.9 * x.kg / unit)));
      EXPECT_FALSE(c->plausible(Eigen::VectorXd::Constant(1, 2.1 * x.kg / unit))) << "kg " << x.kg;
    }
    EXPECT_EQ(found, 1);
  }
}

// Units are the user's: the portal in m, kg, s and in mm, t, s (E in MPa, rho in t/mm^3, A in mm^2, I in mm^4)
// has the same eigenvalues, and its self_weight candidate at load factor 1 (the frame's own weight) moves them by
// the same ratios: gravity is 9.81 m/s^2 in the first and 9810 mm/s^2 in the second, the unit read from the
// materials' sqrt(E / rho) (mesh/units.hpp). Tolerance 1e-9 relative: the two models differ by powers of ten
// only (rounding). Before, gravity was 9.81 in any units: the mm model's own weight was 1000 times too light and
// its load factor of 1 a thousandth of the SI model's effect. Materials outside both ranges (E = rho = 1) or
// disagreeing leave the unit unknown (metres assumed, said in the summary).
TEST(Candidates, SelfWeightTakesGravityInTheModelsUnits) {
  Frame2DSpec mm = portal();
  mm.span *= 1e3;
  mm.height *= 1e3;
  mm.material.E *= 1e-6;     // Pa -> N/mm^2
  mm.material.rho *= 1e-12;  // kg/m^3 -> t/mm^3
  mm.column.A *= 1e6;
  mm.column.Iz *= 1e12;
  mm.beam.A *= 1e6;
  mm.beam.Iz *= 1e12;
  const Model si_model = make_frame2d(portal()), mm_model = make_frame2d(mm);
  EXPECT_TRUE(length_unit(si_model).known);
  EXPECT_EQ(length_unit(si_model).per_metre, 1.0);
  EXPECT_TRUE(length_unit(mm_model).known);
  EXPECT_EQ(length_unit(mm_model).per_metre, 1000.0);
  Frame2DSpec odd = portal();
  odd.material.E = odd.material.rho = 1;
  EXPECT_FALSE(length_unit(make_frame2d(odd)).known);
  // The mass unit from the densities: kg in SI, t in N, mm, t, s and in kN, m, t, s (E in kPa, rho in t/m^3,
  // whose sqrt(E / rho) is SI's); a density in neither range (7.8e-3 in metres) leaves it unknown.
  Frame2DSpec kn = portal();
  kn.material.E *= 1e-3;
  kn.material.rho *= 1e-3;
  Frame2DSpec light = portal();
  light.material.rho *= 1e-6;
  light.material.E *= 1e-6;
  const LengthUnit us = length_unit(si_model), um = length_unit(mm_model), uk = length_unit(make_frame2d(kn)),
                   ul = length_unit(make_frame2d(light));
  EXPECT_TRUE(us.mass_known && us.kilogram == 1.0 && us.mass_name == "kg");
  EXPECT_TRUE(um.mass_known && um.kilogram == 1e-3 && um.mass_name == "t");
  EXPECT_TRUE(uk.known && uk.per_metre == 1.0 && uk.mass_known && uk.kilogram == 1e-3);
  EXPECT_TRUE(ul.known && !ul.mass_known);

  std::vector<Eigen::VectorXd> ratio;
  for (const Model* m : {&si_model, &mm_model}) {
    for (const auto& c : candidate_library(*m, exact_modes(*m, *m, 4), DiscoveryOptions{})) {
      if (c->kind() != "self_weight") continue;
      const Eigen::VectorXd nominal = eigen_with(*m, *c, Eigen::VectorXd::Zero(1), 4);
      ratio.push_back(eigen_with(*m, *c, Eigen::VectorXd::Ones(1), 4).cwiseQuotient(nominal));
      EXPECT_LT(ratio.back().minCoeff(), 1 - 1e-6) << "the own weight softens the sway modes";
    }
  }
  ASSERT_EQ(ratio.size(), 2u);
  EXPECT_LT((ratio[0] - ratio[1]).cwiseAbs().maxCoeff(), 1e-9)
      << ratio[0].transpose() << " vs " << ratio[1].transpose();
}

// A tension no member could carry is no preload: the axial_preload candidate of all the portal's members is plausible
// up to a force stretching the weakest member (the beams, E A = 2.1e11 x 3.91e-3 N) by 1 % and not beyond (steel
// yields near 0.2 %, prestressing tendons near 0.9 %). Found on test3-072 (null data): "an axial tension of 6.6e10 N
// +- 430 %" in a frame's links, 10^4 times what they could carry.
TEST(Candidates, PreloadBeyondWhatMembersCarryIsImplausible) {
  const Model m = make_frame2d(portal());
  const double ea = 2.1e11 * 3.91e-3;
  int found = 0;
  for (const auto& c : candidate_library(m, exact_modes(m, m, 4), DiscoveryOptions{})) {
    if (c->kind() != "axial_preload" || c->site().elements.size() != static_cast<std::size_t>(m.num_elements()))
      continue;
    ++found;
    const double per_unit = c->physical(Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1)).at(0).value;  // N
    EXPECT_TRUE(c->plausible(Eigen::VectorXd::Constant(1, 0.0099 * ea / per_unit)));
    EXPECT_FALSE(c->plausible(Eigen::VectorXd::Constant(1, 0.0101 * ea / per_unit)));
    EXPECT_TRUE(
        c->plausible(Eigen::VectorXd::Constant(1, c->parameters().at(0).lower)));  // compression: buckling bounds it
  }
  EXPECT_EQ(found, 1);
}

// Gravity's direction from the supports: a 3D frame drawn with y up (the z-up frame turned by -90 degrees about x)
// stands on its lowest y, and its self_weight candidate at load factor 1 moves the eigenvalues by the same ratios as
// the z-up frame's (1e-9 relative: the models differ by a rotation, rounding only; square sections, so the members'
// default local axes do not matter). Before, gravity was -z in every space model: the y-up frame's own weight
// pulled it sideways. Plane models keep -y: the portal held only at a wall (its nodes at x = 0) as much as a beam.
TEST(Candidates, GravityPointsFromTheSupportsLevel) {
  Frame3DSpec spec = test::SteelFrame3D(1, 1, 2);
  spec.column.Iy = spec.column.Iz;
  spec.beam.Iy = spec.beam.Iz;
  const Model zup = make_frame3d(spec);
  Model yup;
  for (const Material& x : zup.materials()) yup.add_material(x);
  for (const Section& x : zup.sections()) yup.add_section(x);
  for (const Node& n : zup.nodes()) yup.add_node(n.id, Eigen::Vector3d(n.x.x(), n.x.z(), -n.x.y()));
  for (const Element& e : zup.elements()) yup.add_element(e);
  for (const Node& n : zup.nodes())
    if (n.x.z() == 0) yup.restrain(n.id, kAllDofs);
  yup.finalize();
  bool unconventional = true;
  EXPECT_EQ(internal::default_gravity(zup, &unconventional), Eigen::Vector3d(0, 0, -1));
  EXPECT_FALSE(unconventional);
  EXPECT_EQ(internal::default_gravity(yup, &unconventional), Eigen::Vector3d(0, -1, 0));
  EXPECT_TRUE(unconventional);
  BeamSpec b = square_steel_beam(2.0);
  b.support = BeamSupport::Cantilever;
  EXPECT_EQ(internal::default_gravity(make_beam(b), &unconventional), Eigen::Vector3d(0, -1, 0));
  EXPECT_FALSE(unconventional);
  Model wall = test::UnsupportedCopy(make_frame2d(portal()));
  for (const Node& n : wall.nodes())
    if (n.x.x() == 0) wall.restrain(n.id, kAllDofs);
  wall.finalize();
  EXPECT_EQ(internal::default_gravity(wall, &unconventional), Eigen::Vector3d(0, -1, 0));
  EXPECT_FALSE(unconventional);

  std::vector<Eigen::VectorXd> ratio;
  for (const Model* m : {&zup, static_cast<const Model*>(&yup)}) {
    for (const auto& c : candidate_library(*m, exact_modes(*m, *m, 4), DiscoveryOptions{})) {
      if (c->kind() != "self_weight") continue;
      const Eigen::VectorXd nominal = eigen_with(*m, *c, Eigen::VectorXd::Zero(1), 4);
      ratio.push_back(eigen_with(*m, *c, Eigen::VectorXd::Ones(1), 4).cwiseQuotient(nominal));
    }
  }
  ASSERT_EQ(ratio.size(), 2u);
  EXPECT_LT(ratio[0].maxCoeff(), 1 - 1e-6) << "the own weight softens the sway modes";
  EXPECT_LT((ratio[0] - ratio[1]).cwiseAbs().maxCoeff(), 1e-9)
      << ratio[0].transpose() << " vs " << ratio[1].transpose();
}

}  // namespace
}  // namespace dynid

namespace dynid {
namespace {

// The case file's `expect:` check: damage expected in element 3 (-44.4 %) and named over elements 3 to 4 of
// equal length is one softening seen over twice the length, and is compared with the flexibility average
// 1 / (1 + d_S) - 1 = (1 / 0.556 - 1) / 2, d_S = -28.5 % (the discovery benchmark's rule); the expected set
// itself is compared with the value as given. 1e-9 relative: closed form, rounding only.
TEST(DiscoveryExpect, DamageOverMoreElementsIsComparedByItsFlexibility) {
  BeamSpec b = square_steel_beam(1.0);
  b.elements = 8;
  b.support = BeamSupport::Cantilever;
  const Model m = make_beam(b);
  DiscoverSpec::Expect e;
  e.kinds = {"member_damage", "element_stiffness"};
  e.elements = {3};
  e.parameter = "stiffness change";
  e.value = -44.4;
  const double d_s = 100 * (1 / (1 + (1 / (1 - 0.444) - 1) / 2) - 1);
  DiscoverySummary s;
  s.verdict = Verdict::kMissingPhysics;
  ScoredHypothesis h;
  h.kind = "member_damage";
  h.site.elements = {3, 4};
  h.values.push_back({"stiffness change", "%", d_s * 1.05, 1.0});
  s.findings.push_back(h);
  ExpectCheck c = check_expectation(e, s, m);
  EXPECT_TRUE(c.ok()) << c.words;
  EXPECT_NEAR(c.parameter_error, 0.05, 1e-9);
  s.findings[0].values[0].value = e.value;  // the expected element's own value, over two elements: wrong
  EXPECT_FALSE(check_expectation(e, s, m).ok());
  s.findings[0].site.elements = {3};  // the expected set: the value as given
  s.findings[0].values[0].value = e.value * 1.05;
  c = check_expectation(e, s, m);
  EXPECT_TRUE(c.ok()) << c.words;
  EXPECT_NEAR(c.parameter_error, 0.05, 1e-9);
}

// A spring in ux at any node of a floor the data see as one rigid body predicts the same data, and the finding
// names every such site it tried. The screen ranks them by a linearisation at the model as given, and the
// shortlist's cut (screen_fit 2 here) falls inside the set: the sites beyond it whose screened columns are as
// parallel to the finding's as its fitted equivalents' are fitted too (discovery.cpp, complete_equivalents). The
// roof of a 3-bay portal (13 nodes) with a ground spring in ux at one of them, 0.5 % / 5 % noise: the finding's
// site holds roof nodes the shortlist did not take, and only sites that full fits find equivalent (each roof
// spring fitted alone, the equivalence test of name_equivalent_sites).
TEST(DiscoveryStages, EquivalentSitesBeyondTheShortlistAreTried) {
  Frame2DSpec spec = portal();
  spec.bays = 3;
  spec.divisions = 4;
  const Model analysis = make_frame2d(spec);
  double top = -1e300;
  for (const Node& n : analysis.nodes()) top = std::max(top, n.x.y());
  std::vector<int> roof;
  for (const Node& n : analysis.nodes())
    if (std::abs(n.x.y() - top) < 1e-9) roof.push_back(n.id);
  ASSERT_EQ(roof.size(), 13u);
  Model truth = test::UnsupportedCopy(analysis);
  truth.add_element(test::GroundedSpring(9001, roof[7], Dof::UX, 1e6));
  for (const Node& n : analysis.nodes())
    if (std::abs(n.x.y()) < 1e-9) truth.restrain(n.id, kAllDofs);
  truth.finalize();
  const ModalData meas = exact_modes(truth, analysis, 6);
  DiscoveryOptions o;
  o.screen_fit = 2;
  o.frequency_noise = 0.005;
  o.shape_noise = 0.05;
  internal::Problem p;
  DiscoverySummary S;
  internal::prepare(analysis, meas, o, {}, &p, &S);
  const Localization L = internal::locate(p);
  const internal::Screening sc = internal::screen(p);
  const std::vector<int> list = internal::shortlist(p, sc, L);
  p.n = p.modes * (1 + static_cast<int>(p.data.dofs.size()));
  p.chi2_0 = sc.chi2;
  p.chi2_0_frequency = sc.chi2_frequency;
  const auto roof_ux = [&](const Candidate& c) {
    return c.kind() == "grounded_spring" && c.description().find(" ux ") != std::string::npos &&
           std::find(roof.begin(), roof.end(), c.site().nodes.at(0)) != roof.end();
  };
  std::set<int> shortlisted;
  for (int k : list)
    if (roof_ux(*p.library[k])) shortlisted.insert(p.library[k]->site().nodes[0]);
  std::vector<internal::SetFit> fits;
  for (const auto& c : p.library)
    if (roof_ux(*c)) fits.push_back(internal::fit_set(p, {c.get()}));

  const DiscoverySummary d = discover(analysis, meas, o);
  ASSERT_EQ(d.verdict, Verdict::kMissingPhysics) << said(d);
  ASSERT_EQ(d.findings.at(0).kind, "grounded_spring") << said(d);
  const internal::SetFit* own = nullptr;
  for (const internal::SetFit& f : fits)
    if (f.set[0]->description() == d.findings[0].description) own = &f;
  ASSERT_NE(own, nullptr) << said(d);
  const double le = internal::log_evidence(p, *own);
  const internal::ErrorScale es = internal::error_scale(p, *own);
  std::set<int> equivalent;
  for (const internal::SetFit& f : fits)
    if (internal::log_evidence(p, f) >= le - o.ambiguity &&
        internal::scaled_norm2(p, f.residuals - own->residuals, es) <= 2 * o.ambiguity)
      equivalent.insert(f.set[0]->site().nodes[0]);
  int beyond = 0;
  for (int n : d.findings[0].site.nodes) {
    EXPECT_TRUE(equivalent.count(n)) << "node " << n << " is not equivalent: " << said(d);
    beyond += !shortlisted.count(n);
  }
  EXPECT_GT(beyond, 0) << "only shortlisted sites named: " << said(d);
}

}  // namespace
}  // namespace dynid
