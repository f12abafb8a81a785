// dynid/io/case_file.hpp -- human-edited case files (YAML, or JSON which is read by the same parser).
// The format is documented in docs/case-file.md; every error names the file, line and column.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dynid/engine/detect.hpp"
#include "dynid/engine/discovery.hpp"
#include "dynid/engine/identify.hpp"
#include "dynid/engine/model_fit.hpp"
#include "dynid/engine/multistart.hpp"
#include "dynid/engine/parametric.hpp"
#include "dynid/engine/regularization.hpp"
#include "dynid/engine/virtual_test.hpp"
#include "dynid/io/limits.hpp"
#include "dynid/io/mat_file.hpp"
#include "dynid/io/point_map.hpp"
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
  std::string measured_file;            ///< changed-state modal data (JSON, UFF, .mat) instead of `changes`
  MatModalNames measured_mat;           ///< a .mat measured file's variables
  std::string reference_measured_file;  ///< optional reference-state modal data
  GeometrySpec geometry;                ///< test geometry tying the measured files' points to model nodes
  std::vector<MeasuredDof> measured_dofs;  ///< DOFs the simulated changed state is "measured" at
  DetectOptions options;
  bool has_study = false;
  NoiseStudyOptions study;
};

/// What `update:` asks for (docs/case-file.md): parameters, objective, and the measured data (a file, or a
/// simulated target: the model with element factors changed, sampled at `measured_dofs`).
struct UpdateSpec {
  std::string measured_file;
  MatModalNames measured_mat;            ///< a .mat measured file's variables
  GeometrySpec geometry;  ///< test geometry tying the measured file's points to model nodes
  std::vector<std::pair<int, PropertyFactors>> target_changes;  ///< simulated target
  std::vector<MeasuredDof> measured_dofs;
  int target_modes = 5;                  ///< elastic modes of the simulated target
  int modes = 0;                         ///< measured modes used (0 = all)
  std::vector<Parameter> parameters;     ///< resolved against the model (element indices)
  Eigen::VectorXd initial;
  std::vector<char> free;
  std::vector<std::pair<int, std::pair<int, double>>> ties;
  FitOptions options;
  bool multistart = false;               ///< global search (multistart:), with:
  MultiStartOptions search;
  bool lcurve = false;  ///< regularization: l-curve (the weight chosen by the L-curve rule)
  LCurveOptions lcurve_options;
};

/// What `test:` asks for (docs/case-file.md): a virtual test of the case's model (`dynid simulate-test`), the
/// file it writes, and how to identify its recordings (`dynid identify`, `dynid run`).
struct TestSpec {
  VirtualTestOptions options;
  std::string output;              ///< UFF 58 file (resolved against the case folder); "" = <case>-test.uff
  bool binary = true;              ///< 58b (binary) or ASCII 58
  double max_frequency_hz = 0;     ///< modes computed up to here (0 = 1.2 x Nyquist)
  std::string method;              ///< identification: "lscf" or "ssi" ("" = lscf for impact/random, ssi for ambient)
  IdentificationOptions identify;
};

/// What `discover:` asks for (docs/case-file.md): the measured data (modal data from a file, recordings to
/// identify first, or - for concealed-data studies - a virtual test of a `truth` model the analysis never sees),
/// the discovery options, and optionally what the answer should be (`expect`, for the test suite).
struct DiscoverSpec {
  std::string measured_file;               ///< UFF 55/2414, modal-data JSON or .mat
  MatModalNames measured_mat;              ///< a .mat measured file's variables
  GeometrySpec geometry;                   ///< test geometry tying the measured file's points to model nodes
  std::vector<std::string> recordings;     ///< UFF 58 / text / .mat recordings, identified first
  std::vector<MatRecordingNames> recording_mat;  ///< per recording: a .mat file's variables (file "" = default names)
  std::string method;                      ///< identification method for recordings ("" = by the data)
  IdentificationOptions identify;
  std::shared_ptr<Model> truth;            ///< concealed-data study: the truth model
  std::shared_ptr<TestSpec> truth_test;    ///< and its virtual test
  int modes = 0;                           ///< first modes used (0 = all identified)
  double min_mpc = 0.8;                    ///< identified modes below this MPC are left out (not normal modes)
  DiscoveryOptions options;
  int seeds = 1;                           ///< robustness study: repeat the truth test with this many seeds
  struct Expect {
    std::vector<std::string> kinds;        ///< the finding's kind must be one of these (`kind: a` or `kind: [a, b]`)
    std::vector<int> nodes, elements;      ///< the finding's site must share a node or an element with these
    std::string parameter;                 ///< physical value checked (name as reported)
    double value = 0;
    double tolerance = 0.10;               ///< relative
    std::string verdict = "missing_physics";
    std::vector<Expect> also;              ///< further effects (any order among the findings)
  };
  std::optional<Expect> expect;
};

struct Case {
  std::string path;         ///< the case file
  std::string dir;          ///< its folder (relative paths in the case resolve against it)
  std::string name, description;
  Model model;              ///< finalized
  std::vector<std::string> notes;  ///< remarks on reading the model (mesh-file content that was skipped)
  AnalysisSpec analysis;
  std::optional<DetectSpec> detect;
  std::optional<UpdateSpec> update;
  std::optional<TestSpec> test;
  std::optional<DiscoverSpec> discover;
  ReaderLimits limits;  ///< what its files were (and the data files it names are) read within
};

/// Loads a case from a case file, or from a folder holding case.yaml / case.yml / case.json.
/// Throws InputError("<file>:<line>:<col>: <what is wrong>; <what to do>"). Files are read within `limits`.
Case load_case(const std::string& path, const ReaderLimits& limits = {});

/// Parses a case from text (for tests and host codes); `name` is used in messages as the file name.
Case parse_case(const std::string& text, const std::string& name, const std::string& dir = ".",
                const ReaderLimits& limits = {});

/// A case whose model is built in memory (by a host code, or from Python): `text` (YAML or JSON) holds the
/// other sections (name, description, analysis, detect, update, test, discover; no model:), parsed against
/// `model` (finalized) with every check and message of a case file; `name` names the text in messages and
/// relative paths in it resolve against `dir`.
Case case_with_model(Model model, const std::string& text, const std::string& name, const std::string& dir = ".",
                     const ReaderLimits& limits = {});

/// The changed state of a detect: case: measured data from its file, or the exact modes of the changed model at
/// the measured DOFs (then *changed, unless null, receives that model, for DetectOptions::simulated_changed).
ModalData detect_changed_data(const Case& c, Model* changed);
/// The measured data of an update: case: from its file, or the simulated target; the first `modes` modes.
ModalData update_measured_data(const Case& c);
/// The first `count` modes of `m` (all when count <= 0), with every per-mode value (damping, MPC, standard
/// deviations) cut alike.
ModalData first_modes(ModalData m, int count);

/// The virtual test `t` describes, run on `model`: its modes up to t.max_frequency_hz (default 1.2 x Nyquist) with
/// the solver settings `eo`, then simulate_test with the noise seed shifted by `seed_offset`. Throws
/// NumericalError("<what>failed: ...") if the modal analysis fails.
VirtualTest run_test_spec(const Model& model, const TestSpec& t, EigenOptions eo, std::uint64_t seed_offset,
                          const std::string& what);

/// Throws InputError("<case>: the case has no <section>: section (see docs/case-file.md)") unless `present`.
void require_section(const Case& c, bool present, const std::string& section);

/// Resolves a CASE argument (file or folder) to the case file path; throws InputError if there is none.
std::string resolve_case_path(const std::string& path);

}  // namespace dynid
