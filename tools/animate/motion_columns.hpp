// What `phiq animate` reads of a result, for its .glb (gltf_motion.*) and its HTML viewer (html_motion.*) alike:
// the column t and the column of every coordinate the drawing reads (the sketch's points, the bodies' frames),
// checked once (a result whose output leaves one out: MissingCoordinate, naming the output to add), then q (and
// q̇, from the `NAME.v` columns when the result has them all) at any row, each value checked finite. That the
// result is the scene's at all, plot and animate check before (tools/cli/drawn_result.hpp).
#pragma once

#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

#include "phiq/csv_compare.hpp"
#include "phiq/output_points.hpp"
#include "phiq/scene.hpp"
#include "plot_mechanism.hpp"  // slots_of()

namespace phiq::tools {

// A result of the scene whose output leaves out a coordinate the drawing reads: what() says which and where to add
// it ("r.csv lacks coordinate 'xc': add it to output.coordinates in s.yaml"); the command adds its own remedy.
class MissingCoordinate : public Error {
 public:
  using Error::Error;
};

class MotionColumns {
 public:
  // The columns of the coordinates among `read`. Throws MissingCoordinate for a table without one of those
  // coordinates, phiq::Error with one line (naming `result`) for one without t or without rows.
  MotionColumns(const Scene& scene, const std::vector<Slot>& read, const CsvTable& table, std::string result);

  std::size_t t_column() const { return t_; }
  // Every coordinate read has its `NAME.v` column: velocities can be evaluated.
  bool has_velocities() const { return !qd_.empty() || q_.empty(); }

  // q at `row` (the coordinates read; the others keep their value in `q`), t checked finite too. Throws
  // phiq::Error "RESULT: data row N, column 'c': not a finite number".
  void positions(std::size_t row, Eigen::VectorXd& q) const;
  // q̇ at `row` likewise (has_velocities() must hold; the other entries of `qd` are left alone).
  void velocities(std::size_t row, Eigen::VectorXd& qd) const;
  // "RESULT: data row N" (1-based, as the CSV's data rows are counted), for further messages about a row.
  std::string at_row(std::size_t row) const;

 private:
  void fill(const std::vector<std::pair<Index, std::size_t>>& cols, std::size_t row, Eigen::VectorXd& v) const;
  const CsvTable& table_;
  std::string result_;
  std::size_t t_ = 0;
  std::vector<std::pair<Index, std::size_t>> q_, qd_;  // (coordinate, column)
};

}  // namespace phiq::tools
