#include "dynid/engine/correlation.hpp"

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

const ModePair* Pairing::of_a(int a) const {
  for (const ModePair& p : pairs)
    if (p.a == a) return &p;
  return nullptr;
}

Pairing pair_modes(const Eigen::MatrixXd& mac, const Eigen::VectorXd& fa, const Eigen::VectorXd& fb, double min_mac) {
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
      const double df = freq && fa[i] > 0 ? std::min(1.0, std::abs(fb[j] - fa[i]) / fa[i]) : 0.0;
      // A partner more than a factor 2 away in frequency is a spatial alias (few sensors: a high mode can look
      // like a low one at the measured DOFs), never preferred to a nearer one of similar MAC.
      const double lr = freq && fa[i] > 0 && fb[j] > 0 ? std::abs(std::log(fb[j] / fa[i])) : 0.0;
      c.push_back({i, j, mac(i, j) - 0.1 * df - (lr > std::log(2.0) ? std::min(0.9, 0.2 * lr) : 0.0)});
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
