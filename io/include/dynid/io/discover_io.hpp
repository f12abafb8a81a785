// dynid/io/discover_io.hpp -- the data a discover: case names, the results JSON and the report figure.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dynid/engine/discovery.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/io/case_file.hpp"
#include "dynid/io/plot.hpp"

namespace dynid {

/// The measured modes of a discover: case, and how they were obtained.
struct DiscoveryData {
  ModalData measured;
  bool identified = false;                 ///< identified from recordings (virtual or real)
  IdentificationSummary identification;
  ModalData truth_modes;                   ///< virtual test: the truth model's modes (reporting only)
  std::string source;
  std::vector<std::string> notes;          ///< modes left out and why
};

/// Reads (or identifies, or simulates and identifies) the measured modes; `seed_offset` shifts the truth test's
/// noise seed (robustness studies).
DiscoveryData discovery_data(const Case& c, int seed_offset = 0);

/// How a discovery compares with the case's `expect:`. A stiffness change named over another element set than the
/// expected one is compared with the expected change's flexibility average over the named set (element lengths
/// from `model`).
struct ExpectCheck {
  bool verdict = false, kind = false, location = false, parameter = true, also = true;
  double parameter_error = 0;  ///< relative
  std::string words;
  bool ok() const { return verdict && kind && location && parameter && also; }
};
ExpectCheck check_expectation(const DiscoverSpec::Expect& e, const DiscoverySummary& s, const Model& model);

/// A site in short form: "n4" + sep + "e37".
std::string site_label(const Site& s, const std::string& sep);

/// The words of a discovery, from its data (one story: the verdict, the findings with their values, the fit and
/// the evidence, and what would decide when it is inconclusive).
std::string discovery_explanation(const DiscoverySummary& s);
/// Where the residual forces are, and of what nature.
std::string localization_words(const DiscoverySummary& s);
/// Whether discover() fitted any candidate (none when a single measured mode pairs with the model).
bool candidates_fitted(const DiscoverySummary& s);
/// One sentence per measured mode set aside (a rigid-body mode on the suspension, a mode without a partner).
std::vector<std::string> set_aside_words(const DiscoverySummary& s);

nlohmann::ordered_json discovery_json(const Case& c, const DiscoveryData& d, const DiscoverySummary& s,
                                      const ExpectCheck* check);

/// Four panels: residual-force map on the structure, candidate ranking, frequency errors before/after, MAC
/// before/after.
plot::Figure discovery_figure(const Case& c, const DiscoverySummary& s);

}  // namespace dynid
