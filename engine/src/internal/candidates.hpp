// The candidate library of discovery (internal).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "dynid/engine/discovery.hpp"

namespace dynid::internal {

std::vector<std::unique_ptr<Candidate>> library(const Model& model, const ModalData& measured, const DiscoveryOptions& o);
std::unique_ptr<Candidate> make_recalibration(const Model& model);
std::string fmt_value(double v, int digits);
std::string with_std(const PhysicalValue& v);  ///< "2.1e4 N m/rad ± 4 %"

}  // namespace dynid::internal
