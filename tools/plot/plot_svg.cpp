#include "plot_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "cli_support.hpp"
#include "command_support.hpp"  // printable()
#include "phiq/csv_compare.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

int plot_fail(const std::string& msg, int code) {
  std::cerr << "phiq: plot: " << printable(msg) << "\n";
  return code;
}

// Compact numbers for coordinates in the SVG (a tenth of a pixel is plenty).
std::string px(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", v);
  return b;
}
std::string label(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}
std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else if (c == '"') o += "&quot;";
    else o += c;
  }
  return o;
}

const char* const kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"};

// Data range → pixel box, with a margin and (for the mechanism) equal scales on both axes.
struct Box {
  double x0, y0, w, h;           // pixel box
  double xmin, xmax, ymin, ymax;  // data range
  double sx(double x) const { return x0 + (x - xmin) / (xmax - xmin) * w; }
  double sy(double y) const { return y0 + h - (y - ymin) / (ymax - ymin) * h; }
};
void widen(double& lo, double& hi) {
  if (!(hi > lo)) lo -= 0.5, hi += 0.5;  // a constant: a unit range around it
  const double m = 0.05 * (hi - lo);
  lo -= m, hi += m;
}

std::string polyline(const std::string& cls, const std::string& colour, double width,
                     const std::vector<std::pair<double, double>>& pts, const std::string& extra = "") {
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

}  // namespace

int plot_svg(const PlotOptions& o) {
  Scene scene;
  CsvTable table;
  try {
    scene = load_scene(o.scene);
  } catch (const SceneError& e) {
    return plot_fail(e.what(), 2);
  }
  try {
    table = read_csv_table(o.csv);
  } catch (const Error& e) {
    return plot_fail(e.what(), 2);
  }
  // the SVG exists (as a temporary) before the drawing, which may sweep the scene again
  set_interrupt_subject("plot: " + o.out, "; no output written");
  OutputSet outputs;
  AtomicOutputFile* out = nullptr;
  try {
    out = &outputs.add(o.out);
  } catch (const Error& e) {
    return plot_fail(e.what(), 3);
  }
  // The CSV must be the scene's result: the columns its output lists, in order.
  const std::vector<std::string> expected = CsvFormat(*scene.model, scene.sweep).column_names();
  if (table.columns != expected) {
    std::string want;
    for (const auto& c : expected) {
      if (!want.empty()) want += ',';
      want += c;
    }
    if (want.size() > 120) want = want.substr(0, 117) + "...";
    return plot_fail(o.csv + ": its columns are not the output of " + o.scene + " (expected " + want + ")", 2);
  }
  if (table.rows.empty()) return plot_fail(o.csv + ": no rows", 2);
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
  const Model& model = *scene.model;

  // Columns against time: as asked, else the coordinate columns (at most 6).
  std::vector<std::string> series = o.columns;
  if (series.empty())
    for (std::size_t k = 0; k < scene.sweep.coordinate_columns.size() && k < 6; ++k)
      series.push_back(model.coordinate_names()[scene.sweep.coordinate_columns[k]]);
  if (series.empty())  // no coordinate written (e.g. a coupler curve alone): the first columns after t
    for (std::size_t c = 1; c < table.columns.size() && c <= 6; ++c) series.push_back(table.columns[c]);
  for (const std::string& c : series)
    if (!col.count(c) || c == "t") return plot_fail("--columns: no column '" + c + "' in " + o.csv, 2);

  // The mechanism: every coordinate its lines read must be in the CSV.
  const std::vector<SketchSegment> segments = sketch_segments(model);
  std::vector<Index> needed;
  auto need = [&](const OutputPoint& p) {
    const Slot* slots[] = {&p.point.x, &p.point.y, &p.body.x, &p.body.y, &p.body.psi};
    const int first = p.kind == OutputPointKind::kPlanarPoint ? 0 : 2, last = first == 0 ? 2 : 5;
    for (int k = first; k < last; ++k)
      if (slots[k]->is_coordinate()) needed.push_back(slots[k]->coord());
  };
  for (const SketchSegment& s : segments) need(s.from), need(s.to);
  std::sort(needed.begin(), needed.end());
  needed.erase(std::unique(needed.begin(), needed.end()), needed.end());
  bool all_in_csv = true;
  for (Index j : needed) all_in_csv = all_in_csv && col.count(model.coordinate_names()[j]);

  // Rows drawn: evenly spread, first and last included.
  const std::size_t n_rows = table.rows.size();
  std::vector<std::size_t> drawn;
  const int positions = std::max(1, o.positions);
  for (int k = 0; k < positions; ++k) {
    const std::size_t r = positions == 1 ? 0
                                         : static_cast<std::size_t>(std::llround(static_cast<double>(k) *
                                                                                 static_cast<double>(n_rows - 1) /
                                                                                 (positions - 1)));
    if (drawn.empty() || drawn.back() != r) drawn.push_back(r);
  }
  // The positions at the drawn rows: from the CSV when it has every coordinate the drawing reads; otherwise (the
  // output lists only some, e.g. a coupler curve) by sweeping the scene again, as `phiq run` did, positions kept
  // at the drawn rows, every row checked against the coordinate columns the CSV does have.
  std::map<std::size_t, Eigen::VectorXd> solved;
  if (!all_in_csv) {
    if (static_cast<Index>(n_rows) != scene.sweep.steps + 1)
      return plot_fail(o.csv + ": " + std::to_string(n_rows) + " rows, but " + o.scene + " sweeps " +
                      std::to_string(scene.sweep.steps + 1) + " time points",
                  2);
    SweepOptions opt = scene.sweep;  // the same outputs, so the same predictor and path as the run
    opt.points.clear(), opt.residuals = opt.condition = false;
    opt.threads = 0;
    // a redundant model is solved as `phiq run` solves it: assembled by minimum norm, swept on its independent rows
    SquareScene square;
    if (prepare_scene(model, scene.sweep.t_begin, scene.sweep.assembly, &square) != SolveStatus::kSuccess)
      return plot_fail(o.scene + ": " + square.assembly.message, 1);
    const Model& swept = square.model(model);
    Workspace ws(swept);
    ws.q = square.start;
    // the CSV column of each coordinate (or none), looked up once rather than per row
    std::vector<std::pair<Index, std::size_t>> checked;  // (coordinate, column)
    for (Index j = 0; j < model.num_coordinates(); ++j)
      if (auto c = col.find(model.coordinate_names()[j]); c != col.end()) checked.emplace_back(j, c->second);
    SweepSummary sum;
    std::string mismatch;
    (void)run_sweep(  // its status is sum.status, read below
        swept, opt, ws, [&](const StepView& v) {
      const auto row = static_cast<std::size_t>(v.step);
      for (const auto& [j, c] : checked) {
        const double mine = v.q(j);
        if (!(std::fabs(table.rows[row][c] - mine) <= 1e-6 * (1.0 + std::fabs(mine))))
          mismatch = "row " + std::to_string(row + 2) + ", column '" + model.coordinate_names()[j] +
                     "': " + label(table.rows[row][c]) + ", the scene gives " + label(mine);
      }
      if (!(std::fabs(table.rows[row][0] - v.t) <= 1e-12 * (1.0 + std::fabs(v.t))))
        mismatch = "row " + std::to_string(row + 2) + ": t = " + label(table.rows[row][0]) + ", the scene gives " +
                   label(v.t);
      if (std::binary_search(drawn.begin(), drawn.end(), row)) solved[row] = v.q;
      return mismatch.empty();
    }, &sum);
    if (!mismatch.empty()) return plot_fail(o.csv + " is not the result of " + o.scene + ": " + mismatch, 2);
    if (sum.status != SolveStatus::kSuccess) return plot_fail(o.scene + ": " + sum.message, 1);
  }
  Eigen::VectorXd q = model.initial_positions();
  auto load_row = [&](std::size_t r) {
    if (!all_in_csv) {
      q = solved.at(r);
      return;
    }
    for (Index j : needed) q(j) = table.rows[r][col[model.coordinate_names()[j]]];
  };
  // The lines at each drawn row, and the traces of the output points, in data coordinates.
  using Line = std::vector<std::pair<double, double>>;
  std::vector<std::vector<Line>> frames;
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  auto extend = [&](double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    xmin = std::min(xmin, x), xmax = std::max(xmax, x), ymin = std::min(ymin, y), ymax = std::max(ymax, y);
  };
  for (std::size_t r : drawn) {
    load_row(r);
    std::vector<Line> lines;
    for (const SketchSegment& s : segments) {
      const PointMotion a = evaluate_point(s.from, q.data(), nullptr, nullptr),
                        b = evaluate_point(s.to, q.data(), nullptr, nullptr);
      extend(a.r[0], a.r[1]), extend(b.r[0], b.r[1]);
      lines.push_back({{a.r[0], a.r[1]}, {b.r[0], b.r[1]}});
    }
    frames.push_back(std::move(lines));
  }
  std::vector<Line> traces;
  std::vector<std::string> trace_names;
  for (const OutputPoint& p : scene.sweep.points) {
    const std::size_t cx = col[p.name + ".x"], cy = col[p.name + ".y"];
    Line l;
    for (const auto& row : table.rows) l.push_back({row[cx], row[cy]}), extend(row[cx], row[cy]);
    traces.push_back(std::move(l));
    trace_names.push_back(p.name);
  }
  // An empty panel without a word reads as a broken drawing (every dimension 3 scene, e.g. `phiq generate chain3d`):
  // say why.
  if (segments.empty() && traces.empty())
    std::cerr << "phiq: plot: " << o.scene << ": nothing of the mechanism to draw (its constraints make no lines: "
              << "spatial ones, loops and equations draw none; output.points lists no point to trace): the SVG has "
              << "the columns against t only\n";

  // ---- the SVG: mechanism on the left (equal scales), columns against t on the right
  constexpr double W = 1000, H = 460, M = 40;
  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W
      << " " << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<title>" << escape(scene.name.empty() ? o.scene : scene.name) << ": " << escape(o.csv) << "</title>\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  {
    const double side = H - 2 * M;
    if (!(xmax >= xmin)) xmin = -1, xmax = 1, ymin = -1, ymax = 1;  // nothing to draw
    widen(xmin, xmax), widen(ymin, ymax);
    // equal scales: grow the smaller range
    const double span = std::max(xmax - xmin, ymax - ymin), cx = 0.5 * (xmin + xmax), cy = 0.5 * (ymin + ymax);
    Box b{M, M, side, side, cx - span / 2, cx + span / 2, cy - span / 2, cy + span / 2};
    svg << "<g id=\"mechanism\">\n<text x=\"" << M << "\" y=\"" << M - 12 << "\">mechanism at " << drawn.size()
        << " rows (light: first, dark: last)" << (traces.empty() ? "" : ", traced points") << "</text>\n"
        << "<rect x=\"" << M << "\" y=\"" << M << "\" width=\"" << side << "\" height=\"" << side
        << "\" fill=\"none\" stroke=\"#ccc\"/>\n";
    for (std::size_t f = 0; f < frames.size(); ++f) {
      const int grey = frames.size() == 1 ? 0 : static_cast<int>(190 - 190.0 * f / (frames.size() - 1));
      char colour[16];
      std::snprintf(colour, sizeof colour, "#%02x%02x%02x", grey, grey, grey);
      svg << "<g class=\"position\" data-t=\"" << label(table.rows[drawn[f]][0]) << "\">\n";
      for (const Line& l : frames[f]) {
        Line p;
        for (const auto& [x, y] : l) p.push_back({b.sx(x), b.sy(y)});
        svg << polyline("mechanism", colour, 2, p);
      }
      svg << "</g>\n";
    }
    for (std::size_t k = 0; k < traces.size(); ++k) {
      Line p;
      for (const auto& [x, y] : traces[k])
        if (std::isfinite(x) && std::isfinite(y)) p.push_back({b.sx(x), b.sy(y)});
      svg << polyline("trace", kPalette[k % 8], 1.5, p, " data-point=\"" + escape(trace_names[k]) + "\"");
      svg << "<text x=\"" << M + 6 << "\" y=\"" << M + 16 + 14 * k << "\" fill=\"" << kPalette[k % 8] << "\">"
          << escape(trace_names[k]) << "</text>\n";
    }
    svg << "<text x=\"" << M << "\" y=\"" << H - M + 16 << "\">x " << label(b.xmin) << " … " << label(b.xmax)
        << ", y " << label(b.ymin) << " … " << label(b.ymax) << "</text>\n</g>\n";
  }
  {
    const double x0 = H + 20, w = W - x0 - M, h = H - 2 * M;
    double tmin = table.rows.front()[0], tmax = table.rows.back()[0];
    if (tmin > tmax) std::swap(tmin, tmax);
    double vmin = INFINITY, vmax = -INFINITY;
    for (const std::string& name : series) {
      const std::size_t c = col.at(name);  // once per column, not per row
      for (const auto& row : table.rows)
        if (std::isfinite(row[c])) vmin = std::min(vmin, row[c]), vmax = std::max(vmax, row[c]);
    }
    if (!(vmax >= vmin)) vmin = 0, vmax = 1;
    if (!(tmax > tmin)) tmin -= 0.5, tmax += 0.5;
    widen(vmin, vmax);
    Box b{x0, M, w, h, tmin, tmax, vmin, vmax};
    svg << "<g id=\"series\">\n<text x=\"" << x0 << "\" y=\"" << M - 12 << "\">columns against t</text>\n"
        << "<rect x=\"" << x0 << "\" y=\"" << M << "\" width=\"" << w << "\" height=\"" << h
        << "\" fill=\"none\" stroke=\"#888\"/>\n";
    if (vmin < 0 && vmax > 0)
      svg << "<line x1=\"" << px(x0) << "\" x2=\"" << px(x0 + w) << "\" y1=\"" << px(b.sy(0)) << "\" y2=\""
          << px(b.sy(0)) << "\" stroke=\"#ddd\"/>\n";
    for (std::size_t k = 0; k < series.size(); ++k) {
      Line p;
      const std::size_t c = col.at(series[k]);
      for (const auto& row : table.rows)
        if (std::isfinite(row[c])) p.push_back({b.sx(row[0]), b.sy(row[c])});
      svg << polyline("series", kPalette[k % 8], 1.5, p, " data-column=\"" + escape(series[k]) + "\"");
      svg << "<text x=\"" << px(x0 + w - 150) << "\" y=\"" << M + 16 + 14 * k << "\" fill=\"" << kPalette[k % 8]
          << "\">" << escape(series[k]) << "</text>\n";
    }
    svg << "<text x=\"" << px(x0) << "\" y=\"" << H - M + 16 << "\">t " << label(tmin) << " … " << label(tmax)
        << "</text>\n<text x=\"" << px(x0 + w) << "\" y=\"" << M - 2 << "\" text-anchor=\"end\">" << label(vmax)
        << "</text>\n<text x=\"" << px(x0 + w) << "\" y=\"" << H - M + 16 << "\" text-anchor=\"end\">"
        << label(vmin) << "</text>\n</g>\n";
  }
  svg << "</svg>\n";
  try {
    out->write(svg.str());
    outputs.commit();
  } catch (const Error& e) {
    return plot_fail(e.what(), 3);
  }
  return 0;
}

}  // namespace phiq::tools
