// The constraints section (scene_reader.hpp): read_constraint hands each entry to the kind of the registry that
// claims its type (kinds/registry.hpp), and the references a constraint is made of — points, segments, bodies,
// attachments of a pair, sides of a spatial joint, directions of a dot product — which the kinds read through
// KindFields (kind_fields.hpp).
#include <algorithm>
#include <array>
#include <concepts>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "phiq/constraint_kinds.hpp"
#include "scene/kind_fields.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

// A point reference: a point name or an inline [x, y].
template <class C>
Point2 SceneReader::point(const C& c) const {
  if (c.is_sequence()) {
    if (c.size() != 2) c.fail("an inline point is [x, y]");
    return Point2{slot(c.at(0)), slot(c.at(1))};
  }
  const std::string s = c.name();
  const Index k = entry_at(c, s, names_.points);
  if (k < 0) c.fail("unknown point '" + s + "'");
  return names_.points[k];
}

template <class C>
std::pair<Point2, Point2> SceneReader::segment(const C& c) const {
  if (!c.is_sequence() || c.size() != 2) c.fail("a segment is [from, to]");
  const Point2 from = point(c.at(0)), to = point(c.at(1));
  // a segment from a point to itself has no length and no direction, whatever its coordinates become: every kind
  // that reads one (distance, point_on_line, segment_angle, constant_angle) would be degenerate
  const auto same = [](Slot u, Slot v) {
    return u.is_coordinate() ? u.coord() == v.coord() : !v.is_coordinate() && u.value() == v.value();
  };
  // (two fixed ends are left to the kinds, which say "the same fixed point")
  const bool fixed =
      !from.x.is_coordinate() && !from.y.is_coordinate() && !to.x.is_coordinate() && !to.y.is_coordinate();
  if (!fixed && same(from.x, to.x) && same(from.y, to.y))
    c.fail("the segment's two ends are the same point" +
           (c.at(0).is_scalar() ? " '" + c.at(0).text() + "'" : std::string()) + ": it has no length nor direction");
  return {from, to};
}

template <class C>
Frame2 SceneReader::body(const C& c) const {
  const std::string s = c.name();
  if (s == kGround) return Frame2{Slot::constant(0), Slot::constant(0), Slot::constant(0)};
  const Index k = entry_at(c, s, names_.bodies);
  if (k < 0) c.fail("unknown body '" + s + "'");
  return names_.bodies[k];
}

// An attachment of a revolute or prismatic pair: {body: B, at: [x, y]} (local point) or {point: P}.
template <class C>
std::pair<Frame2, kin::V2> SceneReader::attachment(const C& c) const {
  if (!c.is_map()) c.fail("expected {body: NAME, at: [x, y]} or {point: NAME}");
  if (c.field("point").present()) {
    c.expect_map({"point"});
    Point2 p = point(c.field("point"));
    return {Frame2{p.x, p.y, Slot::constant(0.0)}, kin::V2{0, 0}};
  }
  if (auto axis = c.field("axis"); axis.present())  // where a spatial joint writes it
    axis.fail(
        "in dimension 2 a side has no axis: a revolute turns about z, and a prismatic's sliding axis is its "
        "own field (axis: [x, y], in the first body's frame) beside `between`");
  c.expect_map({"body", "at"});
  Frame2 f = body(c.require("body"));
  kin::V2 at{0, 0};
  if (auto a = c.field("at"); a.present()) at = vec2(a);
  return {f, at};
}

namespace {

// Whether a kind is written in the `constraints` section (some are drivers, or added with bodies and vectors).
template <class K>
constexpr bool read_as_constraint() {
  for (const SceneForm& f : K::kScene)
    if (std::string_view(f.section) == "constraints") return true;
  return false;
}
bool in_dimension(const SceneForm& f, int dimension) { return f.dimension == 0 || f.dimension == dimension; }

// The constraint types of one dimension, in registry order, for the message about an unknown one.
std::string constraint_types(int dimension) {
  std::vector<std::string_view> types;
  ConstraintKinds::for_each([&]<class K>() {
    for (const SceneForm& f : K::kScene)
      if (std::string_view(f.section) == "constraints" && in_dimension(f, dimension) &&
          std::find(types.begin(), types.end(), f.type) == types.end())
        types.push_back(f.type);
  });
  std::string list;
  for (std::string_view t : types) list += (list.empty() ? "" : ", ") + std::string(t);
  return list;
}
}  // namespace

// The kinds that read constraint entries, by type, one table per dimension (built once, from the registry).
template <class C>
const std::unordered_map<std::string, SceneReader::KindReader<C>>& SceneReader::kind_readers(bool spatial) {
  static const auto tables = [] {
    std::array<std::unordered_map<std::string, KindReader<C>>, 2> t;
    ConstraintKinds::for_each([&]<class K>() {
      if constexpr (read_as_constraint<K>()) {
        for (const SceneForm& f : K::kScene) {
          if (std::string_view(f.section) != "constraints") continue;
          for (int d : {2, 3})
            if (in_dimension(f, d)) t[d == 3].try_emplace(f.type, &SceneReader::read_kind<K, C>);
        }
      }
    });
    return t;
  }();
  return tables[spatial];
}

// One entry read by kind K (its own read(), in the scene vocabulary of kind_fields.hpp) and added to the model.
template <class K, class C>
void SceneReader::read_kind(const C& c, const std::string& type, const std::string& name) {
  K spec = K::read(KindFields<C>(*this, c, type));
  if constexpr (SpatialJointKind<K>)  // kept by name, for the drivers, outputs and shafts that refer to it
    if (!name.empty()) names_.joints3[name] = Joint3{type, joint_traits<K>(), spec.a, spec.b};
  add(c, name, std::move(spec));
}

// A constraint is read by the kind that claims its type in the scene's dimension (kinds/registry.hpp).
template <class C>
void SceneReader::read_constraint(const C& c) {
  if (!c.is_map()) c.fail("a constraint is a mapping with a 'type'");
  const std::string type = c.require("type").text();
  std::string name;
  if (auto n = c.field("name"); n.present()) name = n.name();
  const auto& readers = kind_readers<C>(spatial_);
  const auto it = readers.find(type);
  if (it == readers.end()) {
    if (kind_readers<C>(!spatial_).count(type))
      c.require("type").fail("'" + type +
                             (spatial_ ? "' is a planar constraint; this scene has 'dimension: 3'"
                                       : "' is a spatial constraint: it needs 'dimension: 3'"));
    c.require("type").fail("unknown constraint type '" + type + "' (" + (spatial_ ? "dimension 3: " : "") +
                           constraint_types(spatial_ ? 3 : 2) + ")");
  }
  try {
    (this->*(it->second))(c, type, name);
  } catch (const Error& e) {
    c.fail(e.what());
  }
}

// A spatial point reference: a point name or an inline [x, y, z].
template <class C>
Point3 SceneReader::point3(const C& c) const {
  if (c.is_sequence()) {
    if (c.size() != 3) c.fail("an inline point is [x, y, z] (dimension: 3)");
    return Point3{slot(c.at(0)), slot(c.at(1)), slot(c.at(2))};
  }
  const std::string s = c.name();
  const Index k = entry_at(c, s, names_.points3);
  if (k < 0) c.fail("unknown point '" + s + "'");
  return names_.points3[k];
}

template <class C>
Point3 SceneReader::vector3(const C& c) const {
  const std::string s = c.name();
  const Index k = entry_at(c, s, names_.vectors);
  if (k < 0) c.fail("unknown vector '" + s + "'");
  return names_.vectors[k];
}

template <class C>
Frame3 SceneReader::body3(const C& c) const {
  const std::string s = c.name();
  if (s == kGround) return Frame3::ground();
  const Index k = entry_at(c, s, names_.bodies3);
  if (k < 0) c.fail("unknown body '" + s + "'");
  return names_.bodies3[k];
}

// A non-zero finite direction.
template <class C>
kin3::V3 SceneReader::direction3(const C& c) const {
  const kin3::V3 v = vec3(c);
  if (kin3::is_zero(v)) c.fail("must not be the zero vector");
  return v;
}

// A side of a spatial joint: {body: B, at: [x, y, z], axis: [..], ref: [..]} or {point: P, vector: u}.
template <class C>
JointSide3 SceneReader::side3(const C& c) const {
  if (!c.is_map())
    c.fail("expected {body: NAME, at: [x, y, z], axis: [x, y, z], ref: [x, y, z]} or {point: NAME, vector: NAME}");
  if (c.field("point").present()) {
    c.expect_map({"point", "vector"});
    std::optional<Point3> v;
    if (auto u = c.field("vector"); u.present()) v = vector3(u);
    return JointSide3::natural_point(point3(c.field("point")), v);
  }
  c.expect_map({"body", "at", "axis", "ref"});
  JointSide3 s = JointSide3::body(body3(c.require("body")), kin3::V3{});
  if (auto a = c.field("at"); a.present()) s.at = vec3(a);
  if (auto a = c.field("axis"); a.present()) s.axis = direction3(a);
  if (auto r = c.field("ref"); r.present()) s.ref = direction3(r);
  return s;
}

template <class C>
std::pair<JointSide3, JointSide3> SceneReader::sides3(const C& c, const std::string& type) const {
  auto between = c.require("between");
  if (!between.is_sequence() || between.size() != 2) between.fail("a " + type + " joint joins two attachments");
  return {side3(between.at(0)), side3(between.at(1))};
}

// A direction of a dot product: a vector name, or a segment [A, B] of points (B − A).
template <class C>
std::pair<Attachment3, Attachment3> SceneReader::dot_direction(const C& c, Unit& unit) const {
  if (c.is_sequence()) {
    if (c.size() != 2) c.fail("a direction is a vector name or a segment [A, B]");
    unit = Unit::kLength;
    return {Attachment3::natural(point3(c.at(1))), Attachment3::natural(point3(c.at(0)))};
  }
  unit = Unit::kNone;
  return {Attachment3::natural(vector3(c)), Attachment3::zero()};
}

// The constraint readers, and the references they read (points, bodies, attachments, sides), for plain entries
// and family members; body() and body3() also serve the output points.
template void SceneReader::read_constraint(const Cursor&);
template void SceneReader::read_constraint(const TCursor&);
template Point2 SceneReader::point(const Cursor&) const;
template Point2 SceneReader::point(const TCursor&) const;
template std::pair<Point2, Point2> SceneReader::segment(const Cursor&) const;
template std::pair<Point2, Point2> SceneReader::segment(const TCursor&) const;
template Frame2 SceneReader::body(const Cursor&) const;
template Frame2 SceneReader::body(const TCursor&) const;
template std::pair<Frame2, kin::V2> SceneReader::attachment(const Cursor&) const;
template std::pair<Frame2, kin::V2> SceneReader::attachment(const TCursor&) const;
template Point3 SceneReader::point3(const Cursor&) const;
template Point3 SceneReader::point3(const TCursor&) const;
template Point3 SceneReader::vector3(const Cursor&) const;
template Point3 SceneReader::vector3(const TCursor&) const;
template Frame3 SceneReader::body3(const Cursor&) const;
template Frame3 SceneReader::body3(const TCursor&) const;
template kin3::V3 SceneReader::direction3(const Cursor&) const;
template kin3::V3 SceneReader::direction3(const TCursor&) const;
template JointSide3 SceneReader::side3(const Cursor&) const;
template JointSide3 SceneReader::side3(const TCursor&) const;
template std::pair<JointSide3, JointSide3> SceneReader::sides3(const Cursor&, const std::string&) const;
template std::pair<JointSide3, JointSide3> SceneReader::sides3(const TCursor&, const std::string&) const;
template std::pair<Attachment3, Attachment3> SceneReader::dot_direction(const Cursor&, Unit&) const;
template std::pair<Attachment3, Attachment3> SceneReader::dot_direction(const TCursor&, Unit&) const;

}  // namespace phiq::detail::scene
