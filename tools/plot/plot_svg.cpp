#include "plot_svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>

#include "cli_support.hpp"
#include "command_support.hpp"  // printable(), parameter_settings()
#include "drawn_result.hpp"
#include "phiq/csv_compare.hpp"
#include "phiq/phiq.hpp"
#include "plot_draw.hpp"
#include "part_drawing.hpp"
#include "phiq/drawn_parts.hpp"
#include "plot_mechanism.hpp"
#include "plot_parts.hpp"
#include "plot_series.hpp"

namespace phiq::tools {

using svg::escape;
using svg::label;
using svg::px;

namespace {

// What the SVG's title calls the result of a sweep run here.
constexpr const char* kSweptTitle = "its sweep";

int plot_fail(const std::string& msg, int code) {
  std::cerr << "phiq: plot: " << printable(msg) << "\n";
  return code;
}

// The rows drawn: evenly spread, first and last included; but over a full cycle (every point of the drawing where
// it was at the first row) the last would hide the first: then spread over the cycle, the last row left out.
std::vector<std::size_t> drawn_rows(const Model& model, const MechanismSketch& sketch, const CsvTable& table,
                                    const std::map<std::string, std::size_t>& col, const std::vector<Index>& needed,
                                    bool all_in_csv, int positions) {
  const std::size_t n_rows = table.rows.size();
  auto q_of_row = [&](std::size_t r) {
    Eigen::VectorXd q = model.initial_positions();
    for (Index j : needed) q(j) = table.rows[r][col.at(model.coordinate_names()[j])];
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
    for (const SketchSegment& s : sketch.segments) same(s.from), same(s.to);
    for (const SketchJoint& j : sketch.joints) same(j.at);
  }
  std::vector<std::size_t> drawn;
  positions = std::max(1, positions);
  const double span = static_cast<double>(n_rows - 1), parts = cycle ? positions : positions - 1;
  for (int k = 0; k < positions; ++k) {
    const std::size_t r = positions == 1 ? 0 : static_cast<std::size_t>(std::llround(k * span / parts));
    if (drawn.empty() || drawn.back() != r) drawn.push_back(r);
  }
  return drawn;
}

// The positions at the drawn rows of a result whose output lists only some of the coordinates the drawing reads
// (e.g. a coupler curve): the scene swept again as `phiq run` swept it, every row checked against the coordinate
// columns the result does have. Throws DrawError (2: not the scene's result; 1: the scene cannot be swept).
std::map<std::size_t, Eigen::VectorXd> swept_positions(const Scene& scene, const CsvTable& table,
                                                       const std::map<std::string, std::size_t>& col,
                                                       const std::vector<std::size_t>& drawn,
                                                       const std::string& result) {
  const Model& model = *scene.model;
  const std::size_t n_rows = table.rows.size();
  if (static_cast<Index>(n_rows) != scene.sweep.steps + 1)
    throw DrawError(result + ": " + std::to_string(n_rows) + " rows, but " + scene.path + " sweeps " +
                        std::to_string(scene.sweep.steps + 1) + " time points",
                    2);
  SweepOptions opt = scene.sweep;  // the same outputs, so the same predictor and path as the run
  opt.points.clear(), opt.residuals = opt.condition = false;
  opt.threads = 0;
  // a redundant model is solved as `phiq run` solves it: assembled by minimum norm, swept on its independent rows
  SquareScene square;
  if (prepare_scene(model, scene.sweep.t_begin, scene.sweep.assembly, &square) != SolveStatus::kSuccess)
    throw DrawError(scene.path + ": " + square.assembly.message, 1);
  const Model& swept = square.model(model);
  Workspace ws(swept);
  ws.q = square.start;
  // the result's column of each coordinate (or none), looked up once rather than per row
  std::vector<std::pair<Index, std::size_t>> checked;  // (coordinate, column)
  for (Index j = 0; j < model.num_coordinates(); ++j)
    if (auto c = col.find(model.coordinate_names()[j]); c != col.end()) checked.emplace_back(j, c->second);
  std::map<std::size_t, Eigen::VectorXd> solved;
  SweepSummary sum;
  std::string mismatch;
  (void)run_sweep(  // its status is sum.status, read below
      swept, opt, ws,
      [&](const StepView& v) {
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
      },
      &sum);
  if (!mismatch.empty()) throw DrawError(result + " is not the result of " + scene.path + ": " + mismatch, 2);
  if (sum.status != SolveStatus::kSuccess) throw DrawError(scene.path + ": " + sum.message, 1);
  return solved;
}

// The SVG: the mechanism on the left (equal scales), one panel per quantity on the right.
std::string svg_document(const Scene& scene, const CsvTable& table, const std::map<std::string, std::size_t>& col,
                         const std::vector<std::string>& series, const MechanismFrames& frames,
                         const std::string& title) {
  constexpr double W = 1100, M = 60, side = 420;
  const std::size_t panels = panel_count(scene, series);
  const double H = std::max(side + 2 * M, M + static_cast<double>(panels) * 200.0 + 10);
  std::string svg_text =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
      "width=\"" +
      px(W) + "\" height=\"" + px(H) + "\" viewBox=\"0 0 " + px(W) + " " + px(H) +
      "\" font-family=\"sans-serif\" font-size=\"12\">\n<title>" + escape(title) +
      "</title>\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg_text += mechanism_panel(frames, M, M, side);
  const double x0 = M + side + 90;
  svg_text += series_panels(scene, table, col, series, x0, M, W - x0 - 20, H - M - 50);
  return svg_text + "</svg>\n";
}

// The SVG of `table`, the scene's result drawn with `sketch`. Throws DrawError and phiq::Error (status 2) with one
// line.
std::string plot_text(const Scene& scene, const PlotOptions& o, const MechanismSketch& sketch, const CsvTable& table) {
  const Model& model = *scene.model;
  const std::string result = o.csv.empty() ? kSweptTitle : o.csv;
  if (table.rows.empty()) throw DrawError(result + ": no rows", 2);
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
  // Columns against time: as asked, else the driven and the moving coordinates (at most 6), never a constant.
  const std::vector<std::string> series = plotted_columns(scene, table, o.columns, result);
  // The mechanism: every coordinate its lines read must be in the result, else it is swept again.
  std::vector<Part> parts = drawn_parts(scene);  // (once: a 10⁴-loop chain has 3·10⁴)
  const std::vector<Index> needed = coordinates_of(drawing_reads(sketch, parts));
  bool all_in_csv = true;
  for (Index j : needed) all_in_csv = all_in_csv && col.count(model.coordinate_names()[j]);
  for (Index j : needed)  // a coordinate of the drawing that is not a number: as for a plotted column
    if (const auto c = col.find(model.coordinate_names()[j]); c != col.end())
      for (std::size_t r = 0; r < table.rows.size(); ++r)
        if (!std::isfinite(table.rows[r][c->second]))
          throw DrawError(result + ": column '" + c->first + "', data row " + std::to_string(r + 1) + ": " +
                              label(table.rows[r][c->second]) + " cannot be drawn",
                          2);
  const std::vector<std::size_t> drawn = drawn_rows(model, sketch, table, col, needed, all_in_csv, o.positions);
  std::map<std::size_t, Eigen::VectorXd> solved;
  if (!all_in_csv) solved = swept_positions(scene, table, col, drawn, result);
  MechanismFrames frames;
  frames.model = &model, frames.sketch = &sketch, frames.spatial = scene.dimension == 3;
  for (std::size_t r : drawn) {
    Eigen::VectorXd q = model.initial_positions();
    if (all_in_csv)
      for (Index j : needed) q(j) = table.rows[r][col.at(model.coordinate_names()[j])];
    frames.q.push_back(all_in_csv ? q : solved.at(r));
    frames.t.push_back(table.rows[r][0]);
  }
  frames.parts = std::move(parts);
  std::vector<PartBox> boxes;
  for (const Part& part : frames.parts) boxes.push_back(part_box(part));
  for (std::size_t f = 0; f < frames.q.size(); ++f)
    for (const auto& x : parts_extent(frames.parts, boxes, frames.q[f], frames.t[f])) frames.part_bounds.push_back(x);
  for (const OutputPoint& p : scene.sweep.points) {
    const std::size_t cx = col.at(p.name + ".x"), cy = col.at(p.name + ".y");
    const auto cz = p.dimension() == 3 ? col.find(p.name + ".z") : col.end();
    std::vector<std::array<double, 3>> path;
    for (const auto& row : table.rows) path.push_back({row[cx], row[cy], cz == col.end() ? 0.0 : row[cz->second]});
    frames.traces.emplace_back(p.name, std::move(path));
  }
  // An empty panel without a word reads as a broken drawing: say why.
  if (sketch.segments.empty() && sketch.joints.empty() && frames.traces.empty() && frames.parts.empty())
    std::cerr << "phiq: plot: " << o.scene << ": nothing of the mechanism to draw (its constraints make no lines: "
              << "loops, drivers and equations draw none; output.points lists no point to trace): the SVG has "
              << "the columns against t only\n";
  return svg_document(scene, table, col, series, frames, (scene.name.empty() ? o.scene : scene.name) + ": " + result);
}

}  // namespace

int plot_svg(const PlotOptions& o) {
  Scene scene;
  try {
    scene = load_scene(o.scene, SceneLimits{}, parameter_settings(o.sets));
  } catch (const SceneError& e) {
    return plot_fail(e.what(), 2);
  } catch (const Error& e) {  // a --set that is not NAME=VALUE
    return plot_fail(e.what(), 2);
  }
  const MechanismSketch sketch = sketch_mechanism(*scene.model);
  CsvTable table;
  try {
    if (!o.csv.empty()) table = read_scene_result(scene, o.csv);
  } catch (const DrawError& e) {
    return plot_fail(e.what(), e.status());
  }
  // the SVG exists (as a temporary) before the drawing, which may sweep the scene
  set_interrupt_subject("plot: " + o.out, "; no output written");
  OutputSet outputs;
  AtomicOutputFile* out = nullptr;
  try {
    out = &outputs.add(o.out);
  } catch (const Error& e) {
    return plot_fail(e.what(), 3);
  }
  std::string text;
  try {
    // without a result: the scene swept here with every coordinate the drawing reads and the measures of its
    // spatial joints (which the default columns prefer)
    if (o.csv.empty()) table = sweep_scene(scene, {coordinates_of(drawing_reads(sketch, drawn_parts(scene))), true});
    text = plot_text(scene, o, sketch, table);
  } catch (const DrawError& e) {
    return plot_fail(e.what(), e.status());
  } catch (const Error& e) {
    return plot_fail(e.what(), 2);
  }
  try {
    out->write(text);
    outputs.commit();
  } catch (const Error& e) {
    return plot_fail(e.what(), 3);
  }
  return 0;
}

}  // namespace phiq::tools
