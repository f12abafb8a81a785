// YAML helpers with file:line:column error messages (internal to io).
#pragma once

#include <yaml-cpp/yaml.h>

#include <initializer_list>
#include <string>
#include <vector>

#include "dynid/mesh/error.hpp"

namespace dynid::internal {

struct YamlCtx {
  std::string file;
  std::string where(const YAML::Node& n) const {
    YAML::Mark m = YAML::Mark::null_mark();
    try {
      if (n.IsDefined()) m = n.Mark();
    } catch (const YAML::Exception&) {
    }
    if (m.line < 0) return file;
    return file + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& msg) const {
    throw InputError(where(n) + ": " + msg);
  }
  double number(const YAML::Node& n, const std::string& what) const;
  int integer(const YAML::Node& n, const std::string& what) const;
  std::string string(const YAML::Node& n, const std::string& what) const;
  bool boolean(const YAML::Node& n, const std::string& what) const;
  std::vector<double> numbers(const YAML::Node& n, const std::string& what) const;
  /// Fails if `map` has a key not in `known` (catches typos), naming the known keys.
  void only_keys(const YAML::Node& map, const std::string& what, std::initializer_list<const char*> known) const;
  /// Fails unless n is a map.
  void require_map(const YAML::Node& n, const std::string& what) const;
  void require_sequence(const YAML::Node& n, const std::string& what) const;
};

}  // namespace dynid::internal
