#include "internal/yaml_util.hpp"

#include <cmath>

namespace dynid::internal {

double YamlCtx::number(const YAML::Node& n, const std::string& what) const {
  if (!n || !n.IsScalar()) fail(n, what + ": expected a number");
  double v = 0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(n, what + ": '" + n.Scalar() + "' is not a number");
  }
  if (!std::isfinite(v)) fail(n, what + ": must be finite, got '" + n.Scalar() + "'");
  return v;
}

int YamlCtx::integer(const YAML::Node& n, const std::string& what) const {
  if (!n || !n.IsScalar()) fail(n, what + ": expected an integer");
  try {
    return n.as<int>();
  } catch (const YAML::Exception&) {
    fail(n, what + ": '" + n.Scalar() + "' is not an integer");
  }
}

std::string YamlCtx::string(const YAML::Node& n, const std::string& what) const {
  if (!n || !n.IsScalar()) fail(n, what + ": expected a string");
  return n.Scalar();
}

bool YamlCtx::boolean(const YAML::Node& n, const std::string& what) const {
  if (!n || !n.IsScalar()) fail(n, what + ": expected true or false");
  try {
    return n.as<bool>();
  } catch (const YAML::Exception&) {
    fail(n, what + ": '" + n.Scalar() + "' is not true or false");
  }
}

std::vector<double> YamlCtx::numbers(const YAML::Node& n, const std::string& what) const {
  require_sequence(n, what);
  std::vector<double> v;
  for (const auto& x : n) v.push_back(number(x, what));
  return v;
}

void YamlCtx::only_keys(const YAML::Node& map, const std::string& what,
                        std::initializer_list<const char*> known) const {
  for (const auto& kv : map) {
    const std::string k = kv.first.Scalar();
    bool ok = false;
    for (const char* q : known) ok = ok || k == q;
    if (!ok) {
      std::string list;
      for (const char* q : known) list += (list.empty() ? "" : ", ") + std::string(q);
      fail(kv.first, "unknown key '" + k + "' in " + what + " (known keys: " + list + ")");
    }
  }
}

void YamlCtx::require_map(const YAML::Node& n, const std::string& what) const {
  if (!n || !n.IsMap()) fail(n, what + ": expected a mapping (key: value pairs)");
}

void YamlCtx::require_sequence(const YAML::Node& n, const std::string& what) const {
  if (!n || !n.IsSequence()) fail(n, what + ": expected a list");
}

}  // namespace dynid::internal
