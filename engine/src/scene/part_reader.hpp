// PartReader: the `parts` and `loads` sections of a scene (read_parts.cpp, read_shapes.cpp, read_loads.cpp), read
// once the model's constraints are, in the vocabulary of the SceneReader that read them: its names of bodies, points
// and joints, its numbers and expressions. It holds nothing of its own.
#pragma once

#include <array>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

class PartReader {
 public:
  explicit PartReader(const SceneReader& r) : r_(r) {}

  /// Appends the parts of `parts` (a map NAME: {body | frame, shapes, mass, ...}) to scene.parts.
  void read_parts(const Cursor& c, Scene& scene) const;
  /// Reads `loads` (gravity, forces, torques, springs) into scene.loads; pre: the parts are read.
  void read_loads(const Cursor& c, Scene& scene) const;

 private:
  // ---- parts (read_parts.cpp, read_shapes.cpp) ----------------------------------------------------------------
  static bool frame_depends_on_time(const PartFrame& f);
  void part_frame(const Cursor& v, const std::string& name, Part& part) const;
  Attachment3 frame_toward(const Cursor& c, bool& is_point) const;
  void points_or_expression_frame(const Cursor& f, Part& part) const;
  std::shared_ptr<const CompiledExpression> slot_expression(const Cursor& c, const Slot& s) const;
  void part_mass(const Cursor& v, Part& part) const;
  MassProperties shapes_mass(const Cursor& c, const Part& part, double density) const;
  std::array<double, 9> inertia_tensor(const Cursor& c) const;
  std::array<double, 4> colour(const Cursor& c) const;
  std::vector<kin3::V3> shape_points(const Cursor& c, std::size_t n, std::size_t least) const;
  Shape read_shape(const Cursor& c) const;
  void read_shape_size(const Cursor& c, Shape& s) const;

  // ---- loads (read_loads.cpp) ---------------------------------------------------------------------------------
  PartFrame load_frame(const Cursor& c, const Scene& scene) const;
  PartFrame ground_frame() const;
  kin3::V3 load_vector(const Cursor& c, const char* what) const;
  std::array<std::shared_ptr<const CompiledExpression>, 3> load_components(const Cursor& c, const char* what) const;
  LoadAxes load_axes(const Cursor& c) const;
  double non_negative(const Cursor& c) const;
  LinearSpring linear_spring(const Cursor& s, const Scene& scene, std::set<std::string>& names) const;
  TorsionalSpring torsional_spring(const Cursor& s, std::set<std::string>& names) const;

  const SceneReader& r_;
};

}  // namespace phiq::detail::scene
