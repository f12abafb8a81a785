// Section properties of standard shapes, shared by the case-file parser and the Abaqus reader (internal to io).
#pragma once

#include <cmath>
#include <string>

#include "dynid/mesh/model.hpp"

namespace dynid::internal {

/// Solid rectangle: `depth` lies in the plane of bending about the local z axis (Iz = width depth^3 / 12);
/// J by the thin-wall-corrected series (Roark). Abaqus RECT: width = a (1-direction), depth = b (2-direction).
inline Section rectangle_section(const std::string& name, double width, double depth) {
  Section s;
  s.name = name;
  s.A = width * depth;
  s.Iz = width * depth * depth * depth / 12.0;
  s.Iy = depth * width * width * width / 12.0;
  const double a = std::max(width, depth), t = std::min(width, depth);
  s.J = a * t * t * t * (1.0 / 3.0 - 0.21 * (t / a) * (1.0 - std::pow(t / a, 4) / 12.0));
  return s;
}

/// Hollow circle of outer radius `r` and wall thickness `t` (t = r: a solid circle). J = 2 I (polar).
inline Section pipe_section(const std::string& name, double r, double t) {
  const double ri = r - t;
  Section s;
  s.name = name;
  s.A = M_PI * (r * r - ri * ri);
  s.Iy = s.Iz = M_PI * (std::pow(r, 4) - std::pow(ri, 4)) / 4.0;
  s.J = 2.0 * s.Iz;
  return s;
}

}  // namespace dynid::internal
