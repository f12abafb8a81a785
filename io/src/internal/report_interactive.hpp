// The interactive parts of the HTML report (docs/report.md): mode shapes animated in 3D (three.js) and zoomable
// plots (plotly.js), from the JavaScript that Debian packages (libjs-three, python3-plotly), embedded so that the
// page stays one file that works offline. Internal to io (report.cpp uses it).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace dynid::internal {

/// Whether the JavaScript libraries were found (at build time, and are readable now); `why` says what is missing.
bool interactive_available(std::string* why);

/// The libraries as inline scripts: three.js and its OrbitControls as they are, plotly.js gzip-compressed and
/// base64-encoded (the page inflates it with the browser's DecompressionStream). Built once per process.
const std::string& interactive_assets();

/// The zoomable plots of a step's results JSON (plotly figure specifications {"data", "layout", "title"}).
std::vector<nlohmann::json> step_plots(const std::string& step, const nlohmann::json& results);

/// A <div> that the page script turns into a plot.
std::string plot_block(const nlohmann::json& figure, int index);
/// A <div> with the animated 3D mode shapes of a modal-view JSON (dynid/io/model_view.hpp).
std::string view_block(const nlohmann::json& view, int index);

/// The page script: inflates plotly, draws the plots, runs the 3D views, and records for headless checks
/// (scripts/check-report.sh) data-plots-drawn, data-frames, data-frames-differ and data-csp-violations on <body>.
const char* interactive_script();

/// Content-Security-Policy of the page: nothing may be fetched from anywhere (inline scripts and data: images only).
const char* content_security_policy();

}  // namespace dynid::internal
