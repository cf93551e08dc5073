// SceneReader::read (scene_reader.hpp): the sections of a scene in the order they are read — parameters first
// (family ranges and numbers use them), the solver before the constraints (length scale, linear solver), time and
// output last — then the model built from them.
#include <memory>
#include <string_view>

#include "phiq/text.hpp"
#include "scene/family_expansion.hpp"
#include "scene/scene_reader.hpp"
#include "scene/part_reader.hpp"

namespace phiq::detail::scene {

Scene SceneReader::read(const YAML::Node& root) {
  Cursor top(root, "", &file_, YAML::Mark());
  if (!root.IsDefined() || root.IsNull()) top.fail("the scene is empty");
  top.expect_map({"phiq", "name", "description", "dimension", "parameters", "coordinates", "points", "bodies",
                  "vectors", "constraints", "drivers", "parts", "loads", "time", "output", "limits", "solver"});
  if (auto v = top.field("phiq"); v.present() && v.integer(1, 1) != 1) v.fail("unsupported format version");

  Scene scene;
  scene.path = file_;
  if (auto n = top.field("name"); n.present()) scene.name = n.text();
  if (auto d = top.field("description"); d.present()) (void)d.text();

  if (overrides_ && overrides_->share_analysis_with) builder_.share_analysis_with(*overrides_->share_analysis_with);
  if (auto d = top.field("dimension"); d.present()) spatial_ = d.integer(2, 3) == 3;
  read_parameters(top.field("parameters"));
  for (const std::string& n : names_.parameter_order) scene.parameters.emplace_back(n, names_.parameters.at(n));
  check_family_total(top);  // the parameters give the ranges of the families in the sections
  read_coordinates(top.field("coordinates"));
  try {
    if (auto p = top.field("points"); p.present()) read_points(p);
    if (auto b = top.field("bodies"); b.present()) read_bodies(b);
    if (auto v = top.field("vectors"); v.present()) {
      if (!spatial_) v.fail("natural unit vectors need 'dimension: 3'");
      read_vectors(v);
    }
  } catch (const SceneError& e) {  // a name unknown for want of the section that would have named it
    if (builder_.num_coordinates() > 0 || std::string_view(e.what()).find("unknown name '") == std::string::npos) throw;
    throw SceneError(std::string(e.what()) + ": the scene has no `coordinates` section (names and start values)");
  }
  if (builder_.num_coordinates() == 0)
    top.fail("at least one coordinate is needed: a `coordinates` section, or bodies written as maps");
  read_solver(top.field("solver"), scene.sweep);  // before constraints: length scale, linear solver

  reserve_ = [&](std::size_t more) { builder_.reserve(0, static_cast<Index>(more)); };
  if (auto c = top.field("constraints"); c.present()) read_list(c, [&](const auto& item) { read_constraint(item); });
  if (auto d = top.field("drivers"); d.present()) read_list(d, [&](const auto& item) { read_driver(item); });

  if (auto p = top.field("parts"); p.present())
    PartReader(*this).read_parts(p, scene);  // (before the tables of names are freed)
  if (auto l = top.field("loads"); l.present())
    PartReader(*this).read_loads(l, scene);  // (after the parts they act on)
  read_time(top.require("time"), scene.sweep);
  read_output(top.field("output"), scene.sweep);
  if (auto o = top.field("output"); o.present() && o.is_map()) read_clearance(o.field("clearance"), scene);
  if (auto l = top.field("limits"); l.present()) read_limits(l, scene.sweep);
  scene.dimension = spatial_ ? 3 : 2;
  scene.planar_bodies = std::move(names_.planar_bodies), scene.spatial_bodies = std::move(names_.spatial_bodies);
  scene.joint_angles = std::move(names_.joint_angles);
  names_.points = {}, names_.bodies = {};  // not needed any more: their memory is free for the model
  pending_.driver_laws = {};
  names_.points3 = {}, names_.bodies3 = {}, names_.vectors = {}, names_.joints3.clear();

  try {
    scene.model = std::make_unique<Model>(std::move(builder_).build());
  } catch (const Error& e) {
    throw SceneError(single_line(file_ + ": " + e.what()));  // about the model as a whole: no one place in the file
  }
  // Models that are not square (redundant constraints, missing drivers) load: the rank analysis and the
  // minimum-norm assembly (assembly.hpp) tell what they are, and `phiq run` solves the redundant ones.
  resolve_output_residuals(scene);
  resolve_output_efforts(scene);
  resolve_limit_efforts(scene);
  return scene;
}

}  // namespace phiq::detail::scene
