// Bad case files: each error names the file, line and entity, and says what is wrong.
#include "dynid/io/case_file.hpp"
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
