// What the panels of `phiq plot` share: numbers written compactly, text escaped for SVG, a data range mapped onto
// a pixel box, polylines, round tick values and the axes drawn with them.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace phiq::tools::svg {

// A tenth of a pixel is plenty.
std::string px(double v);
// Four significant digits, for tick labels and ranges.
std::string label(double v);
// Text and attribute values with <, >, &, " escaped.
std::string escape(const std::string& s);

extern const char* const kPalette[8];

// Data range → pixel box (y up).
struct Box {
  double x0, y0, w, h;            // pixel box
  double xmin, xmax, ymin, ymax;  // data range
  double sx(double x) const { return x0 + (x - xmin) / (xmax - xmin) * w; }
  double sy(double y) const { return y0 + h - (y - ymin) / (ymax - ymin) * h; }
};

// A constant range becomes a unit one around it; any range gets a 5 % margin.
void widen(double& lo, double& hi);

using Line = std::vector<std::pair<double, double>>;

std::string polyline(const std::string& cls, const std::string& colour, double width, const Line& pts,
                     const std::string& extra = "");

// Round values (1, 2 or 5 × 10^k apart) within [lo, hi], about `target` of them.
std::vector<double> ticks(double lo, double hi, int target);

// The frame of a panel with ticks and tick labels on both axes, the axis labels below and to the left, and a grid.
std::string axes(const Box& b, const std::string& x_label, const std::string& y_label, int x_ticks, int y_ticks);

}  // namespace phiq::tools::svg
