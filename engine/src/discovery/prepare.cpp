// Discovery, stage 1: the noise model, the measured modes set aside, the candidates.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "candidates/common.hpp"
#include "candidates/registry.hpp"
#include "discovery/stages.hpp"
#include "dynid/engine/modal.hpp"
#include "dynid/mesh/error.hpp"
#include "dynid/mesh/units.hpp"

namespace dynid::internal {

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

// A further relative std per mode joins the frequency noise in quadrature (the one level per mode when the noise
// model has none per mode yet).
void add_frequency_std(NoiseModel* nm, const Eigen::VectorXd& extra) {
  const Eigen::Index p = extra.size();
  const Eigen::VectorXd f =
      nm->frequency_modes.size() == p ? nm->frequency_modes : Eigen::VectorXd::Constant(p, nm->frequency);
  nm->frequency_modes = (f.array().square() + extra.array().square()).sqrt();
}

// Closely spaced modes (docs/method.md): an identified mode's shape is its model partner's mixed with each other
// model mode, by about s = r / delta (at most 1), delta the neighbour's relative distance in frequency and r the
// identification's resolution of the pair. When the neighbour has a measured partner of its own, the
// identification resolved the two poles and r is the mode's relative frequency std sigma: an estimate whose pole
// is off by sigma mixes the shapes of poles delta apart by that much (first-order perturbation: the coupling over
// the eigenvalue gap). When it has none, the sensors see it and the two half-power bands overlap (delta < 2
// zeta, zeta the identified damping ratio: modal overlap), the test may have merged the two into one estimate: r
// is then zeta (the half-power half-width; a neighbour delta away responds at the mode's frequency by zeta /
// delta of its own peak), and the estimate's frequency is pulled toward the neighbour's by s^2 delta (the
// neighbour's share of the Rayleigh quotient), which joins the mode's frequency std in quadrature
// (nm->unresolved). A misfit along the neighbour's shape at the sensors (the part orthogonal to the partner's, at
// the scale the mode is measured at) is no evidence: one factor column per neighbour. Only for frequencies whose
// std comes from the data: a stated noise is the user's noise model, taken as stated (independent shape entries).
// The largest share per mode goes to nm->neighbour_mixing.
std::vector<Eigen::MatrixXd> neighbour_mixing(const Model& model, const ModalResult& modes,
                                              const std::vector<int>& partner, const ModalData& data, NoiseModel* nm,
                                              std::vector<std::string>* warnings) {
  std::vector<Eigen::MatrixXd> out;
  const int p = data.num_modes();
  if (nm->frequency_source != NoiseModel::Source::kData) return out;
  if (partner.size() != static_cast<std::size_t>(p) || !modes.ok() || p == 0) return out;
  std::vector<Eigen::Index> ec;
  for (Eigen::Index j = 0; j < modes.eigenvalues.size(); ++j)
    if (!modes.rigid_body[j]) ec.push_back(j);
  const std::vector<int> rows = measured_equations(model, data.dofs);
  const std::vector<int> translations = translation_equations(model);
  const Eigen::Index a = static_cast<Eigen::Index>(rows.size());
  auto at_sensors = [&](Eigen::Index col) {
    Eigen::VectorXd v(a);
    for (Eigen::Index r = 0; r < a; ++r) v[r] = modes.modes(rows[r], col);
    return v;
  };
  std::vector<bool> resolved(ec.size(), false);  // model modes with a measured partner of their own
  for (int j : partner)
    if (j >= 0 && j < static_cast<int>(ec.size())) resolved[static_cast<std::size_t>(j)] = true;
  out.assign(static_cast<std::size_t>(p), Eigen::MatrixXd(a, 0));
  nm->neighbour_mixing = Eigen::VectorXd::Zero(p);
  nm->unresolved = Eigen::VectorXd::Zero(p);
  for (int k = 0; k < p; ++k) {
    const int j = partner[static_cast<std::size_t>(k)];
    if (j < 0 || j >= static_cast<int>(ec.size())) continue;
    const Eigen::VectorXd vj = at_sensors(ec[j]);
    const double vv = vj.squaredNorm();
    const double top = data.shapes.col(k).cwiseAbs().maxCoeff();
    if (!(vv > 0) || !(top > 0)) continue;
    const double c = data.shapes.col(k).dot(vj) / top / vv;  // the model shape's scale at the measured one's
    const double sigma = nm->frequency_modes.size() == p ? nm->frequency_modes[k] : nm->frequency;
    const double zeta = data.damping_ratios.size() == p && std::isfinite(data.damping_ratios[k])
                            ? std::max(0.0, data.damping_ratios[k])
                            : 0.0;
    const double fj = modes.frequencies_hz[ec[j]];
    std::vector<Eigen::VectorXd> cols;
    double nearest = 0;  // the closest neighbour within the resolution (Hz), if any
    double pull2 = 0;    // squared relative frequency pull of unresolved neighbours
    for (int i = 0; i < static_cast<int>(ec.size()); ++i) {
      if (i == j) continue;
      const double delta = std::abs(modes.frequencies_hz[ec[i]] - fj) / fj;
      const bool merged = !resolved[static_cast<std::size_t>(i)] && zeta > sigma && delta < 2 * zeta &&
                          sensor_visibility(modes.modes.col(ec[i]), rows, translations) >= kMinPairingVisibility;
      const double r = merged ? zeta : sigma;
      const double s = delta > r ? r / delta : 1.0;
      if (s < 1e-3) continue;
      nm->neighbour_mixing[k] = std::max(nm->neighbour_mixing[k], s);
      if (merged) pull2 += std::pow(s * s * delta, 2);
      if (s == 1.0 && (nearest == 0 || std::abs(modes.frequencies_hz[ec[i]] - fj) < std::abs(nearest - fj)))
        nearest = modes.frequencies_hz[ec[i]];
      const Eigen::VectorXd vi = at_sensors(ec[i]);
      cols.push_back(s * c * (vi - (vi.dot(vj) / vv) * vj));
    }
    nm->unresolved[k] = std::sqrt(pull2);
    Eigen::MatrixXd& F = out[static_cast<std::size_t>(k)];
    F.resize(a, static_cast<Eigen::Index>(cols.size()));
    for (std::size_t q = 0; q < cols.size(); ++q) F.col(static_cast<Eigen::Index>(q)) = cols[q];
    if (nearest > 0 && warnings)
      warnings->push_back("measured mode at " + fmt_value(data.frequencies_hz[k], 5) + " Hz: the model has modes at " +
                          fmt_value(fj, 5) + " and " + fmt_value(nearest, 5) +
                          " Hz, closer than the test resolves; it cannot tell them apart, so its shape is compared "
                          "with their mixtures (closely spaced modes)");
  }
  if (nm->unresolved.maxCoeff() > 0) add_frequency_std(nm, nm->unresolved);
  return out;
}

}  // namespace

void add_contamination(const ModalData& data, NoiseModel* nm) {
  const int p = data.num_modes();
  if (data.mpc.size() != p || p == 0) return;
  Eigen::VectorXd f =
      nm->frequency_modes.size() == p ? nm->frequency_modes : Eigen::VectorXd::Constant(p, nm->frequency);
  bool any = false;
  for (int k = 0; k < p; ++k) {
    const double mpc = std::clamp(data.mpc[k], 0.0, 1.0);
    if (!(mpc < 1)) continue;
    // Out-of-phase to in-phase energy of the identified shape: MPC = ((A - B) / (A + B))^2.
    const double c = (1 - std::sqrt(mpc)) / (1 + std::sqrt(mpc));
    const double zeta = data.damping_ratios.size() == p && std::isfinite(data.damping_ratios[k]) ? std::abs(data.damping_ratios[k]) : 0.0;
    f[k] = std::hypot(f[k], zeta * std::sqrt(c));
    any = true;
  }
  if (any) nm->frequency_modes = f;
}

NoiseModel noise_model(const ModalData& data, const DiscoveryOptions& o, std::vector<std::string>* warnings) {
  NoiseModel nm;
  const int p = data.num_modes();
  if (std::isfinite(o.frequency_noise)) {
    nm.frequency = o.frequency_noise;
    nm.frequency_source = NoiseModel::Source::kStated;
  } else if (data.frequency_std_hz.size() == p && p > 0) {
    std::vector<double> rel;
    for (int k = 0; k < p; ++k) rel.push_back(data.frequency_std_hz[k] / data.frequencies_hz[k]);
    nm.frequency = std::max(median(rel), o.min_data_frequency_noise);
    nm.frequency_source = NoiseModel::Source::kData;
    nm.frequency_modes = Eigen::Map<const Eigen::VectorXd>(rel.data(), p).cwiseMax(nm.frequency);
  }
  if (!(nm.frequency > 0)) {
    nm.frequency = o.default_frequency_noise;
    nm.frequency_source = NoiseModel::Source::kDefault;
    warnings->push_back("the frequencies' noise is not stated and the data carry none: " +
                        fmt_value(100 * nm.frequency, 3) + " % assumed (conservative: smaller mismatches go unnoticed); "
                        "state frequency_noise for sharper conclusions");
  }
  if (std::isfinite(o.shape_noise)) {
    nm.shape = o.shape_noise;
    nm.shape_source = NoiseModel::Source::kStated;
  } else if (data.shape_std.size() == p && p > 0) {
    nm.shape = std::max(median(std::vector<double>(data.shape_std.data(), data.shape_std.data() + p)), o.min_data_shape_noise);
    nm.shape_source = NoiseModel::Source::kData;
    nm.shape_modes = data.shape_std.cwiseMax(nm.shape);
  }
  if (!(nm.shape > 0)) {
    nm.shape = o.default_shape_noise;
    nm.shape_source = NoiseModel::Source::kDefault;
    warnings->push_back("the mode shapes' noise is not stated and the data carry none: " + fmt_value(100 * nm.shape, 3) +
                        " % of each mode's largest entry assumed; state shape_noise for sharper conclusions");
  }
  add_contamination(data, &nm);
  return nm;
}

std::vector<SetAside> rigid_body_modes(const Model& model, const ModalData& data) {
  std::vector<SetAside> out;
  if (!model.free_free()) return out;
  const Eigen::MatrixXd R = model.free_rigid_body_modes();
  if (R.cols() == 0) return out;
  const std::vector<int> rows = measured_equations(model, data.dofs);
  Eigen::MatrixXd Ra(static_cast<Eigen::Index>(rows.size()), R.cols());
  for (std::size_t r = 0; r < rows.size(); ++r) Ra.row(static_cast<Eigen::Index>(r)) = R.row(rows[r]);
  // Orthonormal basis of the rigid motions as the sensors see them.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Ra, Eigen::ComputeThinU);
  int rank = 0;
  for (Eigen::Index i = 0; i < svd.singularValues().size(); ++i) rank += svd.singularValues()[i] > 1e-8 * svd.singularValues()[0];
  if (rank == 0) return out;
  const Eigen::MatrixXd Q = svd.matrixU().leftCols(rank);
  // The first elastic frequency of the model: rigid-body modes on a suspension lie well below it.
  EigenOptions eo;
  eo.num_modes = std::min(model.num_dofs(), static_cast<int>(R.cols()) + 1);
  if (model.num_dofs() <= 400) eo.method = EigenOptions::Method::kDense;
  const ModalResult mr = modal_analysis(model, eo);
  if (!mr.ok()) throw NumericalError("discover: modal analysis of the model failed: " + mr.summary.message);
  double f1 = 0;
  for (Eigen::Index j = 0; j < mr.frequencies_hz.size(); ++j)
    if (!mr.rigid_body[j]) {
      f1 = mr.frequencies_hz[j];
      break;
    }
  for (int k = 0; k < data.num_modes(); ++k) {
    const Eigen::VectorXd u = data.shapes.col(k);
    const double mac = (Q.transpose() * u).squaredNorm() / u.squaredNorm();
    if (data.frequencies_hz[k] < 0.5 * f1 && mac >= 0.8) {
      SetAside s;
      s.mode = k;
      s.frequency_hz = data.frequencies_hz[k];
      s.reason = SetAside::Reason::kRigidBody;
      s.mac = mac;
      out.push_back(s);
    }
  }
  return out;
}

void prepare(const Model& model, const ModalData& measured, const DiscoveryOptions& o,
             std::vector<std::unique_ptr<Candidate>> extra, Problem* pp, DiscoverySummary* S) {
  std::string why;
  if (!o.IsValid(&why)) throw InputError("discover options: " + why);
  measured.validate("measured modal data");
  if (measured.num_modes() < 1) throw InputError("discover: no measured modes");
  measured_equations(model, measured.dofs);  // throws naming a DOF the model does not have
  Problem& p = *pp;
  p.model = &model;
  p.options = o;
  S->set_aside = rigid_body_modes(model, measured);

  // The fit: frequencies and shapes, whitened at the noise model's levels; pairing never forced.
  p.fit.objective = FitObjective::kCombined;
  p.fit.min_mac = o.min_mac;
  p.fit.max_frequency_ratio = o.max_frequency_ratio;
  p.fit.max_iterations = o.max_iterations;
  p.fit.dense_max_dofs = 40;

  // Modes without a plausible partner in the model as given are not compared (never forced onto another mode).
  std::vector<int> keep, partner;
  for (int k = 0; k < measured.num_modes(); ++k) {
    bool aside = false;
    for (const SetAside& s : S->set_aside) aside = aside || s.mode == k;
    if (!aside) keep.push_back(k);
  }
  {
    ParametricModel pm(model);
    const PlausibleModes pl = plausible_modes(pm, modes_subset(measured, keep), pm.nominal(), p.fit);
    for (int k : pl.unpaired) {
      SetAside s;
      s.mode = keep[static_cast<std::size_t>(k)];
      s.frequency_hz = measured.frequencies_hz[s.mode];
      s.reason = SetAside::Reason::kNoPartner;
      s.mac = pl.correlation.mac[k];
      S->set_aside.push_back(s);
    }
    std::vector<int> paired;
    for (int k : pl.paired) {
      paired.push_back(keep[static_cast<std::size_t>(k)]);
      partner.push_back(pl.correlation.model_mode[static_cast<std::size_t>(k)]);
    }
    keep = paired;
  }
  std::sort(S->set_aside.begin(), S->set_aside.end(), [](const SetAside& a, const SetAside& b) { return a.mode < b.mode; });
  p.data = modes_subset(measured, keep);
  p.data_modes = keep;
  p.modes = p.data.num_modes();
  p.noise = noise_model(p.data, o, &S->warnings);
  // The model's lowest modes, solved once: for its discretisation error and for the candidates' units.
  const int count = partner.empty() ? measured.num_modes() : *std::max_element(partner.begin(), partner.end()) + 1;
  const ModalResult modes = lowest_modes(model, count);
  // The model's own discretisation error joins the frequency noise, mode by mode.
  if (!partner.empty()) {
    const Eigen::VectorXd disc = discretization_error(model, modes, count);
    p.noise.discretization.resize(p.modes);
    for (int k = 0; k < p.modes; ++k) p.noise.discretization[k] = partner[static_cast<std::size_t>(k)] < disc.size() ? disc[partner[static_cast<std::size_t>(k)]] : 0.0;
    if (p.noise.discretization.maxCoeff() > 0) add_frequency_std(&p.noise, p.noise.discretization);
  }
  p.fit.shape_covariance_factors = neighbour_mixing(model, modes, partner, p.data, &p.noise, &S->warnings);
  S->noise = p.noise;  // the noise model as the fit uses it
  p.fit.frequency_noise = p.noise.frequency;
  p.fit.shape_noise = p.noise.shape;
  if (p.noise.frequency_modes.size()) p.fit.frequency_noise_modes = p.noise.frequency_modes;
  if (p.noise.shape_modes.size()) p.fit.shape_noise_modes = p.noise.shape_modes;
  std::vector<int> lone;
  for (const SetAside& s : S->set_aside)
    if (s.reason == SetAside::Reason::kNoPartner) lone.push_back(s.mode);
  p.unpartnered = modes_subset(measured, lone);
  p.unpartnered_edge.resize(static_cast<Eigen::Index>(lone.size()));
  // A mode no model mode pairs has, under the model, only a vague density: uniform over the plausible range of
  // its whitened residuals (frequency ratio within max_frequency_ratio, each shape entry within +-1 of the
  // largest). Pairing it with a residual vector r replaces that density by the noise's normal one: the gain in
  // -2 ln L is sum over entries of 2 ln(width / sqrt(2 pi)) - |r|^2, bounded by the "edge" below: logarithmic in
  // the noise, so that one set-aside mode cannot outweigh the paired ones. The same for every unpartnered mode.
  {
    auto gain = [](double width) { return std::max(0.0, 2.0 * std::log(width / std::sqrt(2 * M_PI))); };
    const double r2 = o.max_frequency_ratio * o.max_frequency_ratio;
    const double wf = (r2 - 1.0 / r2) / (2 * p.noise.frequency);  // width of the frequency residual (eigenvalue-based)
    const double ws = 2.0 / p.noise.shape;                          // width of a shape entry's residual
    p.unpartnered_edge.setConstant(gain(wf) + gain(ws) * static_cast<double>(measured.dofs.size()));
  }

  bool unconventional = false;  // gravity along -y in a space model (default_gravity)
  const Eigen::Vector3d down = o.gravity.norm() > 0 ? o.gravity : default_gravity(model, &unconventional);
  p.context = make_context(model, p.data.num_modes() ? p.data : measured, o.sensor_nodes, o.suspension_nodes, down,
                           modes, partner);
  p.context.measured = &p.data;
  const LengthUnit unit = length_unit(model);
  p.context.gravity_acceleration = o.gravity_acceleration > 0 ? o.gravity_acceleration : gravity_acceleration(unit);
  p.context.kilogram = unit.mass_known ? unit.kilogram : o.si_units ? 1.0 : 0.0;  // the densities say, else the labels
  std::vector<CandidateKind> registry = builtin_candidate_kinds();
  registry.insert(registry.end(), o.extra_kinds.begin(), o.extra_kinds.end());
  p.library = place_candidates(p.context, registry, o.kinds);
  const bool self_weight =
      std::any_of(p.library.begin(), p.library.end(), [](const auto& c) { return c->kind() == "self_weight"; });
  if (self_weight && unconventional)
    S->warnings.push_back(
        "gravity taken along -y for self_weight: every support lies at the structure's lowest y "
        "(discover: gravity says otherwise)");
  if (!(o.gravity_acceleration > 0) && self_weight) {
    if (!unit.known)
      S->warnings.push_back(
          "the materials do not say the model's length unit (slowest sqrt(E / rho) " + fmt_value(unit.wave_speed, 3) +
          " per s; metres: 1,000-12,000, millimetres: 1e6-1.2e7): " +
          "self_weight takes gravity as 9.81 (m/s^2); give discover: gravity_acceleration in the model's units");
    else if (unit.per_metre != 1)
      S->warnings.push_back("the materials (slowest sqrt(E / rho) " + fmt_value(unit.wave_speed, 3) + " " + unit.name +
                            "/s) put the model in " + unit.name + ": self_weight takes gravity as " +
                            fmt_value(p.context.gravity_acceleration, 4) + " " + unit.name + "/s^2");
  }
  for (auto& c : extra) p.library.push_back(std::move(c));
  p.recalibration = make_recalibration(model);
  for (const auto& c : p.library) ++p.sites_per_physics[c->physics()];
}

}  // namespace dynid::internal
