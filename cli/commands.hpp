// The dynid subcommands (each in its own file) and what they share.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace dynid::cli {

struct GlobalOptions {
  int threads = 0;
  bool quiet = false;
  bool verbose = false;
  int exit_code = 0;  ///< set by the subcommand that ran
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

}  // namespace dynid::cli
