// dynid/io/case_file.hpp -- human-edited case files (YAML, or JSON which is read by the same parser).
// The format is documented in docs/case-file.md; every error names the file, line and column.
#pragma once

#include <limits>
#include <string>

#include <optional>

#include "dynid/engine/detect.hpp"
#include "dynid/mesh/model.hpp"
#include "dynid/solvers/eigen.hpp"

namespace dynid {

/// What `analysis:` asks for.
struct AnalysisSpec {
  int modes = 10;                                                  ///< lowest modes (rigid-body included)
  double band_lo_hz = std::numeric_limits<double>::quiet_NaN();    ///< band mode if both set
  double band_hi_hz = std::numeric_limits<double>::quiet_NaN();
  double shift_hz = std::numeric_limits<double>::quiet_NaN();      ///< explicit shift (as a frequency)
  EigenOptions::Method method = EigenOptions::Method::kAuto;
  EigenOptions eigen_options() const;  ///< the solver options this spec means
};

/// What `detect:` asks for (docs/case-file.md): the changed state is either simulated (the reference model with
/// element changes, its exact modes taken at `measured_dofs`) or measured modal data from a file.
struct DetectSpec {
  std::vector<std::pair<int, std::pair<double, double>>> changes;  ///< element id -> (dk, dm)
  std::string measured_file;            ///< changed-state modal data (JSON) instead of `changes`
  std::string reference_measured_file;  ///< optional reference-state modal data
  std::vector<MeasuredDof> measured_dofs;  ///< DOFs the simulated changed state is "measured" at
  DetectOptions options;
  bool has_study = false;
  NoiseStudyOptions study;
};

struct Case {
  std::string path;         ///< the case file
  std::string dir;          ///< its folder (relative paths in the case resolve against it)
  std::string name, description;
  Model model;              ///< finalized
  AnalysisSpec analysis;
  std::optional<DetectSpec> detect;
};

/// Loads a case from a case file, or from a folder holding case.yaml / case.yml / case.json.
/// Throws InputError("<file>:<line>:<col>: <what is wrong>; <what to do>").
Case load_case(const std::string& path);

/// Parses a case from text (for tests and host codes); `name` is used in messages as the file name.
Case parse_case(const std::string& text, const std::string& name, const std::string& dir = ".");

/// Resolves a CASE argument (file or folder) to the case file path; throws InputError if there is none.
std::string resolve_case_path(const std::string& path);

}  // namespace dynid
