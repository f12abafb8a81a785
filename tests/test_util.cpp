#include "test_util.hpp"

#include <Eigen/Dense>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace dynid::test {

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
