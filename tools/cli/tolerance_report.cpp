// What `phiq tolerance` writes: CSV, JSON summary, SVG (tolerance_report.hpp).
#include "tolerance_report.hpp"

#include <algorithm>
#include <cmath>

#include "plot_draw.hpp"
#include "plot_series.hpp"  // column_quantity: the output's quantity and unit
#include "run_summary.hpp"  // host_json
#include "phiq/phiq.hpp"

namespace phiq::tools {

std::string case_label(const FailedCase& c, const tolerance::ParameterSpread& spread) {
  std::string s = "case " + std::to_string(c.index) + " (";
  for (std::size_t j = 0; j < c.values.size(); ++j)
    s += (j ? ", " : "") + spread.parameters[j].name + " = " + shortest(c.values[j]);
  return s + ")";
}

std::string tolerance_csv(const std::vector<double>& t, const std::vector<tolerance::OutputSpread>& outputs,
                          bool identifiers) {
  auto name = [&](const std::string& dotted) { return identifiers ? identifier_column_name(dotted) : dotted; };
  // (appended field by field: GCC 12 warns, wrongly, about "," + std::string under -O2)
  std::string s = "t";
  auto field = [&s](const std::string& f) {
    s += ',';
    s += f;
  };
  for (const auto& o : outputs)
    for (const char* suffix : {"", ".sd_linear", ".sd_mc", ".mean_mc"}) field(name(o.name + suffix));
  s += '\n';
  for (std::size_t r = 0; r < t.size(); ++r) {
    s += shortest(t[r]);
    for (const auto& o : outputs) {
      field(shortest(o.nominal[r]));
      field(shortest(o.sd_linear[r]));
      field(shortest(o.sd_mc[r]));
      field(shortest(o.mean_mc[r]));
    }
    s += '\n';
  }
  return s;
}

namespace {

// A number, or null where it is not finite (JSON has no NaN).
nlohmann::ordered_json number_or_null(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

}  // namespace

nlohmann::ordered_json tolerance_summary(const ToleranceRun& run, const std::vector<tolerance::OutputSpread>& outputs) {
  using json = nlohmann::ordered_json;
  json j;
  j["format"] = kToleranceSummaryFormat;
  j["phiq"] = version();
  j["scene"] = run.scene_path;
  j["name"] = run.scene_name.empty() ? json(nullptr) : json(run.scene_name);
  j["host"] = host_json();
  const tolerance::ParameterSpread& spread = *run.spread;
  json params = json::array();
  for (std::size_t k = 0; k < spread.parameters.size(); ++k) {
    const tolerance::Tolerance& p = spread.parameters[k];
    const auto i = static_cast<Eigen::Index>(k);
    json e{{"name", p.name}, {"nominal", run.nominal[k]}};
    e["distribution"] = p.distribution == tolerance::Distribution::kUniform ? "uniform" : "normal";
    e["source"] = p.from_covariance                                     ? "covariance"
                  : p.distribution == tolerance::Distribution::kUniform ? "limit"
                                                                        : "sd";
    if (p.distribution == tolerance::Distribution::kUniform) e["limit"] = p.spread;
    e["sd"] = std::sqrt(spread.sigma(i, i));
    e["independent"] = std::find(run.independent.begin(), run.independent.end(), p.name) != run.independent.end();
    params.push_back(e);
  }
  j["parameters"] = params;
  json sigma = json::array();
  for (Eigen::Index r = 0; r < spread.sigma.rows(); ++r) {
    json row = json::array();
    for (Eigen::Index c = 0; c < spread.sigma.cols(); ++c) row.push_back(spread.sigma(r, c));
    sigma.push_back(row);
  }
  j["covariance"] = sigma;
  j["covariance_file"] = run.covariance_file.empty() ? json(nullptr) : json(run.covariance_file);
  j["samples"] = run.samples;
  j["seed"] = run.seed;
  j["succeeded"] = run.samples - static_cast<long>(run.failed.size());
  json failed = json::array();
  for (const FailedCase& c : run.failed) {
    json values = json::object();
    for (std::size_t k = 0; k < c.values.size(); ++k) values[spread.parameters[k].name] = c.values[k];
    failed.push_back(json{{"case", c.index}, {"parameters", values}, {"message", c.message}});
  }
  j["failed"] = failed;
  j["threshold"] = run.threshold;
  j["noise_floor"] = run.floor;
  j["sensitivity_form"] = run.sensitivity_form;
  json outs = json::array();
  std::size_t disagreeing = 0;
  for (const tolerance::OutputSpread& o : outputs) {
    const tolerance::Agreement& a = o.agreement;
    disagreeing += a.disagrees;
    outs.push_back(json{{"name", o.name},
                        {"worst_standard_errors", number_or_null(a.worst)},
                        {"worst_t", number_or_null(a.worst_t)},
                        {"sd_linear_at_worst", number_or_null(a.sd_linear_at_worst)},
                        {"sd_mc_at_worst", number_or_null(a.sd_mc_at_worst)},
                        {"disagrees", a.disagrees},
                        {"rows_compared", a.rows_compared},
                        {"rows_without_spread", a.rows_without_spread},
                        {"rows_singular", a.rows_singular}});
  }
  j["disagreeing"] = disagreeing;
  j["outputs"] = outs;
  j["threads"] = run.threads;
  j["seconds"] = run.solve_seconds;
  return j;
}

std::string tolerance_svg(const Scene& scene, const std::vector<double>& t, const tolerance::OutputSpread& s,
                          std::size_t samples) {
  using namespace svg;
  constexpr double W = 900, H = 480, M = 70;
  const std::size_t n = t.size();
  // the curves, each point where its value is finite (a singular row has no σ_lin)
  auto curve = [&](auto value) {
    std::vector<std::pair<double, double>> c;
    for (std::size_t r = 0; r < n; ++r)
      if (const double v = value(r); std::isfinite(v)) c.push_back({t[r], v});
    return c;
  };
  const auto nominal = curve([&](std::size_t r) { return s.nominal[r]; });
  const auto lin_hi = curve([&](std::size_t r) { return s.nominal[r] + 2 * s.sd_linear[r]; });
  const auto lin_lo = curve([&](std::size_t r) { return s.nominal[r] - 2 * s.sd_linear[r]; });
  const auto mc_hi = curve([&](std::size_t r) { return s.mean_mc[r] + 2 * s.sd_mc[r]; });
  const auto mc_lo = curve([&](std::size_t r) { return s.mean_mc[r] - 2 * s.sd_mc[r]; });
  double tmin = t.empty() ? 0.0 : t.front(), tmax = t.empty() ? 1.0 : t.back();
  if (tmin > tmax) std::swap(tmin, tmax);
  if (!(tmax > tmin)) tmin -= 0.5, tmax += 0.5;
  double vmin = INFINITY, vmax = -INFINITY;
  for (const auto* c : {&nominal, &lin_hi, &lin_lo, &mc_hi, &mc_lo})
    for (const auto& [x, y] : *c) vmin = std::min(vmin, y), vmax = std::max(vmax, y);
  if (!(vmin <= vmax)) vmin = 0.0, vmax = 1.0;
  widen(vmin, vmax);
  const Box b{M + 20, M - 20, W - 2 * M - 20, H - 2 * M, tmin, tmax, vmin, vmax};
  auto to_px = [&](const std::vector<std::pair<double, double>>& c) {
    Line l;
    for (const auto& [x, y] : c) l.push_back({b.sx(x), b.sy(y)});
    return l;
  };
  std::string svg_text =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
      "width=\"" +
      px(W) + "\" height=\"" + px(H) + "\" viewBox=\"0 0 " + px(W) + " " + px(H) +
      "\" font-family=\"sans-serif\" font-size=\"12\">\n<title>" +
      escape((scene.name.empty() ? scene.path : scene.name) + ": " + s.name) +
      " with its 2-sigma bands</title>\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg_text += axes(b, "t (s)", column_quantity(scene, s.name).label(), 8, 5);
  // the linear band, filled: upper edge forwards, lower edge backwards
  Line band = to_px(lin_hi);
  const Line lower = to_px(lin_lo);
  band.insert(band.end(), lower.rbegin(), lower.rend());
  std::string points;
  for (const auto& [x, y] : band) points += px(x) + "," + px(y) + " ";
  if (!band.empty())
    svg_text += "<polygon class=\"band-linear\" fill=\"" + std::string(kPalette[0]) +
                "\" fill-opacity=\"0.25\" stroke=\"none\" points=\"" + points + "\"/>\n";
  const std::string dash = " stroke-dasharray=\"6,3\"";
  svg_text += polyline("band-mc", kPalette[1], 1.2, to_px(mc_hi), dash);
  svg_text += polyline("band-mc", kPalette[1], 1.2, to_px(mc_lo), dash);
  svg_text += polyline("nominal", "#000000", 1.5, to_px(nominal), " data-column=\"" + escape(s.name) + "\"");
  const double lx = b.x0 + b.w - 6, ly = b.y0 + 14;
  svg_text += "<text class=\"legend\" x=\"" + px(lx) + "\" y=\"" + px(ly) + "\" text-anchor=\"end\">" + escape(s.name) +
              " (nominal)</text>\n";
  svg_text += "<text class=\"legend\" x=\"" + px(lx) + "\" y=\"" + px(ly + 14) + "\" text-anchor=\"end\" fill=\"" +
              kPalette[0] + "\">nominal ± 2 sd_linear (first order)</text>\n";
  svg_text += "<text class=\"legend\" x=\"" + px(lx) + "\" y=\"" + px(ly + 28) + "\" text-anchor=\"end\" fill=\"" +
              kPalette[1] + "\">mean ± 2 sd_mc (Monte Carlo, " + std::to_string(samples) + " cases)</text>\n";
  return svg_text + "</svg>\n";
}

}  // namespace phiq::tools
