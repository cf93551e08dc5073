#include "html_page.hpp"

#include <algorithm>
#include <filesystem>
#include <map>

#include "html_clearance.hpp"
#include "force_arrows.hpp"
#include "html_motion.hpp"
#include "phiq/phiq.hpp"
#include "phiq/version.hpp"
#include "plot_draw.hpp"
#include "plot_mechanism.hpp"
#include "plot_series.hpp"
#include "viewer_assets.hpp"

namespace phiq::tools {

namespace {

using svg::escape;
using svg::px;

// The mechanism's square and the plots' width, in CSS pixels (viewer.css sizes the WebGL host alike).
constexpr double kSide = 620, kPlotWidth = 560;
// Rows of each plotted column drawn at most: a line this fine is already smooth on any screen.
constexpr std::size_t kPlotRows = 2000;

// The template with each {{KEY}} replaced by its value, in one pass: a value is never searched for keys.
std::string fill(std::string_view page, const std::map<std::string, std::string>& slots) {
  std::string out;
  std::size_t from = 0;
  for (std::size_t at = page.find("{{"); at != std::string_view::npos; at = page.find("{{", from)) {
    const std::size_t end = page.find("}}", at);
    const auto value =
        end == std::string_view::npos ? slots.end() : slots.find(std::string(page.substr(at + 2, end - at - 2)));
    out.append(page.substr(from, at - from));
    if (value == slots.end()) {
      out.append("{{");
      from = at + 2;
    } else {
      out.append(value->second);
      from = end + 2;
    }
  }
  return out.append(page.substr(from));
}

std::string script(std::string_view code) { return "<script>\n" + std::string(code) + "\n</script>\n"; }

}  // namespace

std::string motion_html(const Scene& scene, const CsvTable& table, const std::string& result,
                        const std::vector<std::string>& columns, const ClearanceReport* clearance,
                        const std::vector<std::string>& row_labels, double forces) {
  const MechanismSketch sketch = sketch_mechanism(*scene.model);
  ViewerMotion motion = viewer_motion(scene, sketch, table, result);
  if (forces > 0.0) motion.data["forces"] = force_arrows(scene, table, motion.rows, motion.frames.q, result, forces);
  const std::vector<std::string> series = plotted_columns(scene, table, columns, result);
  nlohmann::json& data = motion.data;
  const bool spatial = scene.dimension == 3;
  if (clearance) data["clearance"] = viewer_clearance(scene, *clearance);
  const std::string title = scene.name.empty() ? std::filesystem::path(scene.path).stem().string() : scene.name;

  // ---- the mechanism: planar, an SVG whose background is phiq plot's (axes, ground) and whose moving layer
  // planar.js fills; spatial, the host of the WebGL canvas
  const MechanismView view = mechanism_view(motion.frames, 70, 20, kSide - 100);
  std::string view_html;
  if (spatial) {
    data["axis_length"] = view.axis_length;
    view_html = "<div id=\"gl\"></div>";
  } else {
    const svg::Box& b = view.box;
    data["box"] = {{"x0", b.x0},     {"y0", b.y0},     {"w", b.w},       {"h", b.h},
                   {"xmin", b.xmin}, {"xmax", b.xmax}, {"ymin", b.ymin}, {"ymax", b.ymax}};
    // two layers: the still background painted once, the moving one (planar.js) repainted each frame on its own
    const std::string open = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + px(kSide) + "\" height=\"" +
                             px(kSide) + "\" viewBox=\"0 0 " + px(kSide) + " " + px(kSide) +
                             "\" font-family=\"sans-serif\" font-size=\"12\"";
    view_html = "<div id=\"planar\">\n" + open +
                " id=\"background-svg\">\n<rect width=\"100%\" height=\"100%\" "
                "fill=\"white\"/>\n" +
                mechanism_background(motion.frames, view, GroundPivots::kUses) + "</svg>\n" + open +
                " id=\"mechanism-svg\">\n<g id=\"moving\"></g>\n</svg>\n</div>";
  }

  // ---- the plots: phiq plot's panels of the chosen columns, at most kPlotRows rows each
  CsvTable plotted;
  plotted.columns = table.columns;
  {
    const std::size_t n = table.rows.size(), most = std::min(n, kPlotRows);
    for (std::size_t k = 0; k < most; ++k) plotted.rows.push_back(table.rows[most == 1 ? 0 : k * (n - 1) / (most - 1)]);
  }
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
  const std::size_t panels = panel_count(scene, series);
  const double height = std::max(kSide, 40 + 190.0 * static_cast<double>(panels));
  const std::string plots = "<svg id=\"plots-svg\" xmlns=\"http://www.w3.org/2000/svg\" width=\"" + px(kPlotWidth) +
                            "\" height=\"" + px(height) + "\" viewBox=\"0 0 " + px(kPlotWidth) + " " + px(height) +
                            "\" font-family=\"sans-serif\" font-size=\"12\">\n" +
                            series_panels(scene, plotted, col, series, 80, 20, kPlotWidth - 100, height - 70) +
                            "</svg>";
  // the t range of the panels' axes, as series_panels() takes it (t is the first column of a result)
  double tmin = plotted.rows.front()[0], tmax = plotted.rows.back()[0];
  if (!(tmax > tmin)) tmin -= 0.5, tmax += 0.5;
  data["plot_t"] = {tmin, tmax};
  if (!row_labels.empty()) data["row_labels"] = row_labels;
  if (data["velocities"].is_null())
    data["velocity_note"] = "no velocity vectors: " + result +
                            " has no velocity columns (the scene's output: {velocities: true} writes them)";

  const std::size_t rows = table.rows.size(), kept = motion.rows.size();
  const std::string about = escape(scene.path) + ", " + escape(result) + ": " + std::to_string(rows) + " rows, " +
                            (kept == rows ? std::string("every one a frame")
                                          : std::to_string(kept) +
                                                " of them frames (evenly spread; the "
                                                "poses between are interpolated)") +
                            ". Written by phiq " + kVersion + (spatial ? "; three.js r111 (MIT licence)" : "") + ".";
  // the JSON sits in a <script> element: "</" must not end it early (\/ is the same in JSON)
  std::string json;
  for (char c : data.dump()) {
    if (c == '/' && !json.empty() && json.back() == '<') json += '\\';
    json += c;
  }
  std::string scripts;
  if (spatial) scripts += script(assets::kThreeJs) + script(assets::kOrbitJs);
  scripts += script(assets::kViewerJs) + script(spatial ? assets::kSpatialJs : assets::kPlanarJs);
  return fill(assets::kPage, {{"TITLE", escape(title)},
                              {"GENERATOR", std::string("phiq ") + kVersion},
                              {"CSS", std::string(assets::kCss)},
                              {"VIEW", view_html},
                              {"PLOTS", plots},
                              {"ABOUT", about},
                              {"DATA", json},
                              {"SCRIPTS", scripts}});
}

}  // namespace phiq::tools
