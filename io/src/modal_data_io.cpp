#include "dynid/io/modal_data_io.hpp"

#include <algorithm>
#include <cctype>

#include "dynid/io/output.hpp"
#include "dynid/mesh/error.hpp"
#include "internal/text_util.hpp"

namespace dynid {

bool parse_dof_label(const std::string& label, MeasuredDof* out, double* sign) {
  std::size_t i = 0;
  while (i < label.size() && std::isspace(static_cast<unsigned char>(label[i]))) ++i;
  const std::size_t start = i;
  if (i < label.size() && (label[i] == '-' || label[i] == '+')) ++i;
  while (i < label.size() && std::isdigit(static_cast<unsigned char>(label[i]))) ++i;
  if (i == start || (i == start + 1 && !std::isdigit(static_cast<unsigned char>(label[start])))) return false;
  long long node = 0;
  try {
    node = std::stoll(label.substr(start, i - start));
  } catch (...) {
    return false;
  }
  if (node < -2147483647LL || node > 2147483647LL) return false;
  std::string rest = label.substr(i);
  while (!rest.empty() && std::isspace(static_cast<unsigned char>(rest.back()))) rest.pop_back();
  double s = 1.0;
  if (!rest.empty() && rest[0] == ':') rest = rest.substr(1);
  Dof d;
  if (rest.size() == 2 && (rest[0] == '+' || rest[0] == '-')) {  // UFF: +X, -Y, +Z (translations)
    s = rest[0] == '-' ? -1.0 : 1.0;
    const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(rest[1])));
    if (c != 'X' && c != 'Y' && c != 'Z') return false;
    d = static_cast<Dof>(c - 'X');
  } else if (!parse_dof(rest, &d)) {
    return false;
  }
  out->node = static_cast<int>(node);
  out->dof = d;
  if (sign) *sign = s;
  return true;
}

ModalData parse_modal_data_json(const std::string& text, const std::string& name) {
  nlohmann::ordered_json j;  // keeps the DOFs in the file's order
  try {
    j = nlohmann::ordered_json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(name + ": not valid JSON (byte " + std::to_string(e.byte) + "): " + e.what());
  } catch (const nlohmann::json::exception& e) {  // e.g. out_of_range: a number too large for a double
    throw InputError(name + ": not valid JSON: " + e.what());
  }
  if (!j.is_object() || !j.contains("modes") || !j["modes"].is_array())
    throw InputError(name + ": expected an object with a \"modes\" list");
  const auto& modes = j["modes"];
  if (modes.empty()) throw InputError(name + ": \"modes\" is empty");
  ModalData d;
  d.source = name;
  for (std::size_t k = 0; k < modes.size(); ++k) {
    const auto& m = modes[k];
    const std::string who = name + ": mode " + std::to_string(k + 1);
    if (!m.is_object()) throw InputError(who + ": expected an object");
    if (!m.contains("frequency_hz") || !m["frequency_hz"].is_number()) throw InputError(who + ": \"frequency_hz\" (a number) is missing");
    if (!m.contains("shape") || !m["shape"].is_object()) throw InputError(who + ": \"shape\" must be an object {dof: value}");
    const auto& sh = m["shape"];
    if (k == 0) {
      for (auto it = sh.begin(); it != sh.end(); ++it) {
        MeasuredDof md;
        if (!parse_dof_label(it.key(), &md, nullptr))
          throw InputError(who + ": \"" + it.key() + "\" is not a DOF label (expected node id + direction, e.g. \"13ux\" or \"13+X\")");
        d.dofs.push_back(md);
      }
      d.shapes.resize(static_cast<Eigen::Index>(d.dofs.size()), static_cast<Eigen::Index>(modes.size()));
      d.frequencies_hz.resize(static_cast<Eigen::Index>(modes.size()));
    }
    if (sh.size() != d.dofs.size())
      throw InputError(who + ": has " + std::to_string(sh.size()) + " DOFs, mode 1 has " + std::to_string(d.dofs.size()));
    // The same DOFs as mode 1, in any order, each with its own sign (13+Y or 13-Y).
    std::vector<char> filled(d.dofs.size(), 0);
    for (auto it = sh.begin(); it != sh.end(); ++it) {
      MeasuredDof md;
      double s = 1;
      if (!parse_dof_label(it.key(), &md, &s))
        throw InputError(who + ": \"" + it.key() +
                         "\" is not a DOF label (expected node id + direction, e.g. \"13ux\" or \"13+X\")");
      const std::size_t r = static_cast<std::size_t>(std::find(d.dofs.begin(), d.dofs.end(), md) - d.dofs.begin());
      if (r == d.dofs.size())
        throw InputError(who + ": DOF \"" + it.key() +
                         "\" is not among mode 1's DOFs (every mode must list the same DOFs)");
      if (filled[r]) throw InputError(who + ": DOF \"" + it.key() + "\" is listed twice");
      if (!it.value().is_number()) throw InputError(who + ": value of \"" + it.key() + "\" is not a number");
      filled[r] = 1;
      d.shapes(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k)) = s * it.value().get<double>();
    }
    d.frequencies_hz[static_cast<Eigen::Index>(k)] = m["frequency_hz"].get<double>();
  }
  // Optional per-mode numbers: kept only when every mode gives them.
  auto optional = [&](const char* key, Eigen::VectorXd* v) {
    for (const auto& m : modes)
      if (!m.contains(key) || !m[key].is_number()) return;
    v->resize(static_cast<Eigen::Index>(modes.size()));
    for (std::size_t k = 0; k < modes.size(); ++k) (*v)[static_cast<Eigen::Index>(k)] = modes[k][key].get<double>();
  };
  optional("damping_ratio", &d.damping_ratios);
  optional("mpc", &d.mpc);
  optional("frequency_std_hz", &d.frequency_std_hz);
  optional("damping_std", &d.damping_std);
  optional("shape_std", &d.shape_std);
  // Per-entry shape standard deviations: "shape_std" as an object {dof: std} like "shape" (every mode, every DOF).
  for (std::size_t k = 0; k < modes.size(); ++k) {
    const auto& m = modes[k];
    if (!m.contains("shape_std") || !m["shape_std"].is_object()) {
      if (k > 0 && d.shape_entry_std.size() != 0)
        throw InputError(name + ": mode " + std::to_string(k + 1) + ": \"shape_std\" must be an object {dof: std} as in mode 1");
      if (k == 0) break;
      continue;
    }
    if (k == 0) d.shape_entry_std.resize(d.shapes.rows(), d.shapes.cols());
    const auto& sd = m["shape_std"];
    const std::string who = name + ": mode " + std::to_string(k + 1) + " shape_std";
    if (sd.size() != d.dofs.size())
      throw InputError(who + ": has " + std::to_string(sd.size()) + " DOFs, the shape " + std::to_string(d.dofs.size()) + " (one std per shape entry)");
    std::vector<char> filled(d.dofs.size(), 0);
    for (auto it = sd.begin(); it != sd.end(); ++it) {
      MeasuredDof md;
      const std::size_t r = parse_dof_label(it.key(), &md, nullptr)
                                ? static_cast<std::size_t>(std::find(d.dofs.begin(), d.dofs.end(), md) - d.dofs.begin())
                                : d.dofs.size();
      if (r == d.dofs.size())
        throw InputError(who + ": DOF \"" + it.key() + "\" is not among the shape's DOFs (one std per shape entry)");
      if (filled[r]) throw InputError(who + ": DOF \"" + it.key() + "\" is listed twice");
      if (!it.value().is_number()) throw InputError(who + ": value of \"" + it.key() + "\" is not a number");
      filled[r] = 1;
      d.shape_entry_std(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(k)) = it.value().get<double>();
    }
  }
  d.validate(name);
  return d;
}

ModalData read_modal_data(const std::string& path) {
  return parse_modal_data_json(internal::read_file_bytes(path), path);
}

nlohmann::ordered_json modal_data_json(const ModalData& d) {
  nlohmann::ordered_json modes = nlohmann::ordered_json::array();
  for (Eigen::Index k = 0; k < d.frequencies_hz.size(); ++k) {
    nlohmann::ordered_json m;
    m["frequency_hz"] = d.frequencies_hz[k];
    if (d.damping_ratios.size() == d.frequencies_hz.size()) m["damping_ratio"] = d.damping_ratios[k];
    if (d.frequency_std_hz.size() == d.frequencies_hz.size()) m["frequency_std_hz"] = d.frequency_std_hz[k];
    if (d.damping_std.size() == d.frequencies_hz.size()) m["damping_std"] = d.damping_std[k];
    if (d.shape_std.size() == d.frequencies_hz.size()) m["shape_std"] = d.shape_std[k];
    if (d.shape_entry_std.cols() == d.frequencies_hz.size() && d.shape_entry_std.rows() == d.shapes.rows()) {
      nlohmann::ordered_json sd = nlohmann::ordered_json::object();
      for (std::size_t r = 0; r < d.dofs.size(); ++r) sd[to_string(d.dofs[r])] = d.shape_entry_std(static_cast<Eigen::Index>(r), k);
      m["shape_std"] = sd;  // per entry (replaces the per-mode value)
    }
    if (d.mpc.size() == d.frequencies_hz.size()) m["mpc"] = d.mpc[k];
    nlohmann::ordered_json sh = nlohmann::ordered_json::object();
    for (std::size_t r = 0; r < d.dofs.size(); ++r) sh[to_string(d.dofs[r])] = d.shapes(static_cast<Eigen::Index>(r), k);
    m["shape"] = sh;
    modes.push_back(m);
  }
  nlohmann::ordered_json out;
  out["modes"] = modes;
  return out;
}

void write_modal_data(const std::string& path, const ModalData& d, bool overwrite) {
  write_file_atomic(path, modal_data_json(d).dump(1) + "\n", overwrite);
}

}  // namespace dynid
