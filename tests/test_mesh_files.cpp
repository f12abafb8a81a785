// Mesh files (Gmsh .msh, Abaqus .inp): the paper frame read from every format gives the frequencies of the
// case-format model; bad files give InputErrors naming the file, the line (or byte) and the entity.
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dynid/engine/modal.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/mesh_files.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

std::string MeshDir() { return test::CasesDir() + "/../tests/data/mesh"; }

using test::Slurp;

/// Writes `text` to a file in a scratch folder (removed when the test program ends) and returns its path.
std::string Write(const std::string& name, const std::string& text) {
  static const test::ScratchDir dir("mesh-files");
  return dir.write(name, text);
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return p == std::string::npos ? s : s.replace(p, from.size(), to);
}

/// 1-based line of the first occurrence of `part` in `text`.
int LineOf(const std::string& text, const std::string& part) {
  const auto p = text.find(part);
  EXPECT_NE(p, std::string::npos) << part;
  return static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(p), '\n')) + 1;
}

/// The paper-frame-gmsh case with its mesh file replaced by `mesh` (an absolute path).
std::string GmshCase(const std::string& mesh) {
  return Replace(Slurp(test::CasesDir() + "/paper-frame-gmsh/case.yaml"), "file: frame.msh", "file: " + mesh);
}

using test::ErrorOf;
std::string MeshError(const std::string& path) {
  return ErrorOf([&] { read_mesh_file(path); });
}

Eigen::VectorXd Frequencies(const Model& m) {
  const ModalResult r = modal_analysis(m, [] {
    EigenOptions o;
    o.num_modes = 8;
    return o;
  }());
  EXPECT_TRUE(r.ok());
  return r.frequencies_hz;
}

void ExpectSameModel(const Model& a, const Model& b, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(a.nodes().size(), b.nodes().size());
  for (const Node& n : a.nodes()) {
    const int k = b.node_index(n.id);
    ASSERT_GE(k, 0) << "node " << n.id;
    EXPECT_EQ(b.nodes()[k].x, n.x) << "node " << n.id;
  }
  ASSERT_EQ(a.elements().size(), b.elements().size());
  for (const Element& e : a.elements()) {
    const int k = b.element_index(e.id);
    ASSERT_GE(k, 0) << "element " << e.id;
    EXPECT_EQ(b.elements()[k].node_ids, e.node_ids) << "element " << e.id;
    EXPECT_EQ(b.elements()[k].type, e.type) << "element " << e.id;
  }
  EXPECT_EQ(a.num_dofs(), b.num_dofs());
}

TEST(MeshFiles, PaperFrameSameFrequencies) {
  const Case ref = load_case(test::CasesDir() + "/paper-frame");
  const Eigen::VectorXd f0 = Frequencies(ref.model);
  ASSERT_EQ(f0.size(), 8);
  EXPECT_TRUE(test::RelClose(f0[0], 0.6496, 1e-4));
  std::vector<std::pair<std::string, Case>> cases;
  cases.emplace_back("gmsh 4.1 ASCII", load_case(test::CasesDir() + "/paper-frame-gmsh"));
  cases.emplace_back("abaqus", load_case(test::CasesDir() + "/paper-frame-abaqus"));
  for (const char* f : {"paper-frame-41-bin.msh", "paper-frame-22.msh", "paper-frame-22-bin.msh"})
    cases.emplace_back(f, parse_case(GmshCase(MeshDir() + "/" + f), "case.yaml"));
  for (const auto& [what, c] : cases) {
    ExpectSameModel(ref.model, c.model, what);
    const Eigen::VectorXd f = Frequencies(c.model);
    ASSERT_EQ(f.size(), 8) << what;
    for (int k = 0; k < 8; ++k) EXPECT_TRUE(test::RelClose(f[k], f0[k], 1e-10)) << what << " mode " << k + 1;
  }
  // What the Abaqus file holds beyond the model is reported, not dropped.
  const Case& abq = cases[1].second;
  ASSERT_EQ(abq.notes.size(), 3u);
  EXPECT_HAS(abq.notes[0], "frame.inp: skipped *STEP (line 73)");
}

TEST(MeshFiles, GmshGroupsAndSkippedElements) {
  const MeshData m = read_gmsh(test::CasesDir() + "/paper-frame-gmsh/frame.msh");
  EXPECT_EQ(m.nodes.size(), 24u);
  EXPECT_EQ(m.elements.size(), 31u);
  ASSERT_NE(m.find_group("base"), nullptr);
  EXPECT_EQ(m.find_group("base")->nodes, (std::vector<int>{1, 2, 3, 4}));
  EXPECT_EQ(m.find_group("columns")->elements.size(), 20u);
  EXPECT_EQ(m.find_group("Columns"), nullptr);  // Gmsh names are case-sensitive
  EXPECT_EQ(m.elements[30].group, "beams");
  // A 2.2 file with a triangle and a $NodeData section: both skipped and reported.
  const std::string p = Write("tri.msh",
                              "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                              "$Elements\n3\n1 1 2 0 1 1 2\n2 2 2 0 1 1 2 3\n3 99 2 0 1 1 2 3 1\n$EndElements\n"
                              "$NodeData\n1\n\"t\"\n$EndNodeData\n");
  const MeshData t = read_gmsh(p);
  EXPECT_EQ(t.elements.size(), 1u);
  ASSERT_EQ(t.skipped.size(), 3u);
  EXPECT_EQ(t.skipped[0], "section $NodeData");
  EXPECT_EQ(t.skipped[1], "1 element of 3-node triangle (only 2-node lines and points are used)");
  EXPECT_EQ(t.skipped[2], "1 element of type 99 (only 2-node lines and points are used)");
}

TEST(MeshFiles, TruncatedNodes) {
  const std::string good = Slurp(test::CasesDir() + "/paper-frame-gmsh/frame.msh");
  // A node block missing: the section ends before the 24 declared nodes.
  std::string bad = Replace(good, "0 24 0 1\n24\n3.0 5.0 0.0\n", "");
  std::string e = MeshError(Write("truncated.msh", bad));
  EXPECT_HAS(e, "truncated.msh:" + std::to_string(LineOf(bad, "$EndNodes")) + ": ");
  EXPECT_HAS(e, "$Nodes: entity dimension: expected a number, found '$EndNodes' (the section is truncated)");
  // The file cut inside $Nodes.
  bad = good.substr(0, good.find("0 12 0 1", good.find("$Nodes")));
  e = MeshError(Write("cut.msh", bad));
  EXPECT_HAS(e, "cut.msh:");
  EXPECT_HAS(e, "the file ends here (truncated?)");
  // Binary: cut inside the last node block (its declared size no longer fits), or inside its coordinates
  // (2.2: one record per node).
  const std::string bin = Slurp(MeshDir() + "/paper-frame-41-bin.msh");
  e = MeshError(Write("cut-bin.msh", bin.substr(0, bin.find("$EndNodes") - 20)));
  EXPECT_HAS(e, "cut-bin.msh: byte 4775: $Nodes: nodes in block is 1, but only 13 bytes follow");
  const std::string bin22 = Slurp(MeshDir() + "/paper-frame-22-bin.msh");
  e = MeshError(Write("cut-bin22.msh", bin22.substr(0, bin22.find("$EndNodes") - 10)));
  EXPECT_HAS(e, "cut-bin22.msh: byte ");
  EXPECT_HAS(e, ": node 24 coordinate: the file ends inside the binary data (truncated)");
}

TEST(MeshFiles, ElementWithMissingNode) {
  std::string bad = Replace(Slurp(test::CasesDir() + "/paper-frame-gmsh/frame.msh"), "\n31 22 23\n", "\n31 22 99\n");
  std::string e = MeshError(Write("missing-node.msh", bad));
  EXPECT_HAS(e, "missing-node.msh:" + std::to_string(LineOf(bad, "31 22 99")) + ": element 31: node 99 does not exist");
  bad = Replace(Slurp(MeshDir() + "/paper-frame-22.msh"), "\n9 1 2 2 9 9 13\n", "\n9 1 2 2 9 9 130\n");
  e = MeshError(Write("missing-node-22.msh", bad));
  EXPECT_HAS(e, "missing-node-22.msh:" + std::to_string(LineOf(bad, "9 9 130")) + ": element 9: node 130 does not exist");
  bad = Replace(Slurp(test::CasesDir() + "/paper-frame-abaqus/frame.inp"), "\n31, 22, 23\n", "\n31, 22, 77\n");
  e = MeshError(Write("missing-node.inp", bad));
  EXPECT_HAS(e, "missing-node.inp:" + std::to_string(LineOf(bad, "31, 22, 77")) + ": element 31: node 77 does not exist");
}

TEST(MeshFiles, UnknownPhysicalGroupInCase) {
  const std::string text = Replace(GmshCase(test::CasesDir() + "/paper-frame-gmsh/frame.msh"), "    beams:", "    beam:");
  const std::string e = ErrorOf([&] { parse_case(text, "case.yaml"); });
  EXPECT_HAS(e, "case.yaml:" + std::to_string(LineOf(text, "    beam:")) + ":");
  EXPECT_HAS(e, "group 'beam' is not in ");
  EXPECT_HAS(e, "frame.msh (its groups: base, beams, columns)");
  // An element no group gives a section names the element where the mesh defines it.
  const std::string no_beams = Replace(text, "    beam: {section: member, material: steel}\n", "");
  const std::string e2 = ErrorOf([&] { parse_case(no_beams, "case.yaml"); });
  EXPECT_HAS(e2, "frame.msh:");
  EXPECT_HAS(e2, ": element 21: no material: assign one in the case file");
}

TEST(MeshFiles, WrongEndiannessMarker) {
  std::string bin = Slurp(MeshDir() + "/paper-frame-41-bin.msh");
  const std::string head = "4.1 1 8\n";
  const std::size_t at = bin.find(head) + head.size();
  bin.replace(at, 4, std::string("\0\0\0\1", 4));  // 1 written big-endian
  std::string e = MeshError(Write("big-endian.msh", bin));
  EXPECT_HAS(e, "big-endian.msh: byte " + std::to_string(at) + ": $MeshFormat: the binary endianness marker reads 16777216, not 1");
  EXPECT_HAS(e, "other byte order");
  bin.replace(at, 4, std::string("\7\0\0\0", 4));
  e = MeshError(Write("bad-marker.msh", bin));
  EXPECT_HAS(e, "marker reads 7, not 1: the file was corrupted");
}

TEST(MeshFiles, HugeDeclaredCountInTinyFile) {
  const std::string fmt = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  std::string e = MeshError(Write("huge.msh", fmt + "$Nodes\n1 4000000000000 1 4000000000000\n0 1 0 1\n1\n0 0 0\n$EndNodes\n"));
  EXPECT_HAS(e, "huge.msh:5: $Nodes: number of nodes is 4000000000000, but only ");
  EXPECT_HAS(e, "bytes follow (a corrupt or truncated file?)");
  e = MeshError(Write("huge22.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2000000000\n1 0 0 0\n$EndNodes\n"));
  EXPECT_HAS(e, "huge22.msh:5: $Nodes: number of nodes is 2000000000");
  // Binary: a huge size_t node count.
  std::string bin = Slurp(MeshDir() + "/paper-frame-41-bin.msh");
  const std::size_t at = bin.find("$Nodes\n") + 7 + 8;  // after the block count
  const std::uint64_t huge = 1ull << 60;
  bin.replace(at, 8, std::string(reinterpret_cast<const char*>(&huge), 8));
  e = MeshError(Write("huge-bin.msh", bin));
  EXPECT_HAS(e, "huge-bin.msh: byte " + std::to_string(at) + ": $Nodes: number of nodes is 1152921504606846976");
  // Abaqus GENERATE ranges are bounded too.
  e = MeshError(Write("huge.inp", "*NODE\n1, 0, 0\n*NSET, NSET=ALL, GENERATE\n1, 2000000000, 1\n"));
  EXPECT_HAS(e, "huge.inp:4: *NSET, GENERATE: more than 10^7 ids");
}

const char* kSpaceFrame = R"(** a two-member space frame
*heading
test
*Node, nset=all
1, 0., 0., 0.
2, 0., 0., 3.
3, 4., 0., 3.
*INCLUDE, INPUT=members.inp
*Elset, elset=posts, generate
1, 1, 1
*ELSET, ELSET=Everything
posts, girders
*Material, name=Steel
*Elastic
2.1e11, 0.3
*Density
7850.
*Damping, alpha=0.1
*Beam Section, elset=POSTS, material=steel, section=RECT
0.2, 0.4
1., 0., 0.
*BEAM SECTION, ELSET=girders, MATERIAL=STEEL,
 SECTION=CIRC
0.05
0., 0., 1.
*BOUNDARY
1, 1, 6
*Element, type=S4R, elset=shells
9, 1, 2, 3, 1
)";

TEST(MeshFiles, AbaqusSubset) {
  Write("members.inp", "*ELEMENT, TYPE=B31, ELSET=GIRDERS\n2, 2,\n 3\n*element, type=b33\n1, 1, 2\n");
  const MeshData m = read_abaqus(Write("space.inp", kSpaceFrame));
  ASSERT_EQ(m.elements.size(), 2u);
  EXPECT_EQ(m.elements[0].id, 2);  // continuation line joined
  EXPECT_EQ(m.elements[0].nodes, (std::array<int, 2>{{2, 3}}));
  EXPECT_EQ(*m.elements[1].type, ElementType::Frame3D);
  ASSERT_NE(m.find_group("everything"), nullptr);
  EXPECT_EQ(m.find_group("EveryThing")->elements, (std::vector<int>{1, 2}));
  ASSERT_EQ(m.restraints.size(), 1u);
  EXPECT_EQ(m.restraints[0], (std::pair<int, DofMask>{1, kAllDofs}));
  ASSERT_EQ(m.skipped.size(), 2u);
  EXPECT_EQ(m.skipped[0], "*DAMPING (line 18)");
  EXPECT_EQ(m.skipped[1], "1 elements of TYPE=S4R (line 28; only B21, B23, B31, B33 are used)");
  // Sections: RECT a = 0.2 (1-direction), b = 0.4: I11 = a b^3 / 12 about n1 = dynid's local z.
  const Case c = parse_case("model: {file: " + Write("space-case.inp", kSpaceFrame) + "}\nanalysis: {modes: 3}\n", "case.yaml");
  const Model& model = c.model;
  const Section& post = model.sections()[model.elements()[model.element_index(1)].section];
  EXPECT_DOUBLE_EQ(post.A, 0.08);
  EXPECT_DOUBLE_EQ(post.Iz, 0.2 * 0.4 * 0.4 * 0.4 / 12);
  EXPECT_DOUBLE_EQ(post.Iy, 0.4 * 0.2 * 0.2 * 0.2 / 12);
  const Element& girder = model.elements()[model.element_index(2)];
  EXPECT_EQ(girder.orientation, Eigen::Vector3d(0, 0, 1));
  EXPECT_DOUBLE_EQ(model.sections()[girder.section].Iz, M_PI * std::pow(0.05, 4) / 4);
  EXPECT_EQ(model.materials()[girder.material].name, "STEEL");
  EXPECT_EQ(model.materials()[girder.material].rho, 7850.0);
  EXPECT_EQ(model.num_dofs(), 12);
  EXPECT_TRUE(modal_analysis(model, c.analysis.eigen_options()).ok());
}

TEST(MeshFiles, B31WithoutDirectionLine) {
  const std::string text = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n*ELEMENT, TYPE=B31, ELSET=BARS\n7, 1, 2\n"
                           "*MATERIAL, NAME=STEEL\n*ELASTIC\n2.1e11, 0.3\n*DENSITY\n7850\n"
                           "*BEAM SECTION, ELSET=BARS, MATERIAL=STEEL, SECTION=RECT\n0.1, 0.2\n*BOUNDARY\n1, ENCASTRE\n";
  const std::string p = Write("no-direction.inp", text);
  const std::string e = ErrorOf([&] { parse_case("model: {file: " + p + "}\n", "case.yaml"); });
  EXPECT_HAS(e, "no-direction.inp:5: element 7: no beam orientation: give the n1 direction as the second data line of "
                "its *BEAM SECTION");
  // With the direction line, or an orientation node, it loads.
  const std::string with_line = Replace(text, "0.1, 0.2\n", "0.1, 0.2\n0, 0, -1\n");
  EXPECT_EQ(ErrorOf([&] { parse_case("model: {file: " + Write("direction.inp", with_line) + "}\n", "case.yaml"); }), "(no error)");
  const std::string with_node = Replace(Replace(text, "7, 1, 2\n", "7, 1, 2, 3\n"), "2, 1, 0, 0\n", "2, 1, 0, 0\n3, 0, 1, 0\n");
  const Case c = parse_case("model: {file: " + Write("node.inp", with_node) + "}\n", "case.yaml");
  EXPECT_EQ(c.model.elements()[0].orientation, Eigen::Vector3d(0, 1, 0));
}

TEST(MeshFiles, AbaqusErrorsNameLineAndEntity) {
  const std::string base = "*NODE\n1, 0, 0\n2, 1, 0\n*ELEMENT, TYPE=B21, ELSET=E\n1, 1, 2\n";
  EXPECT_HAS(MeshError(Write("a.inp", base + "*BEAM SECTION, ELSET=E, MATERIAL=NONE, SECTION=RECT\n1, 1\n")),
             "a.inp:6: *BEAM SECTION: material 'NONE' is not defined");
  EXPECT_HAS(MeshError(Write("b.inp", base + "*BEAM SECTION, ELSET=E, SECTION=I, MATERIAL=M\n1, 1\n*MATERIAL, NAME=M\n")),
             "b.inp:6: *BEAM SECTION: SECTION=I is not supported");
  EXPECT_HAS(MeshError(Write("c.inp", base + "*BOUNDARY\n1, 1, 2, 0.5\n")),
             "c.inp:7: *BOUNDARY: prescribed nonzero displacements are not supported");
  EXPECT_HAS(MeshError(Write("d.inp", base + "*ELSET, ELSET=X\nNOPE\n")),
             "d.inp:7: *ELSET X: 'NOPE' is neither an id nor a set defined above");
  EXPECT_HAS(MeshError(Write("e.inp", base + "*INCLUDE, INPUT=nowhere.inp\n")), "e.inp:6: *INCLUDE: cannot open");
  EXPECT_HAS(MeshError(Write("f.inp", "*NODE\n1, 0, 0\n1, 1, 0\n")), "f.inp:3: node 1 is defined twice");
}

}  // namespace
}  // namespace dynid
