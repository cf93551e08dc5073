#include "motion_columns.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "phiq/phiq.hpp"

namespace phiq::tools {

MotionColumns::MotionColumns(const Scene& scene, const std::vector<Slot>& read, const CsvTable& table,
                             std::string result)
    : table_(table), result_(std::move(result)) {
  const Model& model = *scene.model;
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
  if (!col.count("t")) throw Error(result_ + ": no column 't': not a result of `phiq run`");
  t_ = col["t"];
  std::vector<Index> coords;
  for (const Slot& s : read)
    if (s.is_coordinate()) coords.push_back(s.coord());
  std::sort(coords.begin(), coords.end());
  coords.erase(std::unique(coords.begin(), coords.end()), coords.end());
  bool all_rates = true;
  for (Index j : coords) {
    const std::string& name = model.coordinate_names()[static_cast<std::size_t>(j)];
    const auto c = col.find(name);
    if (c == col.end())
      throw MissingCoordinate(result_ + " lacks coordinate '" + name + "': add it to output.coordinates in " +
                              scene.path);
    q_.emplace_back(j, c->second);
    const auto v = col.find(name + ".v");
    if (v == col.end())
      all_rates = false;
    else
      qd_.emplace_back(j, v->second);
  }
  if (!all_rates) qd_.clear();
  if (table.rows.empty()) throw Error(result_ + ": no rows");
}

std::string MotionColumns::at_row(std::size_t row) const { return result_ + ": data row " + std::to_string(row + 1); }

void MotionColumns::fill(const std::vector<std::pair<Index, std::size_t>>& cols, std::size_t row,
                         Eigen::VectorXd& v) const {
  const std::vector<double>& values = table_.rows[row];
  for (const auto& [j, c] : cols) {
    if (!std::isfinite(values[c]))
      throw Error(at_row(row) + ", column '" + table_.columns[c] + "': not a finite number");
    v(j) = values[c];
  }
}

void MotionColumns::positions(std::size_t row, Eigen::VectorXd& q) const {
  fill(q_, row, q);
  if (!std::isfinite(table_.rows[row][t_])) throw Error(at_row(row) + ", column 't': not a finite number");
}

void MotionColumns::velocities(std::size_t row, Eigen::VectorXd& qd) const { fill(qd_, row, qd); }

}  // namespace phiq::tools
