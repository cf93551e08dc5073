// The drivers section (scene_reader.hpp): drivers of a coordinate, of an expression, or of a named spatial joint
// (its angle or its distance), each with its motion law.
#include "phiq/kinds/registry.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

// {joint: NAME, measure: angle | distance, law}: the rotation of a revolute, cylindrical or screw joint, the
// translation of a prismatic, cylindrical or screw one.
template <class C>
void SceneReader::read_joint_driver(const C& c, const std::string& name, MotionLaw law) {
  auto j = c.field("joint");
  if (!spatial_) j.fail("joint drivers need 'dimension: 3' (in the plane, drive a coordinate)");
  const std::string joint = j.name();
  auto it = names_.joints3.find(joint);
  if (it == names_.joints3.end()) j.fail("unknown joint '" + joint + "' (a named spatial joint of 'constraints')");
  const Joint3& J = it->second;
  const JointTraits::Coordinates drives = J.traits.drives;  // what its kind lets a driver drive
  std::string measure;
  if (auto m = c.field("measure"); m.present()) {
    measure = m.text();
    if (measure != "angle" && measure != "distance") m.fail("measure is angle or distance");
  } else if (drives.angle && drives.distance) {
    c.fail("a " + J.type + " joint's driver needs 'measure: angle' or 'measure: distance'");
  } else if (drives.angle) {
    measure = "angle";
  } else if (drives.distance) {
    measure = "distance";
  }
  if ((measure == "angle" && !drives.angle) || (measure == "distance" && !drives.distance) || measure.empty())
    j.fail("joint '" + joint + "' is a " + J.type + " joint: drivers measure the angle of a " +
           joint_type_list([](const JointTraits& t) { return t.drives.angle; }) + " joint, or the distance of a " +
           joint_type_list([](const JointTraits& t) { return t.drives.distance; }) + " one");
  if (measure == "angle") {
    const kin3::V3 ra = detail3::reference_direction(J.a), rb = detail3::reference_direction(J.b);
    names_.joint_angles.push_back(JointAngleReference{name.empty() ? c.path() : name,
                                                      joint,
                                                      {ra.x, ra.y, ra.z},
                                                      {rb.x, rb.y, rb.z},
                                                      J.a.ref.has_value(),
                                                      J.b.ref.has_value()});
    JointAngleDriverSpec d;
    d.a = J.a, d.b = J.b, d.law = std::move(law);
    add(c, name, std::move(d));
  } else {
    JointDistanceDriverSpec d;
    d.a = J.a, d.b = J.b, d.law = std::move(law);
    add(c, name, std::move(d));
  }
}

template <class C>
void SceneReader::read_driver(const C& c) {
  if (!c.is_map()) c.fail("a driver is a mapping with 'coordinate', 'expr' or 'joint', and a 'law'");
  c.expect_map({"name", "coordinate", "expr", "unit", "joint", "measure", "law"});
  std::string name;
  if (auto n = c.field("name"); n.present()) name = n.name();
  MotionLaw law = motion_law(c.require("law"));
  if (!name.empty()) pending_.driver_laws.emplace(name, law);  // for `output: drivers` (shared data: a cheap copy)
  const bool by_coordinate = c.field("coordinate").present(), by_expr = c.field("expr").present(),
             by_joint = c.field("joint").present();
  if (int(by_coordinate) + int(by_expr) + int(by_joint) != 1)
    c.fail("a driver has one of 'coordinate', 'expr' or 'joint'");
  if (c.field("measure").present() && !by_joint) c.field("measure").fail("'measure' goes with 'joint'");
  try {
    if (by_joint) {
      if (c.field("unit").present()) c.field("unit").fail("'unit' goes with 'expr' (a joint driver has its own)");
      read_joint_driver(c, name, std::move(law));
    } else if (by_coordinate) {
      if (c.field("unit").present()) c.field("unit").fail("'unit' goes with 'expr' (a coordinate has its own)");
      add(c, name, CoordinateDriverSpec{Slot::coordinate(coordinate(c.field("coordinate"))), std::move(law)});
    } else {
      add(c, name, EquationSpec{compile(c.field("expr"), false), std::move(law), unit(c.field("unit"))});
    }
  } catch (const Error& e) {
    c.fail(e.what());
  }
}

template <class C>
MotionLaw SceneReader::motion_law(const C& c) const {
  if (!c.is_map()) c.fail("a law is a mapping with a 'type'");
  const std::string type = c.require("type").text();
  try {
    if (type == "linear") {
      c.expect_map({"type", "initial", "rate"});
      return MotionLaw::linear(number(c.require("initial")), number(c.require("rate")));
    }
    if (type == "polynomial") {
      c.expect_map({"type", "coefficients"});
      auto v = numbers(c.require("coefficients"), 0);
      if (v.empty()) c.require("coefficients").fail("needs at least one coefficient");
      return MotionLaw::polynomial(v);
    }
    if (type == "harmonic") {
      c.expect_map({"type", "offset", "amplitude", "frequency", "phase"});
      double off = c.field("offset").present() ? number(c.field("offset")) : 0.0;
      double ph = c.field("phase").present() ? number(c.field("phase")) : 0.0;
      return MotionLaw::harmonic(off, number(c.require("amplitude")), number(c.require("frequency")), ph);
    }
    if (type == "table") {
      c.expect_map({"type", "t", "values", "periodic"});
      auto t = numbers(c.require("t"), 0), v = numbers(c.require("values"), 0);
      const bool periodic = c.field("periodic").present() && c.field("periodic").boolean();
      if (t.size() != v.size()) c.require("values").fail("needs as many values as times");
      if (t.size() < 2) c.require("t").fail("a table needs at least 2 points");
      for (std::size_t k = 1; k < t.size(); ++k)
        if (!(t[k] > t[k - 1])) c.require("t").at(k).fail("times must increase strictly");
      if (periodic && t.size() < 3) c.require("t").fail("a periodic table needs at least 3 points");
      if (periodic && v.back() != v.front())
        c.require("values").fail("a periodic table ends where it starts: its last value is not its first");
      return MotionLaw::table(t, v, periodic);
    }
    if (type == "expression") {
      c.expect_map({"type", "f"});
      auto f = c.require("f");
      std::shared_ptr<const CompiledExpression> expr;
      try {  // the message names the field, `law.f`
        if constexpr (kInFamily<C>) {
          expr = family_expression(f, true, false);
        } else {
          const std::string text = f.text();
          expr = CompiledExpression::compile(text, resolver(false, text));
        }
      } catch (const Error& e) {
        f.fail(e.what());
      }
      return MotionLaw::expression(expr);
    }
  } catch (const Error& e) {
    c.fail(e.what());
  }
  c.require("type").fail("unknown law type '" + type + "' (linear, polynomial, harmonic, table, expression)");
}

// Used by read() for plain entries and family members.
template void SceneReader::read_driver(const Cursor&);
template void SceneReader::read_driver(const TCursor&);
// and by the loads' components (read_loads.cpp)
template MotionLaw SceneReader::motion_law(const Cursor&) const;
template MotionLaw SceneReader::motion_law(const TCursor&) const;

}  // namespace phiq::detail::scene
