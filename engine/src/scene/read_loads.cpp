// The `loads` section (part_reader.hpp, models/README.md "Loads"): gravity, and the applied forces, torques,
// linear and torsional spring-dampers (phiq/applied_loads.hpp), on the scene's parts or on its bodies. Read after
// the parts, whose frames the loads act on.
#include <cmath>
#include <set>

#include "phiq/applied_loads.hpp"
#include "phiq/text.hpp"
#include "scene/family_expansion.hpp"
#include "scene/part_reader.hpp"
#include "solve/friction_losses.hpp"

namespace phiq::detail::scene {

namespace {

// A load's name, or its place ("loads.forces[1]") when it has none; refused when another load has it.
template <class C>
std::string load_name(const C& c, std::set<std::string>& names) {
  const auto n = c.field("name");
  if (!n.present()) return c.path();
  std::string name = n.name();
  if (!names.insert(name).second) n.fail("duplicate load name '" + name + "'");
  return name;
}

}  // namespace

void PartReader::read_loads(const Cursor& c, Scene& scene) const {
  c.expect_map({"gravity", "forces", "torques", "springs", "torsional_springs", "gear_losses"});
  if (auto g = c.field("gravity"); g.present()) {
    const std::vector<double> v = r_.numbers(g, r_.spatial_ ? 3 : 2);
    scene.loads.gravity = {v[0], v[1], r_.spatial_ ? v[2] : 0.0};
  }
  auto applied = std::make_shared<AppliedLoads>();
  std::set<std::string> names;
  LoadTargets targets{scene, {}};
  targets.parts.reserve(scene.parts.size());
  for (std::size_t i = 0; i < scene.parts.size(); ++i) targets.parts.emplace(scene.parts[i].name, i);
  // each list may hold families (`- for i in A..B: [...]`), as the constraints do
  if (auto fs = c.field("forces"); fs.present())
    r_.read_list(fs, [&](const auto& f) { applied->forces.push_back(applied_force(f, targets, names)); });
  if (auto ts = c.field("torques"); ts.present())
    r_.read_list(ts, [&](const auto& m) { applied->torques.push_back(applied_torque(m, targets, names)); });
  if (auto ss = c.field("springs"); ss.present())
    r_.read_list(ss, [&](const auto& s) { applied->springs.push_back(linear_spring(s, targets, names)); });
  if (auto ts = c.field("torsional_springs"); ts.present())
    r_.read_list(ts, [&](const auto& s) { applied->torsional_springs.push_back(torsional_spring(s, names)); });
  if (auto gs = c.field("gear_losses"); gs.present())
    r_.read_list(gs, [&](const auto& g) { applied->gear_losses.push_back(gear_loss(g)); });
  if (!applied->empty()) scene.loads.applied = std::move(applied);
}

template <class C>
AppliedForce PartReader::applied_force(const C& f, const LoadTargets& targets, std::set<std::string>& names) const {
  f.expect_map({"name", "part", "at", "force", "axes"});
  AppliedForce force;
  force.name = load_name(f, names);
  const auto part = f.require("part");
  force.part = part.name();
  force.frame = load_frame(part, targets, "a force");
  if (auto at = f.field("at"); at.present()) force.at = load_vector(at, "at");
  force.axes = load_axes(f.field("axes"));
  load_components(f.require("force"), "force", force.components);
  return force;
}

template <class C>
AppliedTorque PartReader::applied_torque(const C& m, const LoadTargets& targets, std::set<std::string>& names) const {
  m.expect_map({"name", "part", "torque", "axes"});
  AppliedTorque torque;
  torque.name = load_name(m, names);
  const auto part = m.require("part");
  torque.part = part.name();
  torque.frame = load_frame(part, targets, "a torque");
  torque.axes = load_axes(m.field("axes"));
  const auto value = m.require("torque");
  if (r_.spatial_) {
    load_components(value, "torque", torque.components);
  } else {
    if (value.is_sequence()) value.fail("a torque in the plane is one number, expression or law (about z)");
    torque.components[2] = load_component(value);
  }
  return torque;
}

// The frame of the part, body or ground that `c` names: a part of the scene first, else a body's own frame. With
// `what` (a force, a torque), one that reads no coordinate is refused: a load there does no virtual work (its
// points' ∂/∂q are 0) and would change no effort, silently, where the scene misnamed its part.
template <class C>
PartFrame PartReader::load_frame(const C& c, const LoadTargets& targets, const char* what) const {
  PartFrame f = load_frame(c, targets);
  if (what && frame_coordinates(f).empty())
    c.fail("'" + c.name() + "' reads no coordinate (it is fixed, or moves with t alone): " + what +
           " on it does no work on the coordinates and changes no effort");
  return f;
}

template <class C>
PartFrame PartReader::load_frame(const C& c, const LoadTargets& targets) const {
  const std::string n = c.name();
  if (const auto it = targets.parts.find(n); it != targets.parts.end()) return targets.scene.parts[it->second].frame;
  PartFrame f = ground_frame();
  if (n == kGround) return f;
  const Index b = r_.spatial_ ? r_.entry_at(c, n, r_.names_.bodies3) : r_.entry_at(c, n, r_.names_.bodies);
  if (b < 0) c.fail("unknown part '" + n + "' (no part nor body of the scene has that name)");
  if (r_.spatial_)
    f.spatial = r_.names_.bodies3[b];
  else
    f.planar = r_.names_.bodies[b];
  return f;
}

PartFrame PartReader::ground_frame() const {
  PartFrame f;
  f.kind = r_.spatial_ ? PartFrameKind::kSpatialBody : PartFrameKind::kPlanarBody;
  if (r_.spatial_) f.spatial = Frame3::ground();
  return f;
}

// A point or vector of constants, [x, y] in the plane, [x, y, z] in space.
template <class C>
kin3::V3 PartReader::load_vector(const C& c, const char* what) const {
  const std::size_t n = r_.spatial_ ? 3 : 2;
  if (!c.is_sequence() || c.size() != n)
    c.fail(std::string(what) + " is " + (r_.spatial_ ? "[x, y, z]" : "[x, y]") + " (numbers or constant expressions)");
  const std::vector<double> v = r_.numbers(c, n);
  return {v[0], v[1], r_.spatial_ ? v[2] : 0.0};
}

// A vector of expressions of t, the coordinates, their rates (der()) and the parameters, or laws of one; the
// plane's has no z.
template <class C>
void PartReader::load_components(const C& c, const char* what, std::array<LoadValue, 3>& out) const {
  const std::size_t n = r_.spatial_ ? 3 : 2;
  if (!c.is_sequence() || c.size() != n)
    c.fail(std::string(what) + " is " + (r_.spatial_ ? "[x, y, z]" : "[x, y]") +
           " (numbers, expressions of t, the coordinates, their rates der(…) and the parameters, or laws of one)");
  for (std::size_t k = 0; k < n; ++k) out[k] = load_component(c.at(k));
}

// A law's argument is an expression as a component is (t when `of` is absent): a table of a force measured
// against time, a crank angle, a stroke or a speed.
template <class C>
LoadValue PartReader::load_component(const C& c) const {
  if (!c.is_map()) return {r_.compile(c, true, true), {}};
  c.expect_map({"law", "of"});
  LoadValue v;
  v.law = r_.motion_law(c.require("law"));
  const auto of = c.field("of");
  // (`t` itself compiled once: a family of 10⁴ loads would compile it symbolically for each)
  static const std::shared_ptr<const CompiledExpression> time =
      CompiledExpression::compile("t", [](const std::string& n) -> std::optional<NameBinding> {
        if (n == "t") return NameBinding{NameBinding::Kind::kTime};
        return std::nullopt;
      });
  v.expr = of.present() ? r_.compile(of, true, true) : time;
  return v;
}

template <class C>
LoadAxes PartReader::load_axes(const C& c) const {
  if (!c.present()) return LoadAxes::kWorld;
  const std::string s = c.text();
  if (s == "world") return LoadAxes::kWorld;
  if (s == "part") return LoadAxes::kPart;
  c.fail("axes is world or part, got '" + s + "'");
}

template <class C>
double PartReader::non_negative(const C& c) const {
  const double v = r_.number(c);
  if (v < 0.0) c.fail("must not be negative, got " + c.text());
  return v;
}

// A spring's `stiffness`, or its `law` of the deflection (a motion law's map), one of them; neither where it has
// other terms (`other`: an actuator's `tension` or `moment`, a `damping`, `friction` or `inertia`): a damper, a
// rotor. Returns whether it has a stiffness.
template <class C>
bool PartReader::spring_stiffness(const C& s, double& stiffness, MotionLaw& law, bool other) const {
  const auto k = s.field("stiffness"), l = s.field("law");
  if (k.present() && l.present()) l.fail("a spring has a stiffness or a law of its deflection, not both");
  if (l.present()) {
    law = r_.motion_law(l);
    return false;
  }
  if (other && !k.present()) return false;
  stiffness = non_negative(s.require("stiffness"));
  return true;
}

// A torsional spring-damper on `coordinate: NAME`, `angle: EXPRESSION` of the coordinates, or a spatial `joint`'s
// angle.
template <class C>
TorsionalSpring PartReader::torsional_spring(const C& s, std::set<std::string>& names) const {
  s.expect_map({"name", "coordinate", "angle", "joint", "stiffness", "law", "moment", "free_angle", "damping",
                "friction", "inertia", "bearing"});
  TorsionalSpring spring;
  spring.name = load_name(s, names);
  const auto on_coordinate = s.field("coordinate"), angle = s.field("angle"), joint = s.field("joint");
  if (on_coordinate.present() + angle.present() + joint.present() != 1)
    s.fail("a torsional spring acts on one of `coordinate: NAME`, `angle: EXPRESSION` or `joint: NAME`");
  if (on_coordinate.present()) {
    const std::string n = r_.builder_.coordinate_name(r_.coordinate(on_coordinate));
    spring.angle = CompiledExpression::compile(n, r_.resolver(true, n), false);
  } else if (angle.present()) {
    spring.angle = r_.compile(angle, false);
    if (spring.angle->coordinates().empty()) angle.fail("the angle reads no coordinate: the spring exerts nothing");
  } else {
    const std::string n = joint.name();
    if (!r_.spatial_) joint.fail("a joint's angle is a spatial joint's; in the plane write the `angle` of coordinates");
    const auto it = r_.names_.joints3.find(n);
    if (it == r_.names_.joints3.end()) joint.fail("unknown joint '" + n + "' (a named spatial joint of 'constraints')");
    if (!it->second.traits.measures.angle)
      joint.fail("joint '" + n + "' is a " + it->second.type + ": it has no angle");
    try {
      spring.joint = output_joint(n, JointMeasure::kAngle, it->second.a, it->second.b);
    } catch (const Error& e) {
      joint.fail(e.what());
    }
    std::set<Index> read;
    for (const Attachment3& a : spring.joint->att) {
      for (const Slot& k : a.r)
        if (k.is_coordinate()) read.insert(k.coord());
      for (const Slot& k : a.p)
        if (k.is_coordinate()) read.insert(k.coord());
    }
    spring.joint_coordinates.assign(read.begin(), read.end());
  }
  if (auto m = s.field("moment"); m.present()) spring.moment = load_component(m);
  spring_stiffness(s, spring.stiffness, spring.law,
                   spring.moment.expr || s.field("damping").present() || s.field("friction").present() ||
                       s.field("inertia").present() || s.field("bearing").present());
  if (auto a0 = s.field("free_angle"); a0.present()) spring.free_angle = r_.number(a0);
  if (auto d = s.field("damping"); d.present()) spring.damping = non_negative(d);
  if (auto f = s.field("friction"); f.present()) spring.friction = non_negative(f);
  if (auto j = s.field("inertia"); j.present()) spring.inertia = non_negative(j);
  if (auto b = s.field("bearing"); b.present()) {
    b.expect_map({"joint", "coefficient", "radius", "thrust_radius", "moment_arm"});
    BearingFriction& f = spring.bearing.emplace();
    const auto on = b.field("joint");
    if (!on.present() && !joint.present())
      b.fail("a bearing names its `joint` (a pin, revolute, cylindrical or prismatic joint)");
    f.joint = on.present() ? on.name() : joint.name();
    const std::string_view kind = r_.builder_.constraint_kind(f.joint);
    // or a named point of the plane, where bodies' frames of points may meet (found with the model)
    const bool point = kind.empty() && !r_.spatial_ && r_.names_.points.contains(f.joint);
    if (point) {
      r_.keep_natural_points(), r_.pending_.natural_bearings = true;
      const auto& at = on.present() ? on : joint;
      r_.pending_.bearing_points.push_back({f.joint, at.path(), at.mark()});
    }
    if (!point && !FrictionLosses::carries(kind))
      (on.present() ? on : b)
          .fail((kind.empty() ? "unknown joint '" + f.joint + "'" : "'" + f.joint + "' is a " + std::string(kind)) +
                ": a bearing is a pin, revolute, cylindrical or prismatic joint of 'constraints' (whose reaction "
                "loads it), or a point two parts' frames share");
    f.coefficient = non_negative(b.require("coefficient"));
    // a slide (a prismatic pair, a cylindrical one along its travel) has no radius: its friction is a force
    const auto radius = b.field("radius");
    f.slide = kind == "prismatic" || (kind == "cylindrical" && !radius.present());
    if (kind == "prismatic" && radius.present())
      radius.fail("a prismatic pair slides: its friction is the force μ |F_r| along its travel, with no radius");
    if (!f.slide) f.radius = non_negative(b.require("radius"));
    if (auto a = b.field("thrust_radius"); a.present()) {
      if (!r_.spatial_) a.fail("a thrust collar carries a force along a spatial joint's axis: none in the plane");
      if (f.slide) a.fail("a slide's friction is a force, not a moment: it has no thrust collar");
      f.thrust_radius = non_negative(a);
    }
    if (auto a = b.field("moment_arm"); a.present()) {
      if (!r_.spatial_ && !f.slide)
        a.fail(
            "a pin in the plane carries no moment across its axis: a moment arm is a spatial journal's or a slide's");
      f.moment_arm = r_.number(a);
      if (!(f.moment_arm > 0.0 && std::isfinite(f.moment_arm))) a.fail("a moment arm is a positive length");
    }
  }
  return spring;
}

// A transmission's meshing losses: `{gear: NAME, efficiency: η, reverse_efficiency: η}` or, a worm pair's,
// `{gear: NAME, friction: μ}`.
template <class C>
GearLoss PartReader::gear_loss(const C& g) const {
  g.expect_map({"gear", "efficiency", "reverse_efficiency", "friction"});
  GearLoss l;
  const auto gear = g.require("gear");
  l.gear = gear.name();
  const std::string_view kind = r_.builder_.constraint_kind(l.gear);
  if (!FrictionLosses::transmits(kind))
    gear.fail((kind.empty() ? "unknown transmission '" + l.gear + "'" : "'" + l.gear + "' is a " + std::string(kind)) +
              ": meshing losses are a gear's, rack_pinion's, belt's or spatial_gear's of 'constraints'");
  if (const auto f = g.field("friction"); f.present()) {
    if (g.field("efficiency").present() || g.field("reverse_efficiency").present())
      f.fail("a worm's friction gives its efficiencies: give one or the other");
    if (kind != "spatial_gear") f.fail("a friction coefficient gives a worm pair's efficiencies (a spatial_gear)");
    l.friction = r_.number(f);
    if (!(l.friction > 0.0 && std::isfinite(l.friction))) f.fail("a friction coefficient is positive");
    return l;
  }
  const auto e = g.require("efficiency");
  l.efficiency = r_.number(e);
  if (!(l.efficiency > 0.0 && l.efficiency <= 1.0)) e.fail("an efficiency is in (0, 1], got " + shortest(l.efficiency));
  l.reverse_efficiency = l.efficiency;
  if (const auto r = g.field("reverse_efficiency"); r.present()) {
    l.reverse_efficiency = r_.number(r);
    if (!(l.reverse_efficiency <= 1.0 && std::isfinite(l.reverse_efficiency)))
      r.fail("a reverse efficiency is at most 1 (≤ 0: self-locking), got " + shortest(l.reverse_efficiency));
  }
  return l;
}

// A linear spring-damper: `between: [END, END]`, each {part: P, at: [..]} or {point: [..]} (fixed in the world).
template <class C>
LinearSpring PartReader::linear_spring(const C& s, const LoadTargets& targets, std::set<std::string>& names) const {
  s.expect_map({"name", "between", "stiffness", "law", "tension", "free_length", "damping", "preload", "friction"});
  LinearSpring spring;
  spring.name = load_name(s, names);
  const auto between = s.require("between");
  if (!between.is_sequence() || between.size() != 2)
    between.fail("between is two ends [{part: A, at: [..]}, {part: B, at: [..]} or {point: [..]}]");
  SpringEnd* ends[2] = {&spring.a, &spring.b};
  for (std::size_t k = 0; k < 2; ++k) {
    const auto e = between.at(k);
    e.expect_map({"part", "at", "point"});
    SpringEnd& end = *ends[k];
    if (auto p = e.field("point"); p.present()) {
      if (e.field("part").present() || e.field("at").present())
        p.fail("an end is {part: P, at: [..]} or a world {point: [..]}, not both");
      end.part = kGround;
      end.frame = ground_frame();
      end.at = load_vector(p, "point");
      continue;
    }
    const auto part = e.require("part");
    end.part = part.name();
    end.frame = load_frame(part, targets);
    if (auto at = e.field("at"); at.present()) end.at = load_vector(at, "at");
  }
  if (spring.a.part == spring.b.part && spring.a.at == spring.b.at)
    between.fail("the spring's two ends are the same point");
  if (frame_coordinates(spring.a.frame).empty() && frame_coordinates(spring.b.frame).empty())
    between.fail("neither end reads a coordinate: the spring does no work on the coordinates and changes no effort");
  if (auto f = s.field("tension"); f.present()) spring.tension = load_component(f);
  const bool stiff =
      spring_stiffness(s, spring.stiffness, spring.law,
                       spring.tension.expr || s.field("damping").present() || s.field("friction").present());
  if (auto l0 = stiff ? s.require("free_length") : s.field("free_length"); l0.present())
    spring.free_length = non_negative(l0);
  if (auto d = s.field("damping"); d.present()) spring.damping = non_negative(d);
  if (auto p = s.field("preload"); p.present()) spring.preload = r_.number(p);
  if (auto f = s.field("friction"); f.present()) spring.friction = non_negative(f);
  return spring;
}

}  // namespace phiq::detail::scene
