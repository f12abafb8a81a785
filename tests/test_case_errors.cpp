// Bad case files: each error names the file, line and entity, and says what is wrong.
#include "dynid/io/case_file.hpp"
#include "dynid/io/results_json.hpp"
#include "dynid/mesh/error.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

const char* kGood = R"(name: t
model:
  element: frame2d
  materials: {steel: {E: 2.1e11, rho: 7800}}
  sections: {s: {A: 1e-3, I: 1e-6}}
  defaults: {material: steel, section: s}
  nodes:
    - [1, 0, 0]
    - [2, 0, 1]
  elements:
    - [1, 1, 2]
  supports:
    - {node: 1, fix: all}
)";

std::string Error(const std::string& text) {
  try {
    parse_case(text, "case.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return s.replace(p, from.size(), to);
}


TEST(CaseErrors, GoodCaseParses) { EXPECT_EQ(Error(kGood), "(no error)"); }

// Identified modes that the MPC filter leaves none of: the error names the source, the modes left out with their
// MPC and the threshold, and what would help (not the engine's bare "no measured modes"). One normal mode is enough
// for the consistency test (discover() names no physics from one mode).
TEST(CaseErrors, ComplexModesLeaveNoneForDiscovery) {
  const Case c = parse_case(std::string(kGood) + "discover:\n  measured: modes.uff\n", "case.yaml");
  ModalData m;
  m.dofs = {{2, Dof::UX}, {2, Dof::UY}};
  m.frequencies_hz = Eigen::Vector3d(19.56, 21.76, 24.01);
  m.shapes = Eigen::MatrixXd::Identity(2, 3);
  m.mpc = Eigen::Vector3d(0.61, 0.76, 0.72);
  std::string e = "(no error)";
  try {
    discovery_data(c, m, "rec.uff");
  } catch (const InputError& x) {
    e = x.what();
  }
  EXPECT_HAS(e, "rec.uff: discover: none of the 3 modes is a normal mode");
  EXPECT_HAS(e, "19.56 Hz (MPC 0.61), 21.76 Hz (MPC 0.76), 24.01 Hz (MPC 0.72)");
  EXPECT_HAS(e, "min_mpc = 0.8");
  m.mpc[1] = 0.9;  // one normal mode: enough to test consistency
  EXPECT_EQ(discovery_data(c, m, "rec.uff").measured.num_modes(), 1);
}

// A misspelled kind in discover's kinds: list is an error naming it, its line and the known kinds (the library would
// otherwise silently lack the kind the user asked for).
TEST(CaseErrors, MisspelledDiscoveryKindIsNamed) {
  const std::string e =
      Error(std::string(kGood) + "discover:\n  measured: modes.uff\n  kinds: [lumped_mass, semi_rigid_joit]\n");
  EXPECT_HAS(e, "case.yaml");
  EXPECT_HAS(e, "unknown candidate kind 'semi_rigid_joit'");
  EXPECT_HAS(e, "semi_rigid_joint");
  EXPECT_EQ(Error(std::string(kGood) + "discover:\n  measured: modes.uff\n  kinds: [lumped_mass, semi_rigid_joint]\n"),
            "(no error)");
}

// discover: gravity_acceleration is in the model's units and positive; without it and without units:, a model whose
// materials read as mm, t, s (E in MPa, rho in t/mm^3) reports its values in model units (its masses are tonnes),
// one in m, kg, s in SI.
TEST(CaseErrors, GravityAndUnitsOfDiscovery) {
  const std::string d = "discover:\n  measured: modes.uff\n";
  const std::string e = Error(std::string(kGood) + d + "  gravity_acceleration: 0\n");
  EXPECT_HAS(e, "case.yaml:16:");
  EXPECT_HAS(e, "gravity_acceleration: expected the acceleration of gravity in the model's units");
  const Case si = parse_case(std::string(kGood) + d, "case.yaml");
  EXPECT_TRUE(si.discover->options.si_units);
  EXPECT_EQ(si.discover->options.gravity_acceleration, 0.0);  // from the materials' units, when discovery runs
  const std::string mm_model =
      Replace(Replace(kGood, "E: 2.1e11, rho: 7800", "E: 2.1e5, rho: 7.8e-9"), "[2, 0, 1]", "[2, 0, 1000]");
  const Case mm = parse_case(mm_model + d + "  gravity_acceleration: 9810\n", "case.yaml");
  EXPECT_FALSE(mm.discover->options.si_units);
  EXPECT_EQ(mm.discover->options.gravity_acceleration, 9810.0);
  EXPECT_TRUE(parse_case(mm_model + d + "  units: si\n", "case.yaml").discover->options.si_units);  // as stated
  // kN, m, t, s: metres by sqrt(E / rho) as in SI, tonnes by the density: not SI.
  const std::string kn_model = Replace(kGood, "E: 2.1e11, rho: 7800", "E: 2.1e8, rho: 7.8");
  EXPECT_FALSE(parse_case(kn_model + d, "case.yaml").discover->options.si_units);
}

// Stated noise levels are fractions: a percentage (1 for 1 %) is refused with the line and the right form, never read
// as 100 %, which would make every mismatch noise.
TEST(CaseErrors, NoiseLevelsAreFractions) {
  const std::string d = std::string(kGood) + "discover:\n  measured: modes.uff\n";
  std::string e = Error(d + "  frequency_noise: 1\n");
  EXPECT_HAS(e, "case.yaml:16:");
  EXPECT_HAS(e, "0.01 for 1 %");
  e = Error(d + "  shape_noise: 5\n");
  EXPECT_HAS(e, "case.yaml:16:");
  EXPECT_HAS(e, "0.05 for 5 %");
  EXPECT_EQ(Error(d + "  frequency_noise: 0.01\n  shape_noise: 0.05\n"), "(no error)");
}

TEST(CaseErrors, UnknownElementType) {
  const std::string e = Error(Replace(kGood, "element: frame2d", "element: frame4d"));
  EXPECT_HAS(e, "case.yaml:3:");
  EXPECT_HAS(e, "unknown element type 'frame4d'");
}

TEST(CaseErrors, MissingNode) {
  const std::string e = Error(Replace(kGood, "- [1, 1, 2]", "- [1, 1, 99]"));
  EXPECT_HAS(e, "case.yaml:11:");
  EXPECT_HAS(e, "element 1: node 99 does not exist");
}

TEST(CaseErrors, ZeroAndNegativeSectionProperties) {
  std::string e = Error(Replace(kGood, "A: 1e-3", "A: 0"));
  EXPECT_HAS(e, "element 1 (frame2d): section 's' has area A = 0; it must be > 0");
  EXPECT_HAS(e, "case.yaml:11:");  // points at the element using the section
  e = Error(Replace(kGood, "I: 1e-6", "I: -1e-6"));
  EXPECT_HAS(e, "second moment Iz = -1e-06");
  e = Error(Replace(kGood, "E: 2.1e11", "E: -5"));
  EXPECT_HAS(e, "E must be > 0");
}

TEST(CaseErrors, UnsupportedStructure) {
  const std::string e = Error(Replace(kGood, "- {node: 1, fix: all}", "- {node: 1, fix: pinned}"));
  EXPECT_HAS(e, "not supported against: rotation about z through (0, 0, 0)");
  EXPECT_HAS(e, "Add supports or springs");
  const std::string none = Error(Replace(kGood, "  supports:\n    - {node: 1, fix: all}\n", ""));
  EXPECT_HAS(none, "supports are missing");
}

TEST(CaseErrors, SpringsRestoreSupport) {
  // The pinned column is fine once a rotational spring holds the rotation.
  const std::string t = Replace(kGood, "- {node: 1, fix: all}", "- {node: 1, fix: pinned}") +
                        "  springs:\n    - {id: 9, node: 1, dofs: [rz], k: 1.0e4}\n";
  EXPECT_EQ(Error(Replace(t, "\n  supports:", "\n  supports:")), "(no error)");
}

TEST(CaseErrors, MalformedFile) {
  std::string e = Error("name: t\nmodel: {nodes: [1, 2\n");
  EXPECT_HAS(e, "case.yaml:");
  EXPECT_HAS(e, "malformed case file");
  e = Error(Replace(kGood, "materials:", "materails:"));
  EXPECT_HAS(e, "unknown key 'materails' in model");
  e = Error(Replace(kGood, "rho: 7800", "rho: heavy"));
  EXPECT_HAS(e, "'heavy' is not a number");
  e = Error("");
  EXPECT_HAS(e, "empty");
  e = Error(Replace(kGood, "- [2, 0, 1]", "- [2, 0, 0]"));
  EXPECT_HAS(e, "zero length");
}

TEST(CaseErrors, UnknownMaterialNamesTheDefinedOnes) {
  const std::string e = Error(Replace(kGood, "defaults: {material: steel", "defaults: {material: steeel"));
  EXPECT_HAS(e, "unknown material 'steeel' (defined: steel)");
}

}  // namespace
}  // namespace dynid
