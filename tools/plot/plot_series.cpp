#include "plot_series.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

#include "phiq/phiq.hpp"
#include "plot_draw.hpp"

namespace phiq::tools {

namespace {

// (a column named `tail` itself does not count: a name comes before it)
bool column_ends_with(const std::string& s, const std::string& tail) {
  return s.size() > tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// order 0: the value, 1: its rate, 2: its second rate.
Quantity of_unit(Unit u, int order) {
  static const char* const names[3][3] = {{"unitless", "unitless rate", "unitless second rate"},
                                          {"length", "velocity", "acceleration"},
                                          {"angle", "angular velocity", "angular acceleration"}};
  static const char* const base[3] = {"1", "m", "rad"};
  const int k = u == Unit::kLength ? 1 : (u == Unit::kAngle ? 2 : 0);
  std::string unit = base[k];
  if (order == 1) unit = k == 0 ? "1/s" : unit + "/s";
  if (order == 2) unit = k == 0 ? "1/s²" : unit + "/s²";
  return {names[k][order], unit};
}

}  // namespace

std::string joint_of_column(const Scene& scene, const std::string& column, Unit* unit) {
  if (scene.dimension != 3) return "";
  for (const auto& [tail, u] : {std::pair<const char*, Unit>{".angle", Unit::kAngle}, {".distance", Unit::kLength}}) {
    if (!column_ends_with(column, tail)) continue;
    const std::string name = column.substr(0, column.size() - std::string(tail).size());
    for (const ConstraintInfo& c : scene.model->constraints())
      if (c.name == name && (c.kind == "revolute" || c.kind == "cylindrical" || c.kind == "prismatic")) {
        if (unit) *unit = u;
        return name;
      }
  }
  return "";
}

Quantity column_quantity(const Scene& scene, const std::string& column) {
  const Model& model = *scene.model;
  if (column == "t") return {"time", "s"};
  // the unit of coordinate `name`, if it is one (the model's index of names: O(1) on large models)
  auto coordinate = [&](const std::string& name) -> std::optional<Unit> {
    try {
      return model.coordinate_unit(model.coordinate_index(name));
    } catch (const Error&) {
      return std::nullopt;
    }
  };
  if (const auto u = coordinate(column)) return of_unit(*u, 0);
  for (int order : {1, 2}) {
    const std::string tail = order == 1 ? ".v" : ".a";
    if (column_ends_with(column, tail))
      if (const auto u = coordinate(column.substr(0, column.size() - 2))) return of_unit(*u, order);
  }
  for (const OutputPoint& p : scene.sweep.points)
    for (const char* axis : {"x", "y", "z"})
      for (int order : {0, 1, 2}) {
        const std::string tail = std::string(".") + (order == 1 ? "v" : (order == 2 ? "a" : "")) + axis;
        if (column == p.name + tail) return of_unit(Unit::kLength, order);
      }
  for (int order : {0, 1, 2}) {  // a joint's measure `J.angle`, `J.distance`, and their rates `.v`, `.a`
    if (order > 0 && !column_ends_with(column, order == 1 ? ".v" : ".a")) continue;
    Unit u = Unit::kLength;
    if (!joint_of_column(scene, order == 0 ? column : column.substr(0, column.size() - 2), &u).empty())
      return of_unit(u, order);
  }
  // a driver's effort: a torque where its first row is an angle, a force where a length (a panel per unit)
  for (const char* tail : {".effort", ".power"})
    if (column_ends_with(column, tail)) {
      const std::string name = column.substr(0, column.size() - std::string(tail).size());
      for (Index c : scene.sweep.efforts.constraints) {
        const ConstraintInfo& ci = model.constraints()[static_cast<std::size_t>(c)];
        if (ci.name != name) continue;
        if (std::string(tail) == ".power") return {"power", "W"};
        const Unit u = model.row_unit(ci.first_row);
        return u == Unit::kAngle    ? Quantity{"torque", "N·m"}
               : u == Unit::kLength ? Quantity{"force", "N"}
                                    : Quantity{"effort", ""};
      }
    }
  for (const OutputReaction& r : scene.sweep.efforts.reactions) {  // a joint's reaction: forces and moments
    const std::string name = scene.sweep.efforts.reaction_name(model, r);
    if (column.size() == name.size() + 3 && column.compare(0, name.size(), name) == 0 && column[name.size()] == '.')
      return column[name.size() + 1] == 'F' ? Quantity{"force", "N"} : Quantity{"torque", "N·m"};
  }
  for (const OutputLoss& l : scene.sweep.efforts.losses) {  // a bearing's friction, a loss's power
    if (column == l.name + ".loss") return {"power", "W"};
    if (column == l.name + ".friction") return l.slide ? Quantity{"force", "N"} : Quantity{"torque", "N·m"};
  }
  if (column_ends_with(column, ".residual")) return {"residual", ""};
  if (column_ends_with(column, ".ddf")) return {"driver law, second rate", ""};
  if (column_ends_with(column, ".df")) return {"driver law, rate", ""};
  if (column_ends_with(column, ".f")) return {"driver law", ""};
  return {column, ""};
}

std::vector<std::string> default_columns(const Scene& scene, const CsvTable& table, std::size_t most) {
  const Model& model = *scene.model;
  auto changes = [&](std::size_t c) {
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& row : table.rows)
      if (std::isfinite(row[c])) lo = std::min(lo, row[c]), hi = std::max(hi, row[c]);
    return hi - lo > 1e-9 * (1.0 + std::max(std::fabs(lo), std::fabs(hi)));
  };
  std::set<Index> driven, euler;
  for (const auto& block : model.blocks())
    if (auto* t = dynamic_cast<const TypedBlock<CoordinateDriverSpec>*>(block.get()))
      for (std::size_t i = 0; i < t->size(); ++i) driven.insert(t->spec(i).coordinate.coord());
  for (const Frame3& f : scene.spatial_bodies)
    for (const Slot& e : {f.e0, f.e1, f.e2, f.e3})
      if (e.is_coordinate()) euler.insert(e.coord());
  std::set<std::string> driven_joints;
  for (const JointAngleReference& j : scene.joint_angles) driven_joints.insert(j.joint);
  std::set<std::string> written;  // the coordinate columns
  for (Index k : scene.sweep.coordinate_columns) written.insert(model.coordinate_names()[static_cast<std::size_t>(k)]);
  // in order of preference: driven coordinates and joints, the joints' measures and the drivers' efforts, the other
  // coordinates that move,
  // their Euler parameters last (four numbers of one turn, which say less than any of the others)
  std::vector<std::size_t> ranked[4];
  for (std::size_t c = 1; c < table.columns.size(); ++c) {
    const std::string& name = table.columns[c];
    if (!changes(c)) continue;
    if (column_ends_with(name, ".effort") || column_ends_with(name, ".power")) {
      // the drivers' efforts after what they drive; not one with a singular row's NaN, which --columns may ask for
      const bool finite = std::all_of(table.rows.begin(), table.rows.end(),
                                      [&](const std::vector<double>& row) { return std::isfinite(row[c]); });
      if (finite && column_quantity(scene, name).unit != "") ranked[1].push_back(c);
      continue;
    }
    if (const std::string joint = joint_of_column(scene, name); !joint.empty()) {
      ranked[driven_joints.count(joint) ? 0 : 1].push_back(c);
    } else if (written.count(name)) {
      const Index j = model.coordinate_index(name);
      ranked[driven.count(j) ? 0 : euler.count(j) ? 3 : 2].push_back(c);
    }
  }
  std::vector<std::string> out;
  for (const auto& rank : ranked)
    for (std::size_t c : rank) out.push_back(table.columns[c]);
  if (out.empty())
    for (std::size_t c = 1; c < table.columns.size(); ++c)
      if (changes(c)) out.push_back(table.columns[c]);
  if (out.empty())
    for (std::size_t c = 1; c < table.columns.size(); ++c) out.push_back(table.columns[c]);
  if (out.size() > most) out.resize(most);
  return out;
}

std::vector<std::string> plotted_columns(const Scene& scene, const CsvTable& table,
                                         const std::vector<std::string>& asked, const std::string& result) {
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
  const std::vector<std::string> series = asked.empty() ? default_columns(scene, table, 6) : asked;
  for (const std::string& c : series)
    if (!col.count(c) || c == "t") throw Error("--columns: no column '" + c + "' in " + result);
  // a value that is not a number has no place on an axis: say where it is rather than draw a gap
  for (const std::string& c : series) {
    const std::size_t k = col[c];
    for (std::size_t r = 0; r < table.rows.size(); ++r)
      if (!std::isfinite(table.rows[r][k]))
        throw Error(result + ": column '" + c + "', data row " + std::to_string(r + 1) + ": " +
                    svg::label(table.rows[r][k]) + " cannot be plotted");
  }
  return series;
}

namespace {

// The quantities of `series`, in order of first use, with their columns.
std::vector<std::pair<Quantity, std::vector<std::size_t>>> group(const Scene& scene,
                                                                 const std::vector<std::string>& series) {
  std::vector<std::pair<Quantity, std::vector<std::size_t>>> groups;
  for (std::size_t k = 0; k < series.size(); ++k) {
    const Quantity q = column_quantity(scene, series[k]);
    auto g = std::find_if(groups.begin(), groups.end(),
                          [&](const auto& e) { return e.first.name == q.name && e.first.unit == q.unit; });
    if (g == groups.end())
      groups.push_back({q, {k}});
    else
      g->second.push_back(k);
  }
  return groups;
}

// The ends of the scene's limits (Scene's sweep.limits) on `column`: a bare coordinate's value or rate (`x`,
// `x.v`), a joint's (`J.angle`, `J.angle.v`), an output point's (`P.x`, `P.vx`), a driver's effort
// (`NAME.effort`); each as (limit, end).
std::vector<std::pair<std::string, double>> column_limits(const Scene& scene, const std::string& column) {
  std::vector<std::pair<std::string, double>> out;
  for (const OutputLimit& l : scene.sweep.limits) {
    std::string measured;
    if (l.of) {
      measured = l.of->text();
    } else if (l.joint) {
      measured = l.joint->name + (l.joint->measure == JointMeasure::kAngle ? ".angle" : ".distance");
    } else if (l.point) {  // (`P.x`, its rate `P.vx`)
      const std::string axis(1, "xyz"[l.axis]);
      if ((l.rate ? l.point->name + ".v" + axis : l.point->name + "." + axis) == column)
        out.push_back({l.name, l.lo}), out.push_back({l.name, l.hi});
      continue;
    } else {
      const Index c = scene.sweep.efforts.constraints[static_cast<std::size_t>(l.effort)];
      measured = scene.model->constraints()[static_cast<std::size_t>(c)].name + ".effort";
    }
    if ((l.rate ? measured + ".v" : measured) == column) out.push_back({l.name, l.lo}), out.push_back({l.name, l.hi});
  }
  return out;
}

}  // namespace

std::size_t panel_count(const Scene& scene, const std::vector<std::string>& series) {
  return group(scene, series).size();
}

std::string series_panels(const Scene& scene, const CsvTable& table, const std::map<std::string, std::size_t>& col,
                          const std::vector<std::string>& series, double x0, double y0, double w, double h) {
  using namespace svg;
  const auto groups = group(scene, series);
  if (groups.empty()) return "<g id=\"series\"/>\n";  // a result of t alone
  double tmin = table.rows.front()[0], tmax = table.rows.back()[0];
  if (tmin > tmax) std::swap(tmin, tmax);
  if (!(tmax > tmin)) tmin -= 0.5, tmax += 0.5;
  const double gap = 50, ph = (h - gap * static_cast<double>(groups.size() - 1)) / static_cast<double>(groups.size());
  std::string s = "<g id=\"series\">\n";
  for (std::size_t p = 0; p < groups.size(); ++p) {
    const auto& [quantity, members] = groups[p];
    double vmin = INFINITY, vmax = -INFINITY;
    for (std::size_t k : members) {
      const std::size_t c = col.at(series[k]);
      for (const auto& row : table.rows) vmin = std::min(vmin, row[c]), vmax = std::max(vmax, row[c]);
      for (const auto& [name, end] : column_limits(scene, series[k]))
        vmin = std::min(vmin, end), vmax = std::max(vmax, end);
    }
    widen(vmin, vmax);
    const Box b{x0, y0 + static_cast<double>(p) * (ph + gap), w, ph, tmin, tmax, vmin, vmax};
    s += "<g class=\"panel\" data-quantity=\"" + escape(quantity.name) + "\" data-unit=\"" + escape(quantity.unit) +
         "\">\n";
    s += axes(b, "t (s)", quantity.label(), 8, 4);
    for (std::size_t i = 0; i < members.size(); ++i) {
      const std::size_t k = members[i], c = col.at(series[k]);
      Line pts;
      for (const auto& row : table.rows) pts.push_back({b.sx(row[0]), b.sy(row[c])});
      s += polyline("series", kPalette[k % 8], 1.5, pts, " data-column=\"" + escape(series[k]) + "\"");
      for (const auto& [name, end] : column_limits(scene, series[k]))  // a limit's ends, dashed, in its colour
        s += polyline("limit", kPalette[k % 8], 1.0, {{b.x0, b.sy(end)}, {b.x0 + b.w, b.sy(end)}},
                      " stroke-dasharray=\"6 4\" data-limit=\"" + escape(name) + "\" data-column=\"" +
                          escape(series[k]) + "\" data-value=\"" + label(end) + "\"");
      s += "<text class=\"legend\" x=\"" + px(b.x0 + b.w - 6) + "\" y=\"" +
           px(b.y0 + 14 + 13 * static_cast<double>(i)) + "\" text-anchor=\"end\" fill=\"" + kPalette[k % 8] + "\">" +
           escape(series[k]) + "</text>\n";
    }
    s += "</g>\n";
  }
  return s + "</g>\n";
}

}  // namespace phiq::tools
