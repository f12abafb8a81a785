// dynid/engine/parametric.hpp -- K(theta), M(theta) of a model with named physical parameters, and their
// analytic sensitivities through element matrices (no finite differences, no re-assembly).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "dynid/mesh/model.hpp"
#include "dynid/solvers/sparse.hpp"

namespace dynid {

/// What a parameter changes. Factors are dimensionless (1 = nominal) and multiply element properties:
///   kStiffness  E       -> every stiffness part of its elements, springs' k     (delta k = theta - 1)
///   kMass       rho     -> every mass part of its elements, point masses' m     (delta m = theta - 1)
///   kArea       A       -> axial stiffness and translational mass
///   kInertia    I       -> bending and torsional stiffness, rotary mass
/// Additive parameters are in the user's units (nominal 0):
///   kPointMass  kg on the translations `dofs` of `node`;  kSpring  N/m (or N m/rad) grounded on `dofs` of `node`.
/// Parts touched by several factors scale by their product (E and I on one element act as E*I), so K(theta)
/// is always exact.
///   kCustom     acts only through CustomTerms (any smooth dependence; model augmentations of discovery).
enum class ParameterKind { kStiffness, kMass, kArea, kInertia, kPointMass, kSpring, kCustom };
std::string_view parameter_kind_name(ParameterKind k);  // "E", "rho", "A", "I", "mass", "spring"

struct Parameter {
  std::string name;
  ParameterKind kind = ParameterKind::kStiffness;
  std::vector<int> elements;  ///< element indices (factor kinds)
  int node = -1;              ///< node index (additive kinds)
  DofMask dofs = 0;           ///< DOF types (additive kinds)
  double nominal = 1.0;       ///< 1 for factors, 0 for additive parameters
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  double scale = 1.0;         ///< typical magnitude (prior std for regularisation; 1 for factors)
};

/// A block of K and M that depends on parameters in any smooth way (the model augmentations of discovery: a
/// semi-rigid joint, shear deformation, a preload, ...). It lives on equations `dofs` (-1 = restrained: those
/// rows and columns are skipped), whose pairs must lie in the model's sparsity pattern (an element's DOFs, or
/// one node's DOFs), and is added to K(theta), M(theta) at every theta.
struct CustomTerm {
  std::vector<int> dofs;
  std::vector<int> params;  ///< the parameters it depends on (ParametricModel indices)
  /// Evaluates the block at `theta` (values of `params`, in order): dK and dM (left empty = zero) and, when dKd
  /// and dMd are not null, their exact derivatives, one matrix per parameter (empty = zero).
  std::function<void(const Eigen::VectorXd& theta, Eigen::MatrixXd* dK, Eigen::MatrixXd* dM,
                     std::vector<Eigen::MatrixXd>* dKd, std::vector<Eigen::MatrixXd>* dMd)>
      eval;
};

/// A copy of `model` with element property factors multiplied (simulated targets: e.g. element 4's rho x 1.2).
Model apply_factors(const Model& model, const std::vector<std::pair<int, PropertyFactors>>& changes);

class ParametricModel {
 public:
  /// Keeps a reference to `model` (which must outlive this object) and assembles its nominal K0, M0.
  explicit ParametricModel(const Model& model);

  /// Adds a parameter (before the first matrices()/sensitivity call). Returns its index. Throws InputError for
  /// unknown elements or nodes, or DOFs the node does not have.
  int add(const Parameter& p);
  /// Adds a custom term (before the first evaluation); its parameters must exist. Throws InputError otherwise.
  void add_term(CustomTerm t);
  int num_terms() const { return static_cast<int>(custom_.size()); }
  int num_parameters() const { return static_cast<int>(params_.size()); }
  const Parameter& parameter(int p) const { return params_[p]; }
  Eigen::VectorXd nominal() const;

  /// K(theta), M(theta) on the nominal pattern (exact).
  void matrices(const Eigen::VectorXd& theta, SparseMatrix* K, SparseMatrix* M) const;

  /// d lambda_i / d theta_p = phi_i^T (dK/dtheta_p - lambda_i dM/dtheta_p) phi_i for mass-normalised modes
  /// Phi of (K(theta), M(theta)), from element matrices: a modes x parameters matrix.
  Eigen::MatrixXd eigenvalue_sensitivities(const Eigen::VectorXd& theta, const Eigen::VectorXd& lambda,
                                           const Eigen::MatrixXd& Phi) const;

  /// dK/dtheta_p * v and dM/dtheta_p * v, which live on the DOFs of the parameter's elements only: returned
  /// as entries (dof[t], dKv[t], dMv[t]); a DOF may appear more than once (entries add up).
  struct SparseProducts {
    std::vector<int> dof;
    std::vector<double> dKv, dMv;
  };
  void derivative_products(int p, const Eigen::VectorXd& theta, const Eigen::VectorXd& v, SparseProducts* out) const;

  /// V^T (dK/dtheta_p) V and V^T (dM/dtheta_p) V (r x r) for a basis V (n x r, row-major so that a DOF's row
  /// is contiguous): the parameter's derivative projected on V, from element matrices.
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  void projected_derivatives(int p, const Eigen::VectorXd& theta, const RowMatrix& V, Eigen::MatrixXd* dK,
                             Eigen::MatrixXd* dM) const;

  const Model& model() const { return model_; }
  const SparseMatrix& K0() const { return K0_; }
  const SparseMatrix& M0() const { return M0_; }

 private:
  // A part of an element (or an added mass/spring) whose matrix scales with a product of parameters.
  struct Term {
    std::vector<int> dofs;      // global equations (-1 = restrained)
    Eigen::MatrixXd A;          // element-level matrix at nominal (dense terms; empty for sparse ones)
    std::vector<int> pos;       // CSC positions of the free (a, b) pairs, row-major over (a, b); -1 skipped
    /// Sparse terms (elements assembled on their coupling, Model::element_coupling): the nonzero free entries
    /// (ea[t], eb[t]) of the element-level matrix, their values ev[t] and CSC positions epos[t]; A and pos empty.
    bool sparse = false;
    std::vector<int> ea, eb, epos;
    std::vector<double> ev;
    bool mass = false;          // contributes to M (else K)
    std::vector<int> params;    // parameters multiplying it
    bool additive = false;      // scale = theta_p (additive kinds) instead of a product of factors
  };
  void build() const;
  // build()'s parts: the factor terms of element e (the parts the parameters ps act on), the additive terms.
  void build_element_terms(int e, const std::vector<int>& ps) const;
  void build_additive_terms() const;
  // The CSC position of entry (i, j) of the pattern, or -1 outside it; per (a, b) pair of dofs, row-major.
  int position(int i, int j) const;
  std::vector<int> positions(const std::vector<int>& dofs) const;
  double scale(const Term& t, const Eigen::VectorXd& theta) const;
  double dscale(const Term& t, int p, const Eigen::VectorXd& theta) const;

  const Model& model_;
  SparseMatrix K0_, M0_;
  std::vector<Parameter> params_;
  mutable bool built_ = false;
  mutable std::vector<Term> terms_;
  mutable Eigen::VectorXd Kfixed_, Mfixed_;           // nominal values minus the parameterised terms
  mutable std::vector<std::vector<int>> terms_of_param_;
  struct Custom {
    CustomTerm term;
    std::vector<int> pos;  // CSC positions of the (a, b) pairs, row-major; -1 skipped
  };
  mutable std::vector<Custom> custom_;
  mutable std::vector<std::vector<int>> custom_of_param_;
  Eigen::VectorXd sub(const Custom& c, const Eigen::VectorXd& theta) const;
  void custom_derivative(int k, int p, const Eigen::VectorXd& theta, Eigen::MatrixXd* dK, Eigen::MatrixXd* dM) const;
};

}  // namespace dynid
