// `phiq plot SCENE [RESULT] -o OUT.svg`: what a user looks at first. The mechanism drawn at a few rows of the
// result with the traced output points (a coupler curve; plot_mechanism.*), beside chosen columns against time, one
// panel per quantity (plot_series.*), as one SVG written by hand (no plotting dependency; plot_draw.*).
#pragma once

#include <string>
#include <vector>

namespace phiq::tools {

struct PlotOptions {
  std::string scene;                 // the scene the result was computed from
  std::string csv;                   // `phiq run` output for that scene (CSV or HDF5); empty: swept here
  std::string out;                   // the SVG to write
  std::vector<std::string> columns;  // plotted against t; empty: default_columns() (plot_series.hpp), at most 6
  int positions = 5;                 // rows at which the mechanism is drawn, evenly spread, first and last included
  std::vector<std::string> sets;     // --set NAME=VALUE: the scene's parameters as the run had them
};

// Writes the SVG (under a temporary name, renamed when complete). Returns the exit status of `phiq plot`: 0, 1 when
// the scene cannot be swept, 2 for bad input (scene, a result that is not its own, unknown column, a value to plot
// or draw that is not a number), 3 when the file cannot be written; errors are one line on stderr.
int plot_svg(const PlotOptions& options);

}  // namespace phiq::tools
