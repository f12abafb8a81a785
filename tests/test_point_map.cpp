// Measurement points tied to model nodes (dynid/io/point_map.hpp): a test geometry in millimetres with its own
// point ids (UFF 164 + 15) and measured modes at those points (UFF 55), mapped onto the paper frame by position,
// must give the same detection as the same modes labelled with model node ids (the reference: no mapping at
// all); and each way the mapping can fail is named.
#include <gtest/gtest.h>

#include <filesystem>

#include "dynid/engine/detect.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/modal_data_io.hpp"
#include "dynid/io/point_map.hpp"
#include "dynid/io/uff.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

using test::ErrorOf;


class PointMap : public ::testing::Test {
 protected:
  void SetUp() override {
    frame_ = load_case(test::CasesDir() + "/paper-frame-damage/element28-case3.yaml");
    // The damaged frame's first 6 modes at the x and y translations of every free node, labelled with model ids.
    const Model damaged = changed_model(frame_.model, {{28, {-0.15, -0.15}}});
    EigenOptions o;
    o.num_modes = 6;
    const ModalResult r = modal_analysis(damaged, o);
    truth_ = sample_modes(damaged, r, dofs_of_types(frame_.model, dof_bit(Dof::UX) | dof_bit(Dof::UY)), 0, 6, "test");
    write_modal_data(Path("truth.json"), truth_, true);
    // The same modes at test points 1000 + node, geometry in mm, each point 0.4 mm off its node.
    ModalData test = truth_;
    for (MeasuredDof& q : test.dofs) q.node += 1000;
    UffNodes pts;
    for (const Node& n : frame_.model.nodes()) {
      UffNode p;
      p.id = n.id + 1000;
      p.x = 1000.0 * n.x + Eigen::Vector3d(0.4, 0, 0);
      pts.nodes.push_back(p);
    }
    UffUnits mm;
    mm.code = 9;
    mm.description = "mm";
    mm.length = 1e-3;
    std::vector<UffDataset> geom(2);
    geom[0].type = 164, geom[0].data = mm;
    geom[1].type = 15, geom[1].data = pts;
    write_uff(Path("points.uff"), geom, true);
    write_uff55(Path("modes.uff"), test, true);
  }
  std::string Path(const std::string& f) const { return scratch_.path(f); }
  Case Detect(const std::string& measured, const std::string& geometry) const {
    const std::string text = "name: t\nmodel: {include: " + test::CasesDir() + "/paper-frame/case.yaml}\n"
                             "detect:\n  modes: 4\n  measured: " + measured + "\n" + (geometry.empty() ? "" : "  geometry: " + geometry + "\n");
    return load_case(scratch_.write("t.yaml", text));
  }
  const test::ScratchDir scratch_{"points"};
  Case frame_;
  ModalData truth_;
};

// Same detection to 1e-12 (the mapped data are the same numbers on the same DOFs; UFF 55 stores 13 significant
// digits, hence not bitwise): element 28 first, dk and dm equal.
TEST_F(PointMap, MappedByPositionGivesTheSameDetection) {
  const Case plain = Detect(Path("truth.json"), "");
  const Case mapped = Detect(Path("modes.uff"), "{file: " + Path("points.uff") + ", tolerance: 0.001}");
  const ModalData a = detect_changed_data(plain, nullptr), b = detect_changed_data(mapped, nullptr);
  ASSERT_EQ(a.dofs.size(), b.dofs.size());
  for (std::size_t k = 0; k < a.dofs.size(); ++k) EXPECT_EQ(a.dofs[k], b.dofs[k]);
  const DetectSummary sa = detect(plain.model, a, plain.detect->options), sb = detect(mapped.model, b, mapped.detect->options);
  ASSERT_FALSE(sb.elements.empty());
  EXPECT_EQ(sb.elements.front().element, 28);
  EXPECT_EQ(sa.elements.front().element, sb.elements.front().element);
  ASSERT_EQ(sa.amounts.size(), sb.amounts.size());
  ASSERT_FALSE(sb.amounts.empty());
  EXPECT_NEAR(sa.amounts[0].dk, sb.amounts[0].dk, 1e-9);
  EXPECT_NEAR(sa.amounts[0].dm, sb.amounts[0].dm, 1e-9);
  std::vector<std::string> notes;
  const auto map = map_test_points(frame_.model, read_uff(Path("points.uff")), GeometrySpec{"", true, 0.001}, &notes);
  EXPECT_EQ(map.at(1020), 20);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_HAS(notes[0], "24 test points mapped to model nodes by position, largest distance 0.0004 (tolerance 0.001)");
}

TEST_F(PointMap, MismatchesAreNamed) {
  const UffFile g = read_uff(Path("points.uff"));
  // Default tolerance: 1 % of the 5 m frame = 0.05 m; 0.0001 m is too tight for the 0.4 mm offsets.
  EXPECT_HAS(ErrorOf([&] { map_test_points(frame_.model, g, GeometrySpec{"", true, 1e-4}); }),
             "test point 1001 at (0.0004, 0, 0) (coordinates scaled by the file's length factor 0.001 to metres) is 0.0004 "
             "from the nearest model node 1, more than the tolerance 0.0001");
  EXPECT_HAS(ErrorOf([&] { map_test_points(frame_.model, g, GeometrySpec{"", false, 0}); }),
             "test point 1001 is not a model node (geometry: match: id); use match: position");
  // A tolerance so loose that two points land on one node.
  UffFile two = g;
  std::get<UffNodes>(two.datasets[1].data).nodes[1].x = std::get<UffNodes>(two.datasets[1].data).nodes[0].x;
  EXPECT_HAS(ErrorOf([&] { map_test_points(frame_.model, two, GeometrySpec{}); }), "test points 1001 and 1002 both map to model node 1");
  // Measured DOFs at a point the geometry lacks.
  ModalData d = truth_;
  EXPECT_HAS(ErrorOf([&] { relabel_points({{1005, 5}}, "modes.uff", &d); }),
             "modes.uff: DOF 5ux is at test point 5, which the test geometry does not define");
  // Case-file errors name the line.
  EXPECT_HAS(ErrorOf([&] { Detect(Path("modes.uff"), "{file: " + Path("points.uff") + ", match: nearest}"); }),
             "t.yaml:6:");
  EXPECT_HAS(ErrorOf([&] { Detect(Path("modes.uff"), "{file: " + Path("points.uff") + ", match: nearest}"); }),
             "geometry: match must be position or id, got 'nearest'");
}

}  // namespace
}  // namespace dynid
