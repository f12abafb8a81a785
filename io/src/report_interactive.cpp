// The report's animated 3D mode shapes and zoomable plots (internal/report_interactive.hpp).
#include "internal/report_interactive.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "internal/text_util.hpp"

// Where Debian puts the libraries (io/CMakeLists.txt finds them; empty when a package is missing).
#ifndef DYNID_THREE_JS
#define DYNID_THREE_JS ""
#endif
#ifndef DYNID_ORBIT_JS
#define DYNID_ORBIT_JS ""
#endif
#ifndef DYNID_PLOTLY_JS
#define DYNID_PLOTLY_JS ""
#endif

using nlohmann::json;

namespace dynid::internal {

namespace {

// gzip (RFC 1952) of `in` with zlib.
std::string gzip(const std::string& in) {
  z_stream z{};
  if (deflateInit2(&z, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK) return {};
  std::string out(deflateBound(&z, in.size()), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  return rc == Z_STREAM_END ? out : std::string();
}

// JSON for embedding in a <script type="application/json">: "</" cannot end the element.
std::string script_json(const json& j) {
  std::string s = j.dump();
  std::string o;
  o.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '<' && i + 1 < s.size() && s[i + 1] == '/') o += "<\\/", ++i;
    else o += s[i];
  }
  return o;
}

// A script file's text, made safe to inline (no "</script" inside).
std::string inline_js(const std::string& path) {
  std::string s = read_file_bytes(path);
  for (std::size_t p = s.find("</script"); p != std::string::npos; p = s.find("</script", p + 2)) s.replace(p, 2, "<\\/");
  return s;
}

std::vector<double> numbers(const json& a) {
  std::vector<double> v;
  if (!a.is_array()) return v;
  for (const json& x : a) v.push_back(x.is_number() ? x.get<double>() : std::nan(""));
  return v;
}

json field(const json& j, const char* k) { return j.is_object() && j.contains(k) ? j.at(k) : json(); }

json axis(const std::string& title, bool log = false) {
  json a = {{"title", {{"text", title}}}, {"zeroline", false}};
  if (log) a["type"] = "log";
  return a;
}

json figure(const std::string& title, json data, json xaxis, json yaxis) {
  return {{"title", title},
          {"data", std::move(data)},
          {"layout", {{"title", {{"text", title}}}, {"xaxis", std::move(xaxis)}, {"yaxis", std::move(yaxis)},
                      {"margin", {{"l", 70}, {"r", 30}, {"t", 50}, {"b", 60}}}, {"height", 380}, {"hovermode", "closest"},
                      {"legend", {{"orientation", "h"}}}}}};
}

std::vector<double> modes_axis(std::size_t n) {
  std::vector<double> x;
  for (std::size_t k = 0; k < n; ++k) x.push_back(static_cast<double>(k + 1));
  return x;
}

// Frequency errors (%) and MAC of paired modes, before and after (update, discover).
void before_after(const std::vector<double>& measured, const std::vector<double>& before, const std::vector<double>& after,
                  const std::vector<double>& mac_before, const std::vector<double>& mac_after, const std::string& what,
                  std::vector<json>* out) {
  auto err = [&](const std::vector<double>& f) {
    std::vector<double> e;
    for (std::size_t k = 0; k < measured.size() && k < f.size(); ++k) e.push_back(100 * (f[k] / measured[k] - 1));
    return e;
  };
  const auto x = modes_axis(measured.size());
  out->push_back(figure("Frequency error against the measured modes (" + what + ")",
                        json::array({{{"type", "bar"}, {"name", "before"}, {"x", x}, {"y", err(before)}},
                                     {{"type", "bar"}, {"name", "after"}, {"x", x}, {"y", err(after)}}}),
                        axis("measured mode"), axis("frequency error [%]")));
  out->push_back(figure("MAC of the paired modes (" + what + ")",
                        json::array({{{"type", "scatter"}, {"mode", "lines+markers"}, {"name", "before"}, {"x", x}, {"y", mac_before}},
                                     {{"type", "scatter"}, {"mode", "lines+markers"}, {"name", "after"}, {"x", x}, {"y", mac_after}}}),
                        axis("measured mode"), axis("MAC")));
}

}  // namespace

bool interactive_available(std::string* why) {
  std::string missing;
  for (const auto& [path, pkg] : {std::pair<const char*, const char*>{DYNID_THREE_JS, "libjs-three (three.min.js)"},
                                 {DYNID_ORBIT_JS, "libjs-three (OrbitControls.js)"},
                                 {DYNID_PLOTLY_JS, "python3-plotly (plotly.js)"}}) {
    std::error_code ec;
    if (std::string(path).empty() || !std::filesystem::is_regular_file(path, ec)) missing += (missing.empty() ? "" : ", ") + std::string(pkg);
  }
  if (why) *why = missing.empty() ? "" : "the JavaScript of " + missing + " is not installed (scripts/setup.sh installs it)";
  return missing.empty();
}

const std::string& interactive_assets() {
  // Built once (thread-safe initialization of a function-local constant), then only read.
  static const std::string assets = []() -> std::string {
    if (!interactive_available(nullptr)) return "";
    const std::string plotly = gzip(read_file_bytes(DYNID_PLOTLY_JS));
    if (plotly.empty()) return "";
    return "<script>" + inline_js(DYNID_THREE_JS) + "\n</script>\n<script>" + inline_js(DYNID_ORBIT_JS) +
           "\n</script>\n" + "<script id=\"plotly-gz\" type=\"application/octet-stream\">" + base64(plotly) +
           "</script>\n";
  }();
  return assets;
}

std::vector<json> step_plots(const std::string& step, const json& j) {
  std::vector<json> out;
  if (!j.is_object()) return out;
  if (step == "modal") {
    std::vector<double> f;
    std::vector<std::string> kind;
    for (const json& m : field(j, "modes").is_array() ? j["modes"] : json::array()) {
      f.push_back(field(m, "frequency_hz").is_number() ? m["frequency_hz"].get<double>() : std::nan(""));
      kind.push_back(field(m, "rigid_body") == true ? "rigid body" : "elastic");
    }
    out.push_back(figure("Natural frequencies", json::array({{{"type", "scatter"}, {"mode", "markers"}, {"x", modes_axis(f.size())},
                                                               {"y", f}, {"text", kind}, {"name", "modes"}}}),
                         axis("mode"), axis("frequency [Hz]")));
  } else if (step == "detect") {
    const json m = field(j, "modes");
    const auto model = numbers(field(m, "model_hz")), changed = numbers(field(m, "changed_hz")), mac = numbers(field(m, "mac"));
    std::vector<double> change;
    for (std::size_t k = 0; k < model.size() && k < changed.size(); ++k) change.push_back(100 * (changed[k] / model[k] - 1));
    const auto x = modes_axis(model.size());
    out.push_back(figure("Frequency change per mode (changed against the model)",
                         json::array({{{"type", "bar"}, {"name", "change"}, {"x", x}, {"y", change}}}), axis("mode"), axis("change [%]")));
    out.push_back(figure("MAC per mode (changed against the model)",
                         json::array({{{"type", "scatter"}, {"mode", "lines+markers"}, {"name", "MAC"}, {"x", x}, {"y", mac}}}),
                         axis("mode"), axis("MAC")));
    std::vector<std::string> dofs;
    std::vector<double> delta;
    for (const json& d : field(field(j, "localization"), "dofs").is_array() ? j["localization"]["dofs"] : json::array()) {
      dofs.push_back(field(d, "dof").is_string() ? d["dof"].get<std::string>() : "?");
      delta.push_back(field(d, "delta").is_number() ? std::max(d["delta"].get<double>(), 1e-300) : std::nan(""));
    }
    out.push_back(figure("Pseudo residual force per DOF (eq. 7-8; zoom to read the DOFs)",
                         json::array({{{"type", "bar"}, {"name", "delta pseudo residual"}, {"x", dofs}, {"y", delta}}}),
                         axis("DOF"), axis("|r|", true)));
    std::vector<double> id, score, id_f, score_f;
    for (const json& e : field(field(j, "localization"), "elements").is_array() ? j["localization"]["elements"] : json::array()) {
      const bool flagged = field(e, "flagged") == true;
      (flagged ? id_f : id).push_back(field(e, "id").is_number() ? e["id"].get<double>() : std::nan(""));
      (flagged ? score_f : score).push_back(field(e, "score").is_number() ? e["score"].get<double>() : std::nan(""));
    }
    out.push_back(figure("Localization: score per element",
                         json::array({{{"type", "bar"}, {"name", "elements"}, {"x", id}, {"y", score}},
                                      {{"type", "bar"}, {"name", "flagged"}, {"x", id_f}, {"y", score_f}, {"marker", {{"color", "#c0392b"}}}}}),
                         axis("element id"), axis("score")));
  } else if (step == "update") {
    const json f = field(j, "frequencies_hz"), mac = field(j, "mac");
    before_after(numbers(field(f, "measured")), numbers(field(f, "initial")), numbers(field(f, "updated")), numbers(field(mac, "initial")),
                 numbers(field(mac, "updated")), "initial and updated model", &out);
    std::vector<std::string> names;
    std::vector<double> init, value, err;
    for (const json& p : field(j, "parameters").is_array() ? j["parameters"] : json::array()) {
      names.push_back(field(p, "name").is_string() ? p["name"].get<std::string>() : "?");
      init.push_back(field(p, "initial").is_number() ? p["initial"].get<double>() : std::nan(""));
      value.push_back(field(p, "value").is_number() ? p["value"].get<double>() : std::nan(""));
      err.push_back(field(p, "std").is_number() ? p["std"].get<double>() : 0.0);
    }
    out.push_back(figure("Parameters (updated value with one standard deviation)",
                         json::array({{{"type", "scatter"}, {"mode", "markers"}, {"name", "initial"}, {"x", names}, {"y", init}},
                                      {{"type", "scatter"}, {"mode", "markers"}, {"name", "updated"}, {"x", names}, {"y", value},
                                       {"error_y", {{"type", "data"}, {"array", err}, {"visible", true}}}}}),
                         axis("parameter"), axis("value")));
  } else if (step == "discover") {
    const json b = field(field(j, "fit"), "before"), a = field(field(j, "fit"), "after");
    before_after(numbers(field(b, "measured_hz")), numbers(field(b, "model_hz")), numbers(field(a, "model_hz")), numbers(field(b, "mac")),
                 numbers(field(a, "mac")), "the model as given and with the findings", &out);
    std::vector<std::string> labels, text;
    std::vector<double> score;
    int shown = 0;
    for (const json& c : field(j, "candidates").is_array() ? j["candidates"] : json::array()) {
      if (shown++ == 20) break;
      labels.push_back(std::to_string(shown) + " " + (field(c, "kind").is_string() ? c["kind"].get<std::string>() : "?"));
      text.push_back(field(c, "description").is_string() ? c["description"].get<std::string>() : "");
      score.push_back(field(c, "score").is_number() ? c["score"].get<double>() : std::nan(""));
    }
    out.push_back(figure("Candidate ranking (ln Bayes factor over the model as given)",
                         json::array({{{"type", "bar"}, {"name", "candidates"}, {"x", labels}, {"y", score}, {"text", text}}}),
                         axis("candidate"), axis("evidence")));
  } else if (step == "identify") {
    const json st = field(j, "stabilization");
    const char* names[4] = {"new or unstable", "stable in frequency", "stable in frequency, damping", "stable in frequency, damping, vector"};
    const char* symbols[4] = {"circle-open", "x", "cross", "circle"};
    std::vector<double> fx[4], oy[4];
    std::vector<std::string> hover[4];
    for (const json& p : field(st, "poles").is_array() ? st["poles"] : json::array()) {
      if (!p.is_array() || p.size() < 4 || !p[3].is_number_integer()) continue;
      const int c = std::clamp(p[3].get<int>(), 0, 3);
      oy[c].push_back(p[0].is_number() ? p[0].get<double>() : std::nan(""));
      fx[c].push_back(p[1].is_number() ? p[1].get<double>() : std::nan(""));
      hover[c].push_back("damping " + (p[2].is_number() ? format_number(100 * p[2].get<double>(), 3) : std::string("?")) + " %");
    }
    json data = json::array();
    const auto f = numbers(field(st, "frequency_hz")), bg = numbers(field(st, "background"));
    if (!f.empty())
      data.push_back({{"type", "scatter"}, {"mode", "lines"}, {"name", field(st, "background_label").is_string() ? st["background_label"] : json("spectrum")},
                      {"x", f}, {"y", bg}, {"yaxis", "y2"}, {"line", {{"color", "#999"}, {"width", 1}}}});
    for (int c = 0; c < 4; ++c)
      data.push_back({{"type", "scatter"}, {"mode", "markers"}, {"name", names[c]}, {"x", fx[c]}, {"y", oy[c]}, {"text", hover[c]},
                      {"marker", {{"symbol", symbols[c]}, {"size", c == 3 ? 7 : 6}}}});
    json fig = figure("Stabilization diagram over the spectrum (drag to zoom, double-click to reset)", data, axis("frequency [Hz]"),
                      axis("model order"));
    fig["layout"]["yaxis2"] = {{"type", "log"}, {"overlaying", "y"}, {"side", "right"}, {"showgrid", false},
                               {"title", {{"text", field(st, "background_label").is_string() ? st["background_label"] : json("")}}}};
    json shapes = json::array();
    for (const json& m : field(j, "modes").is_array() ? j["modes"] : json::array())
      if (field(m, "frequency_hz").is_number())
        shapes.push_back({{"type", "line"}, {"xref", "x"}, {"yref", "paper"}, {"x0", m["frequency_hz"]}, {"x1", m["frequency_hz"]},
                          {"y0", 0}, {"y1", 1}, {"line", {{"color", "#2a7"}, {"dash", "dot"}}}});
    fig["layout"]["shapes"] = shapes;
    fig["layout"]["height"] = 520;
    out.push_back(fig);
  }
  return out;
}

std::string plot_block(const json& fig, int index) {
  const std::string id = "plot-" + std::to_string(index);
  return "<div class=\"plot\" id=\"" + id + "\"></div>\n<script type=\"application/json\" id=\"" + id + "-data\">" + script_json(fig) +
         "</script>\n";
}

std::string view_block(const json& view, int index) {
  const std::string id = "view-" + std::to_string(index);
  return "<div class=\"view3d\" id=\"" + id + "\"><canvas width=\"900\" height=\"520\"></canvas><div class=\"controls\">"
         "<button class=\"play\">pause</button> <select class=\"mode\"></select> amplitude <input class=\"amp\" type=\"range\" "
         "min=\"0\" max=\"0.4\" step=\"0.01\" value=\"0.12\"> <span class=\"hint\">drag to rotate, wheel to zoom, right-drag to pan</span>"
         "</div></div>\n<script type=\"application/json\" id=\"" + id + "-data\">" + script_json(view) + "</script>\n";
}

const char* content_security_policy() {
  return "default-src 'none'; script-src 'unsafe-inline' 'unsafe-eval'; style-src 'unsafe-inline'; img-src data:; "
         "connect-src 'none'; worker-src 'none'; font-src 'none'; base-uri 'none'; form-action 'none'";
}

const char* interactive_script() {
  return R"JS(<script>
(function () {
  var body = document.body, frames = 0, drawn = 0, violations = 0;
  document.addEventListener('securitypolicyviolation', function () { body.setAttribute('data-csp-violations', ++violations); });
  body.setAttribute('data-csp-violations', 0);
  function note(where, text) { var p = document.createElement('p'); p.className = 'rc'; p.textContent = text; where.appendChild(p); }
  // Animated mode shapes: three.js line segments, displaced by sin(2 pi t / T) times the mode, OrbitControls.
  function view(el) {
    var data = JSON.parse(document.getElementById(el.id + '-data').textContent);
    var canvas = el.querySelector('canvas'), renderer;
    try { renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true, preserveDrawingBuffer: true}); }
    catch (e) { note(el, 'The 3D view needs WebGL, which this browser does not offer (' + e.message + ').'); body.setAttribute('data-webgl', 0); return; }
    body.setAttribute('data-webgl', 1);
    renderer.setClearColor(0xffffff);
    var scene = new THREE.Scene(), n = data.points.length / 3, size = data.size || 1;
    var c = [0, 0, 0];
    for (var i = 0; i < n; i++) for (var k = 0; k < 3; k++) c[k] += data.points[3 * i + k] / n;
    var camera = new THREE.PerspectiveCamera(40, canvas.width / canvas.height, size / 100, size * 100);
    camera.position.set(c[0] + 0.2 * size, c[1] - 0.3 * size, c[2] + 2.2 * size);
    camera.up.set(0, 1, 0);
    var controls = new THREE.OrbitControls(camera, canvas);
    controls.target.set(c[0], c[1], c[2]);
    controls.update();
    function segments(color) {
      var g = new THREE.BufferGeometry();
      var pos = new Float32Array(data.segments.length * 3);
      g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
      var line = new THREE.LineSegments(g, new THREE.LineBasicMaterial({color: color}));
      scene.add(line);
      return pos;
    }
    var base = segments(0xbbbbbb), moving = segments(0x1f5fa8), movingGeometry = scene.children[1].geometry;
    for (var s = 0; s < data.segments.length; s++) for (var k = 0; k < 3; k++) base[3 * s + k] = data.points[3 * data.segments[s] + k];
    var select = el.querySelector('select.mode'), play = el.querySelector('button.play'), amp = el.querySelector('input.amp');
    data.modes.forEach(function (m, i) { var o = document.createElement('option'); o.value = i; o.textContent = m.label; select.appendChild(o); });
    if (!data.modes.length) { note(el, 'No elastic mode to show.'); return; }
    var running = true, phase = 0, last = null, snapshots = [], snapshotSin = 0;
    play.onclick = function () { running = !running; play.textContent = running ? 'pause' : 'play'; };
    function draw(t) {
      if (last === null) last = t;
      // A period of 1.6 s; one frame advances at most 0.1 s, so a slow renderer (software GL on a busy machine)
      // shows a slower motion instead of an aliased one (frames a whole period apart would look still).
      if (running) phase += Math.min(t - last, 100) / 1000 * 2 * Math.PI / 1.6;
      last = t;
      var u = data.modes[select.value || 0].u, a = amp.value * size * Math.sin(phase);
      for (var s = 0; s < data.segments.length; s++) {
        var p = data.segments[s];
        for (var k = 0; k < 3; k++) moving[3 * s + k] = data.points[3 * p + k] + a * u[3 * p + k];
      }
      movingGeometry.attributes.position.needsUpdate = true;
      controls.update();
      renderer.render(scene, camera);
      frames++;
      if (frames % 10 === 0) body.setAttribute('data-frames', frames);
      // For headless checks: two pictures whose displacements differ by at least 0.7 of the amplitude (about a
      // quarter period apart) must differ (the shape moves).
      if (frames === 5 || (snapshots.length === 1 && Math.abs(Math.sin(phase) - snapshotSin) > 0.7)) {
        snapshotSin = Math.sin(phase);
        snapshots.push(canvas.toDataURL());
        if (snapshots.length === 2) {
          body.setAttribute('data-frames-differ', snapshots[0] !== snapshots[1] ? 1 : 0);
          body.setAttribute('data-snapshots', 'frame ' + frames + ', PNG sizes ' + snapshots[0].length + ' and ' + snapshots[1].length);
        }
      }
      requestAnimationFrame(draw);
    }
    requestAnimationFrame(draw);
  }
  document.querySelectorAll('.view3d').forEach(view);
  // Zoomable plots: plotly.js, inflated from its gzip-compressed copy in the page (no network).
  var plots = document.querySelectorAll('.plot');
  if (!plots.length) return;
  var packed = document.getElementById('plotly-gz');
  if (!packed || typeof DecompressionStream === 'undefined') { plots.forEach(function (p) { note(p, 'Zoomable plots need a browser with DecompressionStream.'); }); return; }
  var bin = atob(packed.textContent), bytes = new Uint8Array(bin.length);
  for (var i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  new Response(new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'))).text().then(function (code) {
    (0, eval)(code);
    plots.forEach(function (p) {
      var fig = JSON.parse(document.getElementById(p.id + '-data').textContent);
      Plotly.newPlot(p, fig.data, fig.layout, {responsive: true, displaylogo: false}).then(function () {
        if (p.querySelector('.main-svg')) body.setAttribute('data-plots-drawn', ++drawn);
      });
    });
  }).catch(function (e) { plots.forEach(function (p) { note(p, 'The plot library could not be loaded: ' + e); }); });
})();
</script>
)JS";
}

}  // namespace dynid::internal
