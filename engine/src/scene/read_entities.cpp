// The sections that define names (scene_reader.hpp): parameters, coordinates, points, bodies and natural unit
// vectors, plain entries and family members, each checked for a valid and unused name.
#include <algorithm>
#include <cmath>
#include <limits>

#include "phiq/text.hpp"
#include "scene/family_expansion.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

// An override that names no parameter: located where the names were given (a batch header) when the caller says
// where, else in the scene.
void SceneReader::unknown_override(const Cursor& c, const std::string& name) const {
  if (overrides_->parameters_source.empty())
    c.fail("'" + name + "' (given for this run) is not a parameter of the scene");
  std::vector<std::string> names;
  for (const auto& [n, v] : parameters_) names.push_back(n);
  std::sort(names.begin(), names.end());
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  throw SceneError(single_line(overrides_->parameters_source + ": '" + name + "' is not a parameter of " + file_ +
                               (list.empty() ? " (it has none)" : " (its parameters: " + list + ")")));
}

void SceneReader::read_parameters(const Cursor& c) {
  if (!c.present()) {
    if (overrides_ && !overrides_->parameters.empty()) unknown_override(c, overrides_->parameters[0].first);
    return;
  }
  for (auto& [name, key_mark, value] : c.entries()) {
    if (!valid_name(name)) value.fail("'" + name + "' is not a valid parameter name");
    if (name == "t" || name == "pi") value.fail("'" + name + "' is reserved");
    parameters_[name] = number(value);  // may use the parameters above it
    if (overrides_)
      for (const auto& [n, v] : overrides_->parameters)
        if (n == name) parameters_[name] = v;
  }
  if (overrides_)
    for (const auto& [n, v] : overrides_->parameters)
      if (!parameters_.count(n)) unknown_override(c, n);
}

void SceneReader::read_coordinates(const Cursor& c) {
  const auto entries = c.entries();
  if (entries.empty()) c.fail("at least one coordinate is needed");
  reserve_ = [&](std::size_t more) { builder_.reserve(static_cast<Index>(more), 0); };
  read_map(entries, [&](const std::string& name, const auto& value) {
    if (!valid_name(name)) value.fail("'" + name + "' is not a valid coordinate name");
    if (name == "t" || name == "pi") value.fail("'" + name + "' is reserved");
    if (parameters_.count(name)) value.fail("'" + name + "' is already a parameter");
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
  const bool taken = points3_.contains(name) || bodies3_.contains(name) || vectors_.contains(name);
  const Index k = taken ? -1 : table.add(name);
  if (k < 0) where.fail("duplicate point, body or vector name '" + name + "'");
  return k;
}

void SceneReader::read_points(const Cursor& c) {
  if (spatial_) {
    reserve_ = [&](std::size_t more) { points3_.reserve(more); };
    read_map(c.entries(), [&](const std::string& name, const auto& value) {
      const Index k = new_entity3(value, name, points3_);
      if (value.size() != 3 || !value.is_sequence()) value.fail("a point is [x, y, z] (dimension: 3)");
      points3_[k] = Point3{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
    });
    return;
  }
  reserve_ = [&](std::size_t more) { points_.reserve(more); };
  read_map(c.entries(), [&](const std::string& name, const auto& value) {
    const Index k = new_entity(value, name, points_, bodies_);
    if (value.size() != 2 || !value.is_sequence()) value.fail("a point is [x, y]");
    points_[k] = Point2{slot(value.at(0)), slot(value.at(1))};
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

// Bodies that move are recorded for the Grübler–Kutzbach count (a body of constants is a fixed frame, as ground);
// a spatial body's Euler normalisation `NAME.euler` is added with it.
void SceneReader::read_bodies(const Cursor& c) {
  if (spatial_) {
    reserve_ = [&](std::size_t more) { bodies3_.reserve(more); };
    read_map(c.entries(), [&](const std::string& name, const auto& value) {
      if (name == kGround) value.fail("'ground' is predefined (the fixed frame)");
      const Index k = new_entity3(value, name, bodies3_);
      if (value.size() != 7 || !value.is_sequence()) value.fail("a body is [x, y, z, e0, e1, e2, e3] (dimension: 3)");
      Slot v[7];
      for (int i = 0; i < 7; ++i) v[i] = slot(value.at(static_cast<std::size_t>(i)));
      Frame3 f{v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
      if (f.is_fixed()) fixed_euler_parameters(value, f);
      bodies3_[k] = f;
      if (!f.is_fixed()) {
        try {
          builder_.add_body(name, f);
          spatial_bodies_.push_back(f);
        } catch (const Error& e) {
          value.fail(e.what());
        }
      }
    });
    return;
  }
  reserve_ = [&](std::size_t more) { bodies_.reserve(more); };
  read_map(c.entries(), [&](const std::string& name, const auto& value) {
    if (name == kGround) value.fail("'ground' is predefined (the fixed frame)");
    const Index k = new_entity(value, name, bodies_, points_);
    if (value.size() != 3 || !value.is_sequence()) value.fail("a body is [x, y, psi]");
    const Frame2 f{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
    bodies_[k] = f;
    if (f.x.is_coordinate() || f.y.is_coordinate() || f.psi.is_coordinate()) {
      builder_.add_body(name, f);
      planar_bodies_.push_back(f);
    }
  });
}

// Natural unit vectors (dimension 3), each with its unit-norm constraint `NAME.unit`.
void SceneReader::read_vectors(const Cursor& c) {
  reserve_ = [&](std::size_t more) { vectors_.reserve(more); };
  read_map(c.entries(), [&](const std::string& name, const auto& value) {
    const Index k = new_entity3(value, name, vectors_);
    if (value.size() != 3 || !value.is_sequence()) value.fail("a vector is [ux, uy, uz]");
    const Point3 u{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
    vectors_[k] = u;
    try {
      builder_.add_unit_vector(name, u);
    } catch (const Error& e) {
      value.fail(e.what());
    }
  });
}

}  // namespace phiq::detail::scene
