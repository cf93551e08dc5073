#include "drawn_result.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <map>
#include <set>

#include "command_support.hpp"  // make_square()
#include "phiq/hdf5_reader.hpp"
#include "phiq/phiq.hpp"

namespace phiq::tools {

namespace {

// The shortest text that reads back to `v`, as --set takes it.
std::string shown(double v) {
  char b[32];
  return std::string(b, std::to_chars(b, b + sizeof b, v).ptr);
}

// An HDF5 result must record the scene's text and the parameter values it was loaded with.
void check_provenance(const Scene& scene, const std::string& path) {
  Hdf5Provenance p;
  try {
    p = read_hdf5_provenance(path);
  } catch (const Error& e) {
    throw DrawError(e.what(), 2);
  }
  if (p.scene_text != scene.text)
    throw DrawError(path + ": not a result of " + scene.path + ": " +
                        (p.scene_path == scene.path ? std::string("it records another text of that scene")
                                                    : "it records the scene " + p.scene_path + ", whose text differs"),
                    2);
  for (const auto& [name, value] : p.parameters)
    for (const auto& [mine, given] : scene.parameters)
      if (name == mine && std::memcmp(&value, &given, sizeof value) != 0)
        throw DrawError(path + ": not a result of " + scene.path + " with " + name + " = " + shown(given) +
                            ": it was run with " + name + " = " + shown(value) + " (give the run's --set " + name +
                            "=" + shown(value) + ")",
                        2);
}

// Whether `column` is a `phiq run --sensitivity` column of `scene` (`x.d_P`, `x.v.d_P`, `x.a.d_P`) beside the
// columns it writes.
bool sensitivity_column(const Scene& scene, const std::set<std::string>& written, const std::string& column) {
  for (const auto& [name, value] : scene.parameters) {
    const std::string tail = ".d_" + name;
    if (column.size() > tail.size() && column.compare(column.size() - tail.size(), tail.size(), tail) == 0 &&
        written.count(column.substr(0, column.size() - tail.size())))
      return true;
  }
  return false;
}

}  // namespace

CsvTable read_scene_result(const Scene& scene, const std::string& path) {
  CsvTable table;
  try {
    const bool hdf5 = is_hdf5_file(path) || has_hdf5_extension(path);
    if (hdf5) check_provenance(scene, path);
    table = hdf5 ? read_hdf5_table(path) : read_csv_table(path);
  } catch (const DrawError&) {
    throw;
  } catch (const Error& e) {
    throw DrawError(e.what(), 2);
  }
  CsvFormat format(*scene.model, scene.sweep);
  const std::vector<std::string> dotted = format.column_names();
  const std::set<std::string> have(table.columns.begin(), table.columns.end());
  try {  // `phiq run --names identifiers`: the same columns under other names, read back dotted
    format.set_naming(ColumnNaming::kIdentifiers);
    const std::vector<std::string> identifiers = format.column_names();
    if (identifiers != dotted && std::set<std::string>(identifiers.begin(), identifiers.end()) == have) {
      std::map<std::string, std::size_t> at;  // a result of 10⁴ coordinates: no search per column
      for (std::size_t k = 0; k < identifiers.size(); ++k) at.emplace(identifiers[k], k);
      for (std::string& c : table.columns) c = dotted[at.at(c)];
      return table;
    }
  } catch (const Error&) {  // names that collide as identifiers: no such result was written
  }
  const std::string refused = path + ": its columns are not the output of " + scene.path + ": ";
  for (const std::string& c : dotted)
    if (!have.count(c)) throw DrawError(refused + "no column '" + c + "'", 2);
  const std::set<std::string> written(dotted.begin(), dotted.end());
  for (const std::string& c : table.columns)
    if (!written.count(c) && !sensitivity_column(scene, written, c))
      throw DrawError(refused + "column '" + c + "' is not one it writes", 2);
  return table;
}

std::vector<Index> coordinates_of(const std::vector<Slot>& slots) {
  std::vector<Index> out;
  for (const Slot& s : slots)
    if (s.is_coordinate()) out.push_back(s.coord());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

template <class Spec>
void measure(const Model& model, const ConstraintBlock& block, bool angle, bool distance,
             std::vector<std::pair<Index, OutputJoint>>& out) {
  const auto* typed = dynamic_cast<const TypedBlock<Spec>*>(&block);
  if (!typed) return;
  for (std::size_t i = 0; i < typed->size(); ++i) {
    const Index c = model.constraint_of_row(typed->first_row(i));
    const std::string& name = model.constraints()[static_cast<std::size_t>(c)].name;
    const Spec& s = typed->spec(i);
    try {  // a side without the frame a measure needs (a natural point) has none
      if (angle) out.emplace_back(c, output_joint(name, JointMeasure::kAngle, s.a, s.b));
      if (distance) out.emplace_back(c, output_joint(name, JointMeasure::kDistance, s.a, s.b));
    } catch (const Error&) {
    }
  }
}

}  // namespace

std::vector<OutputJoint> measured_joints(const Scene& scene) {
  std::vector<std::pair<Index, OutputJoint>> found;  // (constraint, measure)
  if (scene.dimension != 3) return {};
  const Model& model = *scene.model;
  for (const auto& block : model.blocks()) {
    measure<SpatialRevoluteSpec>(model, *block, true, false, found);
    measure<CylindricalSpec>(model, *block, true, true, found);
    measure<SpatialPrismaticSpec>(model, *block, false, true, found);
  }
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<OutputJoint> out;
  for (auto& f : found) out.push_back(std::move(f.second));
  return out;
}

namespace {

// `plan` with `add`'s outputs: coordinates appended to the q (and restricted q̇) columns, joint measures the scene
// does not list.
void add_outputs(const Scene& scene, const DrawnOutputs& add, OutputPlan& plan) {
  auto extend = [&](std::vector<Index>& columns) {
    const std::set<Index> listed(columns.begin(), columns.end());
    for (Index j : add.coordinates)
      if (!listed.count(j)) columns.push_back(j);
  };
  if (plan.velocity_columns) extend(*plan.velocity_columns);
  extend(plan.coordinate_columns);
  if (!add.joints) return;
  for (OutputJoint& j : measured_joints(scene)) {
    const bool listed = std::any_of(plan.joints.begin(), plan.joints.end(),
                                    [&](const OutputJoint& o) { return o.name == j.name && o.measure == j.measure; });
    if (!listed) plan.joints.push_back(std::move(j));
  }
}

}  // namespace

CsvTable sweep_scene(const Scene& scene, const DrawnOutputs& add) {
  SweepOptions options = scene.sweep;
  add_outputs(scene, add, options);
  options.threads = 0;  // `phiq run`'s default: the rows are the same bits on every thread count
  SquareScene square;
  if (const auto why = make_square(scene, &square)) throw DrawError(scene.path + ": " + *why, 1);
  const Model& model = square.model(*scene.model);
  Workspace ws(model);
  ws.q = square.start;
  // residuals of a model solved on its independent rows are evaluated on the whole scene model, as run writes them
  const CsvFormat format(*scene.model, options);
  CsvTable table;
  table.path = scene.path;
  table.columns = format.column_names();
  table.rows.reserve(static_cast<std::size_t>(rows_written(options)));
  SweepSummary summary;
  try {
    (void)run_sweep(  // its status is summary.status, read below
        model, options, ws,
        [&](const StepView& step) {
          table.rows.emplace_back(format.num_values());
          format.append_values(step, table.rows.back().data());
          return true;
        },
        &summary);
  } catch (const Error& e) {
    throw DrawError(scene.path + ": " + e.what(), 1);
  }
  if (summary.status != SolveStatus::kSuccess) throw DrawError(scene.path + ": " + summary.message, 1);
  return table;
}

}  // namespace phiq::tools
