// The identification band a model implies for a test (identify.hpp, band_from_model).
#include <algorithm>
#include <cmath>

#include "dynid/engine/identify.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/engine/modal_data.hpp"
#include "dynid/mesh/error.hpp"

namespace dynid {

ModelBand band_from_model(const Model& model, const std::vector<MeasuredDof>& sensors, double nyquist_hz, int modes) {
  std::vector<MeasuredDof> known;
  for (const MeasuredDof& d : sensors)
    if (model.node_index(d.node) >= 0 && model.dof_map().eq(model.node_index(d.node), d.dof) >= 0) known.push_back(d);
  if (known.empty()) throw InputError("identification band: no sensor is on a free DOF of the model");
  const std::vector<int> rows = measured_equations(model, known);
  const std::vector<int> translations = translation_equations(model);
  const int want = std::max(1, std::min(modes, static_cast<int>(known.size())));
  const double cap = nyquist_hz > 0 ? 0.8 * nyquist_hz : 1e300;
  // The lowest modes until `want` of them are visible at the sensors; local modes the sensors cannot see (a
  // frame's many member modes) can outnumber the visible ones, so the count grows (to 8 times the first) until the
  // band's cap is passed.
  EigenOptions eo;
  eo.num_modes = std::min(model.num_dofs(), 6 + 4 * want + 10);
  const int most = std::min(model.num_dofs(), 8 * eo.num_modes);
  if (model.num_dofs() <= 400) eo.method = EigenOptions::Method::kDense;
  ModelBand b;
  for (;;) {
    const ModalResult mr = modal_analysis(model, eo);
    if (!mr.ok())
      throw NumericalError("identification band: modal analysis of the model failed: " + mr.summary.message);
    b = ModelBand{};
    bool capped = false;
    for (Eigen::Index j = 0; j < mr.eigenvalues.size() && static_cast<int>(b.visible_hz.size()) < want; ++j) {
      if (mr.rigid_body[j]) continue;
      if (1.2 * mr.frequencies_hz[j] > cap) {  // a mode at the band's edge is identified poorly
        capped = true;
        break;
      }
      if (sensor_visibility(mr.modes.col(j), rows, translations) < 0.05) continue;
      b.visible_hz.push_back(mr.frequencies_hz[j]);
      ExpectedMode e{mr.frequencies_hz[j], known, Eigen::VectorXd(static_cast<Eigen::Index>(rows.size()))};
      for (std::size_t r = 0; r < rows.size(); ++r) e.shape[static_cast<Eigen::Index>(r)] = mr.modes(rows[r], j);
      b.expected.push_back(std::move(e));
    }
    if (capped || static_cast<int>(b.visible_hz.size()) >= want || eo.num_modes >= most) break;
    eo.num_modes = std::min(most, 2 * eo.num_modes);
  }
  if (b.visible_hz.empty())
    throw InputError("identification band: the sensors see no mode of the model below " + std::to_string(cap) +
                     " Hz (0.8 x Nyquist); give identify: band_hz");
  b.lo_hz = 0.6 * b.visible_hz.front();
  b.hi_hz = std::min(1.25 * b.visible_hz.back(), cap);
  return b;
}

}  // namespace dynid
