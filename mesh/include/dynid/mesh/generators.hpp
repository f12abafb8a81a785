// dynid/mesh/generators.hpp -- parametric models: straight beams, 2D and 3D multi-bay multi-story frames.
#pragma once

#include "dynid/mesh/model.hpp"

namespace dynid {

enum class BeamSupport { Free, Cantilever, SimplySupported, Clamped };

/// A straight Beam2D line along x from 0 to `length`, `elements` elements, nodes numbered 1..elements+1.
struct BeamSpec {
  double length = 1.0;
  int elements = 10;
  Material material;
  Section section;
  BeamSupport support = BeamSupport::Free;
  MassType mass = MassType::Consistent;
};
Model make_beam(const BeamSpec& spec);

/// Plane frame (Frame2D) in x-y: `bays` bays of width `span`, `stories` stories of height `height`, each member
/// split into `divisions` elements, base nodes clamped. Element groups: "column", "beam".
/// DOFs = 3 * nodes: nodes = (bays+1)(stories+1) + (divisions-1) * (members).
struct Frame2DSpec {
  int bays = 1, stories = 1, divisions = 1;
  double span = 1.0, height = 1.0;
  Material material;
  Section column, beam;
  MassType mass = MassType::Consistent;
};
Model make_frame2d(const Frame2DSpec& spec);

/// Space frame (Frame3D): a grid of `bays_x` x `bays_y` bays, `stories` stories; columns along z, floor beams
/// along x and y at every story; each member split into `divisions` elements; base nodes clamped.
struct Frame3DSpec {
  int bays_x = 1, bays_y = 1, stories = 1, divisions = 1;
  double span_x = 1.0, span_y = 1.0, height = 1.0;
  Material material;
  Section column, beam;
  MassType mass = MassType::Consistent;
};
Model make_frame3d(const Frame3DSpec& spec);

/// A copy of a finalized model with every beam and frame element split in two at its midpoint (new nodes and
/// elements numbered after the largest ids); everything else as it was: supports, point masses, springs, matrix
/// elements, groups, factors, axial forces. Comparing the two estimates the discretisation error.
Model refined(const Model& model);

/// Number of DOFs make_frame2d / make_frame3d would produce (without building the model).
long long frame2d_dofs(const Frame2DSpec& s);
long long frame3d_dofs(const Frame3DSpec& s);

}  // namespace dynid
