// dynid/mesh/element_source.hpp -- the interface through which anything with elements (a dynid Model, a model
// read from exported matrices, a host FE code) hands its element DOF maps and element matrices to dynid.
#pragma once

#include <Eigen/Core>
#include <utility>
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
///  * element_coupling(e, &pairs) may say which pairs of an element's DOFs can hold nonzero entries (sparse element
///    matrices, e.g. a group of a structure exported from another FE code): assembly then reserves only those
///    (and the diagonal). The default says every pair can (dense element matrices).
class ElementSource {
 public:
  virtual ~ElementSource() = default;
  virtual int num_dofs() const = 0;
  virtual int num_elements() const = 0;
  virtual void element_dofs(int e, std::vector<int>* dofs) const = 0;
  virtual void element_matrices(int e, Eigen::MatrixXd* K, Eigen::MatrixXd* M) const = 0;
  /// Sparse elements: true, with the pairs (a, b), a < b, of element_dofs() positions whose entries may be nonzero
  /// (an entry outside them must be zero in K and M). Dense elements: false (every pair may be nonzero).
  virtual bool element_coupling(int e, std::vector<std::pair<int, int>>* pairs) const {
    pairs->clear();
    return false;
  }
};

}  // namespace dynid
