// The length unit a model's materials imply (units.hpp).
#include "dynid/mesh/units.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace dynid {

LengthUnit length_unit(const Model& model) {
  // sqrt(E / rho) of the materials members use (a material nothing uses says nothing about the model).
  std::vector<char> used(model.materials().size(), 0);
  for (const Element& e : model.elements())
    if (e.material >= 0 && e.material < static_cast<int>(used.size())) used[static_cast<std::size_t>(e.material)] = 1;
  double lo = INFINITY, hi = 0, rlo = INFINITY, rhi = 0;
  for (std::size_t k = 0; k < used.size(); ++k) {
    const Material& m = model.materials()[k];
    if (!used[k] || !(m.E > 0) || !(m.rho > 0)) continue;
    const double c = std::sqrt(m.E / m.rho);
    lo = std::min(lo, c);
    hi = std::max(hi, c);
    rlo = std::min(rlo, m.rho);
    rhi = std::max(rhi, m.rho);
  }
  LengthUnit u;
  if (!(hi > 0)) return u;
  u.wave_speed = lo;
  constexpr double kSlowest = 1000, kFastest = 12000;  // m/s: structural materials
  if (lo >= kSlowest && hi <= kFastest) {
    u.known = true;
  } else if (lo >= 1000 * kSlowest && hi <= 1000 * kFastest) {
    u.known = true;
    u.per_metre = 1000;
    u.name = "mm";
  }
  if (!u.known) return u;
  // Densities in kg/m^3 if the mass unit is the kilogram, 1000 times more if it is the tonne.
  constexpr double kLightest = 100, kHeaviest = 25000;  // kg/m^3: structural materials
  const double to_kg_m3 = u.per_metre * u.per_metre * u.per_metre;
  for (const double kilogram : {1.0, 1e-3}) {
    const double a = rlo * to_kg_m3 / kilogram, b = rhi * to_kg_m3 / kilogram;
    if (a >= kLightest && b <= kHeaviest) {
      u.mass_known = true;
      u.kilogram = kilogram;
      u.mass_name = kilogram == 1.0 ? "kg" : "t";
    }
  }
  return u;
}

double gravity_acceleration(const LengthUnit& unit) { return 9.81 * unit.per_metre; }

}  // namespace dynid
