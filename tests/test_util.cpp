#include "test_util.hpp"

#include <Eigen/Dense>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace dynid::test {

Frame3DSpec SteelFrame3D(int bays_x, int bays_y, int stories) {
  Frame3DSpec s;
  s.bays_x = bays_x;
  s.bays_y = bays_y;
  s.stories = stories;
  s.divisions = 2;
  s.span_x = 5;
  s.span_y = 4;
  s.height = 3;
  s.material = {"steel", 2.1e11, 0, 0.3, 7800};
  s.column = {"col", 4e-3, 8e-6, 1.2e-5, 0};
  s.beam = {"beam", 3e-3, 5e-6, 9e-6, 0};
  return s;
}

Model UnsupportedCopy(const Model& base) {
  Model m;
  for (const Material& x : base.materials()) m.add_material(x);
  for (const Section& x : base.sections()) m.add_section(x);
  for (const Node& n : base.nodes()) m.add_node(n.id, n.x);
  for (const Element& e : base.elements()) m.add_element(e);
  return m;
}

Model WithoutSupports(const Model& base) {
  Model m = UnsupportedCopy(base);
  m.set_free_free(true);
  m.finalize();
  return m;
}

Element GroundedSpring(int id, int node, Dof dof, double k) {
  Element s;
  s.id = id;
  s.type = ElementType::Spring;
  s.num_nodes = 1;
  s.node_ids = {{node, 0}};
  s.spring_dofs = dof_bit(dof);
  s.stiffness = k;
  return s;
}

Element PointMass(int id, int node, double m) {
  Element p;
  p.id = id;
  p.type = ElementType::PointMass;
  p.num_nodes = 1;
  p.node_ids = {{node, 0}};
  p.mass = m;
  return p;
}

double SubspaceGap(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  const Eigen::MatrixXd Qa = Eigen::HouseholderQR<Eigen::MatrixXd>(A).householderQ() *
                             Eigen::MatrixXd::Identity(A.rows(), A.cols());
  const Eigen::MatrixXd Qb = Eigen::HouseholderQR<Eigen::MatrixXd>(B).householderQ() *
                             Eigen::MatrixXd::Identity(B.rows(), B.cols());
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Qa.transpose() * Qb);
  return 1.0 - svd.singularValues().minCoeff();
}

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << path;
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

ScratchDir::ScratchDir(const std::string& tag) {
  const ::testing::TestInfo* t = ::testing::UnitTest::GetInstance()->current_test_info();
  dir_ = std::filesystem::temp_directory_path() /
         ("dynid-" + tag + "-" + std::to_string(::getpid()) + (t ? std::string("-") + t->name() : std::string()));
  std::filesystem::remove_all(dir_);
  std::filesystem::create_directories(dir_);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(dir_, ec);
}

std::string ScratchDir::write(const std::string& name, const std::string& text) const {
  const std::string p = path(name);
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

std::string CasesDir() { return DYNID_CASES_DIR; }
std::string SharedDir() { return DYNID_SHARED_DIR; }
bool HaveShared() { return std::filesystem::is_directory(std::string(DYNID_SHARED_DIR) + "/cases"); }

}  // namespace dynid::test
