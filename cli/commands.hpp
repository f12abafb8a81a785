// The dynid subcommands (each in its own file) and what they share.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "dynid/io/limits.hpp"

namespace dynid::cli {

struct GlobalOptions {
  int threads = 0;
  bool quiet = false;
  bool verbose = false;
  ReaderLimits limits;  ///< every file the command reads is read within these (dynid's defaults)
  int exit_code = 0;  ///< set by the subcommand that ran
  /// Started by mpirun with several ranks: `dynid modal` solves with the distributed backend; only rank 0 prints
  /// and writes files (`root`).
  bool distributed = false;
  bool root = true;
};

void set_threads(int n);

/// Runs `body`, mapping dynid's exceptions to messages on stderr and exit codes (0, 1, 2, 3).
int run_guarded(const std::string& command, const std::function<int()>& body);

void register_commands(CLI::App& app, GlobalOptions& g);
void register_modal(CLI::App& app, GlobalOptions& g);
void register_detect(CLI::App& app, GlobalOptions& g);
void register_update(CLI::App& app, GlobalOptions& g);
void register_identify(CLI::App& app, GlobalOptions& g);  // identify and simulate-test
void register_info(CLI::App& app, GlobalOptions& g);
void register_discover(CLI::App& app, GlobalOptions& g);
void register_run(CLI::App& app, GlobalOptions& g);  // run and report

/// One step of a case, as its subcommand does it, writing the results JSON and the figure (PNG) to the given
/// paths; returns the subcommand's exit code. `dynid run` chains them.
int modal_step(const std::string& case_path, const std::string& json, const std::string& plot, bool force, const GlobalOptions& g);
int detect_step(const std::string& case_path, const std::string& json, const std::string& plot, bool force, const GlobalOptions& g);
int update_step(const std::string& case_path, const std::string& json, const std::string& plot, bool force, const GlobalOptions& g);
/// A case's test: section: simulate-test into `dir` (test*.uff), then identify those recordings with the case's
/// identification options (identify.json, identify-modes.uff, identify.png: the stabilization diagram).
int test_step(const std::string& case_path, const std::string& dir, bool force, const GlobalOptions& g);
int discover_step(const std::string& case_path, const std::string& json, const std::string& plot, bool force, const GlobalOptions& g);

}  // namespace dynid::cli
