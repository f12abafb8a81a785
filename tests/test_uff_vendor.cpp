// Vendor UFF coverage (issue 18): dataset 2414 (FE mode shapes as NX, Simcenter and Permas export them) and the
// coordinate systems of datasets 18 and 2420 applied to 15/2411 points and to 55/2414 shape directions. The files
// are written here, by a small writer that follows the datasets' documented layouts (the I-DEAS/SDRL descriptions
// quoted in dynid/io/uff.hpp), independently of dynid's own UFF writer; expected values are computed here from
// rotation matrices and angles, not by the reader's code.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <map>
#include <string>

#include "dynid/io/point_map.hpp"
#include "dynid/io/uff.hpp"
#include "dynid/mesh/error.hpp"
#include "test_util.hpp"

namespace dynid {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Some note contains `part`.
#define EXPECT_HAS_NOTE(notes, part)                                                              \
  do {                                                                                            \
    std::string all;                                                                              \
    for (const std::string& n_ : notes) all += n_ + "\n";                                        \
    EXPECT_NE(all.find(part), std::string::npos) << "notes:\n" << all;                           \
  } while (0)

std::string line(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string line(const char* fmt, ...) {
  char b[512];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(b, sizeof b, fmt, ap);
  va_end(ap);
  return std::string(b) + "\n";
}

std::string open(int type) { return line("%6d", -1) + line("%6d", type); }
std::string close() { return line("%6d", -1); }

// 2414, data at nodes: records 1-13, then record 14 (node) and 15 (6E13.5 values, six per line) per node.
struct Shape2414 {
  int analysis_type = 2, data_characteristic = 3, data_type = 2, nvaldc = 6, mode = 1;
  double frequency = 0, damping = 0;
  double lambda_re = 0, lambda_im = 0;  // complex modes
  std::vector<int> nodes;
  std::vector<std::vector<double>> values;  // per node: nvaldc (re, im pairs when complex) values
};

std::string write2414(const Shape2414& s, bool truncate = false) {
  std::string t = open(2414);
  t += line("%10d", s.mode);
  t += line("%-80s", "Mode shape record");
  t += line("%10d", 1);  // data at nodes
  for (const char* id : {"Model: test frame", "Run: modes", "24-Nov-25", "LoadCase 1", "NONE"}) t += line("%-80s", id);
  t += line("%10d%10d%10d%10d%10d%10d", 1, s.analysis_type, s.data_characteristic, 8, s.data_type, s.nvaldc);
  t += line("%10d%10d%10d%10d%10d%10d%10d%10d", 0, 0, 1, 0, 0, s.mode, 0, 0);
  t += line("%10d%10d", 0, 0);
  t += line("%13.5E%13.5E%13.5E%13.5E%13.5E%13.5E", 0.0, s.frequency, 0.0, 1.0, s.damping, 0.0);
  t += line("%13.5E%13.5E%13.5E%13.5E%13.5E%13.5E", s.lambda_re, s.lambda_im, 0.0, 0.0, 0.0, 0.0);
  for (std::size_t n = 0; n < s.nodes.size(); ++n) {
    t += line("%10d", s.nodes[n]);
    std::string l;
    const std::size_t count = truncate && n + 1 == s.nodes.size() ? s.values[n].size() / 2 : s.values[n].size();
    for (std::size_t k = 0; k < count; ++k) {
      char b[32];
      std::snprintf(b, sizeof b, "%13.5E", s.values[n][k]);
      l += b;
      if (k % 6 == 5 || k + 1 == count) t += l + "\n", l.clear();
    }
  }
  return truncate ? t : t + close();
}

// 15: 4I10,3E13.5 per node.
std::string write15(const std::vector<UffNode>& nodes) {
  std::string t = open(15);
  for (const UffNode& n : nodes)
    t += line("%10d%10d%10d%10d%13.5E%13.5E%13.5E", n.id, n.definition_cs, n.displacement_cs, 8, n.x[0], n.x[1], n.x[2]);
  return t + close();
}

// 2411: 4I10 then 3D25.16 per node.
std::string write2411(const std::vector<UffNode>& nodes) {
  std::string t = open(2411);
  for (const UffNode& n : nodes) {
    t += line("%10d%10d%10d%10d", n.id, n.definition_cs, n.displacement_cs, 11);
    std::string c = line("%25.16E%25.16E%25.16E", n.x[0], n.x[1], n.x[2]);
    for (char& ch : c)
      if (ch == 'E') ch = 'D';  // Fortran D exponents, as I-DEAS writes them
    t += c;
  }
  return t + close();
}

// 18: per system 5I10, name, 6E13.5 (origin, +x point), 3E13.5 (+xz point), in the reference system.
struct Cs18 {
  int id, type, reference;
  Eigen::Vector3d origin, xpoint, xzpoint;
};
std::string write18(const std::vector<Cs18>& systems) {
  std::string t = open(18);
  for (const Cs18& s : systems) {
    t += line("%10d%10d%10d%10d%10d", s.id, s.type, s.reference, 8, 1);
    t += line("%-40s", ("SYS" + std::to_string(s.id)).c_str());
    t += line("%13.5E%13.5E%13.5E%13.5E%13.5E%13.5E", s.origin[0], s.origin[1], s.origin[2], s.xpoint[0], s.xpoint[1], s.xpoint[2]);
    t += line("%13.5E%13.5E%13.5E", s.xzpoint[0], s.xzpoint[1], s.xzpoint[2]);
  }
  return t + close();
}

// 2420: part UID, part name, then per system 3I10, name, 4 rows of 1P3D25.16 (local axes as rows, origin).
std::string write2420(const std::vector<std::tuple<int, int, Eigen::Matrix3d, Eigen::Vector3d>>& systems) {
  std::string t = open(2420);
  t += line("%10d", 1);
  t += line("%-80s", "Part1");
  for (const auto& [id, type, axes, origin] : systems) {
    t += line("%10d%10d%10d", id, type, 8);
    t += line("%-80s", ("CS" + std::to_string(id)).c_str());
    for (int r = 0; r < 3; ++r) t += line("%25.16E%25.16E%25.16E", axes(0, r), axes(1, r), axes(2, r));
    t += line("%25.16E%25.16E%25.16E", origin[0], origin[1], origin[2]);
  }
  return t + close();
}

Eigen::Matrix3d rot(const Eigen::Vector3d& axis, double deg) {
  return Eigen::AngleAxisd(deg * kPi / 180, axis.normalized()).toRotationMatrix();
}

UffNode node(int id, int def, int disp, double x, double y, double z) {
  UffNode n;
  n.id = id;
  n.definition_cs = def;
  n.displacement_cs = disp;
  n.x = Eigen::Vector3d(x, y, z);
  return n;
}

// E13.5 keeps 6 significant digits: values agree to half a unit in the last (5e-6 relative) plus rounding.
constexpr double kE13 = 6e-6;

TEST(Uff2414, NormalModesSixDofRealSingle) {
  std::string file;
  const double f[2] = {12.345, 67.891}, zeta[2] = {0.012, 0.034};
  std::vector<std::vector<double>> shapes[2];
  for (int m = 0; m < 2; ++m) {
    Shape2414 s;
    s.mode = m + 1;
    s.frequency = f[m];
    s.damping = zeta[m];
    s.nodes = {3, 7, 11};
    for (int n = 0; n < 3; ++n) {
      std::vector<double> v;
      for (int j = 0; j < 6; ++j) v.push_back(std::sin(1.0 + m + 0.7 * n + 0.3 * j));
      s.values.push_back(v);
    }
    shapes[m] = s.values;
    file += write2414(s);
  }
  const UffFile u = parse_uff(file, "modes-2414.unv");
  ASSERT_EQ(u.datasets.size(), 2u);
  const Uff2414& d = std::get<Uff2414>(u.datasets[0].data);
  EXPECT_EQ(d.analysis_type, 2);
  EXPECT_EQ(d.data_characteristic, 3);
  EXPECT_EQ(d.result_type, 8);
  EXPECT_EQ(d.mode_number(), 1);
  EXPECT_EQ(d.location, 1);
  const ModalData md = uff_modal_data(u);
  ASSERT_EQ(md.num_modes(), 2);
  ASSERT_EQ(md.dofs.size(), 18u);  // 3 nodes x 6 DOFs
  for (int m = 0; m < 2; ++m) {
    EXPECT_TRUE(test::RelClose(md.frequencies_hz[m], f[m], kE13));
    EXPECT_TRUE(test::RelClose(md.damping_ratios[m], zeta[m], kE13));
    for (int n = 0; n < 3; ++n)
      for (int j = 0; j < 6; ++j) EXPECT_NEAR(md.shapes(6 * n + j, m), shapes[m][n][j], kE13) << m << " " << n << " " << j;
  }
  EXPECT_EQ(md.dofs[7].node, 7);
  EXPECT_EQ(md.dofs[7].dof, Dof::UY);
}

TEST(Uff2414, NxComplexSingleThreeDofAndComplexModes) {
  // NX writes normal modes as complex single (data type 5) three-DOF vectors with zero imaginary parts.
  Shape2414 s;
  s.data_characteristic = 2;
  s.data_type = 5;
  s.nvaldc = 3;
  s.frequency = 23383.2;
  s.nodes = {3992, 9581};
  s.values = {{1.95655E-02, 0, 1.30354E+01, 0, -1.92335E-07, -0.0}, {1.56530E-01, 0, 1.31011E+01, 0, -3.29940E-05, 0}};
  // A complex mode (analysis type 3): eigenvalue -sigma + i omega, shape rotated by 40 degrees.
  Shape2414 c;
  c.analysis_type = 3;
  c.data_characteristic = 2;
  c.data_type = 5;
  c.nvaldc = 3;
  c.mode = 2;
  const double wn = 2 * kPi * 31.5, zeta = 0.02;
  c.lambda_re = -zeta * wn;
  c.lambda_im = wn * std::sqrt(1 - zeta * zeta);
  c.nodes = {3992, 9581};
  const std::complex<double> phase = std::polar(1.0, 40 * kPi / 180);
  const double real[2][3] = {{0.2, -1.0, 0.5}, {0.8, 0.3, -0.1}};
  for (int n = 0; n < 2; ++n) {
    std::vector<double> v;
    for (int j = 0; j < 3; ++j) v.push_back((phase * real[n][j]).real()), v.push_back((phase * real[n][j]).imag());
    c.values.push_back(v);
  }
  const UffFile u = parse_uff(write2414(s) + write2414(c), "nx.unv");
  const ModalData md = uff_modal_data(u);
  ASSERT_EQ(md.num_modes(), 2);
  EXPECT_TRUE(test::RelClose(md.frequencies_hz[0], 23383.2, kE13));
  EXPECT_TRUE(test::RelClose(md.frequencies_hz[1], 31.5, 1e-5));
  EXPECT_TRUE(test::RelClose(md.damping_ratios[1], zeta, 1e-4));
  ASSERT_EQ(md.dofs.size(), 6u);
  EXPECT_NEAR(md.shapes(1, 0), 1.30354E+01, 1e-9);
  // The complex shape rotated back to real: proportional to `real` (largest entry -1.0 turned positive).
  for (int n = 0; n < 2; ++n)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(md.shapes(3 * n + j, 1), -real[n][j], 2e-5) << n << j;
}

TEST(Uff2414, TruncatedDatasetKeepsItsPreciseError) {
  Shape2414 s;
  s.frequency = 5;
  s.nodes = {1, 2, 7};
  s.values = {{1, 2, 3, 4, 5, 6}, {1, 2, 3, 4, 5, 6}, {1, 2, 3, 4, 5, 6}};
  const std::string text = write2414(s, true);
  EXPECT_HAS(test::ErrorOf([&] { parse_uff(text, "cut.unv"); }),
             "cut.unv: dataset 2414 starting at line 1, record 15 (line 21): node 7: expected 6 values, found 3 (file truncated?)");
  // A header cut short, and an unknown data type.
  EXPECT_HAS(test::ErrorOf([&] { parse_uff(text.substr(0, text.find("Run:")), "head.unv"); }), "head.unv: dataset 2414 starting at line 1, record 5 (line 6): the header has 4 of its 13 records (file truncated?)");
  std::string bad = write2414(s);
  bad.replace(bad.find("         8         2         6"), 30, "         8         3         6");
  EXPECT_HAS(test::ErrorOf([&] { parse_uff(bad, "type.unv"); }), "type.unv: dataset 2414 starting at line 1, record 9 (line 11): data type (field 5) must be 1, 2, 4, 5 or 6, found 3");
}

TEST(UffCoordinateSystems, PointsInARotatedCartesianSystem18) {
  // System 5: origin (1, 2, 0.5), rotated 30 degrees about z and then 90 about its own x (local z = global -y').
  const Eigen::Matrix3d R = rot(Eigen::Vector3d::UnitZ(), 30) * rot(Eigen::Vector3d::UnitX(), 90);
  const Eigen::Vector3d o(1, 2, 0.5);
  const Cs18 cs{5, 0, 0, o, o + 2.0 * R.col(0), o + 1.5 * R.col(0) + 3.0 * R.col(2)};
  const std::vector<Eigen::Vector3d> local = {{0.1, 0.2, 0.3}, {-1.0, 0.5, 2.0}, {0.0, 0.0, 0.0}};
  std::vector<UffNode> nodes;
  for (int k = 0; k < 3; ++k) nodes.push_back(node(k + 1, 5, 0, local[k][0], local[k][1], local[k][2]));
  nodes.push_back(node(4, 0, 0, 7, 8, 9));
  for (const bool double_precision : {false, true}) {
    const UffFile u = parse_uff(write18({cs}) + (double_precision ? write2411(nodes) : write15(nodes)), "cs18.unv");
    const UffNodes& n = std::get<UffNodes>(u.datasets[1].data);
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d expect = o + R * local[k];
      EXPECT_LT((n.nodes[k].x - expect).norm(), 1e-5) << k << ": " << n.nodes[k].x.transpose() << " vs " << expect.transpose();
      EXPECT_EQ(n.nodes[k].x_file, local[k]);
      EXPECT_TRUE(n.nodes[k].global);
    }
    EXPECT_EQ(n.nodes[3].x, Eigen::Vector3d(7, 8, 9));
    const auto& sys = std::get<UffCoordinateSystems>(u.datasets[0].data).systems[0];
    EXPECT_TRUE(sys.resolved);
    EXPECT_LT((sys.axes - R).cwiseAbs().maxCoeff(), 1e-5);  // E13.5 definition points
  }
}

TEST(UffCoordinateSystems, PointsInARotatedCylindricalSystem2420AndAChained18) {
  // 2420 system 2: cylindrical, its axis (local z) along global x, origin (0, 1, 2).
  const Eigen::Matrix3d A = rot(Eigen::Vector3d::UnitY(), 90);  // local z -> global x, local x -> global -z
  const Eigen::Vector3d o(0, 1, 2);
  // 18 system 3: Cartesian, defined by points given in system 2's cylindrical coordinates (r, theta, z).
  auto cyl = [&](double r, double t, double z) -> Eigen::Vector3d { return o + A * Eigen::Vector3d(r * std::cos(t * kPi / 180), r * std::sin(t * kPi / 180), z); };
  const Cs18 c3{3, 0, 2, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 90, 0), Eigen::Vector3d(0, 0, 4)};
  std::vector<UffNode> nodes = {node(1, 2, 0, 0.5, 0, 0), node(2, 2, 0, 2.0, 90, 1.5), node(3, 2, 0, 1.0, 225, -3),
                                node(4, 3, 0, 1.0, 0.0, 0.0)};
  const std::string text = write2420({{2, 1, A, o}}) + write18({c3}) + write15(nodes);
  const UffFile u = parse_uff(text, "cyl.unv");
  const UffNodes& n = std::get<UffNodes>(u.datasets[2].data);
  EXPECT_LT((n.nodes[0].x - cyl(0.5, 0, 0)).norm(), 1e-12);
  EXPECT_LT((n.nodes[1].x - cyl(2.0, 90, 1.5)).norm(), 1e-12);
  EXPECT_LT((n.nodes[2].x - cyl(1.0, 225, -3)).norm(), 1e-12);
  // System 3: origin at (r 1, theta 0), +x toward (r 1, theta 90): x = (cyl(1,90,0) - cyl(1,0,0)) normalised.
  const Eigen::Vector3d o3 = cyl(1, 0, 0), x3 = (cyl(1, 90, 0) - o3).normalized();
  EXPECT_LT((n.nodes[3].x - (o3 + x3)).norm(), 1e-5);
  EXPECT_HAS_NOTE(u.notes, "4 node coordinates converted from local coordinate systems to global");
}

TEST(UffCoordinateSystems, ShapeDirectionsOfA55InCylindricalDisplacementSystems) {
  // Four points on a ring of radius 2 about global z; their displacement system is cylindrical (z axis global z):
  // a purely radial mode shape (u_r = 1) must come out pointing away from the axis.
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  std::vector<UffNode> nodes;
  for (int k = 0; k < 4; ++k) {
    const double t = (30 + 90 * k) * kPi / 180;
    nodes.push_back(node(k + 1, 0, 7, 2 * std::cos(t), 2 * std::sin(t), 0.25 * k));
  }
  std::string modes = open(55);
  for (const char* id : {"radial mode", "NONE", "NONE", "NONE", "NONE"}) modes += line("%-80s", id);
  modes += line("%10d%10d%10d%10d%10d%10d", 1, 2, 2, 8, 2, 3);
  modes += line("%10d%10d%10d%10d", 2, 4, 1, 1);
  modes += line("%13.5E%13.5E%13.5E%13.5E", 42.0, 1.0, 0.01, 0.0);
  for (int k = 0; k < 4; ++k) modes += line("%10d", k + 1) + line("%13.5E%13.5E%13.5E", 1.0, 0.0, 0.5);  // u_r, u_theta, u_z
  modes += close();
  const UffFile u = parse_uff(write2420({{7, 1, I, Eigen::Vector3d::Zero()}}) + write15(nodes) + modes, "ring.unv");
  const ModalData md = uff_modal_data(u);
  ASSERT_EQ(md.dofs.size(), 12u);
  // The points' positions carry 6 significant digits (E13.5), so the radial directions do too.
  for (int k = 0; k < 4; ++k) {
    const double t = (30 + 90 * k) * kPi / 180;
    EXPECT_NEAR(md.shapes(3 * k, 0), std::cos(t), 1e-6);
    EXPECT_NEAR(md.shapes(3 * k + 1, 0), std::sin(t), 1e-6);
    EXPECT_NEAR(md.shapes(3 * k + 2, 0), 0.5, 1e-12);
  }
  EXPECT_HAS_NOTE(u.notes, "nodal vectors at 4 nodes turned from their local displacement coordinate systems to global directions");
}

TEST(UffCoordinateSystems, A2414InARotatedCartesianSystemAndASeparateGeometryFile) {
  // FE mode shapes exported in nodal systems (analysis coordinate systems): node 2's system is rotated 90 degrees
  // about z, node 3's is global. The geometry (18 + 15) comes in its own file, as test programs write it.
  const Eigen::Matrix3d R = rot(Eigen::Vector3d::UnitZ(), 90);
  const Cs18 cs{4, 0, 0, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 1, 1)};  // x -> global y
  const std::string geometry = write18({cs}) + write15({node(2, 0, 4, 1, 0, 0), node(3, 0, 0, 2, 0, 0)});
  Shape2414 s;
  s.data_characteristic = 2;
  s.nvaldc = 3;
  s.frequency = 3.5;
  s.nodes = {2, 3};
  s.values = {{1.0, 0.0, 0.25}, {0.0, 1.0, 0.0}};  // node 2: along its local x = global y
  test::ScratchDir dir("uff-vendor");
  const std::string data_path = dir.write("modes.unv", write2414(s)), geo_path = dir.write("geometry.unv", geometry);
  // Read alone, the data file cannot know node 2's system: the values are as written.
  const ModalData raw = uff_modal_data(read_uff(data_path));
  EXPECT_EQ(raw.shapes(0, 0), 1.0);
  // With the geometry: turned to global (node 2: u_x' = 1 -> global +y).
  Model model;
  model.add_node(20, Eigen::Vector3d(1, 0, 0));
  model.add_node(30, Eigen::Vector3d(2, 0, 0));
  GeometrySpec g;
  g.file = geo_path;
  std::vector<std::string> notes;
  const ModalData md = read_measured_modal_data(data_path, g, model, &notes);
  ASSERT_EQ(md.dofs.size(), 3u);  // 20uy, 20uz, 30uy (DOFs zero in every mode are left out: 20ux once turned)
  std::map<std::string, double> v;
  for (std::size_t r = 0; r < md.dofs.size(); ++r) v[to_string(md.dofs[r])] = md.shapes(static_cast<Eigen::Index>(r), 0);
  EXPECT_NEAR(v["20uy"], 1.0, 1e-5);
  EXPECT_NEAR(v["20uz"], 0.25, 1e-12);
  EXPECT_NEAR(v["30uy"], 1.0, 1e-12);
  EXPECT_EQ(v.count("20ux"), 0u);
  EXPECT_HAS_NOTE(notes, "nodal vectors at 1 nodes turned");
  (void)R;
}

TEST(UffCoordinateSystems, UndefinedSystemsAreNamed) {
  const UffFile u = parse_uff(write15({node(1, 9, 0, 1, 2, 3), node(2, 0, 0, 0, 0, 0)}), "nocs.unv");
  const UffNodes& n = std::get<UffNodes>(u.datasets[0].data);
  EXPECT_FALSE(n.nodes[0].global);
  EXPECT_EQ(n.nodes[0].x, Eigen::Vector3d(1, 2, 3));
  EXPECT_HAS_NOTE(u.notes, "nodes are defined in coordinate system 9, which the file does not define (dataset 18 or 2420)");
  Model model;
  model.add_node(1, Eigen::Vector3d(1, 2, 3));
  model.add_node(2, Eigen::Vector3d(0, 0, 0));
  GeometrySpec g;
  EXPECT_HAS(test::ErrorOf([&] { map_test_points(model, u, g); }), "nocs.unv: test point 1 is given in coordinate system 9, which the file does not define");
  g.by_position = false;
  EXPECT_EQ(map_test_points(model, u, g).at(1), 1);  // by id the position is not needed
  // A circular reference between two 18 systems, and a degenerate definition.
  const std::string loop = write18({{1, 0, 2, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}}, {2, 0, 1, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}},
                                    {3, 0, 0, {0, 0, 0}, {1, 0, 0}, {2, 0, 0}}});
  const UffFile l = parse_uff(loop, "loop.unv");
  EXPECT_HAS_NOTE(l.notes, "coordinate system 1 refers to system 2, which the file does not define (or which refers back to it)");
  EXPECT_HAS_NOTE(l.notes, "coordinate system 3: its origin, +x point and +xz point do not span a plane");
  // A 2420 matrix that is not a rotation.
  EXPECT_HAS(test::ErrorOf([&] { parse_uff(write2420({{1, 0, 2.0 * Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()}}), "scaled.unv"); }),
             "scaled.unv: dataset 2420 starting at line 1, record 5 (line 7): coordinate system 1: rows 1-3 of its transformation matrix are not a right-handed set of unit axes");
}

TEST(UffSamples, VendorCoordinateSystemsInTheSharedSamples) {
  DYNID_REQUIRE_SHARED();
  // Simcenter Test.Lab: 18 with one Cartesian system per point (its measurement directions); points in global.
  const UffFile t = read_uff(test::SharedDir() + "/data/uff-samples/TestLab 161 164 18 15 82.uff");
  const auto& systems = std::get<UffCoordinateSystems>(t.datasets[2].data).systems;
  ASSERT_EQ(systems.size(), 36u);
  // SYS1: origin (-2.4, -0.95, 0), +x toward -X, +xz plane toward -Z: a half turn about y.
  EXPECT_TRUE(systems[0].resolved);
  EXPECT_LT((systems[0].axes - rot(Eigen::Vector3d::UnitY(), 180)).cwiseAbs().maxCoeff(), 1e-6);
  const UffNodes& n = std::get<UffNodes>(t.datasets[3].data);
  EXPECT_EQ(n.nodes[6].x, Eigen::Vector3d(-1.75, 0.0, 0.1));  // defined in the global system: unchanged
  // Oros: points in system 1, which is the global one.
  const UffFile o = read_uff(test::SharedDir() + "/data/uff-samples/mesh_Oros-modal_uff15_uff2412.uff");
  const UffNodes& on = std::get<UffNodes>(o.datasets[1].data);
  EXPECT_EQ(on.nodes[0].x, on.nodes[0].x_file);
  EXPECT_TRUE(on.nodes[0].global);
}

}  // namespace
}  // namespace dynid
