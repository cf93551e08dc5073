// `phiq plot`'s columns against time: each column's physical quantity and unit (from the model's coordinate units
// and the output plan), the default columns (the driven and the moving coordinates, never constants), and the
// panels, one per quantity (lengths, angles, velocities, ...), each with its axes, ticks and unit.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/scene.hpp"

namespace phiq::tools {

// What a column measures: "length" in "m", "angular velocity" in "rad/s", "unitless" in "1", ... ; a column phiq
// cannot tell (a driver's law, a residual, rcond) has its own quantity and an empty unit.
struct Quantity {
  std::string name;
  std::string unit;
  std::string label() const { return unit.empty() ? name : name + " (" + unit + ")"; }
  bool operator<(const Quantity& o) const { return name != o.name ? name < o.name : unit < o.unit; }
};

// The quantity of `column` of `scene`'s results (dotted names, CsvFormat's default).
Quantity column_quantity(const Scene& scene, const std::string& column);

// The joint whose measure `column` is (`J.angle` of a spatial revolute or cylindrical joint, `J.distance` of a
// prismatic or cylindrical one), with its unit in `*unit`; empty for any other column.
std::string joint_of_column(const Scene& scene, const std::string& column, Unit* unit = nullptr);

// The columns drawn when none is asked for, those whose value changes over the rows, in this order: the
// coordinates a coordinate driver drives and the measures of joints a joint driver drives; the other joints'
// measures (output.joints) and the drivers' efforts and powers (output.efforts; not one with a NaN: a singular
// row); the other coordinates; Euler parameters last; each group in column order, at most
// `most`, never a constant. Without any: the first columns after t that change, else the first columns after t.
std::vector<std::string> default_columns(const Scene& scene, const CsvTable& table, std::size_t most);

// The columns to plot: `asked` (--columns), else default_columns(…, 6). Throws phiq::Error with one line for a
// column the table lacks (or t), or a value of one that is not finite (`result` names the table in messages).
std::vector<std::string> plotted_columns(const Scene& scene, const CsvTable& table,
                                         const std::vector<std::string>& asked, const std::string& result);

// The panels of `series` against t, stacked in the box (x0, y0, w, h), one per quantity in order of first use.
// Every value of the columns is finite (plot_svg() checks).
std::string series_panels(const Scene& scene, const CsvTable& table, const std::map<std::string, std::size_t>& col,
                          const std::vector<std::string>& series, double x0, double y0, double w, double h);

// How many panels series_panels() draws for `series`.
std::size_t panel_count(const Scene& scene, const std::vector<std::string>& series);

}  // namespace phiq::tools
