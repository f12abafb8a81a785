#include "commands.hpp"

#include <fmt/core.h>

#include <cstdio>
#include <new>

#include "dynid/mesh/error.hpp"

namespace dynid::cli {

int run_guarded(const std::string& command, const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    fmt::print(stderr, "dynid {}: error: {}\n", command, e.what());
    return 2;
  } catch (const NumericalError& e) {
    fmt::print(stderr, "dynid {}: numerical failure: {}\n", command, e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "dynid {}: out of memory\n", command);
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "dynid {}: internal error (please report): {}\n", command, e.what());
    return 3;
  }
}

void register_commands(CLI::App& app, GlobalOptions& g) {
  register_modal(app, g);
  register_detect(app, g);
  register_update(app, g);
  register_identify(app, g);
  register_info(app, g);
  register_discover(app, g);
  register_run(app, g);
}

}  // namespace dynid::cli
