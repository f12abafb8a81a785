// dynid/mesh/element_source.hpp -- the interface through which anything with elements (a dynid Model, a model
// read from exported matrices, a host FE code) hands its element DOF maps and element matrices to dynid.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace dynid {

/// A set of finite elements on `num_dofs()` global (free) DOFs.
///
/// Contract:
///  * element_dofs(e, &dofs) fills the element's global equation numbers in element-matrix order; -1 marks a
///    DOF that is eliminated (restrained) and is skipped by assembly.
///  * element_matrices(e, K, M) writes the element's stiffness and mass matrices in the same order, in global
///    coordinates, symmetric, full storage. Either pointer may be null (not wanted). Implementations resize the
///    output and must not keep hidden mutable state: they are called concurrently from several threads.
///  * The same element always gets the same DOF list (the sparsity pattern is computed once).
class ElementSource {
 public:
  virtual ~ElementSource() = default;
  virtual int num_dofs() const = 0;
  virtual int num_elements() const = 0;
  virtual void element_dofs(int e, std::vector<int>* dofs) const = 0;
  virtual void element_matrices(int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const = 0;
};

}  // namespace dynid
