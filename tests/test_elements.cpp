// Element matrices: exactness for rigid-body motions (to rounding), symmetry, total mass, and the exact static
// tip response of a cantilever (cubic Hermite beams are exact for end loads).
#include <Eigen/Dense>

#include "dynid/mesh/error.hpp"
#include "dynid/mesh/model.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

Material Steel() { return {"steel", 2.1e11, 8.1e10, 0.3, 7800}; }
Section Box() { return {"box", 2e-3, 3e-6, 5e-6, 4e-6}; }

// One member from a to b, nothing restrained (free-free), of the given type.
Model OneMember(ElementType t, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                const Eigen::Vector3d& orient = Eigen::Vector3d::Zero(), MassType mass = MassType::Consistent) {
  Model m;
  m.set_mass_type(mass);
  m.add_node(1, a);
  m.add_node(2, b);
  m.add_material(Steel());
  m.add_section(Box());
  Element e;
  e.id = 1;
  e.type = t;
  e.node_ids = {{1, 2}};
  e.material = 0;
  e.section = 0;
  e.orientation = orient;
  m.add_element(e);
  m.set_free_free(true);
  m.finalize();
  return m;
}

// ||K r|| / (||K|| ||r||) for every rigid-body motion of the model (must be rounding level).
double WorstRigidResidual(const Model& m) {
  Eigen::MatrixXd K;
  m.element_matrices(0, &K, nullptr);
  const Eigen::MatrixXd R = m.rigid_body_motions();
  double worst = 0;
  for (Eigen::Index c = 0; c < R.cols(); ++c)
    worst = std::max(worst, (K * R.col(c)).norm() / (K.norm() * R.col(c).norm()));
  return worst;
}

TEST(Elements, RigidBodyMotionsAreStressFree) {
  // Tolerance: 1e-13, i.e. a few hundred ulps of the largest stiffness entry: rigid motions are in the null
  // space of an exact element stiffness, so only rounding remains.
  const Eigen::Vector3d a(0.3, -0.2, 0.0), b(1.7, 0.9, 0.0);
  EXPECT_LT(WorstRigidResidual(OneMember(ElementType::Frame2D, a, b)), 1e-13);
  EXPECT_LT(WorstRigidResidual(OneMember(ElementType::Beam2D, a, Eigen::Vector3d(2.1, -0.2, 0))), 1e-13);
  EXPECT_LT(WorstRigidResidual(OneMember(ElementType::Beam2D, Eigen::Vector3d(2.1, 0, 0), Eigen::Vector3d(0.5, 0, 0))), 1e-13);
  const Eigen::Vector3d c(0.1, 0.4, -0.3), d(1.1, -0.7, 2.2);
  EXPECT_LT(WorstRigidResidual(OneMember(ElementType::Frame3D, c, d, Eigen::Vector3d(0.3, 1.0, 0.2))), 1e-13);
  EXPECT_LT(WorstRigidResidual(OneMember(ElementType::Frame3D, c, Eigen::Vector3d(0.1, 0.4, 2.0))), 1e-13);
  // The model sees the rigid motions as free: 3 in the plane, 2 for a beam, 6 in space.
  EXPECT_EQ(OneMember(ElementType::Frame2D, a, b).free_rigid_body_modes().cols(), 3);
  EXPECT_EQ(OneMember(ElementType::Frame3D, c, d).free_rigid_body_modes().cols(), 6);
}

TEST(Elements, SymmetricPositiveSemidefiniteAndPartsAddUp) {
  for (MassType mt : {MassType::Consistent, MassType::Lumped}) {
    const Model m = OneMember(ElementType::Frame3D, {0, 0, 0}, {1.2, 0.5, 0.8}, {0, 0, 1}, mt);
    Eigen::MatrixXd K, M;
    m.element_matrices(0, &K, &M);
    EXPECT_LT((K - K.transpose()).norm(), 1e-14 * K.norm());
    EXPECT_LT((M - M.transpose()).norm(), 1e-14 * M.norm());
    const Eigen::VectorXd ek = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(K).eigenvalues();
    const Eigen::VectorXd em = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues();
    EXPECT_GT(ek.minCoeff(), -1e-12 * ek.maxCoeff());
    EXPECT_GT(em.minCoeff(), -1e-12 * em.maxCoeff());
    // The fast assembly path and the per-property parts agree.
    const ElementParts p = m.element_parts(0);
    EXPECT_LT((p.K() - K).norm(), 1e-14 * K.norm());
    EXPECT_LT((p.M() - M).norm(), 1e-14 * M.norm());
  }
}

TEST(Elements, TranslationalMassIsRhoAL) {
  // Kinetic energy of a unit rigid translation = total mass rho A L, for consistent and lumped mass (1e-14).
  const Eigen::Vector3d a(0, 0, 0), b(0.6, 0.8, 0);  // L = 1
  for (MassType mt : {MassType::Consistent, MassType::Lumped}) {
    const Model m = OneMember(ElementType::Frame2D, a, b, Eigen::Vector3d::Zero(), mt);
    Eigen::MatrixXd M;
    m.element_matrices(0, nullptr, &M);
    const Eigen::MatrixXd R = m.rigid_body_motions();
    for (int c = 0; c < 2; ++c) {
      const Eigen::VectorXd r = R.col(c) / R.col(c).cwiseAbs().maxCoeff();
      EXPECT_TRUE(test::RelClose(r.dot(M * r), 7800 * 2e-3 * 1.0, 1e-14));
    }
  }
}

// Static tip response of a one-element cantilever, compared with the exact beam solutions
// PL^3/(3EI), PL/(EA), TL/(GJ); the cubic Hermite element is exact here (tolerance 1e-10).
TEST(Elements, CantileverTipDeflectionIsExact) {
  const double L = 2.0;
  Model m = OneMember(ElementType::Frame3D, {0, 0, 0}, {L, 0, 0}, {0, 0, 1});
  Eigen::MatrixXd K;
  m.element_matrices(0, &K, nullptr);
  const Eigen::MatrixXd K22 = K.bottomRightCorner(6, 6);  // node 1 clamped
  const Eigen::VectorXd f = (Eigen::VectorXd(6) << 10, 20, 30, 40, 0, 0).finished();  // Px, Py, Pz, T
  const Eigen::VectorXd u = K22.ldlt().solve(f);
  const Material s = Steel();
  const Section b = Box();
  EXPECT_TRUE(test::RelClose(u[0], 10 * L / (s.E * b.A), 1e-10));
  EXPECT_TRUE(test::RelClose(u[1], 20 * L * L * L / (3 * s.E * b.Iz), 1e-10));
  EXPECT_TRUE(test::RelClose(u[2], 30 * L * L * L / (3 * s.E * b.Iy), 1e-10));
  EXPECT_TRUE(test::RelClose(u[3], 40 * L / (s.G * b.J), 1e-10));
  // Rotations at the tip: theta_z = P_y L^2 / (2 E Iz), theta_y = -P_z L^2 / (2 E Iy).
  EXPECT_TRUE(test::RelClose(u[5], 20 * L * L / (2 * s.E * b.Iz), 1e-10));
  EXPECT_TRUE(test::RelClose(u[4], -30 * L * L / (2 * s.E * b.Iy), 1e-10));
}

TEST(Elements, PropertyFactorsScaleTheRightParts) {
  Model m = OneMember(ElementType::Frame2D, {0, 0, 0}, {1, 1, 0});
  const ElementParts p0 = m.element_parts(0);
  m.element(0).factors.E = 0.85;
  m.element(0).factors.rho = 1.2;
  const ElementParts p1 = m.element_parts(0);
  EXPECT_LT((p1.K() - 0.85 * p0.K()).norm(), 1e-14 * p0.K().norm());
  EXPECT_LT((p1.M() - 1.2 * p0.M()).norm(), 1e-14 * p0.M().norm());
  m.element(0).factors = {};
  m.element(0).factors.I = 2.0;
  const ElementParts p2 = m.element_parts(0);
  EXPECT_LT((p2.K_bending - 2.0 * p0.K_bending).norm(), 1e-14 * p0.K_bending.norm());
  EXPECT_LT((p2.K_axial - p0.K_axial).norm(), 1e-14 * p0.K_axial.norm());
}

TEST(Elements, PointMassAndSprings) {
  Model m;
  m.add_node(1, {0, 0, 0});
  m.add_node(2, {1, 0, 0});
  Element s;
  s.id = 1;
  s.type = ElementType::Spring;
  s.node_ids = {{1, 2}};
  s.spring_dofs = dof_bit(Dof::UX);
  s.stiffness = 1000;
  m.add_element(s);
  Element g = s;
  g.id = 2;
  g.num_nodes = 1;
  g.node_ids = {{1, 0}};
  m.add_element(g);
  Element pm;
  pm.id = 3;
  pm.type = ElementType::PointMass;
  pm.num_nodes = 1;
  pm.node_ids = {{2, 0}};
  pm.mass = 2.5;
  m.add_element(pm);
  m.add_element([&] { Element q = pm; q.id = 4; q.node_ids = {{1, 0}}; return q; }());
  m.finalize();  // supported by the grounded spring: no rigid-body motion left
  EXPECT_EQ(m.num_dofs(), 2);
  Eigen::MatrixXd K, M;
  m.element_matrices(0, &K, &M);
  EXPECT_EQ(K, (Eigen::Matrix2d() << 1000, -1000, -1000, 1000).finished());
  m.element_matrices(2, &K, &M);
  EXPECT_EQ(M(0, 0), 2.5);
}

// The element registry: every ElementType has its kind in its place, names parse back to their type, and the
// kinds declare the nature the rest of dynid relies on (candidates, updating parameters, detection).
TEST(ElementRegistry, EveryTypeHasItsKind) {
  const std::vector<const ElementKind*>& kinds = element_kinds();
  ASSERT_EQ(kinds.size(), 6u);
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    const ElementType t = static_cast<ElementType>(i);
    EXPECT_EQ(&element_kind(t), kinds[i]);
    EXPECT_EQ(kinds[i]->type(), t);
    ElementType back = ElementType::Matrix;
    ASSERT_TRUE(parse_element_type(kinds[i]->name(), &back)) << kinds[i]->name();
    EXPECT_EQ(back, t);
    EXPECT_EQ(element_type_name(t), kinds[i]->name());
  }
  ElementType t;
  EXPECT_FALSE(parse_element_type("truss", &t));
  for (ElementType m : {ElementType::Beam2D, ElementType::Frame2D, ElementType::Frame3D}) {
    EXPECT_TRUE(is_member(m));
    EXPECT_TRUE(element_kind(m).has_stiffness() && element_kind(m).has_mass());
    EXPECT_EQ(element_kind(m).spatial(), m == ElementType::Frame3D);
  }
  EXPECT_FALSE(is_member(ElementType::Matrix));
  EXPECT_FALSE(element_kind(ElementType::PointMass).has_stiffness());
  EXPECT_FALSE(element_kind(ElementType::Spring).has_mass());
}

// Non-members have no geometric stiffness or axis: a clear error naming the element, not a crash.
TEST(ElementRegistry, MemberOnlyQueriesRejectOtherKinds) {
  Model m;
  m.add_node(1, {0, 0, 0});
  m.add_element(test::GroundedSpring(7, 1, Dof::UX, 10));
  m.finalize();
  EXPECT_THROW(m.unit_geometric_stiffness(0), InputError);
  EXPECT_THROW(m.member_point_interpolation(0, 0.5), InputError);
  EXPECT_THROW(m.member_bending_planes(0), InputError);
  EXPECT_EQ(m.member_axial_force(0, Eigen::VectorXd::Ones(1)), 0.0);
}

}  // namespace
}  // namespace dynid
