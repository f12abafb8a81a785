#include "dynid/io/plot.hpp"

#include <plplot/plplot.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <stdexcept>

#include "dynid/mesh/error.hpp"

namespace dynid::plot {

namespace {

std::mutex g_plplot;  // PLplot keeps global state
std::string g_error;

int on_plplot_exit(const char* msg) {  // PLplot must not exit() the program
  g_error = msg ? msg : "PLplot error";
  return 0;
}

// White background, black axes, then a ten-colour palette (matplotlib's tab10).
void palette() {
  static const PLINT r[] = {255, 0, 31, 255, 44, 214, 148, 140, 227, 127, 188, 23, 200};
  static const PLINT g[] = {255, 0, 119, 127, 160, 39, 103, 86, 119, 127, 189, 190, 200};
  static const PLINT b[] = {255, 0, 180, 14, 44, 40, 189, 75, 194, 127, 34, 207, 200};
  plscmap0(r, g, b, 13);
}
constexpr int kAxis = 1, kGrid = 12, kFirst = 2;

double tr(double y, bool log) { return log ? std::log10(std::max(y, 1e-300)) : y; }

void draw_panel(const Panel& p, double vx0, double vx1, double vy0, double vy1) {
  // Data range.
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const Series& s : p.series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (p.log_y && s.y[i] <= 0)) continue;
      x0 = std::min(x0, s.x[i] + s.dx);
      x1 = std::max(x1, s.x[i] + s.dx);
      const double e = i < s.yerr.size() && std::isfinite(s.yerr[i]) && !p.log_y ? s.yerr[i] : 0.0;
      y0 = std::min(y0, tr(s.y[i], p.log_y) - e);
      y1 = std::max(y1, tr(s.y[i], p.log_y) + e);
    }
  for (const auto& h : p.hlines) {
    if (p.log_y && h.first <= 0) continue;
    y0 = std::min(y0, tr(h.first, p.log_y));
    y1 = std::max(y1, tr(h.first, p.log_y));
  }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1;
  if (!std::isfinite(y0)) y0 = 0, y1 = 1;
  bool bars = false;
  for (const Series& s : p.series) bars = bars || s.kind == Kind::kBars || s.kind == Kind::kStems;
  if (bars || !p.xticks.empty()) x0 -= 0.7, x1 += 0.7;
  if (x1 == x0) x0 -= 0.5, x1 += 0.5;
  if (y1 == y0) y0 -= 0.5, y1 += 0.5;
  const double dy = y1 - y0;
  if (p.log_y) {
    y0 = std::floor(y0 - 0.05 * dy);
    y1 = std::ceil(y1 + 0.05 * dy);
  } else {
    if (bars && y0 > 0) y0 = 0;
    y0 -= 0.05 * dy;
    y1 += 0.08 * dy;
  }
  if (!std::isnan(p.xmin)) x0 = p.xmin;
  if (!std::isnan(p.xmax)) x1 = p.xmax;
  if (!std::isnan(p.ymin)) y0 = tr(p.ymin, p.log_y);
  if (!std::isnan(p.ymax)) y1 = tr(p.ymax, p.log_y);
  plvpor(vx0, vx1, vy0, vy1);
  plwind(x0, x1, y0, y1);
  plschr(0, 0.62);
  // Log axes: a labelled tick every 1, 2, 5, 10... decades so that at most ~8 labels show.
  double ystep = 0;
  if (p.log_y) {
    const double decades = y1 - y0;
    for (double st : {1.0, 2.0, 5.0, 10.0, 20.0, 50.0})
      if (decades / st <= 8) {
        ystep = st;
        break;
      }
  }
  // Grid, then axes.
  plcol0(kGrid);
  plwidth(0.5);
  const char* ybox = p.log_y ? "glt" : "gt";
  plbox(p.xticks.empty() ? "gt" : "", 0, 0, ybox, ystep, 0);
  plcol0(kAxis);
  plwidth(1.0);
  plbox(p.xticks.empty() ? "bcnst" : "bc", 0, 0, p.log_y ? "bcst" : "bcnstv", ystep, 0);
  if (p.log_y) {  // labels 10^k at every ystep decades (PLplot's own log labels crowd)
    for (double k = std::ceil(y0 / ystep) * ystep; k <= y1 + 1e-9; k += ystep) {
      const std::string lab = "10#u" + std::to_string(static_cast<long long>(k)) + "#d";
      plmtex("lv", 0.6, (k - y0) / (y1 - y0), 1.0, lab.c_str());
    }
  }
  if (!p.xticks.empty()) {
    const std::size_t stride = std::max<std::size_t>(1, p.xticks.size() / 40 + 1);
    plschr(0, p.xticks.size() > 30 ? 0.45 : 0.55);
    for (std::size_t i = 0; i < p.xticks.size(); i += stride) {
      const double xx = p.xticks[i].first;
      if (xx < x0 || xx > x1) continue;
      const double dxf = (xx - x0) / (x1 - x0);
      plmtex("bv", 0.8, dxf, 1.0, p.xticks[i].second.c_str());
    }
    plschr(0, 0.62);
  }
  plschr(0, 0.7);
  plmtex("b", p.xticks.empty() ? 2.6 : 4.2, 0.5, 0.5, p.xlabel.c_str());
  plmtex("l", 5.4, 0.5, 0.5, p.ylabel.c_str());
  plschr(0, 0.8);
  plmtex("t", 1.0, 0.5, 0.5, p.title.c_str());
  // Right-axis series (behind), then back to the left axis's window.
  if (!p.right.empty()) {
    double r0 = INFINITY, r1 = -INFINITY;
    for (const Series& s : p.right)
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (std::isfinite(s.y[i]) && (!p.log_right || s.y[i] > 0) && s.x[i] >= x0 && s.x[i] <= x1) {
          r0 = std::min(r0, tr(s.y[i], p.log_right));
          r1 = std::max(r1, tr(s.y[i], p.log_right));
        }
    if (!std::isfinite(r0)) r0 = 0, r1 = 1;
    if (r1 == r0) r0 -= 0.5, r1 += 0.5;
    if (p.log_right) r0 = std::floor(r0), r1 = std::ceil(r1);
    plwind(x0, x1, r0, r1);
    int rc = kFirst + 7;  // grey
    for (const Series& s : p.right) {
      plcol0(s.color >= 0 ? kFirst + (s.color % 10) : rc);
      plwidth(s.width);
      std::vector<PLFLT> xs, ys;
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (std::isfinite(s.y[i]) && s.x[i] >= x0 && s.x[i] <= x1) {
          xs.push_back(s.x[i]);
          ys.push_back(p.log_right && s.y[i] <= 0 ? r0 : tr(s.y[i], p.log_right));
        }
      plline(static_cast<PLINT>(xs.size()), xs.data(), ys.data());
    }
    plcol0(kAxis);
    plwidth(1.0);
    plschr(0, 0.62);
    plbox("", 0, 0, p.log_right ? "cmstlv" : "cmstv", 0, 0);
    plschr(0, 0.7);
    plmtex("r", 4.5, 0.5, 0.5, p.ylabel_right.c_str());
    plwind(x0, x1, y0, y1);
  }
  // Reference lines.
  for (const auto& h : p.hlines) {
    if (p.log_y && h.first <= 0) continue;
    const PLFLT hx[2] = {x0, x1}, hy[2] = {tr(h.first, p.log_y), tr(h.first, p.log_y)};
    plcol0(3);
    pllsty(2);
    plwidth(1.2);
    plline(2, hx, hy);
    pllsty(1);
    plschr(0, 0.55);
    plptex(x1, hy[0], 1, 0, 1.02, h.second.c_str());
    plschr(0, 0.62);
  }
  // Series.
  int next = kFirst;
  std::vector<PLINT> lcol, ltype;
  std::vector<std::string> ltext;
  for (const Series& s : p.series) {
    const int c = s.color >= 0 ? kFirst + (s.color % 10) : next++;
    plcol0(c);
    plwidth(s.width);
    std::vector<PLFLT> xs, ys;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xs.push_back(s.x[i] + s.dx);
      ys.push_back(p.log_y && s.y[i] <= 0 ? y0 : tr(s.y[i], p.log_y));
      if (i < s.yerr.size() && std::isfinite(s.yerr[i]) && s.yerr[i] > 0) {
        PLFLT ex = s.x[i] + s.dx, lo = tr(s.y[i] - s.yerr[i], p.log_y), hi = tr(s.y[i] + s.yerr[i], p.log_y);
        plerry(1, &ex, &lo, &hi);
      }
    }
    const PLINT n = static_cast<PLINT>(xs.size());
    const double base = p.log_y ? y0 : std::max(y0, std::min(0.0, y1));
    switch (s.kind) {
      case Kind::kLine: plline(n, xs.data(), ys.data()); break;
      case Kind::kSegments:
        for (PLINT i = 0; i + 1 < n; i += 2) plline(2, &xs[i], &ys[i]);
        break;
      case Kind::kMarkers:
        plssym(0, s.symbol_scale);
        plpoin(n, xs.data(), ys.data(), s.symbol);
        plssym(0, 1.0);
        break;
      case Kind::kLineMarkers:
        plline(n, xs.data(), ys.data());
        plpoin(n, xs.data(), ys.data(), 17);
        break;
      case Kind::kBars:
        for (PLINT i = 0; i < n; ++i) {
          const double w = s.bar_width / 2;
          PLFLT bx[4] = {xs[i] - w, xs[i] + w, xs[i] + w, xs[i] - w}, by[4] = {base, base, ys[i], ys[i]};
          plfill(4, bx, by);
        }
        break;
      case Kind::kStems:
        for (PLINT i = 0; i < n; ++i) {
          PLFLT sx[2] = {xs[i], xs[i]}, sy[2] = {base, ys[i]};
          plline(2, sx, sy);
        }
        plpoin(n, xs.data(), ys.data(), 17);
        break;
    }
    if (!s.label.empty()) {
      lcol.push_back(c);
      ltext.push_back(s.label);
    }
  }
  plwidth(1.0);
  if (p.legend && !ltext.empty()) {
    const PLINT nl = static_cast<PLINT>(ltext.size());
    std::vector<PLINT> opt(nl, PL_LEGEND_LINE), lstyle(nl, 1), sym_col(nl), sym_n(nl, 1), box_col(nl, 0), box_pat(nl, 0);
    std::vector<PLFLT> lwidth(nl, 2.0), sym_scale(nl, 1.0), box_scale(nl, 1.0), box_w(nl, 1.0);
    std::vector<const char*> text(nl), syms(nl, "");
    for (PLINT i = 0; i < nl; ++i) text[i] = ltext[i].c_str();
    PLFLT lw, lh;
    plschr(0, 0.6);
    pllegend(&lw, &lh, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, PL_POSITION_RIGHT | PL_POSITION_TOP | PL_POSITION_INSIDE,
             0.01, 0.01, 0.05, 0, kAxis, 1, 0, 0, nl, opt.data(), 1.0, 0.65, 1.6, 1.0, lcol.data(), text.data(),
             box_col.data(), box_pat.data(), box_scale.data(), box_w.data(), lcol.data(), lstyle.data(), lwidth.data(),
             sym_col.data(), sym_scale.data(), sym_n.data(), syms.data());
    plschr(0, 0.62);
  }
}

}  // namespace

void save(const Figure& f, const std::string& path, bool overwrite) {
  namespace fs = std::filesystem;
  const std::string ext = fs::path(path).extension().string();
  if (ext != ".png" && ext != ".svg") throw InputError(path + ": a plot must end in .png or .svg");
  std::error_code ec;
  if (!overwrite && fs::exists(path, ec)) throw InputError(path + ": file exists; pass --force to overwrite it");
  const fs::path dir = fs::path(path).has_parent_path() ? fs::path(path).parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) throw InputError(path + ": folder '" + dir.string() + "' does not exist");
  const fs::path tmp = dir / ("." + fs::path(path).filename().string() + ".tmp" + std::to_string(::getpid()) + ext);
  {
    std::lock_guard<std::mutex> lock(g_plplot);
    g_error.clear();
    plsexit(on_plplot_exit);
    plsdev(ext == ".png" ? "pngcairo" : "svgcairo");
    plsfnam(tmp.c_str());
    plspage(0, 0, f.width, f.height, 0, 0);
    palette();
    plinit();
    if (!g_error.empty()) {
      plend();
      fs::remove(tmp, ec);
      throw std::runtime_error("plot " + path + ": " + g_error);
    }
    pladv(0);
    const int rows = std::max(1, f.rows), cols = std::max(1, f.cols);
    const double top = f.title.empty() ? 0.96 : 0.92;
    if (!f.title.empty()) {
      plvpor(0, 1, 0, 1);
      plwind(0, 1, 0, 1);
      plcol0(kAxis);
      plschr(0, 0.95);
      plptex(0.5, 0.965, 1, 0, 0.5, f.title.c_str());
    }
    for (std::size_t k = 0; k < f.panels.size() && static_cast<int>(k) < rows * cols; ++k) {
      const int r = static_cast<int>(k) / cols, c = static_cast<int>(k) % cols;
      const double w = 1.0 / cols, h = top / rows;
      const bool ticks = !f.panels[k].xticks.empty();
      draw_panel(f.panels[k], c * w + 0.07 * w + 0.05, (c + 1) * w - 0.03,
                 top - (r + 1) * h + (ticks ? 0.22 : 0.15) * h, top - r * h - 0.10 * h);
    }
    plend();
    if (!g_error.empty()) {
      fs::remove(tmp, ec);
      throw std::runtime_error("plot " + path + ": " + g_error);
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(path + ": cannot write the plot: " + ec.message());
  }
}

}  // namespace dynid::plot
