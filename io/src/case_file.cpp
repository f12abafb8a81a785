#include "dynid/io/case_file.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "dynid/engine/modal.hpp"
#include "internal/model_yaml.hpp"

namespace dynid {

namespace fs = std::filesystem;
using internal::YamlCtx;

EigenOptions AnalysisSpec::eigen_options() const {
  EigenOptions o;
  o.num_modes = modes;
  if (!std::isnan(band_lo_hz)) {
    o.band_lo = hz_to_eigenvalue(band_lo_hz);
    o.band_hi = hz_to_eigenvalue(band_hi_hz);
  }
  if (!std::isnan(shift_hz)) o.shift = hz_to_eigenvalue(shift_hz);
  o.method = method;
  return o;
}

namespace {

AnalysisSpec parse_analysis(const YAML::Node& n, const YamlCtx& ctx) {
  AnalysisSpec a;
  if (!n) return a;
  ctx.require_map(n, "analysis");
  ctx.only_keys(n, "analysis", {"modes", "band_hz", "shift_hz", "method"});
  if (n["modes"]) {
    a.modes = ctx.integer(n["modes"], "analysis modes");
    if (a.modes < 1) ctx.fail(n["modes"], "analysis: modes must be >= 1");
  }
  if (n["band_hz"]) {
    const auto b = ctx.numbers(n["band_hz"], "analysis band_hz");
    if (b.size() != 2 || !(b[0] >= 0 && b[1] > b[0]))
      ctx.fail(n["band_hz"], "analysis: band_hz must be [low, high] with 0 <= low < high");
    a.band_lo_hz = b[0];
    a.band_hi_hz = b[1];
  }
  if (n["shift_hz"]) a.shift_hz = ctx.number(n["shift_hz"], "analysis shift_hz");
  if (n["method"]) {
    const std::string m = ctx.string(n["method"], "analysis method");
    if (m == "auto") a.method = EigenOptions::Method::kAuto;
    else if (m == "sparse") a.method = EigenOptions::Method::kSparse;
    else if (m == "dense") a.method = EigenOptions::Method::kDense;
    else ctx.fail(n["method"], "analysis: method must be auto, sparse or dense");
  }
  return a;
}

}  // namespace

std::string resolve_case_path(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    for (const char* f : {"case.yaml", "case.yml", "case.json"}) {
      const fs::path p = fs::path(path) / f;
      if (fs::exists(p, ec)) return p.string();
    }
    throw InputError(path + ": folder has no case.yaml, case.yml or case.json");
  }
  if (!fs::exists(path, ec)) throw InputError(path + ": no such case file or folder");
  return path;
}

Case parse_case(const std::string& text, const std::string& name, const std::string& dir) {
  YamlCtx ctx{name};
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(name + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                     ": malformed case file: " + e.msg);
  }
  if (!root || root.IsNull()) throw InputError(name + ": the case file is empty");
  ctx.require_map(root, "case file");
  ctx.only_keys(root, "the case file", {"name", "description", "model", "analysis"});
  Case c;
  c.path = name;
  c.dir = dir;
  c.name = root["name"] ? ctx.string(root["name"], "name") : fs::path(dir).filename().string();
  if (root["description"]) c.description = ctx.string(root["description"], "description");
  if (!root["model"]) ctx.fail(root, "the case has no model: section");
  c.model = internal::parse_model(root["model"], ctx);
  c.analysis = parse_analysis(root["analysis"], ctx);
  return c;
}

Case load_case(const std::string& path) {
  const std::string file = resolve_case_path(path);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file + ": cannot open for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_case(ss.str(), file, fs::path(file).parent_path().string());
}

}  // namespace dynid
