// dynid/mesh/units.hpp -- the length and mass units a model's materials imply. dynid takes units as the user gives them
// (consistent, time in seconds since frequencies are in Hz); the few physical constants it needs (gravity) must
// be in the same units, and this is where they come from when the user does not say.
#pragma once

#include <string>

#include "dynid/mesh/model.hpp"

namespace dynid {

/// The length unit of a model, read from its materials: with time in seconds, sqrt(E / rho) of every structural
/// material (steel, aluminium, concrete, timber, glass, fibre composites) lies within 1,000-12,000 m/s; the same
/// speed reads 1e6-1.2e7 in mm/s (mm, tonne, s, N: E in MPa, rho in t/mm^3). The two ranges are 83 times apart,
/// so a model whose members' materials all fall within one of them has that unit. Others (cm, inch, feet; E = 1 or
/// other normalised materials; matrix-only models) are not guessed: `known` is false and the model is taken to be
/// in metres.
struct LengthUnit {
  bool known = false;      ///< every member's material reads the same unit
  double per_metre = 1.0;  ///< model length units in one metre (1 or 1000)
  std::string name = "m";  ///< "m" or "mm"
  double wave_speed = 0;   ///< the members' slowest sqrt(E / rho), in model units per second (0: no material)
  /// The mass unit, read from the densities once the length unit is known: structural materials weigh 100-25,000
  /// kg/m^3 (timber to tungsten), 0.1-25 in t/m^3; the two ranges are 1000 times apart (N, m, kg, s against kN, m,
  /// t, s, whose sqrt(E / rho) are the same; N, mm, t, s). Not known when the length is not, or the densities fall
  /// in neither range or in different ones.
  bool mass_known = false;
  double kilogram = 1.0;         ///< one kilogram in the model's mass unit (1 or 1e-3)
  std::string mass_name = "kg";  ///< "kg" or "t"
};
LengthUnit length_unit(const Model& model);

/// The acceleration of gravity, 9.81 m/s^2, in the unit's length per s^2.
double gravity_acceleration(const LengthUnit& unit);

}  // namespace dynid
