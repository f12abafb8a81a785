// The registry of candidate kinds and the context they are placed with (internal).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/candidate.hpp"
#include "dynid/engine/modal.hpp"

namespace dynid::internal {

/// The context of a discovery: scales, members, sensors, suspension points and gravity of `model`.
/// `sensor_nodes`, `suspension_nodes`: user ids (empty = the measured nodes; the two nodes farthest apart);
/// `gravity`: a direction (non-zero; the caller's default_gravity when the user gives none); `modes`: the model's
/// lowest modes (lowest_modes(), solved once by the caller); `band_modes`: those of its elastic modes (0-based,
/// rigid-body modes not counted) paired with the data (empty: the first as many as `measured` holds). Throws InputError
/// for unknown nodes.
CandidateContext make_context(const Model& model, const ModalData& measured, const std::vector<int>& sensor_nodes,
                              const std::vector<int>& suspension_nodes, const Eigen::Vector3d& gravity,
                              const ModalResult& modes, const std::vector<int>& band_modes);

/// Gravity's direction when the user gives none: -y for plane models; for space models -z, or -y when the model
/// stands on its lowest y (every support there, not every one at the lowest z, the structure extending along two
/// axes or more: a frame drawn with y up). `unconventional` (optional): the -y of a space model.
Eigen::Vector3d default_gravity(const Model& model, bool* unconventional = nullptr);

/// Every candidate of the kinds named in `kinds` (empty = all) among `registry`, placed on the model. Throws
/// InputError naming a kind that is not in the registry, with the known ones.
std::vector<std::unique_ptr<Candidate>> place_candidates(const CandidateContext& c, const std::vector<CandidateKind>& registry,
                                                         const std::vector<std::string>& kinds);

/// The classic alternative: E and rho of the whole model.
std::unique_ptr<Candidate> make_recalibration(const Model& model);

}  // namespace dynid::internal
