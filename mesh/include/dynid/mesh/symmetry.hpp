// dynid/mesh/symmetry.hpp -- geometric symmetries of a model (mirror planes, half turns), to recognise
// "twin" elements that vibration data of a symmetric structure cannot tell apart.
#pragma once

#include <string>
#include <vector>

#include "dynid/mesh/model.hpp"

namespace dynid {

struct Symmetry {
  std::string description;   ///< e.g. "mirror x = 1.5"
  std::vector<int> node;     ///< node index -> image node index
  std::vector<int> element;  ///< element index -> image element index
};

/// The symmetries of a finalized model among: mirror planes normal to x, y and z through the centroid of the
/// nodes, and half turns about the x, y and z axes through it. A symmetry holds when every node maps onto a
/// node (within 1e-9 of the model size), every element onto an element of the same type, material, section,
/// property factors (and mass, stiffness, DOF types), and every support onto the same support.
std::vector<Symmetry> find_symmetries(const Model& model);

/// Images of element e under the symmetries, excluding e itself (sorted, unique).
std::vector<int> element_twins(const std::vector<Symmetry>& symmetries, int e);

}  // namespace dynid
