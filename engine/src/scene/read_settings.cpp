// The sections that set how the scene is swept and what it writes (scene_reader.hpp): time, output (and the output
// points and residuals it names), solver. They are never in families: they read plain Cursors only.
#include <fnmatch.h>
#include <algorithm>

#include <cmath>
#include <set>
#include <unordered_map>

#include "phiq/kinds/registry.hpp"
#include "scene/scene_reader.hpp"
#include "sweep/time_grid.hpp"

namespace phiq::detail::scene {

void SceneReader::read_time(const Cursor& c, TimeGrid& o) const {
  c.expect_map({"start", "end", "steps"});
  o.t_begin = number(c.require("start"));
  o.t_end = number(c.require("end"));
  o.steps = c.require("steps").integer(0, 1000000000);
  if (o.steps > 0 && o.t_end == o.t_begin) c.require("end").fail("end equals start but steps > 0");
  if (const std::string why = detail::time_grid_problem(o.t_begin, o.t_end, o.steps); !why.empty())
    c.require("end").fail(why);  // steps that would not move time: run_sweep refuses them
}

namespace {
bool is_pattern(const std::string& s) { return s.find_first_of("*?[") != std::string::npos; }
}  // namespace

// A list of coordinates to write: names, and shell patterns (`x1*`, `theta?`, `y[0-9]`) that select every
// coordinate whose name matches, in scene order. A name listed twice is refused; a coordinate a pattern selects
// again is not repeated; a pattern that selects nothing is refused (a misspelt pattern would write nothing).
std::vector<Index> SceneReader::coordinate_selection(const Cursor& list) const {
  std::vector<Index> out;
  std::set<Index> seen;
  for (const Cursor& i : list.items()) {
    const std::string text = i.text();
    if (!is_pattern(text)) {
      const Index j = coordinate(i);
      if (!seen.insert(j).second) i.fail("coordinate listed twice");
      out.push_back(j);
      continue;
    }
    bool any = false;
    for (Index j = 0; j < builder_.num_coordinates(); ++j) {
      if (fnmatch(text.c_str(), builder_.coordinate_name(j).c_str(), 0) != 0) continue;
      any = true;
      if (seen.insert(j).second) out.push_back(j);
    }
    if (!any) i.fail("pattern '" + text + "' selects no coordinate");
  }
  return out;
}

// The output list, and from it the sweep's plan: derivatives, points, residuals and the condition estimate are
// computed only when listed here (models/README.md, `output`).
void SceneReader::read_output(const Cursor& c, OutputPlan& plan) {
  plan.velocities = plan.accelerations = false;
  bool coordinates_listed = false;
  if (c.present()) {
    c.expect_map({"velocities",   "accelerations", "coordinates",   "points",           "joints",
                  "orientations", "drivers",       "residuals",     "max_residual",     "rcond",
                  "every",        "window",        "sensitivities", "sensitivity_form", "efforts",
                  "power",        "reactions",     "reaction_axes", "losses",           "clearance"});
    // true / false, or the coordinates whose derivative is written (q̇ or q̈ is solved whole either way)
    auto derivative = [&](const char* key, bool& asked, std::optional<std::vector<Index>>& columns) {
      const Cursor d = c.field(key);
      if (!d.present()) return;
      if (d.is_sequence()) {
        columns = coordinate_selection(d);
        asked = true;
      } else {
        asked = d.boolean();
      }
    };
    derivative("velocities", plan.velocities, plan.velocity_columns);
    derivative("accelerations", plan.accelerations, plan.acceleration_columns);
    if (auto cs = c.field("coordinates"); cs.present()) {
      coordinates_listed = true;
      plan.coordinate_columns = coordinate_selection(cs);
    }
    if (auto e = c.field("every"); e.present()) plan.every = static_cast<Index>(e.integer(1, 1000000000));
    if (auto w = c.field("window"); w.present()) {
      if (!w.is_sequence() || w.size() != 2) w.fail("must be [begin, end] (s)");
      plan.window_begin = number(w.at(0));
      plan.window_end = number(w.at(1));
      if (!(plan.window_begin <= plan.window_end)) w.fail("begin must not be above end");
    }
    if (auto ps = c.field("points"); ps.present()) {
      std::set<std::string> seen;
      for (const Cursor& i : ps.items()) {
        OutputPoint p = output_point(i);
        if (!seen.insert(p.name).second) i.fail("output point '" + p.name + "' listed twice");
        plan.points.push_back(std::move(p));
      }
    }
    if (auto js = c.field("joints"); js.present()) output_joints(js, plan);
    if (auto os = c.field("orientations"); os.present()) output_orientations(os, plan);
    if (auto ds = c.field("drivers"); ds.present()) {
      std::set<std::string> seen;
      for (const Cursor& i : ds.items()) {
        const std::string n = i.name();
        auto it = pending_.driver_laws.find(n);
        if (it == pending_.driver_laws.end()) i.fail("unknown driver '" + n + "' (a named entry of `drivers`)");
        if (!seen.insert(n).second) i.fail("driver listed twice");
        plan.driver_columns.push_back({n, it->second});
      }
    }
    if (auto rs = c.field("residuals"); rs.present()) {
      std::set<std::string> seen;
      for (const Cursor& i : rs.items()) {
        const std::string n = i.name();
        if (!builder_.has_constraint(n)) i.fail("unknown constraint or driver '" + n + "'");
        if (!seen.insert(n).second) i.fail("constraint listed twice");
        pending_.residual_names.push_back(n);
      }
    }
    if (auto ss = c.field("sensitivities"); ss.present()) output_sensitivities(ss, plan);
    if (auto f = c.field("sensitivity_form"); f.present()) {
      const std::string form = f.text();
      if (form == "auto")
        plan.sensitivity_form = SensitivityForm::kAuto;
      else if (form == "direct")
        plan.sensitivity_form = SensitivityForm::kDirect;
      else if (form == "adjoint")
        plan.sensitivity_form = SensitivityForm::kAdjoint;
      else
        f.fail("sensitivity_form is auto, direct or adjoint");
    }
    read_output_efforts(c);
    if (auto v = c.field("max_residual"); v.present()) plan.max_residual_column = v.boolean();
    if (auto v = c.field("rcond"); v.present()) plan.condition = v.boolean();
    plan.residuals = plan.max_residual_column || !pending_.residual_names.empty();
  }
  if (!coordinates_listed)
    for (Index j = 0; j < builder_.num_coordinates(); ++j) plan.coordinate_columns.push_back(j);
  // the columns `residual` and `rcond` must not collide with a coordinate's
  for (Index j : plan.coordinate_columns) {
    const std::string& n = builder_.coordinate_name(j);
    if ((n == "residual" && plan.max_residual_column) || (n == "rcond" && plan.condition))
      c.fail("coordinate '" + n + "' and the column '" + n + "' would share a name: leave it out of coordinates");
  }
}

// `joints: [NAME, ...]`: named spatial joints, each with what its kind measures (JointTraits): a revolute's angle, a
// prismatic's distance, a cylindrical's or a screw's both.
void SceneReader::output_joints(const Cursor& js, OutputPlan& plan) const {
  if (!spatial_)
    js.fail("joint outputs are of spatial joints (dimension: 3); in the plane, output the angle coordinate");
  std::set<std::string> seen;
  for (const Cursor& i : js.items()) {
    const std::string n = i.name();
    auto it = names_.joints3.find(n);
    if (it == names_.joints3.end()) i.fail("unknown joint '" + n + "' (a named spatial joint of 'constraints')");
    if (!seen.insert(n).second) i.fail("joint listed twice");
    const Joint3& J = it->second;
    const JointTraits::Coordinates measures = J.traits.measures;
    if (!measures.any())
      i.fail("joint '" + n + "' is a " + J.type + " joint: outputs measure the angle of a " +
             joint_type_list([](const JointTraits& t) { return t.measures.angle; }) + " joint, or the distance of a " +
             joint_type_list([](const JointTraits& t) { return t.measures.distance; }) +
             " one (output its bodies' orientations instead)");
    try {
      if (measures.angle) plan.joints.push_back(output_joint(n, JointMeasure::kAngle, J.a, J.b));
      if (measures.distance) plan.joints.push_back(output_joint(n, JointMeasure::kDistance, J.a, J.b));
    } catch (const Error& e) {
      i.fail(e.what());
    }
  }
}

// `orientations: [BODY, ...]` (as rotation matrices) or `{bodies: [BODY, ...], as: matrix | axis_angle | zyx …}`.
void SceneReader::output_orientations(const Cursor& os, OutputPlan& plan) const {
  if (!spatial_) os.fail("orientations are of spatial bodies (dimension: 3); a planar body's is its angle coordinate");
  // (no Cursor assignment: a YAML::Node assigned to rewrites the node it refers to)
  if (os.is_map()) {
    os.expect_map({"bodies", "as"});
    if (auto as = os.field("as"); as.present()) {
      const std::string f = as.text();
      if (f != "matrix" && f != "axis_angle" && !is_euler_sequence(f))
        as.fail("'" + f +
                "' is not an orientation form: matrix, axis_angle, or an Euler sequence (zyx, xyz, zxz, ...)");
      plan.orientation_form.form = f;
    }
  }
  std::set<std::string> seen;
  for (const Cursor& i : (os.is_map() ? os.require("bodies") : os).items()) {
    const std::string n = i.name();
    const Index k = entry_at(i, n, names_.bodies3);
    if (k < 0) i.fail("unknown body '" + n + "'");
    if (!seen.insert(n).second) i.fail("body listed twice");
    if (plan.orientation_form.form == "axis_angle")
      for (const OutputJoint& j : plan.joints)
        if (j.name == n && j.measure == JointMeasure::kAngle)
          i.fail("the columns '" + n + ".angle' of joint '" + n +
                 "' and of this body's axis and angle would share a "
                 "name: write the orientation in another form, or rename one");
    const Frame3& f = names_.bodies3[k];
    plan.orientations.push_back(OutputOrientation{n, {f.e0, f.e1, f.e2, f.e3}});
  }
}

// An output point: a point name, or {name: P, body: B, at: [x, y]} (a point fixed on body B, in B's frame;
// [x, y, z] in dimension 3).
OutputPoint SceneReader::output_point(const Cursor& c) const {
  if (spatial_) {
    if (!c.is_map()) {
      const std::string n = c.name();
      const Index k = entry_at(c, n, names_.points3);
      if (k < 0) c.fail("unknown point '" + n + "' (or write {name: P, body: B, at: [x, y, z]})");
      return spatial_point(n, names_.points3[k]);
    }
    c.expect_map({"name", "body", "at"});
    const std::string n = c.require("name").name();
    if (!valid_name(n)) c.require("name").fail("'" + n + "' is not a valid name");
    const Frame3 f = body3(c.require("body"));
    kin3::V3 at;
    if (auto a = c.field("at"); a.present()) at = vec3(a);
    return spatial_body_point(n, f, at);
  }
  if (!c.is_map()) {
    const std::string n = c.name();
    const Index k = entry_at(c, n, names_.points);
    if (k < 0) c.fail("unknown point '" + n + "' (or write {name: P, body: B, at: [x, y]})");
    return planar_point(n, names_.points[k]);
  }
  c.expect_map({"name", "body", "at"});
  const std::string n = c.require("name").name();
  if (!valid_name(n)) c.require("name").fail("'" + n + "' is not a valid name");
  const Frame2 f = body(c.require("body"));
  kin::V2 at{0, 0};
  if (auto a = c.field("at"); a.present()) at = vec2(a);
  return planar_body_point(n, f, at.x, at.y);
}

// Constraint names of `output: residuals` to indices, once the model is built (one pass over the constraints).
void SceneReader::resolve_output_residuals(Scene& scene) const {
  if (pending_.residual_names.empty()) return;
  std::unordered_map<std::string, Index> wanted;
  for (const std::string& n : pending_.residual_names) wanted.emplace(n, -1);
  const auto& cs = scene.model->constraints();
  for (std::size_t k = 0; k < cs.size(); ++k)
    if (auto it = wanted.find(cs[k].name); it != wanted.end()) it->second = static_cast<Index>(k);
  for (const std::string& n : pending_.residual_names) scene.sweep.residual_columns.push_back(wanted.at(n));
}

void SceneReader::read_solver(const Cursor& c, SolverSettings& o) {
  if (!c.present()) return;
  c.expect_map({"tolerance", "max_iterations", "assembly_max_iterations", "line_search", "predictor",
                "max_subdivisions", "length_scale", "linear_solver", "newton"});
  if (auto v = c.field("tolerance"); v.present()) {
    double tol = positive(v);
    if (tol >= 1.0) v.fail("tolerance must be below 1");
    o.newton.tolerance = o.assembly.tolerance = tol;
  }
  if (auto v = c.field("max_iterations"); v.present()) o.newton.max_iterations = static_cast<int>(v.integer(1, 1000));
  if (auto v = c.field("assembly_max_iterations"); v.present())
    o.assembly.max_iterations = static_cast<int>(v.integer(1, 10000));
  if (auto v = c.field("line_search"); v.present()) o.newton.line_search = v.boolean();
  if (auto v = c.field("max_subdivisions"); v.present()) o.max_subdivisions = static_cast<int>(v.integer(0, 30));
  if (auto v = c.field("newton"); v.present()) {
    const std::string s = v.text();
    if (s == "modified")
      o.newton.jacobian_update = JacobianUpdate::kWhenSlow;
    else if (s == "full")
      o.newton.jacobian_update = JacobianUpdate::kEveryIteration;
    else
      v.fail("newton is modified or full");
  }
  if (auto v = c.field("predictor"); v.present()) {
    if (!predictor_from_string(v.text(), &o.predictor)) v.fail(std::string("predictor is ") + predictor_names());
  }
  if (auto v = c.field("length_scale"); v.present()) builder_.set_length_scale(positive(v));
  if (auto v = c.field("linear_solver"); v.present()) {
    const std::string s = v.text();
    if (s == "umfpack")
      builder_.set_linear_solver(LinearSolverKind::kUmfpack);
    else if (s == "klu")
      builder_.set_linear_solver(LinearSolverKind::kKlu);
    else if (s == "dense")
      builder_.set_linear_solver(LinearSolverKind::kDense);
    else
      v.fail("linear_solver is umfpack, klu or dense");
  }
  pending_.predictor_given = c.field("predictor").present();
}

}  // namespace phiq::detail::scene

namespace phiq::detail::scene {

// `output.sensitivities`: parameters by name, or {parameter: NAME, step: H}. Their models along the parameter are
// built once the scene is read (parse_scene), from the same text with the parameter moved.
void SceneReader::output_sensitivities(const Cursor& c, OutputPlan& plan) {
  std::set<std::string> seen;
  for (const Cursor& i : c.items()) {
    // (a Cursor is never assigned: assigning a YAML::Node rewrites the node it refers to)
    if (i.is_map()) i.expect_map({"parameter", "step"});
    const Cursor name = i.is_map() ? i.require("parameter") : i;
    const Cursor step = i.is_map() ? i.field("step") : Cursor(YAML::Node(), i.join("step"), i.file(), i.mark());
    OutputSensitivity s;
    s.name = name.name();
    const auto it = names_.parameters.find(s.name);
    if (it == names_.parameters.end()) {
      std::vector<std::string> names;
      for (const auto& [n, v] : names_.parameters) names.push_back(n);
      name.fail("'" + s.name + "' is not a parameter of the scene" + parameters_note(names));
    }
    if (!seen.insert(s.name).second) name.fail("parameter '" + s.name + "' listed twice");
    s.value = it->second;
    s.step = step.present() ? number(step) : default_sensitivity_step(s.value);
    if (!(s.step > 0.0)) step.fail("the difference step must be positive");
    plan.sensitivities.push_back(std::move(s));
  }
}

}  // namespace phiq::detail::scene
