// The paper's modal results: Table 1 'Model' row (free-free beam) and Table 2 (five-story frame), from the
// bundled cases; and the bundled frame case against the shared reconstruction of the paper's geometry.
#include <nlohmann/json.hpp>

#include <fstream>

#include "dynid/engine/modal.hpp"
#include "dynid/io/case_file.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

TEST(PaperModal, Table1FreeFreeBeam) {
  const Case c = load_case(test::CasesDir() + "/paper-beam");
  EigenOptions o = c.analysis.eigen_options();
  o.num_modes = 7;
  const ModalResult r = modal_analysis(c.model, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.dofs, 22);
  EXPECT_TRUE(r.rigid_body[0] && r.rigid_body[1]);
  EXPECT_FALSE(r.rigid_body[2]);
  // Table 1 'Model' row; the paper prints 4-5 digits, the issue asks for 0.1 %.
  const double table1[] = {45.49, 125.43, 246.05, 407.3, 610.1};
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(test::RelClose(r.frequencies_hz[2 + k], table1[k], 1e-3)) << k;
}

TEST(PaperModal, Table2FiveStoryFrame) {
  DYNID_REQUIRE_SHARED();
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  const ModalResult r = modal_analysis(c.model, c.analysis.eigen_options());
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.dofs, 60);
  // Table 2 to 0.01 % (the paper gives 5 significant digits).
  const double table2[] = {0.6496, 1.5019, 2.0748, 3.2737};
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(test::RelClose(r.frequencies_hz[k], table2[k], 1e-4)) << k;
  // The reconstruction's own 8 reference frequencies (6 digits).
  std::ifstream in(test::SharedDir() + "/cases/paper-frame.json");
  ASSERT_TRUE(in) << "needs ../shared/cases/paper-frame.json";
  const nlohmann::json ref = nlohmann::json::parse(in);
  const auto f = ref["reference_frequencies_hz_first_8"];
  for (int k = 0; k < 8; ++k) EXPECT_TRUE(test::RelClose(r.frequencies_hz[k], f[k].get<double>(), 2e-6)) << k;
}

TEST(PaperModal, FrameCaseMatchesSharedGeometry) {
  DYNID_REQUIRE_SHARED();
  const Case c = load_case(test::CasesDir() + "/paper-frame");
  std::ifstream in(test::SharedDir() + "/cases/paper-frame.json");
  ASSERT_TRUE(in);
  const nlohmann::json ref = nlohmann::json::parse(in);
  ASSERT_EQ(c.model.nodes().size(), ref["nodes"].size());
  for (const auto& [id, xy] : ref["nodes"].items()) {
    const int n = c.model.node_index(std::stoi(id));
    ASSERT_GE(n, 0);
    EXPECT_EQ(c.model.nodes()[n].x.x(), xy[0].get<double>());
    EXPECT_EQ(c.model.nodes()[n].x.y(), xy[1].get<double>());
  }
  ASSERT_EQ(c.model.elements().size(), ref["elements"].size());
  for (const auto& [id, e] : ref["elements"].items()) {
    const int k = c.model.element_index(std::stoi(id));
    ASSERT_GE(k, 0);
    EXPECT_EQ(c.model.elements()[k].node_ids[0], e["nodes"][0].get<int>());
    EXPECT_EQ(c.model.elements()[k].node_ids[1], e["nodes"][1].get<int>());
  }
}

}  // namespace
}  // namespace dynid
