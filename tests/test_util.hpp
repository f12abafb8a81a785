// Numeric test helpers: relative comparisons, MAC, eigen-residuals, case paths.
#pragma once

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>

#include "dynid/engine/identify.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/mesh/generators.hpp"
#include "dynid/solvers/sparse.hpp"

/// `text` (a std::string or a C string) contains `part`; the text is shown when it does not.
#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << "message: " << (text)

namespace dynid::test {

/// Identification options with only the band set (the rest at their defaults).
inline IdentificationOptions Band(double lo, double hi) {
  IdentificationOptions io;
  io.band_lo_hz = lo;
  io.band_hi_hz = hi;
  return io;
}

/// |a - b| <= rtol * max(|a|, |b|) (or both exactly zero).
inline ::testing::AssertionResult RelClose(double a, double b, double rtol) {
  const double scale = std::max(std::abs(a), std::abs(b));
  if (std::abs(a - b) <= rtol * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b << ": relative difference "
                                       << std::abs(a - b) / scale << " > " << rtol;
}

/// Modal assurance criterion of two real vectors: (a.b)^2 / (a.a b.b); 1 = same shape up to scale and sign.
inline double Mac(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double ab = a.dot(b);
  return ab * ab / (a.squaredNorm() * b.squaredNorm());
}

/// Largest angle-based distance between two subspaces given as column blocks (1 - min singular value of the
/// product of their orthonormal bases): 0 when the spaces coincide.
double SubspaceGap(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B);

/// The message of the InputError that f() throws, or "(no error)".
template <class F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

/// The whole content of a file (a failed expectation if it cannot be read).
std::string Slurp(const std::string& path);

/// A fresh, empty folder for the running test's files (<temp>/dynid-<tag>-<pid>-<test name>), removed when the
/// object goes out of scope.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& dir() const { return dir_; }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }  ///< a file in it
  /// Writes `text` to the file `name` in it; returns its path.
  std::string write(const std::string& name, const std::string& text) const;

 private:
  std::filesystem::path dir_;
};

/// Folder of the repository's bundled cases and of ../shared (set by CMake).
std::string CasesDir();
std::string SharedDir();
/// Whether the shared data folder exists (tests that need it skip with a message otherwise).
bool HaveShared();

}  // namespace dynid::test

/// Skips the test, saying why, when ../shared (the paper's data) is not available.
#define DYNID_REQUIRE_SHARED()                                                                          \
  do {                                                                                                  \
    if (!::dynid::test::HaveShared())                                                                   \
      GTEST_SKIP() << "shared data not found at " << ::dynid::test::SharedDir()                          \
                   << " (clone dynid beside ../shared, or set DYNID_SHARED_DIR when configuring)";      \
  } while (0)

namespace dynid::test {

/// Dense copy of a sparse matrix.
inline Eigen::MatrixXd Dense(const SparseMatrix& A) { return Eigen::MatrixXd(A); }

/// f() with one OpenMP thread, then with two (the caller's thread count restored): {one, two}, for the tests that a
/// result does not depend on the thread count.
template <class F>
auto OnOneThreadAndTwo(F&& f) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  auto one = f();
  omp_set_num_threads(2);
  auto two = f();
  omp_set_num_threads(saved);
  return std::make_pair(std::move(one), std::move(two));
}

/// A steel 3D frame without symmetry in plan (spans 5 m x 4 m, storeys 3 m, members in 2 elements): simple
/// eigenvalues.
Frame3DSpec SteelFrame3D(int bays_x, int bays_y, int stories);

/// The model's nodes, materials, sections and elements without its supports, not finalized (to add to).
Model UnsupportedCopy(const Model& base);

/// The model with its supports removed, declared free-free (finalized): 6 rigid-body modes.
Model WithoutSupports(const Model& base);

/// A one-node spring element to ground on DOF `dof` of node `node`, stiffness k.
Element GroundedSpring(int id, int node, Dof dof, double k);

/// A point mass element of mass m on node `node` (no rotary inertia).
Element PointMass(int id, int node, double m);

}  // namespace dynid::test
