#include "dynid/engine/candidate_checks.hpp"

#include <cmath>
#include <sstream>

#include "candidates/common.hpp"

namespace dynid {

std::string CandidateCheck::report() const {
  std::string s;
  for (const std::string& f : failures) s += f + "\n";
  return s;
}

namespace {

// Largest absolute entry of the model's element matrices on `dofs` (a scale for "zero" and for derivatives).
double scale_on(const Model& m, const std::vector<int>& dofs) {
  double s = 0;
  for (int e = 0; e < m.num_elements(); ++e) {
    std::vector<int> ed;
    m.element_dofs(e, &ed);
    bool touches = false;
    for (int d : ed)
      for (int x : dofs) touches = touches || (d >= 0 && d == x);
    if (!touches) continue;
    Eigen::MatrixXd K, M;
    m.element_matrices(e, &K, &M);
    s = std::max({s, K.cwiseAbs().maxCoeff(), M.cwiseAbs().maxCoeff()});
  }
  return s > 0 ? s : 1.0;
}

}  // namespace

CandidateCheck check_candidate(const Model& model, const Candidate& c, double tol) {
  CandidateCheck out;
  auto fail = [&](const std::string& what) { out.failures.push_back(c.kind() + " (" + c.description() + "): " + what); };
  const std::vector<CandidateParameter> ps = c.parameters();
  if (ps.empty()) fail("no parameters");
  const Eigen::Index np = static_cast<Eigen::Index>(ps.size());
  Eigen::VectorXd nominal(np), probe(np);
  for (Eigen::Index q = 0; q < np; ++q) {
    const CandidateParameter& p = ps[static_cast<std::size_t>(q)];
    if (!(p.lower < p.upper)) fail("parameter '" + p.name + "': lower bound not below the upper one");
    if (!(p.nominal >= p.lower && p.nominal <= p.upper)) fail("parameter '" + p.name + "': nominal outside the bounds");
    if (!(p.prior_scale >= 0)) fail("parameter '" + p.name + "': negative prior scale");
    nominal[q] = p.nominal;
    // A point inside the bounds, away from the nominal (and from the bounds): a tenth of the way to the far bound.
    const double far = p.upper - p.nominal >= p.nominal - p.lower ? p.upper : p.lower;
    probe[q] = p.nominal + 0.1 * (far - p.nominal);
  }
  if (!out.ok()) return out;
  std::vector<CustomTerm> terms;
  try {
    ParametricModel pm(model);
    terms = c.terms(model, 0);
    for (Eigen::Index q = 0; q < np; ++q) {
      Parameter p;
      p.name = ps[static_cast<std::size_t>(q)].name;
      p.kind = ParameterKind::kCustom;
      p.nominal = nominal[q];
      p.lower = ps[static_cast<std::size_t>(q)].lower;
      p.upper = ps[static_cast<std::size_t>(q)].upper;
      pm.add(p);
    }
    for (const CustomTerm& t : c.terms(model, 0)) pm.add_term(t);
    SparseMatrix K, M;
    pm.matrices(probe, &K, &M);
  } catch (const std::exception& e) {
    fail(std::string("does not install on the model: ") + e.what());
    return out;
  }
  for (std::size_t k = 0; k < terms.size(); ++k) {
    const CustomTerm& t = terms[k];
    const double s = scale_on(model, t.dofs);
    auto sub = [&](const Eigen::VectorXd& th) {
      Eigen::VectorXd v(static_cast<Eigen::Index>(t.params.size()));
      for (std::size_t i = 0; i < t.params.size(); ++i) v[static_cast<Eigen::Index>(i)] = th[t.params[i]];
      return v;
    };
    Eigen::MatrixXd dK, dM;
    t.eval(sub(nominal), &dK, &dM, nullptr, nullptr);
    const double zk = dK.size() ? dK.cwiseAbs().maxCoeff() : 0.0, zm = dM.size() ? dM.cwiseAbs().maxCoeff() : 0.0;
    if (zk > tol * s || zm > tol * s)
      fail("term " + std::to_string(k) + " is not zero at the nominal parameters (|dK| " + internal::fmt_value(zk, 3) +
           ", |dM| " + internal::fmt_value(zm, 3) + " against element entries of " + internal::fmt_value(s, 3) + ")");
    std::vector<Eigen::MatrixXd> dKd, dMd;
    t.eval(sub(probe), nullptr, nullptr, &dKd, &dMd);
    if (dKd.size() != t.params.size() || dMd.size() != t.params.size()) {
      fail("term " + std::to_string(k) + " returns " + std::to_string(dKd.size()) + " derivatives for " +
           std::to_string(t.params.size()) + " parameters");
      continue;
    }
    for (std::size_t i = 0; i < t.params.size(); ++i) {
      const int q = t.params[i];
      const double h = 1e-6 * (ps[static_cast<std::size_t>(q)].upper - ps[static_cast<std::size_t>(q)].lower);
      Eigen::VectorXd tp = probe, tm = probe;
      tp[q] += h;
      tm[q] -= h;
      Eigen::MatrixXd Kp, Mp, Km, Mm;
      t.eval(sub(tp), &Kp, &Mp, nullptr, nullptr);
      t.eval(sub(tm), &Km, &Mm, nullptr, nullptr);
      auto check = [&](const Eigen::MatrixXd& plus, const Eigen::MatrixXd& minus, const Eigen::MatrixXd& analytic, const char* what) {
        const Eigen::Index n = static_cast<Eigen::Index>(t.dofs.size());
        const Eigen::MatrixXd P = plus.size() ? plus : Eigen::MatrixXd::Zero(n, n);
        const Eigen::MatrixXd Mn = minus.size() ? minus : Eigen::MatrixXd::Zero(n, n);
        const Eigen::MatrixXd A = analytic.size() ? analytic : Eigen::MatrixXd::Zero(n, n);
        const Eigen::MatrixXd fd = (P - Mn) / (2 * h);
        const double err = (fd - A).cwiseAbs().maxCoeff(), size = std::max(A.cwiseAbs().maxCoeff(), 1e-9 * s);
        // Central differences: truncation O(h^2) within tol, rounding about 1e-14 |matrix| / h.
        const double rounding = 1e-14 * std::max(P.cwiseAbs().maxCoeff(), Mn.cwiseAbs().maxCoeff()) / h;
        if (err > tol * size + rounding)
          fail("term " + std::to_string(k) + ": d" + what + "/d(" + ps[static_cast<std::size_t>(q)].name + ") differs from central differences by " +
               internal::fmt_value(err / size, 3) + " (relative)");
      };
      check(Kp, Km, dKd[i], "K");
      check(Mp, Mm, dMd[i], "M");
    }
  }
  const Eigen::VectorXd sd = Eigen::VectorXd::Constant(np, 0.01);
  const std::vector<PhysicalValue> v = c.physical(probe, sd);
  if (v.size() < ps.size()) fail("physical() gives fewer values than parameters");
  for (const PhysicalValue& x : v)
    if (x.name.empty() || !std::isfinite(x.value) || !std::isfinite(x.std)) fail("physical value '" + x.name + "' is unnamed or not finite");
  return out;
}

}  // namespace dynid
