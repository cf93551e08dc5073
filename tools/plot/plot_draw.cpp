#include "plot_draw.hpp"

#include <cmath>
#include <cstdio>

namespace phiq::tools::svg {

std::string px(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", std::fabs(v) < 0.05 ? 0.0 : v);  // "0.0", never "-0.0"
  return b;
}

std::string label(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", std::fabs(v) < 1e-300 ? 0.0 : v);
  return b;
}

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else if (c == '"')
      o += "&quot;";
    else
      o += c;
  }
  return o;
}

const char* const kPalette[8] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                 "#9467bd", "#8c564b", "#e377c2", "#17becf"};

void widen(double& lo, double& hi) {
  if (!(hi > lo)) lo -= 0.5, hi += 0.5;
  const double m = 0.05 * (hi - lo);
  lo -= m, hi += m;
}

std::string polyline(const std::string& cls, const std::string& colour, double width, const Line& pts,
                     const std::string& extra) {
  std::string s = "<polyline class=\"" + cls + "\" fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"" +
                  px(width) + "\"" + extra + " points=\"";
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (i) s += ' ';
    s += px(pts[i].first);
    s += ',';
    s += px(pts[i].second);
  }
  return s + "\"/>\n";
}

std::vector<double> ticks(double lo, double hi, int target) {
  std::vector<double> v;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return v;
  // the 1, 2 or 5 × 10^k whose count of ticks in the range is nearest the target (the larger step on a tie)
  const double raw = (hi - lo) / std::max(1, target), mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag, best = INFINITY;
  for (double scale : {0.1, 1.0, 10.0})
    for (double m : {1.0, 2.0, 5.0}) {
      const double s = m * mag * scale, n = std::floor(hi / s) - std::ceil(lo / s) + 1;
      if (std::fabs(n - target) <= best) best = std::fabs(n - target), step = s;
    }
  for (double k = std::ceil(lo / step); k * step <= hi * (1 + 1e-12) + 1e-300; ++k) {
    const double t = k * step;
    v.push_back(std::fabs(t) < step * 1e-9 ? 0.0 : t);  // 0, not 1e-17
  }
  return v;
}

std::string axes(const Box& b, const std::string& x_label, const std::string& y_label, int x_ticks, int y_ticks) {
  std::string s = "<rect class=\"frame\" x=\"" + px(b.x0) + "\" y=\"" + px(b.y0) + "\" width=\"" + px(b.w) +
                  "\" height=\"" + px(b.h) + "\" fill=\"none\" stroke=\"#888\"/>\n";
  for (double t : ticks(b.xmin, b.xmax, x_ticks)) {
    const std::string x = px(b.sx(t));
    s += "<line class=\"grid\" x1=\"" + x + "\" x2=\"" + x + "\" y1=\"" + px(b.y0) + "\" y2=\"" + px(b.y0 + b.h) +
         "\" stroke=\"#eee\"/>\n<line class=\"tick\" x1=\"" + x + "\" x2=\"" + x + "\" y1=\"" + px(b.y0 + b.h) +
         "\" y2=\"" + px(b.y0 + b.h + 4) + "\" stroke=\"#888\"/>\n<text class=\"tick-label\" x=\"" + x + "\" y=\"" +
         px(b.y0 + b.h + 15) + "\" text-anchor=\"middle\" font-size=\"10\">" + label(t) + "</text>\n";
  }
  for (double t : ticks(b.ymin, b.ymax, y_ticks)) {
    const std::string y = px(b.sy(t));
    s += "<line class=\"grid\" x1=\"" + px(b.x0) + "\" x2=\"" + px(b.x0 + b.w) + "\" y1=\"" + y + "\" y2=\"" + y +
         "\" stroke=\"#eee\"/>\n<line class=\"tick\" x1=\"" + px(b.x0 - 4) + "\" x2=\"" + px(b.x0) + "\" y1=\"" + y +
         "\" y2=\"" + y + "\" stroke=\"#888\"/>\n<text class=\"tick-label\" x=\"" + px(b.x0 - 6) + "\" y=\"" +
         px(b.sy(t) + 3) + "\" text-anchor=\"end\" font-size=\"10\">" + label(t) + "</text>\n";
  }
  if (!x_label.empty())
    s += "<text class=\"axis-label\" x=\"" + px(b.x0 + b.w / 2) + "\" y=\"" + px(b.y0 + b.h + 30) +
         "\" text-anchor=\"middle\">" + escape(x_label) + "</text>\n";
  if (!y_label.empty())
    s += "<text class=\"axis-label\" transform=\"translate(" + px(b.x0 - 48) + "," + px(b.y0 + b.h / 2) +
         ") rotate(-90)\" text-anchor=\"middle\">" + escape(y_label) + "</text>\n";
  return s;
}

}  // namespace phiq::tools::svg
