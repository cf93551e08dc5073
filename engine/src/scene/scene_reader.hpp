// SceneReader: reads the sections of a scene's YAML tree into a ModelBuilder and SweepOptions. This header
// declares the class; its members are defined by subject, one file each:
//   scene_reader.cpp     read(): the sections in their order, then the model
//   read_values.cpp      numbers, constant expressions, slots, coordinates and names looked up in the tables
//   read_equations.cpp   equation and law expressions (compiled once per family body, rebound per member)
//   read_families.cpp    family keys and bodies copied out of the YAML tree, the total of family entries
//   family_expansion.hpp the walk over the members of families (templates over the callers' lambdas)
//   read_entities.cpp    parameters, coordinates, points, bodies, vectors
//   read_constraints.cpp constraints, each read by its kind (kinds/registry.hpp, through kind_fields.hpp), and the
//                        attachments, sides and segments they refer to
//   read_drivers.cpp     drivers, joint drivers and motion laws
//   part_reader.hpp      parts and loads, read after the model by a PartReader of their own
//   read_settings.cpp    time, output, solver
// The readers are templates over the cursor type C: Cursor (a plain entry of the YAML tree) or TCursor (a member
// of a family, families.hpp). The .cpp that defines a member template used elsewhere instantiates it explicitly
// for both cursors.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "phiq/applied_loads.hpp"
#include "phiq/orientation.hpp"
#include "phiq/scene.hpp"
#include "scene/families.hpp"
#include "scene/name_table.hpp"
#include "scene/yaml_cursor.hpp"

namespace phiq::detail::scene {

// The fixed frame, predefined in every scene.
const char* const kGround = "ground";

template <class C>
class KindFields;

// "'x' is a coordinate: a law is a function of t alone ...": the message for a coordinate in a law expression.
std::string coordinate_in_law(const std::string& name);

// " (its parameters: A, B)" naming `names` sorted, or " (it has none)": what a message about a name that is no
// parameter of the scene ends with.
std::string parameters_note(std::vector<std::string> names);

class SceneReader {
  template <class C>
  friend class KindFields;  // the scene vocabulary the constraint kinds read themselves with
  friend class PartReader;  // and the parts and loads (part_reader.hpp)

 public:
  SceneReader(const std::string& file, const SceneLimits& limits) : file_(file), limits_(limits) {
    families_.file = &file_;
    families_.parameters = &names_.parameters;
    families_.budget = limits.max_family_instances;
  }

  Scene read(const YAML::Node& root);

 private:
  // ---- names and numbers (read_values.cpp) --------------------------------------------------------------------
  std::optional<double> parameter(const std::string& name) const;
  template <class C>
  double constant_expression(const C& c, const std::string& s) const;
  template <class C>
  double number(const C& c) const;
  bool uses_member(const TCursor& c, const std::string& s) const;
  Meanings member_meanings(const TCursor& c) const;
  template <class C>
  double positive(const C& c) const;
  template <class C>
  std::vector<double> numbers(const C& c, std::size_t n) const;
  template <class C>
  kin::V2 vec2(const C& c) const;
  template <class C>
  kin3::V3 vec3(const C& c) const;
  template <class C>
  Index coordinate(const C& c) const;
  template <class C, class Find, class NameAt>
  Index lookup(const C& c, const std::string& name, Index size, const Find& find, const NameAt& name_at) const;
  template <class C>
  Index coordinate_at(const C& c, const std::string& name) const;
  template <class C, class T>
  Index entry_at(const C& c, const std::string& name, const NameTable<T>& table) const;
  template <class C>
  Slot slot(const C& c) const;
  template <class C>
  Unit unit(const C& c) const;

  // ---- expressions (read_equations.cpp) -----------------------------------------------------------------------
  template <class C>
  std::shared_ptr<const CompiledExpression> compile(const C& c, bool allow_time, bool allow_rates = false) const;
  NameResolver resolver(bool coordinates, const std::string& text) const;
  std::shared_ptr<const CompiledExpression> family_expression(const TCursor& c, bool allow_time, bool allow_coordinates,
                                                              bool allow_rates = false) const;

  // ---- families (read_families.cpp, family_expansion.hpp) -----------------------------------------------------
  FamilyRange parse_range(const std::string& key, const YAML::Mark& key_mark, const std::string& path,
                          const std::vector<std::string>& enclosing) const;
  std::pair<std::int64_t, std::int64_t> range_bounds(const FamilyRange& r, const YAML::Mark& mark,
                                                     const std::string& path) const;
  std::shared_ptr<Family> parse_family(const std::string& key, const YAML::Mark& key_mark, const YAML::Node& body,
                                       const std::string& path, const std::vector<std::string>& enclosing, bool list);
  std::optional<std::string> family_item_key(const YAML::Node& item, const std::string& path) const;
  TNode copy(const YAML::Node& n, const std::string& path, const YAML::Mark& parent_mark) const;
  void check_family_total(const Cursor& top);
  template <class Each>
  void for_each_member(const Family& f, Each&& each);
  template <class Each>
  void expand_map(const Family& f, Each& each);
  template <class Each>
  void read_map(const std::vector<Cursor::Entry>& entries, Each each);
  template <class Each>
  void read_list(const Cursor& c, Each each);
  template <class Each>
  void expand_list(const Family& f, Each& each);

  // ---- parameters, coordinates, points, bodies, vectors (read_entities.cpp) ----------------------------------
  void read_parameters(const Cursor& c);
  [[noreturn]] void unknown_override(const Cursor& c, const std::string& name) const;
  void read_coordinates(const Cursor& c);
  template <class C, class T, class U>
  Index new_entity(const C& where, const std::string& name, NameTable<T>& table, const NameTable<U>& other);
  template <class C, class T>
  Index new_entity3(const C& where, const std::string& name, NameTable<T>& table);
  void read_points(const Cursor& c);
  void read_bodies(const Cursor& c);
  void read_vectors(const Cursor& c);
  // How far from 1 a fixed frame's |e| may be and still be normalised (read_entities.cpp).
  static constexpr double kEulerNormSlack = 1e-3;
  template <class C>
  void fixed_euler_parameters(const C& value, Frame3& f) const;
  template <class C>
  EulerParameters orientation(const C& o) const;
  template <class C>
  void body_from_map(const C& value, const std::string& name, Slot* v, int dimension);

  // ---- constraints (read_constraints.cpp) ---------------------------------------------------------------------
  template <class C>
  Point2 point(const C& c) const;
  template <class C>
  std::pair<Point2, Point2> segment(const C& c) const;
  template <class C>
  Frame2 body(const C& c) const;
  template <class C>
  std::pair<Frame2, kin::V2> attachment(const C& c) const;
  template <class C>
  void read_constraint(const C& c);
  // Reads one entry as a constraint of kind K (read_constraints.cpp); kind_readers() finds K by type.
  template <class K, class C>
  void read_kind(const C& c, const std::string& type, const std::string& name);
  template <class C>
  using KindReader = void (SceneReader::*)(const C&, const std::string&, const std::string&);
  template <class C>
  static const std::unordered_map<std::string, KindReader<C>>& kind_readers(bool spatial);
  template <class C>
  Point3 point3(const C& c) const;
  template <class C>
  Point3 vector3(const C& c) const;
  template <class C>
  Frame3 body3(const C& c) const;
  template <class C>
  kin3::V3 direction3(const C& c) const;
  template <class C>
  JointSide3 side3(const C& c) const;
  template <class C>
  std::pair<JointSide3, JointSide3> sides3(const C& c, const std::string& type) const;
  template <class C>
  std::pair<Attachment3, Attachment3> dot_direction(const C& c, Unit& unit) const;
  // Adds a constraint or driver to the model, named `name` or, unnamed, by its place: "drivers[2] (line 31)".
  template <class C, class Spec>
  void add(const C& c, const std::string& name, Spec spec);

  // ---- drivers (read_drivers.cpp) -----------------------------------------------------------------------------
  template <class C>
  void read_joint_driver(const C& c, const std::string& name, MotionLaw law);
  template <class C>
  void read_driver(const C& c);
  template <class C>
  MotionLaw motion_law(const C& c) const;

  // ---- time, output, solver (read_settings.cpp) ---------------------------------------------------------------
  void read_time(const Cursor& c, TimeGrid& o) const;
  void read_output(const Cursor& c, OutputPlan& plan);
  void output_sensitivities(const Cursor& c, OutputPlan& plan);
  std::vector<Index> coordinate_selection(const Cursor& list) const;
  OutputPoint output_point(const Cursor& c) const;
  void output_joints(const Cursor& js, OutputPlan& plan) const;
  void output_orientations(const Cursor& os, OutputPlan& plan) const;
  void resolve_output_residuals(Scene& scene) const;
  void keep_natural_points();  // pending_.natural_points from the named points, once (read_efforts.cpp)
  void read_output_efforts(const Cursor& output);                                  // read_efforts.cpp
  void resolve_output_efforts(Scene& scene) const;                                 // read_efforts.cpp
  void resolve_output_reactions(Scene& scene) const;                               // read_efforts.cpp
  std::vector<OutputLoss> resolve_output_losses(const AppliedLoads* loads) const;  // read_efforts.cpp
  void read_solver(const Cursor& c, SolverSettings& o);
  void read_clearance(const Cursor& c, Scene& scene) const;  // output.clearance (read_clearance.cpp)
  void read_limits(const Cursor& c, OutputPlan& plan);       // read_limits.cpp
  void resolve_limit_efforts(Scene& scene) const;            // read_limits.cpp

  const std::string& file_;
  const SceneLimits& limits_;
  ModelBuilder builder_;

 public:
  const SceneOverrides* overrides_ = nullptr;  ///< the caller's changes, if any

 private:
  // The scene's named entities, which later sections and the outputs refer to.
  struct Joint3 {  // a named spatial joint; what it offers is its kind's JointTraits (kinds/registry.hpp)
    std::string type;
    JointTraits traits;
    JointSide3 a, b;
  };
  struct Names {
    std::unordered_map<std::string, double> parameters;
    std::vector<std::string> parameter_order;  // file order (Scene::parameters)
    NameTable<Point2> points;
    NameTable<Frame2> bodies;
    NameTable<Point3> points3;
    NameTable<Frame3> bodies3;
    NameTable<Point3> vectors;
    // the frames of the moving bodies, in the order of ModelBuilder::add_body() (Scene::planar_bodies)
    std::vector<Frame2> planar_bodies;
    std::vector<Frame3> spatial_bodies;
    std::unordered_map<std::string, Joint3> joints3;  // for the drivers, outputs and shafts that name them
    std::vector<JointAngleReference> joint_angles;    // Scene::joint_angles
  };
  Names names_;
  bool spatial_ = false;  // dimension: 3
  Families families_;
  std::function<void(std::size_t)> reserve_;  // room for that many more entries of the section being read
  // What `output` and `solver` ask of things the build makes, resolved after it.
  struct Pending {
    bool predictor_given = false;                            // `solver: predictor` was given
    std::unordered_map<std::string, MotionLaw> driver_laws;  // named drivers, for `output: drivers`
    std::vector<std::string> residual_names;                 // `output: residuals`
    std::optional<Cursor> efforts_field;                     // `output: efforts` (its items when it lists names)
    std::vector<Cursor> effort_items;
    bool efforts_power = false;             // and `power`
    bool reactions_in_joint_axes = false;   // `reaction_axes: joint`
    std::optional<Cursor> reactions_field;  // `output: reactions` (its items when it lists names)
    // with `reactions`: the named natural points, kept past the tables' release for the natural joints
    std::vector<std::pair<std::string, Attachment3>> natural_points;
    std::vector<Cursor> reaction_items;
    bool natural_bearings = false;  // a bearing names a point (natural_points kept for its joint)
    // the `joint` fields that name a point, checked with the natural joints once the model is built: the name, and
    // where a message points (fail_at())
    struct BearingPoint {
      std::string name, path;
      YAML::Mark mark;
    };
    std::vector<BearingPoint> bearing_points;
    std::optional<Cursor> losses_field;  // `output: losses` (its items when it lists names)
    std::vector<Cursor> loss_items;
    std::vector<std::pair<std::size_t, Cursor>> limit_efforts;  // `limits`' efforts: the limit, its driver's name
  };
  Pending pending_;

 public:
  bool predictor_given() const { return pending_.predictor_given; }
};

// Defined here, not in a .cpp: it is instantiated for every Spec of every constraint and driver kind.
template <class C, class Spec>
void SceneReader::add(const C& c, const std::string& name, Spec spec) {
  // an unnamed entry is called by its place and line, which every message about it then shows
  const std::string label = name.empty() ? c.path() + " (line " + std::to_string(c.mark().line + 1) + ")" : name;
  bool any_coordinate = false;
  spec.for_each_slot([&](const Slot& s, Unit) { any_coordinate = any_coordinate || s.is_coordinate(); });
  if constexpr (requires { Spec::kAddedCoordinates; }) {
    // its own coordinates (a curve parameter) are named after it, and added with it
    if (name.empty())
      c.fail(std::string("a constraint with a coordinate of its own needs a name (its coordinate is NAME.") +
             Spec::kAddedCoordinates[0] + ")");
    any_coordinate = true;
  }
  // one that involves no coordinate nor t and is 0 (`0*x`, a joint between two coincident fixed points) holds
  // everywhere: a redundant row the rank analysis reports, not an error
  bool holds_everywhere = false;
  if (!any_coordinate && !spec.depends_on_time()) {
    double phi[Spec::kRows > 0 ? Spec::kRows : 1] = {};
    const double no_coordinates[1] = {0.0};
    spec.residual(no_coordinates, 0.0, phi);
    holds_everywhere = true;
    for (int r = 0; r < Spec::kRows; ++r) holds_everywhere = holds_everywhere && phi[r] == 0.0;
  }
  try {
    builder_.add(label, std::move(spec));
  } catch (const Error&) {
    // the builder registers the name only when it adds the constraint: a name it has is a duplicate (reported
    // before anything else wrong with the constraint, as a check before adding would)
    if (builder_.has_constraint(label)) c.field("name").fail("duplicate constraint or driver name '" + label + "'");
    throw;
  }
  // Any other equation of constants and t holds at no position (or at isolated times): said here, where its line
  // is known, not by a factorisation library refusing the empty row of the Jacobian.
  if (!any_coordinate && !holds_everywhere) {
    const C expr = c.field("expr");
    if (expr.present() && expr.is_scalar())
      expr.fail("expression \"" + expr.text() + "\" involves no coordinate and is not zero: no position satisfies it");
    c.fail("involves no coordinate and is not zero: no position satisfies it");
  }
}

}  // namespace phiq::detail::scene
