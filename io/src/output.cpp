#include "dynid/io/output.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "dynid/mesh/error.hpp"

namespace dynid {

namespace fs = std::filesystem;

void refuse_existing(const std::vector<std::string>& paths, bool overwrite) {
  std::error_code ec;
  for (const std::string& p : paths)
    if (!overwrite && fs::exists(p, ec)) throw InputError(p + ": file exists; pass --force to overwrite it, or choose another name");
}

void write_file_atomic(const std::string& path, const std::string& content, bool overwrite) {
  refuse_existing({path}, overwrite);
  std::error_code ec;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw InputError(path + ": folder '" + dir.string() + "' does not exist");
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path + ": cannot write in folder '" + dir.string() + "'");
    out << content;
    out.flush();
    if (!out) {
      out.close();
      fs::remove(tmp, ec);
      throw InputError(path + ": write failed (disk full?)");
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(path + ": cannot replace file: " + ec.message());
  }
}

nlohmann::json modal_json(const Case& c, const ModalResult& r) { return modal_json(c.name, r); }

nlohmann::json modal_json(const std::string& name, const ModalResult& r) {
  nlohmann::json j;
  j["case"] = name;
  j["dofs"] = r.dofs;
  j["nonzeros"] = r.nonzeros;
  nlohmann::json modes = nlohmann::json::array();
  int elastic = 0, rigid = 0;
  for (Eigen::Index k = 0; k < r.eigenvalues.size(); ++k) {
    nlohmann::json m;
    m["index"] = k + 1;
    m["frequency_hz"] = r.frequencies_hz[k];
    m["eigenvalue"] = r.eigenvalues[k];
    m["rigid_body"] = static_cast<bool>(r.rigid_body[k]);
    m["residual"] = r.residuals[k];
    if (r.rigid_body[k]) {
      if (rigid < static_cast<int>(r.rigid_body_descriptions.size())) m["description"] = r.rigid_body_descriptions[rigid];
      ++rigid;
    } else {
      m["elastic_index"] = ++elastic;
    }
    modes.push_back(m);
  }
  j["modes"] = modes;
  const EigenSummary& s = r.summary;
  j["solver"] = {{"method", s.method},         {"status", s.ok() ? "success" : "failed"},
                 {"message", s.message},       {"shift", s.shift},
                 {"factor_nonzeros", s.factor_nonzeros}, {"solves", s.solves},
                 {"time_assembly_s", r.time_assembly},   {"time_factorize_s", s.time_factorize},
                 {"time_lanczos_s", s.time_lanczos},     {"max_residual", s.max_residual}};
  return j;
}

}  // namespace dynid
