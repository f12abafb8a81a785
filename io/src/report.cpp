#include "dynid/io/report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "dynid/mesh/error.hpp"
#include "internal/report_interactive.hpp"
#include "internal/text_util.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace dynid {

namespace {

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

json read_json(const fs::path& p) {
  const std::string text = internal::read_file_bytes(p.string());
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(p.string() + ": not valid JSON (" + e.what() + ")");
  }
}

std::string num(const json& v, const char* f = "%.6g") {
  if (!v.is_number()) return "-";
  char b[64];
  std::snprintf(b, sizeof b, f, v.get<double>());
  return b;
}

std::string str(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_null()) return "-";
  return v.dump();
}

// <table> from a header and rows of cells (already escaped).
std::string table(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows) {
  std::string s = "<table><tr>";
  for (const std::string& h : head) s += "<th>" + h + "</th>";
  s += "</tr>\n";
  for (const auto& r : rows) {
    s += "<tr>";
    for (const std::string& c : r) s += "<td>" + c + "</td>";
    s += "</tr>\n";
  }
  return s + "</table>\n";
}

// A member of an object, or null / an empty list / false when the object or the member is missing: results
// written by another version, or edited, still give a page (with "-" cells).
json field(const json& j, const char* k) { return j.is_object() && j.contains(k) ? j.at(k) : json(); }
json list(const json& j, const char* k) {
  json v = field(j, k);
  return v.is_array() ? v : json::array();
}
bool flag(const json& j, const char* k) { return field(j, k) == true; }

std::string modal_section(json j) {  // by value: operator[] on a missing key gives null
  std::vector<std::vector<std::string>> rows;
  for (json m : list(j, "modes"))
    rows.push_back({num(m["index"], "%.0f"), num(m["frequency_hz"]),
                    flag(m, "rigid_body") ? "rigid body" : "elastic " + num(m["elastic_index"], "%.0f"),
                    num(m["residual"], "%.1e")});
  return "<p>" + num(j["dofs"], "%.0f") + " DOFs, " + num(j["nonzeros"], "%.0f") + " nonzeros; solver " +
         esc(str(j["solver"]["method"])) + " (" + esc(str(j["solver"]["status"])) + ").</p>\n" +
         table({"mode", "frequency [Hz]", "kind", "relative residual"}, rows);
}

std::string detect_section(json j) {  // by value: operator[] on a missing key gives null
  std::string s;
  json m = j["modes"];
  std::vector<std::vector<std::string>> rows;
  const json mh = list(m, "model_hz");
  const json ch = list(m, "changed_hz");
  const json mac = list(m, "mac");
  for (std::size_t k = 0; k < mh.size(); ++k)
    rows.push_back({std::to_string(k + 1), num(mh[k]), k < ch.size() ? num(ch[k]) : "-",
                    k < ch.size() && ch[k].is_number() && mh[k].is_number()
                        ? num(json(100.0 * (ch[k].get<double>() / mh[k].get<double>() - 1)), "%+.3f")
                        : "-",
                    k < mac.size() ? num(mac[k], "%.4f") : "-"});
  s += "<h3>Frequencies and MAC: model (reference) against the changed structure</h3>\n" +
       table({"mode", "model [Hz]", "changed [Hz]", "change [%]", "MAC"}, rows);
  rows.clear();
  int shown = 0;
  for (json e : list(j["localization"], "elements")) {
    if (shown++ == 10) break;
    rows.push_back({num(e["rank"], "%.0f"), num(e["id"], "%.0f"), num(e["score"], "%.4g"), num(e["pseudo"], "%.4g"),
                    flag(e, "flagged") ? "<b>yes</b>" : ""});
  }
  s += "<h3>Candidate ranking (residual-force localization)</h3>\n<p>" + esc(str(j["localization"]["score"])) +
       "</p>\n" + table({"rank", "element", "score", "pseudo residual (paper)", "flagged"}, rows);
  rows.clear();
  for (json q : list(j, "quantification"))
    rows.push_back({num(q["element"], "%.0f"), num(q["dk"], "%+.5f"), num(q["dm"], "%+.5f"), num(q["dk_std"], "%.3g"),
                    num(q["dm_std"], "%.3g")});
  s += "<h3>Quantification (fractions; -0.15 = 15 % loss)</h3>\n" +
       (rows.empty() ? std::string("<p>No element flagged.</p>\n")
                     : table({"element", "&delta;k", "&delta;m", "std &delta;k", "std &delta;m"}, rows));
  return s;
}

std::string update_section(json j) {  // by value: operator[] on a missing key gives null
  std::vector<std::vector<std::string>> rows;
  for (json p : list(j, "parameters"))
    rows.push_back({esc(str(p["name"])), esc(str(p["kind"])), num(p["initial"]), num(p["value"]), num(p["std"], "%.3g"),
                    esc(str(p["status"])) + (flag(p, "at_bound") ? " (at bound)" : "")});
  std::string s = "<p>Objective " + esc(str(j["objective"])) + ", " + esc(str(j["termination"])) + " after " +
                  num(j["iterations"], "%.0f") + " iterations; cost " + num(j["cost"]["initial"], "%.3g") + " &rarr; " +
                  num(j["cost"]["final"], "%.3g") + ".</p>\n" +
                  table({"parameter", "kind", "initial", "updated", "std", "status"}, rows);
  rows.clear();
  json fr = j["frequencies_hz"];
  const json me = list(fr, "measured");
  for (std::size_t k = 0; k < me.size(); ++k)
    rows.push_back({std::to_string(k + 1), num(me[k]), num(fr["initial"][k]), num(fr["updated"][k]),
                    num(j["mac"]["initial"][k], "%.4f"), num(j["mac"]["updated"][k], "%.4f")});
  return s + "<h3>Frequencies and MAC before and after updating</h3>\n" +
         table({"mode", "measured [Hz]", "initial [Hz]", "updated [Hz]", "MAC initial", "MAC updated"}, rows);
}

std::string discover_section(json j) {  // by value: operator[] on a missing key gives null
  std::string s = "<p><b>Verdict: " + esc(str(j["verdict"])) + ".</b> " + esc(str(j["explanation"])) + "</p>\n";
  if (j.contains("localization")) s += "<p>Where: " + esc(str(j["localization"]["words"])) + "</p>\n";
  std::vector<std::vector<std::string>> rows;
  int shown = 0;
  for (json c : list(j, "candidates")) {
    if (shown++ == 10) break;
    rows.push_back({std::to_string(shown), esc(str(c["kind"])), esc(str(c["description"])), num(c["score"], "%.4g"),
                    num(c["max_freq_error_pct"], "%.3g"), num(c["mean_mac"], "%.4f")});
  }
  s += "<h3>Candidate ranking (BIC improvement over the model as given)</h3>\n" +
       table({"rank", "kind", "candidate", "score", "max freq. error [%]", "mean MAC"}, rows);
  if (j.contains("fit")) {
    json b = j["fit"]["before"];
    json a = j["fit"]["after"];
    s += "<p>Fit: largest frequency error " + num(b["max_freq_error_pct"], "%.3g") + " % &rarr; " +
         num(a["max_freq_error_pct"], "%.3g") + " %, mean MAC " + num(b["mean_mac"], "%.4f") + " &rarr; " +
         num(a["mean_mac"], "%.4f") + ".</p>\n";
  }
  return s;
}

std::string identify_section(json j) {  // by value: operator[] on a missing key gives null
  std::vector<std::vector<std::string>> rows;
  int k = 0;
  for (json m : list(j, "modes"))
    rows.push_back({std::to_string(++k), num(m["frequency_hz"]), m.contains("damping_ratio") ? num(json(100.0 * m["damping_ratio"].get<double>()), "%.3g") : "-",
                    num(field(m, "mpc"), "%.4f"), num(field(m, "poles"), "%.0f")});
  return "<p>Method " + esc(str(j["method"])) + ", model orders " + num(j["orders"][0], "%.0f") + "-" + num(j["orders"][1], "%.0f") +
         ", " + std::to_string(list(j, "dofs").size()) + " output DOFs. The stabilization diagram below shows "
         "the poles per model order over the measured spectrum.</p>\n" +
         (rows.empty() ? std::string("<p>No stable physical mode in the band.</p>\n")
                       : table({"mode", "frequency [Hz]", "damping [%]", "MPC", "stable poles"}, rows));
}

const char* kStyle = R"(body{font-family:sans-serif;max-width:1500px;margin:1em auto;padding:0 1em;color:#222}
h1{margin-bottom:0.2em} h2{border-bottom:2px solid #346;padding-bottom:0.2em;margin-top:1.6em}
table{border-collapse:collapse;margin:0.5em 0 1em} th,td{border:1px solid #bbb;padding:2px 8px;text-align:right}
th{background:#e8eef4} img{max-width:100%;border:1px solid #ccc;margin:0.5em 0} .meta{color:#666}
nav a{margin-right:1em} .rc{color:#a00}
.plot{width:100%;min-height:380px;margin:0.5em 0} .view3d{margin:0.5em 0} .view3d canvas{border:1px solid #ccc;max-width:100%}
.view3d .controls{margin:0.3em 0} .hint{color:#666;font-size:90%})";

}  // namespace

namespace {
// A file named by the manifest: a plain name inside the results folder (nothing outside it is read).
fs::path step_file(const fs::path& d, const fs::path& manifest, const json& st, const char* key) {
  const std::string name = st.value(key, std::string());
  if (name.empty()) return {};
  if (fs::path(name).filename().string() != name || name == "." || name == "..")
    throw InputError(manifest.string() + ": step file '" + name + "' must be a file name inside the results folder");
  return d / name;
}
}  // namespace

std::string html_report(const std::string& dir) {
  const fs::path d(dir);
  const fs::path manifest = d / kRunManifest;
  std::error_code ec;
  if (!fs::is_regular_file(manifest, ec))
    throw InputError(dir + ": no " + std::string(kRunManifest) + " here; make the folder with `dynid run CASE --out " + dir + "`");
  const json run = read_json(manifest);
  if (!run.is_object() || !run.contains("steps") || !run["steps"].is_array())
    throw InputError(manifest.string() + ": not a dynid run manifest (no \"steps\" list)");
  try {
    const std::string name = run.value("case", std::string("?"));
    std::string body, nav;
    int images = 0, plots = 0, views = 0;
    std::string unavailable;
    const bool interactive = internal::interactive_available(&unavailable);
    static const std::vector<std::pair<std::string, std::string>> titles = {
        {"modal", "Modal analysis: mode shapes on the structure"},
        {"detect", "Detection: residual forces, localization and quantification (the paper's method)"},
        {"update", "Model updating (Ceres)"},
        {"discover", "Discovery: what physics the model leaves out"},
        {"identify", "Virtual test and modal identification: stabilization diagram"}};
    for (json st : run["steps"]) {
      const std::string step = st.value("name", std::string());
      std::string title = step;
      for (const auto& [k, t] : titles)
        if (k == step) title = t;
      nav += "<a href=\"#" + esc(step) + "\">" + esc(step) + "</a>";
      body += "<section id=\"" + esc(step) + "\"><h2>" + esc(title) + "</h2>\n";
      const int rc = st.value("exit_code", 0);
      if (rc != 0) body += "<p class=\"rc\">This step ended with exit code " + std::to_string(rc) + ".</p>\n";
      const fs::path jp = step_file(d, manifest, st, "json");
      if (!jp.empty() && fs::is_regular_file(jp, ec)) {
        const json j = read_json(jp);
        try {
          if (step == "modal") body += modal_section(j);
          else if (step == "detect") body += detect_section(j);
          else if (step == "update") body += update_section(j);
          else if (step == "discover") body += discover_section(j);
          else if (step == "identify") body += identify_section(j);
        } catch (const json::exception& e) {
          throw InputError(jp.string() + ": not the results JSON of dynid " + step + " (" + e.what() + ")");
        }
        if (j.contains("warnings"))
          for (json w : j["warnings"]) body += "<p class=\"rc\">warning: " + esc(str(w)) + "</p>\n";
        if (interactive) {
          // The animated 3D mode shapes (modal-view.json beside modal.json) and the zoomable plots.
          const fs::path vp = step_file(d, manifest, st, "view");
          if (!vp.empty() && fs::is_regular_file(vp, ec)) {
            const json v = read_json(vp);
            if (v.is_object() && v.contains("points") && v.contains("segments") && v.contains("modes"))
              body += "<h3>Mode shapes in 3D</h3>\n" + internal::view_block(v, views++);
            else
              body += "<p class=\"rc\">" + esc(vp.filename().string()) + " is not a mode-shape view.</p>\n";
          }
          for (const json& fig : internal::step_plots(step, j)) body += internal::plot_block(fig, plots++);
        }
      } else {
        body += "<p class=\"rc\">No results (" + esc(jp.filename().string()) + " is missing).</p>\n";
      }
      const fs::path pp = step_file(d, manifest, st, "plot");
      if (!pp.empty() && fs::is_regular_file(pp, ec) && pp.extension() == ".png") {
        body += "<img alt=\"" + esc(step) + " figure\" src=\"data:image/png;base64," +
                internal::base64(internal::read_file_bytes(pp.string())) + "\">\n";
        ++images;
      }
      body += "</section>\n";
    }
    std::string html = "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<meta http-equiv=\"Content-Security-Policy\" content=\"" +
                       std::string(internal::content_security_policy()) + "\">\n<title>dynid report: " + esc(name) +
                       "</title>\n<style>" + kStyle + "</style></head>\n<body data-images=\"" + std::to_string(images) +
                       "\" data-plots=\"" + std::to_string(plots) + "\" data-views=\"" + std::to_string(views) +
                       "\">\n<h1>dynid report: " + esc(name) + "</h1>\n<p class=\"meta\">" + esc(run.value("description", std::string())) +
                       "<br>case " + esc(run.value("case_path", std::string())) + " &middot; " +
                       esc(run.value("dynid", std::string())) + "</p>\n" +
                       (interactive ? std::string() : "<p class=\"rc\">Interactive views left out: " + esc(unavailable) + ".</p>\n") +
                       "<nav>" + nav + "</nav>\n" + body;
    if (plots + views > 0) html += internal::interactive_assets() + internal::interactive_script();
    // For headless checks (scripts/check-report.sh): the number of figures the browser decoded.
    html += "<script>window.addEventListener('load',function(){var n=0;for(const i of document.images)"
            "if(i.complete&&i.naturalWidth>0)n++;document.body.setAttribute('data-images-loaded',n);});</script>\n";
    return html + "</body></html>\n";
  } catch (const json::exception& e) {
    throw InputError(manifest.string() + ": not a dynid run manifest (" + e.what() + ")");
  }
}

}  // namespace dynid
