#include "plot_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>

#include "cli_support.hpp"
#include "command_support.hpp"  // printable(), parameter_settings()
#include "phiq/csv_compare.hpp"
#include "phiq/phiq.hpp"
#include "plot_draw.hpp"
#include "plot_mechanism.hpp"
#include "plot_series.hpp"

namespace phiq::tools {

using svg::escape;
using svg::label;
using svg::px;

namespace {

int plot_fail(const std::string& msg, int code) {
  std::cerr << "phiq: plot: " << printable(msg) << "\n";
  return code;
}

}  // namespace

int plot_svg(const PlotOptions& o) {
  Scene scene;
  CsvTable table;
  try {
    scene = load_scene(o.scene, SceneLimits{}, parameter_settings(o.sets));
  } catch (const SceneError& e) {
    return plot_fail(e.what(), 2);
  } catch (const Error& e) {  // a --set that is not NAME=VALUE
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

  // Columns against time: as asked, else the driven and the moving coordinates (at most 6), never a constant.
  std::vector<std::string> series;
  try {
    series = plotted_columns(scene, table, o.columns, o.csv);
  } catch (const Error& e) {
    return plot_fail(e.what(), 2);
  }
  // The mechanism: every coordinate its lines read must be in the CSV.
  const MechanismSketch sketch = sketch_mechanism(model);
  const std::vector<SketchSegment>& segments = sketch.segments;
  std::vector<Index> needed;
  auto need = [&](const OutputPoint& p) {
    const Slot* slots[] = {&p.point.x,     &p.point.y,     &p.body.x,      &p.body.y,      &p.body.psi,
                           &p.spatial.r[0], &p.spatial.r[1], &p.spatial.r[2], &p.spatial.p[0], &p.spatial.p[1],
                           &p.spatial.p[2], &p.spatial.p[3]};
    const int first = p.kind == OutputPointKind::kPlanarPoint ? 0 : (p.kind == OutputPointKind::kPlanarBodyPoint ? 2 : 5);
    const int last = first == 0 ? 2 : (first == 2 ? 5 : 12);
    for (int k = first; k < last; ++k)
      if (slots[k]->is_coordinate()) needed.push_back(slots[k]->coord());
  };
  for (const SketchSegment& s : segments) need(s.from), need(s.to);
  for (const SketchJoint& j : sketch.joints) need(j.at);
  std::sort(needed.begin(), needed.end());
  needed.erase(std::unique(needed.begin(), needed.end()), needed.end());
  bool all_in_csv = true;
  for (Index j : needed) all_in_csv = all_in_csv && col.count(model.coordinate_names()[j]);
  for (Index j : needed)  // a coordinate of the drawing that is not a number: as for a plotted column
    if (const auto c = col.find(model.coordinate_names()[j]); c != col.end())
      for (std::size_t r = 0; r < table.rows.size(); ++r)
        if (!std::isfinite(table.rows[r][c->second]))
          return plot_fail(o.csv + ": column '" + c->first + "', data row " + std::to_string(r + 1) + ": " +
                           label(table.rows[r][c->second]) + " cannot be drawn", 2);

  // Rows drawn: evenly spread, first and last included; but over a full cycle (every point of the drawing where it
  // was at the first row) the last would hide the first: then spread over the cycle, the last row left out.
  const std::size_t n_rows = table.rows.size();
  auto q_of_row = [&](std::size_t r) {
    Eigen::VectorXd q = model.initial_positions();
    for (Index j : needed) q(j) = table.rows[r][col[model.coordinate_names()[j]]];
    return q;
  };
  bool cycle = all_in_csv && n_rows > 2 && !needed.empty();
  if (cycle) {
    const Eigen::VectorXd first = q_of_row(0), last = q_of_row(n_rows - 1);
    const double tol = 1e-6 * model.length_scale();  // a millionth of the drawing: the same picture
    auto same = [&](const OutputPoint& p) {
      const PointMotion a = evaluate_point(p, first.data(), nullptr, nullptr),
                        b = evaluate_point(p, last.data(), nullptr, nullptr);
      for (int k = 0; k < 3; ++k) cycle = cycle && std::fabs(a.r[k] - b.r[k]) <= tol;
    };
    for (const SketchSegment& s : segments) same(s.from), same(s.to);
    for (const SketchJoint& j : sketch.joints) same(j.at);
  }
  std::vector<std::size_t> drawn;
  const int positions = std::max(1, o.positions);
  const double span = static_cast<double>(n_rows - 1), parts = cycle ? positions : positions - 1;
  for (int k = 0; k < positions; ++k) {
    const std::size_t r = positions == 1 ? 0 : static_cast<std::size_t>(std::llround(k * span / parts));
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
  MechanismFrames frames;
  frames.model = &model, frames.sketch = &sketch, frames.spatial = scene.dimension == 3;
  for (std::size_t r : drawn) {
    frames.q.push_back(all_in_csv ? q_of_row(r) : solved.at(r));
    frames.t.push_back(table.rows[r][0]);
  }
  for (const OutputPoint& p : scene.sweep.points) {
    const std::size_t cx = col[p.name + ".x"], cy = col[p.name + ".y"];
    const auto cz = p.dimension() == 3 ? col.find(p.name + ".z") : col.end();
    std::vector<std::array<double, 3>> path;
    for (const auto& row : table.rows) path.push_back({row[cx], row[cy], cz == col.end() ? 0.0 : row[cz->second]});
    frames.traces.emplace_back(p.name, std::move(path));
  }
  // An empty panel without a word reads as a broken drawing: say why.
  if (segments.empty() && sketch.joints.empty() && frames.traces.empty())
    std::cerr << "phiq: plot: " << o.scene << ": nothing of the mechanism to draw (its constraints make no lines: "
              << "loops, drivers and equations draw none; output.points lists no point to trace): the SVG has "
              << "the columns against t only\n";

  // ---- the SVG: mechanism on the left (equal scales), one panel per quantity on the right
  constexpr double W = 1100, M = 60, side = 420;
  const std::size_t panels = panel_count(scene, series);
  const double H = std::max(side + 2 * M, M + static_cast<double>(panels) * 200.0 + 10);
  std::string svg_text = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
                         "width=\"" + px(W) + "\" height=\"" + px(H) + "\" viewBox=\"0 0 " + px(W) + " " + px(H) +
                         "\" font-family=\"sans-serif\" font-size=\"12\">\n<title>" +
                         escape(scene.name.empty() ? o.scene : scene.name) + ": " + escape(o.csv) +
                         "</title>\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg_text += mechanism_panel(frames, M, M, side);
  const double x0 = M + side + 90;
  svg_text += series_panels(scene, table, col, series, x0, M, W - x0 - 20, H - M - 50);
  svg_text += "</svg>\n";
  try {
    out->write(svg_text);
    outputs.commit();
  } catch (const Error& e) {
    return plot_fail(e.what(), 3);
  }
  return 0;
}

}  // namespace phiq::tools
