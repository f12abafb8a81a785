// Missing-physics discovery: the candidates' matrices against explicit models of the same physics, and the
// four steps on exact data where the answer is known. (The concealed-data suite with virtual tests,
// identification and different discretizations is cases/discovery, run by tests/CMakeLists.txt.)
#include <gtest/gtest.h>

#include <cmath>

#include "dynid/engine/discovery.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/mesh/generators.hpp"
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

const PhysicalValue* value(const ScoredHypothesis& h, const std::string& name) {
  for (const PhysicalValue& v : h.values)
    if (v.name == name) return &v;
  return nullptr;
}

// A column base on a rotational spring: the truth releases the base rotation and adds a grounded spring (an
// explicit DOF); the candidate condenses the released rotation into the column's first element. Same physics,
// so discovery must name it and recover k to the Guyan condensation's accuracy (the released rotation's mass is
// condensed statically: 1 % here).
TEST(Discovery, FlexibleBaseMatchesAnExplicitSpring) {
  const Model analysis = make_frame2d(portal());
  Model truth = make_frame2d(portal());
  // Rebuild the truth with node 2's rotation free and a spring on it.
  Model t2;
  for (const Node& n : truth.nodes()) t2.add_node(n.id, n.x);
  for (const Material& m : truth.materials()) t2.add_material(m);
  for (const Section& s : truth.sections()) t2.add_section(s);
  for (const Element& e : truth.elements()) t2.add_element(e);
  const double k = 6.0e6;
  Element sp;
  sp.id = 9001;
  sp.type = ElementType::Spring;
  sp.num_nodes = 1;
  sp.node_ids = {{2, 2}};
  sp.spring_dofs = dof_bit(Dof::RZ);
  sp.stiffness = k;
  t2.add_element(sp);
  for (int id : {1, 3}) t2.restrain(id, kAllDofs);
  t2.restrain(2, dof_bit(Dof::UX) | dof_bit(Dof::UY));
  t2.finalize();
  const ModalData meas = exact_modes(t2, analysis, 6);
  DiscoveryOptions o;
  const DiscoverySummary s = discover(analysis, meas, o);
  ASSERT_EQ(s.verdict, "missing_physics") << s.explanation;
  ASSERT_FALSE(s.findings.empty());
  EXPECT_EQ(s.findings[0].kind, "flexible_support") << s.explanation;
  EXPECT_EQ(s.findings[0].site.nodes, std::vector<int>{2});
  const PhysicalValue* v = value(s.findings[0], "stiffness");
  ASSERT_NE(v, nullptr);
  EXPECT_TRUE(test::RelClose(v->value, k, 0.02)) << v->value;
  EXPECT_LT(s.after.max_freq_error_pct, 0.05 * s.before.max_freq_error_pct);
  EXPECT_EQ(s.findings.size(), 1u) << s.explanation;
}

// Nothing missing: the data are the analysis model's own modes.
TEST(Discovery, ExactDataOfTheModelIsConsistent) {
  const Model analysis = make_frame2d(portal());
  const ModalData meas = exact_modes(analysis, analysis, 6);
  const DiscoverySummary s = discover(analysis, meas, DiscoveryOptions{});
  EXPECT_EQ(s.verdict, "consistent") << s.explanation;
  EXPECT_TRUE(s.findings.empty());
  EXPECT_LT(s.before.max_freq_error_pct, 1e-6);
}

}  // namespace
}  // namespace dynid
