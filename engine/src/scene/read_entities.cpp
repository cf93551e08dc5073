// The sections that define names (scene_reader.hpp): parameters, coordinates, points, bodies and natural unit
// vectors, plain entries and family members, each checked for a valid and unused name.
#include <algorithm>
#include <cmath>
#include <limits>

#include "phiq/orientation.hpp"
#include "phiq/text.hpp"
#include "scene/family_expansion.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

// An override that names no parameter: located where the names were given (a batch header) when the caller says
// where, else in the scene.
std::string parameters_note(std::vector<std::string> names) {
  std::sort(names.begin(), names.end());
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  return list.empty() ? " (it has none)" : " (its parameters: " + list + ")";
}

void SceneReader::unknown_override(const Cursor& c, const std::string& name) const {
  if (overrides_->parameters_source.empty())
    c.fail("'" + name + "' (given for this run) is not a parameter of the scene");
  std::vector<std::string> names;
  for (const auto& [n, v] : names_.parameters) names.push_back(n);
  throw SceneError(single_line(overrides_->parameters_source + ": '" + name + "' is not a parameter of " + file_ +
                               parameters_note(names)));
}

void SceneReader::read_parameters(const Cursor& c) {
  if (!c.present()) {
    if (overrides_ && !overrides_->parameters.empty()) unknown_override(c, overrides_->parameters[0].first);
    return;
  }
  for (auto& [name, key_mark, value] : c.entries()) {
    if (!valid_name(name)) value.fail("'" + name + "' is not a valid parameter name");
    if (name == "t" || name == "pi") value.fail("'" + name + "' is reserved");
    names_.parameters[name] = number(value);  // may use the parameters above it
    names_.parameter_order.push_back(name);
    if (overrides_)
      for (const auto& [n, v] : overrides_->parameters)
        if (n == name) names_.parameters[name] = v;
  }
  if (overrides_)
    for (const auto& [n, v] : overrides_->parameters)
      if (!names_.parameters.count(n)) unknown_override(c, n);
}

void SceneReader::read_coordinates(const Cursor& c) {
  if (!c.present()) return;  // bodies written as maps may bring every coordinate (checked after them)
  const auto entries = c.entries();
  if (entries.empty()) c.fail("at least one coordinate is needed");
  reserve_ = [&](std::size_t more) { builder_.reserve(static_cast<Index>(more), 0); };
  read_map(entries, [&](const std::string& name, const auto& value) {
    if (!valid_name(name)) value.fail("'" + name + "' is not a valid coordinate name");
    if (name == "t" || name == "pi") value.fail("'" + name + "' is reserved");
    if (names_.parameters.count(name)) value.fail("'" + name + "' is already a parameter");
    const double v = number(value);
    try {
      builder_.add_coordinate(name, v);  // v is finite: a duplicate name is its only error
    } catch (const Error&) {
      value.fail("duplicate name '" + name + "'");
    }
  });
  if (builder_.num_coordinates() == 0) c.fail("at least one coordinate is needed");
}

// A new point or body: its index in `table`, after the checks (valid, not yet a point or a body).
template <class C, class T, class U>
Index SceneReader::new_entity(const C& where, const std::string& name, NameTable<T>& table, const NameTable<U>& other) {
  if (!valid_name(name)) where.fail("'" + name + "' is not a valid name");
  const Index k = other.contains(name) ? -1 : table.add(name);
  if (k < 0) where.fail("duplicate point or body name '" + name + "'");
  return k;
}

// A new spatial point, body or vector: its index in `table`, after the checks (valid, not yet any of them).
template <class C, class T>
Index SceneReader::new_entity3(const C& where, const std::string& name, NameTable<T>& table) {
  if (!valid_name(name)) where.fail("'" + name + "' is not a valid name");
  const bool taken = names_.points3.contains(name) || names_.bodies3.contains(name) || names_.vectors.contains(name);
  const Index k = taken ? -1 : table.add(name);
  if (k < 0) where.fail("duplicate point, body or vector name '" + name + "'");
  return k;
}

void SceneReader::read_points(const Cursor& c) {
  if (spatial_) {
    reserve_ = [&](std::size_t more) { names_.points3.reserve(more); };
    read_map(c.entries(), [&](const std::string& name, const auto& value) {
      const Index k = new_entity3(value, name, names_.points3);
      if (value.size() != 3 || !value.is_sequence()) value.fail("a point is [x, y, z] (dimension: 3)");
      names_.points3[k] = Point3{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
    });
    return;
  }
  reserve_ = [&](std::size_t more) { names_.points.reserve(more); };
  read_map(c.entries(), [&](const std::string& name, const auto& value) {
    const Index k = new_entity(value, name, names_.points, names_.bodies);
    if (value.size() != 2 || !value.is_sequence()) value.fail("a point is [x, y]");
    names_.points[k] = Point2{slot(value.at(0)), slot(value.at(1))};
  });
}

// A fixed frame's Euler parameters are data, not coordinates the assembly normalises: within kEulerNormSlack of
// unit norm (constants rounded to a few digits, cos(pi/8) written 0.9239) they are normalised, which keeps the
// rotation they mean; beyond, they would scale every attachment by |e|^2, so they are refused.
template <class C>
void SceneReader::fixed_euler_parameters(const C& value, Frame3& f) const {
  Slot* e[4] = {&f.e0, &f.e1, &f.e2, &f.e3};
  double norm2 = 0.0;
  for (Slot* s : e) norm2 += s->value() * s->value();
  const double norm = std::sqrt(norm2);
  if (std::abs(norm - 1.0) <= kEulerNormSlack) {
    if (std::abs(norm - 1.0) > 8 * std::numeric_limits<double>::epsilon())  // unit to rounding: kept as written
      for (Slot* s : e) *s = Slot::constant(s->value() / norm);
    return;
  }
  value.fail("the Euler parameters of a fixed frame [" + shortest(e[0]->value()) + ", " + shortest(e[1]->value()) +
             ", " + shortest(e[2]->value()) + ", " + shortest(e[3]->value()) + "] have norm " + significant(norm, 6) +
             "; they must have norm 1 (within " + significant(kEulerNormSlack, 1) +
             "): a rotation by angle a about the unit axis u is [cos(a/2), u sin(a/2)]");
}

// A body's `orientation` (dimension 3) as Euler parameters, from whichever one form the map uses.
template <class C>
EulerParameters SceneReader::orientation(const C& o) const {
  o.expect_map({"axis", "angle", "x", "y", "z", "euler", "angles", "euler_parameters"});
  const bool by_axis = o.field("axis").present() || o.field("angle").present();
  const bool by_axes = o.field("x").present() || o.field("y").present() || o.field("z").present();
  const bool by_sequence = o.field("euler").present() || o.field("angles").present();
  const bool by_parameters = o.field("euler_parameters").present();
  if (int(by_axis) + int(by_axes) + int(by_sequence) + int(by_parameters) != 1)
    o.fail(
        "an orientation is one of {axis: [ux, uy, uz], angle: a}, the world directions of one or two body axes "
        "{x: [..], z: [..]}, {euler: zyx, angles: [a, b, c]} or {euler_parameters: [e0, e1, e2, e3]}");
  auto array3 = [&](const auto& c) {
    const kin3::V3 v = vec3(c);
    return std::array<double, 3>{v.x, v.y, v.z};
  };
  try {
    if (by_axis) return euler_parameters_from_axis_angle(array3(o.require("axis")), number(o.require("angle")));
    if (by_sequence) {
      const auto seq = o.require("euler");
      if (!is_euler_sequence(seq.text()))
        seq.fail("'" + seq.text() +
                 "' is not an Euler sequence: three of x, y, z, no two neighbours equal "
                 "(zyx, xyz, zxz, ...), rotations about the axes as already rotated");
      return euler_parameters_from_sequence(seq.text(), array3(o.require("angles")));
    }
    if (by_parameters) {
      const std::vector<double> e = numbers(o.require("euler_parameters"), 4);
      const double n = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
      if (!(n > 0.0)) o.field("euler_parameters").fail("Euler parameters must not all be zero");
      return {e[0] / n, e[1] / n, e[2] / n, e[3] / n};
    }
    // The direction written first is followed exactly, the second only in its part perpendicular to the first.
    std::vector<std::pair<int, int>> given;  // (position in the file, axis)
    static const char* const kAxes[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k)
      if (auto d = o.field(kAxes[k]); d.present()) given.emplace_back(d.mark().pos, k);
    std::sort(given.begin(), given.end());
    if (given.size() == 3)
      o.field(kAxes[given[2].second]).fail("give the directions of at most two body axes (the third follows)");
    std::optional<std::pair<int, std::array<double, 3>>> second;
    if (given.size() == 2) second = std::make_pair(given[1].second, array3(o.field(kAxes[given[1].second])));
    return euler_parameters_from_axes(given[0].second, array3(o.field(kAxes[given[0].second])), second);
  } catch (const Error& e) {
    o.fail(e.what());
  }
}

// A body written as a map: {at: [x, y(, z)], angle: psi | orientation: {...}, fixed: false}. phiq adds its
// coordinates NAME_x, NAME_y, NAME_psi (planar) or NAME_x … NAME_z, NAME_e0 … NAME_e3 (spatial) with these values as
// initial guesses, or, `fixed: true`, makes it a frame of constants. `v` receives the frame's slots.
template <class C>
void SceneReader::body_from_map(const C& value, const std::string& name, Slot* v, int dimension) {
  if (dimension == 3)
    value.expect_map({"at", "orientation", "fixed"});
  else
    value.expect_map({"at", "angle", "fixed"});
  double initial[7] = {0, 0, 0, 1, 0, 0, 0};
  if (auto at = value.field("at"); at.present()) {
    const std::vector<double> p = numbers(at, static_cast<std::size_t>(dimension));
    std::copy(p.begin(), p.end(), initial);
  }
  if (dimension == 2) {
    initial[2] = value.field("angle").present() ? number(value.field("angle")) : 0.0;
  } else if (auto o = value.field("orientation"); o.present()) {
    const EulerParameters e = orientation(o);
    std::copy(e.begin(), e.end(), initial + 3);
  }
  const int n = dimension == 3 ? 7 : 3;
  const bool fixed = value.field("fixed").present() && value.field("fixed").boolean();
  static const char* const kPlanar[3] = {"x", "y", "psi"};
  static const char* const kSpatial[7] = {"x", "y", "z", "e0", "e1", "e2", "e3"};
  for (int i = 0; i < n; ++i) {
    if (fixed) {
      v[i] = Slot::constant(initial[i]);
      continue;
    }
    const std::string coordinate = name + "_" + (dimension == 3 ? kSpatial[i] : kPlanar[i]);
    if (names_.parameters.count(coordinate)) value.fail("its coordinate '" + coordinate + "' is already a parameter");
    try {
      v[i] = Slot::coordinate(builder_.add_coordinate(coordinate, initial[i]));
    } catch (const Error&) {
      value.fail("its coordinate '" + coordinate +
                 "' is already a coordinate (bodies written as maps name their "
                 "coordinates NAME_x, NAME_y, ...)");
    }
  }
}

// Bodies that move are recorded for the Grübler–Kutzbach count (a body of constants is a fixed frame, as ground);
// a spatial body's Euler normalisation `NAME.euler` is added with it.
void SceneReader::read_bodies(const Cursor& c) {
  if (spatial_) {
    reserve_ = [&](std::size_t more) { names_.bodies3.reserve(more); };
    read_map(c.entries(), [&](const std::string& name, const auto& value) {
      if (name == kGround) value.fail("'ground' is predefined (the fixed frame)");
      const Index k = new_entity3(value, name, names_.bodies3);
      Slot v[7];
      if (value.is_map()) {
        body_from_map(value, name, v, 3);
      } else {
        if (value.size() != 7 || !value.is_sequence())
          value.fail("a body is [x, y, z, e0, e1, e2, e3], or {at: [x, y, z], orientation: {...}} (dimension: 3)");
        for (int i = 0; i < 7; ++i) v[i] = slot(value.at(static_cast<std::size_t>(i)));
      }
      Frame3 f{v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
      if (f.is_fixed()) fixed_euler_parameters(value, f);
      names_.bodies3[k] = f;
      if (!f.is_fixed()) {
        try {
          builder_.add_body(name, f);
          names_.spatial_bodies.push_back(f);
        } catch (const Error& e) {
          value.fail(e.what());
        }
      }
    });
    return;
  }
  reserve_ = [&](std::size_t more) { names_.bodies.reserve(more); };
  read_map(c.entries(), [&](const std::string& name, const auto& value) {
    if (name == kGround) value.fail("'ground' is predefined (the fixed frame)");
    const Index k = new_entity(value, name, names_.bodies, names_.points);
    Slot v[3];
    if (value.is_map()) {
      body_from_map(value, name, v, 2);
    } else {
      if (value.size() != 3 || !value.is_sequence()) value.fail("a body is [x, y, psi], or {at: [x, y], angle: psi}");
      for (int i = 0; i < 3; ++i) v[i] = slot(value.at(static_cast<std::size_t>(i)));
    }
    const Frame2 f{v[0], v[1], v[2]};
    names_.bodies[k] = f;
    if (f.x.is_coordinate() || f.y.is_coordinate() || f.psi.is_coordinate()) {
      builder_.add_body(name, f);
      names_.planar_bodies.push_back(f);
    }
  });
}

// Natural unit vectors (dimension 3), each with its unit-norm constraint `NAME.unit`.
void SceneReader::read_vectors(const Cursor& c) {
  reserve_ = [&](std::size_t more) { names_.vectors.reserve(more); };
  read_map(c.entries(), [&](const std::string& name, const auto& value) {
    const Index k = new_entity3(value, name, names_.vectors);
    if (value.size() != 3 || !value.is_sequence()) value.fail("a vector is [ux, uy, uz]");
    const Point3 u{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
    names_.vectors[k] = u;
    try {
      builder_.add_unit_vector(name, u);
    } catch (const Error& e) {
      value.fail(e.what());
    }
  });
}

}  // namespace phiq::detail::scene
