#include "dynid/engine/parametric.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "dynid/engine/modal.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid {

std::string_view parameter_kind_name(ParameterKind k) {
  switch (k) {
    case ParameterKind::kStiffness: return "E";
    case ParameterKind::kMass: return "rho";
    case ParameterKind::kArea: return "A";
    case ParameterKind::kInertia: return "I";
    case ParameterKind::kPointMass: return "mass";
    case ParameterKind::kSpring: return "spring";
    case ParameterKind::kCustom: return "custom";
  }
  return "?";
}

Model apply_factors(const Model& model, const std::vector<std::pair<int, PropertyFactors>>& changes) {
  Model m = model;
  for (const auto& [id, f] : changes) {
    const int e = m.element_index(id);
    if (e < 0) throw InputError("element " + std::to_string(id) + " does not exist");
    for (double v : {f.E, f.rho, f.A, f.I})
      if (!(v > 0 && std::isfinite(v))) throw InputError("element " + std::to_string(id) + ": factors must be finite and > 0");
    PropertyFactors& g = m.element(e).factors;
    g.E *= f.E;
    g.rho *= f.rho;
    g.A *= f.A;
    g.I *= f.I;
  }
  m.finalize();
  return m;
}

ParametricModel::ParametricModel(const Model& model) : model_(model) {
  if (!model.finalized()) throw InputError("ParametricModel: the model is not finalized");
  AssembledSystem s = assemble_system(model);
  K0_ = std::move(s.K);
  M0_ = std::move(s.M);
}

int ParametricModel::add(const Parameter& p) {
  if (built_) throw InputError("ParametricModel: parameters must be added before the model is evaluated");
  const std::string who = "parameter '" + p.name + "'";
  const bool additive = p.kind == ParameterKind::kPointMass || p.kind == ParameterKind::kSpring;
  if (p.kind == ParameterKind::kCustom) {
    // acts through custom terms only
  } else if (additive) {
    if (p.node < 0 || p.node >= static_cast<int>(model_.nodes().size())) throw InputError(who + ": node does not exist");
    if (p.dofs == 0) throw InputError(who + ": no DOF types given");
    for (int t = 0; t < kNumDofTypes; ++t)
      if ((p.dofs & (1u << t)) && model_.dof_map().eq(p.node, static_cast<Dof>(t)) < 0)
        throw InputError(who + ": " + std::string(dof_name(static_cast<Dof>(t))) + " at node " +
                         std::to_string(model_.nodes()[p.node].id) + " is not a free DOF of the model");
  } else {
    if (p.elements.empty()) throw InputError(who + ": acts on no elements");
    for (int e : p.elements) {
      if (e < 0 || e >= model_.num_elements()) throw InputError(who + ": element index " + std::to_string(e) + " does not exist");
      const ElementType t = model_.elements()[e].type;
      const std::string eid = "element " + std::to_string(model_.elements()[e].id);
      if (t == ElementType::Spring && p.kind != ParameterKind::kStiffness)
        throw InputError(who + ": " + eid + " is a spring; only a stiffness factor (E) acts on it");
      if (t == ElementType::Matrix && p.kind != ParameterKind::kStiffness && p.kind != ParameterKind::kMass)
        throw InputError(who + ": " + eid + " is given by its matrices; only a stiffness (E) or mass (rho) factor acts on it");
      if (t == ElementType::PointMass && p.kind != ParameterKind::kMass)
        throw InputError(who + ": " + eid + " is a point mass; only a mass factor (rho) acts on it");
      const int sec = model_.elements()[e].section;
      if ((p.kind == ParameterKind::kArea || p.kind == ParameterKind::kInertia) && sec >= 0 &&
          model_.sections()[sec].shear_factor > 0)
        throw InputError(who + ": " + eid + " has shear deformation, whose stiffness is not linear in A or I; use E or rho");
    }
  }
  if (!(p.lower <= p.nominal && p.nominal <= p.upper))
    throw InputError(who + ": nominal value " + std::to_string(p.nominal) + " outside its bounds");
  params_.push_back(p);
  return static_cast<int>(params_.size()) - 1;
}

void ParametricModel::add_term(CustomTerm t) {
  if (built_) throw InputError("ParametricModel: terms must be added before the model is evaluated");
  if (!t.eval) throw InputError("ParametricModel: custom term without an evaluation function");
  for (int p : t.params)
    if (p < 0 || p >= num_parameters()) throw InputError("ParametricModel: custom term on parameter " + std::to_string(p) + ", which does not exist");
  for (int d : t.dofs)
    if (d < -1 || d >= model_.num_dofs()) throw InputError("ParametricModel: custom term on equation " + std::to_string(d) + ", which does not exist");
  custom_.push_back({std::move(t), {}});
}

Eigen::VectorXd ParametricModel::sub(const Custom& c, const Eigen::VectorXd& theta) const {
  Eigen::VectorXd v(static_cast<Eigen::Index>(c.term.params.size()));
  for (std::size_t k = 0; k < c.term.params.size(); ++k) v[static_cast<Eigen::Index>(k)] = theta[c.term.params[k]];
  return v;
}

Eigen::VectorXd ParametricModel::nominal() const {
  Eigen::VectorXd v(num_parameters());
  for (int p = 0; p < num_parameters(); ++p) v[p] = params_[p].nominal;
  return v;
}

int ParametricModel::position(int i, int j) const {
  const int* first = K0_.innerIndexPtr() + K0_.outerIndexPtr()[j];
  const int* last = K0_.innerIndexPtr() + K0_.outerIndexPtr()[j + 1];
  const int* it = std::lower_bound(first, last, i);
  return it == last || *it != i ? -1 : static_cast<int>(it - K0_.innerIndexPtr());
}

std::vector<int> ParametricModel::positions(const std::vector<int>& dofs) const {
  const int nd = static_cast<int>(dofs.size());
  std::vector<int> pos(static_cast<std::size_t>(nd) * nd, -1);
  for (int a = 0; a < nd; ++a)
    for (int b = 0; b < nd; ++b) {
      if (dofs[a] < 0 || dofs[b] < 0) continue;
      const int q = position(dofs[a], dofs[b]);
      if (q < 0) throw InternalError("ParametricModel: DOF pair outside the pattern");
      pos[static_cast<std::size_t>(a) * nd + b] = q;
    }
  return pos;
}

void ParametricModel::build_element_terms(int e, const std::vector<int>& ps) const {
  const ElementParts parts = model_.element_parts(e);
  std::vector<int> dofs;
  model_.element_dofs(e, &dofs);
  // Elements assembled on their coupling (a group matrix of hundreds of DOFs, mostly zeros) keep their nonzero
  // entries only: evaluations and sensitivities then cost their nonzeros, not the square of their DOFs.
  std::vector<std::pair<int, int>> coupling;
  const bool sparse = model_.element_coupling(e, &coupling);
  const std::vector<int> pos = sparse ? std::vector<int>() : positions(dofs);
  struct PartDef {
    const Eigen::MatrixXd* m;
    bool mass;
    bool e, rho, a, i;  // which kinds act on it
  };
  const Eigen::MatrixXd Kbt = parts.K_bending + parts.K_torsion;
  // Springs scale with a stiffness factor, point masses with a mass factor. (A table: one part a row.)
  // clang-format off
  const PartDef defs[] = {{&parts.K_axial, false, true, false, true, false},
                          {&Kbt, false, true, false, false, true},
                          {&parts.K_discrete, false, true, false, false, false},
                          {&parts.M_translational, true, false, true, true, false},
                          {&parts.M_rotary, true, false, true, false, true},
                          {&parts.M_discrete, true, false, true, false, false}};
  // clang-format on
  for (const PartDef& d : defs) {
    if (d.m->cwiseAbs().maxCoeff() == 0.0) continue;
    Term t;
    t.dofs = dofs;
    t.A = *d.m;
    t.pos = pos;
    t.mass = d.mass;
    for (int p : ps) {
      const ParameterKind k = params_[p].kind;
      const bool acts = (k == ParameterKind::kStiffness && d.e) || (k == ParameterKind::kMass && d.rho) ||
                        (k == ParameterKind::kArea && d.a) || (k == ParameterKind::kInertia && d.i);
      if (acts) t.params.push_back(p);
    }
    if (t.params.empty()) continue;  // this part is not parameterised: it stays in the fixed values
    Eigen::VectorXd& fixed = t.mass ? Mfixed_ : Kfixed_;
    const int nd = static_cast<int>(dofs.size());
    if (sparse) {
      t.sparse = true;
      for (int b = 0; b < nd; ++b)
        for (int a = 0; a < nd; ++a) {
          if (t.A(a, b) == 0.0 || dofs[a] < 0 || dofs[b] < 0) continue;
          const int q = position(dofs[a], dofs[b]);
          if (q < 0)
            throw InternalError("ParametricModel: a nonzero entry of element " + std::to_string(e) +
                                " outside the pattern");
          t.ea.push_back(a);
          t.eb.push_back(b);
          t.ev.push_back(t.A(a, b));
          t.epos.push_back(q);
          fixed[q] -= t.A(a, b);
        }
      t.A.resize(0, 0);
      t.pos.clear();
    } else {
      for (int a = 0; a < nd; ++a)
        for (int b = 0; b < nd; ++b) {
          const int q = pos[static_cast<std::size_t>(a) * nd + b];
          if (q >= 0) fixed[q] -= t.A(a, b);
        }
    }
    terms_.push_back(std::move(t));
  }
}

// Additive parameters: unit matrices on the node's DOFs, scaled by theta.
void ParametricModel::build_additive_terms() const {
  for (int p = 0; p < num_parameters(); ++p) {
    const Parameter& q = params_[p];
    if (q.kind != ParameterKind::kPointMass && q.kind != ParameterKind::kSpring) continue;
    Term t;
    for (int d = 0; d < kNumDofTypes; ++d)
      if (q.dofs & (1u << d)) t.dofs.push_back(model_.dof_map().eq(q.node, static_cast<Dof>(d)));
    t.A = Eigen::MatrixXd::Identity(static_cast<Eigen::Index>(t.dofs.size()), static_cast<Eigen::Index>(t.dofs.size()));
    t.pos = positions(t.dofs);
    t.mass = q.kind == ParameterKind::kPointMass;
    t.params = {p};
    t.additive = true;
    terms_.push_back(std::move(t));
  }
}

void ParametricModel::build() const {
  if (built_) return;
  terms_.clear();
  Kfixed_ = Eigen::Map<const Eigen::VectorXd>(K0_.valuePtr(), K0_.nonZeros());
  Mfixed_ = Eigen::Map<const Eigen::VectorXd>(M0_.valuePtr(), M0_.nonZeros());
  // Factor parameters, grouped per element: each element part becomes one term with the parameters acting on it.
  std::map<int, std::vector<int>> by_element;
  for (int p = 0; p < num_parameters(); ++p)
    for (int e : params_[p].elements) by_element[e].push_back(p);
  for (const auto& [e, ps] : by_element) build_element_terms(e, ps);
  build_additive_terms();
  custom_of_param_.assign(params_.size(), {});
  for (std::size_t k = 0; k < custom_.size(); ++k) {
    try {
      custom_[k].pos = positions(custom_[k].term.dofs);
    } catch (const InternalError&) {
      throw InputError("ParametricModel: custom term " + std::to_string(k) +
                       " couples DOFs that the model's matrices do not (outside the sparsity pattern); a term may act "
                       "on one element's DOFs or one node's DOFs");
    }
    for (int p : custom_[k].term.params) custom_of_param_[p].push_back(static_cast<int>(k));
  }
  terms_of_param_.assign(params_.size(), {});
  for (std::size_t k = 0; k < terms_.size(); ++k)
    for (int p : terms_[k].params) terms_of_param_[p].push_back(static_cast<int>(k));
  built_ = true;
}

double ParametricModel::scale(const Term& t, const Eigen::VectorXd& theta) const {
  if (t.additive) return theta[t.params[0]];
  double s = 1.0;
  for (int p : t.params) s *= theta[p];
  return s;
}

double ParametricModel::dscale(const Term& t, int p, const Eigen::VectorXd& theta) const {
  if (t.additive) return 1.0;
  double s = 1.0;
  for (int q : t.params)
    if (q != p) s *= theta[q];
  return s;
}

void ParametricModel::matrices(const Eigen::VectorXd& theta, SparseMatrix* K, SparseMatrix* M) const {
  if (theta.size() != num_parameters())
    throw InputError("ParametricModel: " + std::to_string(theta.size()) + " values for " + std::to_string(num_parameters()) + " parameters");
  build();
  if (K) {
    *K = K0_;
    Eigen::Map<Eigen::VectorXd>(K->valuePtr(), K->nonZeros()) = Kfixed_;
  }
  if (M) {
    *M = M0_;
    Eigen::Map<Eigen::VectorXd>(M->valuePtr(), M->nonZeros()) = Mfixed_;
  }
  for (const Term& t : terms_) {
    SparseMatrix* target = t.mass ? M : K;
    if (!target) continue;
    const double s = scale(t, theta);
    double* v = target->valuePtr();
    if (t.sparse) {
      for (std::size_t k = 0; k < t.ev.size(); ++k) v[t.epos[k]] += s * t.ev[k];
      continue;
    }
    const int nd = static_cast<int>(t.dofs.size());
    for (int a = 0; a < nd; ++a)
      for (int b = 0; b < nd; ++b) {
        const int q = t.pos[static_cast<std::size_t>(a) * nd + b];
        if (q >= 0) v[q] += s * t.A(a, b);
      }
  }
  Eigen::MatrixXd dK, dM;
  for (const Custom& c : custom_) {
    dK.resize(0, 0);
    dM.resize(0, 0);
    c.term.eval(sub(c, theta), K ? &dK : nullptr, M ? &dM : nullptr, nullptr, nullptr);
    const int nd = static_cast<int>(c.term.dofs.size());
    for (auto [target, A] : {std::pair{K, &dK}, std::pair{M, &dM}}) {
      if (!target || A->size() == 0) continue;
      double* v = target->valuePtr();
      for (int a = 0; a < nd; ++a)
        for (int b = 0; b < nd; ++b) {
          const int q = c.pos[static_cast<std::size_t>(a) * nd + b];
          if (q >= 0) v[q] += (*A)(a, b);
        }
    }
  }
}

void ParametricModel::custom_derivative(int k, int p, const Eigen::VectorXd& theta, Eigen::MatrixXd* dK,
                                        Eigen::MatrixXd* dM) const {
  const Custom& c = custom_[k];
  std::vector<Eigen::MatrixXd> dKd, dMd;
  c.term.eval(sub(c, theta), nullptr, nullptr, &dKd, &dMd);
  const auto j = static_cast<std::size_t>(std::find(c.term.params.begin(), c.term.params.end(), p) - c.term.params.begin());
  const Eigen::Index nd = static_cast<Eigen::Index>(c.term.dofs.size());
  *dK = j < dKd.size() && dKd[j].size() ? dKd[j] : Eigen::MatrixXd::Zero(nd, nd);
  *dM = j < dMd.size() && dMd[j].size() ? dMd[j] : Eigen::MatrixXd::Zero(nd, nd);
}

Eigen::MatrixXd ParametricModel::eigenvalue_sensitivities(const Eigen::VectorXd& theta, const Eigen::VectorXd& lambda,
                                                          const Eigen::MatrixXd& Phi) const {
  build();
  const Eigen::Index m = Phi.cols();
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(m, num_parameters());
  Eigen::VectorXd pe;
  for (int p = 0; p < num_parameters(); ++p)
    for (int k : terms_of_param_[p]) {
      const Term& t = terms_[k];
      const double ds = dscale(t, p, theta);
      const int nd = static_cast<int>(t.dofs.size());
      if (t.sparse) {
        for (Eigen::Index i = 0; i < m; ++i) {
          const double* phi = Phi.col(i).data();
          double q = 0;
          for (std::size_t e = 0; e < t.ev.size(); ++e) q += t.ev[e] * phi[t.dofs[t.ea[e]]] * phi[t.dofs[t.eb[e]]];
          q *= ds;
          S(i, p) += t.mass ? -lambda[i] * q : q;
        }
        continue;
      }
      for (Eigen::Index i = 0; i < m; ++i) {
        pe.setZero(nd);
        for (int a = 0; a < nd; ++a)
          if (t.dofs[a] >= 0) pe[a] = Phi(t.dofs[a], i);
        const double q = pe.dot(t.A * pe) * ds;
        S(i, p) += t.mass ? -lambda[i] * q : q;
      }
    }
  Eigen::MatrixXd dK, dM;
  for (int p = 0; p < num_parameters(); ++p)
    for (int k : custom_of_param_[p]) {
      custom_derivative(k, p, theta, &dK, &dM);
      const std::vector<int>& dofs = custom_[k].term.dofs;
      const int nd = static_cast<int>(dofs.size());
      for (Eigen::Index i = 0; i < m; ++i) {
        pe.setZero(nd);
        for (int a = 0; a < nd; ++a)
          if (dofs[a] >= 0) pe[a] = Phi(dofs[a], i);
        S(i, p) += pe.dot((dK - lambda[i] * dM) * pe);
      }
    }
  return S;
}

void ParametricModel::derivative_products(int p, const Eigen::VectorXd& theta, const Eigen::VectorXd& v,
                                          SparseProducts* out) const {
  build();
  out->dof.clear();
  out->dKv.clear();
  out->dMv.clear();
  Eigen::VectorXd ve;
  for (int k : terms_of_param_[p]) {
    const Term& t = terms_[k];
    const double ds = dscale(t, p, theta);
    const int nd = static_cast<int>(t.dofs.size());
    ve.setZero(nd);
    for (int a = 0; a < nd; ++a)
      if (t.dofs[a] >= 0) ve[a] = v[t.dofs[a]];
    Eigen::VectorXd y;
    if (t.sparse) {
      y.setZero(nd);
      for (std::size_t e = 0; e < t.ev.size(); ++e) y[t.ea[e]] += t.ev[e] * ve[t.eb[e]];
      y *= ds;
    } else {
      y = ds * (t.A * ve);
    }
    for (int a = 0; a < nd; ++a) {
      if (t.dofs[a] < 0) continue;
      out->dof.push_back(t.dofs[a]);
      out->dKv.push_back(t.mass ? 0.0 : y[a]);
      out->dMv.push_back(t.mass ? y[a] : 0.0);
    }
  }
  Eigen::MatrixXd dK, dM;
  for (int k : custom_of_param_[p]) {
    custom_derivative(k, p, theta, &dK, &dM);
    const std::vector<int>& dofs = custom_[k].term.dofs;
    const int nd = static_cast<int>(dofs.size());
    ve.setZero(nd);
    for (int a = 0; a < nd; ++a)
      if (dofs[a] >= 0) ve[a] = v[dofs[a]];
    const Eigen::VectorXd yk = dK * ve, ym = dM * ve;
    for (int a = 0; a < nd; ++a) {
      if (dofs[a] < 0) continue;
      out->dof.push_back(dofs[a]);
      out->dKv.push_back(yk[a]);
      out->dMv.push_back(ym[a]);
    }
  }
}

void ParametricModel::projected_derivatives(int p, const Eigen::VectorXd& theta, const RowMatrix& V,
                                            Eigen::MatrixXd* dK, Eigen::MatrixXd* dM) const {
  build();
  const Eigen::Index r = V.cols();
  // Stacked over the parameter's terms: G holds V's rows at each term's free DOFs, H the rows of dA V there, so
  // that V^T dA V = G^T H (one product per matrix).
  RowMatrix G[2] = {RowMatrix(0, r), RowMatrix(0, r)}, H[2] = {RowMatrix(0, r), RowMatrix(0, r)};
  Eigen::Index used[2] = {0, 0};
  auto reserve = [&](int which, Eigen::Index rows) {
    if (G[which].rows() < used[which] + rows) {
      const Eigen::Index want = std::max<Eigen::Index>(2 * G[which].rows(), used[which] + rows);
      G[which].conservativeResize(want, r);
      H[which].conservativeResize(want, r);
    }
  };
  RowMatrix Ve, Y;
  auto add = [&](int which, const std::vector<int>& dofs, const Eigen::MatrixXd& A, double ds) {
    const int nd = static_cast<int>(dofs.size());
    Ve.setZero(nd, r);
    for (int a = 0; a < nd; ++a)
      if (dofs[a] >= 0) Ve.row(a) = V.row(dofs[a]);
    Y.noalias() = ds * A * Ve;
    reserve(which, nd);
    for (int a = 0; a < nd; ++a) {
      if (dofs[a] < 0) continue;
      G[which].row(used[which]) = Ve.row(a);
      H[which].row(used[which]) = Y.row(a);
      ++used[which];
    }
  };
  Eigen::MatrixXd A;
  for (int k : terms_of_param_[p]) {
    const Term& t = terms_[k];
    const double ds = dscale(t, p, theta);
    if (t.sparse) {
      A.setZero(static_cast<Eigen::Index>(t.dofs.size()), static_cast<Eigen::Index>(t.dofs.size()));
      for (std::size_t e = 0; e < t.ev.size(); ++e) A(t.ea[e], t.eb[e]) += t.ev[e];
      add(t.mass ? 1 : 0, t.dofs, A, ds);
    } else {
      add(t.mass ? 1 : 0, t.dofs, t.A, ds);
    }
  }
  Eigen::MatrixXd cK, cM;
  for (int k : custom_of_param_[p]) {
    custom_derivative(k, p, theta, &cK, &cM);
    add(0, custom_[k].term.dofs, cK, 1.0);
    add(1, custom_[k].term.dofs, cM, 1.0);
  }
  Eigen::MatrixXd* out[2] = {dK, dM};
  for (int which = 0; which < 2; ++which) {
    const Eigen::Index u = used[which];
    *out[which] = G[which].topRows(u).transpose() * H[which].topRows(u);
  }
}

}  // namespace dynid
