// PartReader: the `parts` and `loads` sections of a scene (read_parts.cpp, read_shapes.cpp, read_loads.cpp), read
// once the model's constraints are, in the vocabulary of the SceneReader that read them: its names of bodies, points
// and joints, its numbers and expressions. It holds only the meshes it has read, each file once.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

class PartReader {
 public:
  explicit PartReader(SceneReader& r) : r_(r) {}

  /// Appends the parts of `parts` (a map NAME: {body | frame, shapes, mass, ...}, with families) to scene.parts.
  void read_parts(const Cursor& c, Scene& scene);
  /// Reads `loads` (gravity, forces, torques, springs) into scene.loads; pre: the parts are read.
  void read_loads(const Cursor& c, Scene& scene) const;

 private:
  // ---- parts (read_parts.cpp, read_shapes.cpp): templates over the cursor, a plain entry or a family's member
  static bool frame_depends_on_time(const PartFrame& f);
  template <class C>
  void read_part(const std::string& name, const C& v, Scene& scene) const;
  template <class C>
  void part_frame(const C& v, const std::string& name, Part& part) const;
  template <class C>
  Attachment3 frame_toward(const C& c, bool& is_point) const;
  template <class C>
  void points_or_expression_frame(const C& f, Part& part) const;
  template <class C>
  std::shared_ptr<const CompiledExpression> slot_expression(const C& c, const Slot& s) const;
  template <class C>
  void part_mass(const C& v, Part& part) const;
  template <class C>
  MassProperties shapes_mass(const C& c, const Part& part, double density) const;
  template <class C>
  std::array<double, 9> inertia_tensor(const C& c) const;
  template <class C>
  std::array<double, 4> colour(const C& c) const;
  template <class C>
  std::vector<kin3::V3> shape_points(const C& c, std::size_t n, std::size_t least) const;
  template <class C>
  Shape read_shape(const C& c) const;
  template <class C>
  void read_shape_size(const C& c, Shape& s) const;

  // ---- loads (read_loads.cpp): templates over the cursor, a plain entry or a family's member ------------------
  // What a load may act on: the scene's parts, by name (found once: 10⁴ loads on 10⁴ parts compared 10⁸ names).
  struct LoadTargets {
    const Scene& scene;
    std::unordered_map<std::string_view, std::size_t> parts;  // name → index in scene.parts
  };
  template <class C>
  AppliedForce applied_force(const C& f, const LoadTargets& targets, std::set<std::string>& names) const;
  template <class C>
  AppliedTorque applied_torque(const C& m, const LoadTargets& targets, std::set<std::string>& names) const;
  template <class C>
  PartFrame load_frame(const C& c, const LoadTargets& targets) const;
  template <class C>
  PartFrame load_frame(const C& c, const LoadTargets& targets, const char* what) const;
  PartFrame ground_frame() const;
  template <class C>
  kin3::V3 load_vector(const C& c, const char* what) const;
  template <class C>
  void load_components(const C& c, const char* what, std::array<LoadValue, 3>& out) const;
  template <class C>
  bool spring_stiffness(const C& s, double& stiffness, MotionLaw& law, bool other) const;
  // one component: an expression, or `{law: LAW, of: EXPRESSION}` (of: t when absent)
  template <class C>
  LoadValue load_component(const C& c) const;
  template <class C>
  LoadAxes load_axes(const C& c) const;
  template <class C>
  double non_negative(const C& c) const;
  template <class C>
  LinearSpring linear_spring(const C& s, const LoadTargets& targets, std::set<std::string>& names) const;
  template <class C>
  TorsionalSpring torsional_spring(const C& s, std::set<std::string>& names) const;
  template <class C>
  GearLoss gear_loss(const C& g) const;

  SceneReader& r_;  // (not const: a family's walk keeps its state there)
  // the meshes read so far, by file (as written, joined to the scene's folder) and scale
  mutable std::map<std::pair<std::string, double>, std::shared_ptr<const TriangleMesh>> meshes_;
};

}  // namespace phiq::detail::scene
