#include "dynid/engine/correlation.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "dynid/mesh/error.hpp"

namespace dynid {

Eigen::MatrixXd mac_matrix(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  if (A.rows() != B.rows())
    throw InputError("MAC: shapes compared on different DOF sets (" + std::to_string(A.rows()) + " vs " +
                     std::to_string(B.rows()) + " rows)");
  const Eigen::MatrixXd AB = A.transpose() * B;
  const Eigen::VectorXd aa = A.colwise().squaredNorm(), bb = B.colwise().squaredNorm();
  Eigen::MatrixXd mac(A.cols(), B.cols());
  for (Eigen::Index i = 0; i < A.cols(); ++i)
    for (Eigen::Index j = 0; j < B.cols(); ++j) {
      const double d = aa[i] * bb[j];
      mac(i, j) = d > 0 ? AB(i, j) * AB(i, j) / d : 0.0;
    }
  return mac;
}

std::vector<std::vector<int>> repeated_groups(const Eigen::VectorXd& fb, double rel_tol) {
  std::vector<std::vector<int>> groups;
  for (Eigen::Index j = 0; j < fb.size(); ++j) {
    const bool same = j > 0 && std::abs(fb[j] - fb[j - 1]) <= rel_tol * std::max(std::abs(fb[j]), std::abs(fb[j - 1]));
    if (same)
      groups.back().push_back(static_cast<int>(j));
    else
      groups.push_back({static_cast<int>(j)});
  }
  return groups;
}

namespace {
Eigen::MatrixXd group_columns(const Eigen::MatrixXd& B, const std::vector<int>& group) {
  Eigen::MatrixXd Bg(B.rows(), static_cast<Eigen::Index>(group.size()));
  for (std::size_t k = 0; k < group.size(); ++k) {
    if (group[k] < 0 || group[k] >= B.cols()) throw InputError("repeated-mode group names column " + std::to_string(group[k]) + " of " + std::to_string(B.cols()));
    Bg.col(static_cast<Eigen::Index>(k)) = B.col(group[k]);
  }
  return Bg;
}
}  // namespace

Eigen::MatrixXd subspace_mac_matrix(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B,
                                    const std::vector<std::vector<int>>& groups) {
  Eigen::MatrixXd mac = mac_matrix(A, B);
  for (const std::vector<int>& g : groups) {
    if (g.size() < 2) continue;
    // Orthonormal basis of the group's columns (at the rows of A); rank-revealing, so dependent shapes at few
    // sensors do not blow up the projector.
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(group_columns(B, g));
    const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(B.rows(), qr.rank());
    for (Eigen::Index i = 0; i < A.cols(); ++i) {
      const double aa = A.col(i).squaredNorm();
      const double m = aa > 0 ? (Q.transpose() * A.col(i)).squaredNorm() / aa : 0.0;
      for (int j : g) mac(i, j) = m;
    }
  }
  return mac;
}

Eigen::VectorXd subspace_coefficients(const Eigen::VectorXd& a, const Eigen::MatrixXd& B, const std::vector<int>& group) {
  const Eigen::MatrixXd Bg = group_columns(B, group);
  if (a.size() != Bg.rows())
    throw InputError("subspace fit: shape has " + std::to_string(a.size()) + " rows, modes " + std::to_string(Bg.rows()));
  Eigen::VectorXd c = Bg.completeOrthogonalDecomposition().solve(a);
  const double n = c.norm();
  if (n > 0) return c / n;
  c.setZero();
  c[0] = 1;  // a orthogonal to the subspace: any member is as good
  return c;
}

Eigen::VectorXd subspace_member(const Eigen::VectorXd& a, const Eigen::MatrixXd& B, const std::vector<int>& group) {
  return group_columns(B, group) * subspace_coefficients(a, B, group);
}

const ModePair* Pairing::of_a(int a) const {
  for (const ModePair& p : pairs)
    if (p.a == a) return &p;
  return nullptr;
}

Pairing pair_modes(const Eigen::MatrixXd& mac, const Eigen::VectorXd& fa, const Eigen::VectorXd& fb, double min_mac,
                   double max_ratio) {
  const int na = static_cast<int>(mac.rows()), nb = static_cast<int>(mac.cols());
  const bool freq = fa.size() == na && fb.size() == nb;
  struct Cand {
    int a, b;
    double score;
  };
  std::vector<Cand> c;
  for (int i = 0; i < na; ++i)
    for (int j = 0; j < nb; ++j) {
      if (!(mac(i, j) >= min_mac)) continue;
      // A partner more than a factor 2 away in frequency (or max_ratio, if tighter) is not plausible: a spatial
      // alias (few sensors: a high mode can look like a low one at the measured DOFs) or a spurious mode.
      const double bound = max_ratio > 0 ? std::min(max_ratio, kMaxPairingRatio) : kMaxPairingRatio;
      if (freq && fa[i] > 0 && fb[j] > 0 && std::abs(std::log(fb[j] / fa[i])) > std::log(bound)) continue;
      const double df = freq && fa[i] > 0 ? std::min(1.0, std::abs(fb[j] - fa[i]) / fa[i]) : 0.0;
      c.push_back({i, j, mac(i, j) - kPairingFrequencyWeight * df});
    }
  std::stable_sort(c.begin(), c.end(), [](const Cand& x, const Cand& y) { return x.score > y.score; });
  std::vector<char> ua(na, 0), ub(nb, 0);
  Pairing p;
  for (const Cand& k : c) {
    if (ua[k.a] || ub[k.b]) continue;
    ua[k.a] = ub[k.b] = 1;
    p.pairs.push_back({k.a, k.b, mac(k.a, k.b), freq && fa[k.a] > 0 ? (fb[k.b] - fa[k.a]) / fa[k.a] : 0.0});
  }
  std::sort(p.pairs.begin(), p.pairs.end(), [](const ModePair& x, const ModePair& y) { return x.a < y.a; });
  for (int i = 0; i < na; ++i)
    if (!ua[i]) p.unpaired_a.push_back(i);
  for (int j = 0; j < nb; ++j)
    if (!ub[j]) p.unpaired_b.push_back(j);
  return p;
}

double modal_scale_factor(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double bb = b.squaredNorm();
  return bb > 0 ? a.dot(b) / bb : 0.0;
}

Eigen::VectorXd comac(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Pairing& p) {
  const Eigen::Index n = A.rows();
  Eigen::VectorXd num = Eigen::VectorXd::Zero(n), da = num, db = num;
  for (const ModePair& q : p.pairs) {
    const Eigen::VectorXd a = A.col(q.a);
    const Eigen::VectorXd b = B.col(q.b) * modal_scale_factor(A.col(q.a), B.col(q.b));
    num += a.cwiseProduct(b).cwiseAbs();
    da += a.cwiseAbs2();
    db += b.cwiseAbs2();
  }
  Eigen::VectorXd out(n);
  for (Eigen::Index i = 0; i < n; ++i) out[i] = da[i] * db[i] > 0 ? num[i] * num[i] / (da[i] * db[i]) : 0.0;
  return out;
}

}  // namespace dynid
