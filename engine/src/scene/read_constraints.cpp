// The constraints section (scene_reader.hpp): the planar readers (read_constraint) and the spatial ones
// (read_constraint_3d, add_joint3), with the references a constraint is made of — points, segments, bodies,
// attachments of a pair, sides of a spatial joint, directions of a dot product. One file, so that the reading of
// constraint kinds can be replaced as a whole.
#include <set>
#include <tuple>

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
  const Index k = entry_at(c, s, points_);
  if (k < 0) c.fail("unknown point '" + s + "'");
  return points_[k];
}

template <class C>
std::pair<Point2, Point2> SceneReader::segment(const C& c) const {
  if (!c.is_sequence() || c.size() != 2) c.fail("a segment is [from, to]");
  return {point(c.at(0)), point(c.at(1))};
}

template <class C>
Frame2 SceneReader::body(const C& c) const {
  const std::string s = c.name();
  if (s == kGround) return Frame2{Slot::constant(0), Slot::constant(0), Slot::constant(0)};
  const Index k = entry_at(c, s, bodies_);
  if (k < 0) c.fail("unknown body '" + s + "'");
  return bodies_[k];
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
  c.expect_map({"body", "at"});
  Frame2 f = body(c.require("body"));
  kin::V2 at{0, 0};
  if (auto a = c.field("at"); a.present()) at = vec2(a);
  return {f, at};
}

template <class C>
void SceneReader::read_constraint(const C& c) {
  if (!c.is_map()) c.fail("a constraint is a mapping with a 'type'");
  const std::string type = c.require("type").text();
  std::string name;
  if (auto n = c.field("name"); n.present()) name = n.name();
  if (spatial_) return read_constraint_3d(c, type, name);
  static const std::set<std::string> spatial_only = {"spherical", "cylindrical", "universal", "planar",
                                                     "rigid",     "point_on_plane", "dot"};
  if (spatial_only.count(type))
    c.require("type").fail("'" + type + "' is a spatial constraint: it needs 'dimension: 3'");
  try {
    if (type == "distance") {
      c.expect_map({"type", "name", "points", "length"});
      auto [a, b] = segment(c.require("points"));
      add(c, name, DistanceSpec{a, b, positive(c.require("length"))});
    } else if (type == "fixed_point") {
      c.expect_map({"type", "name", "point", "at"});
      Point2 p = point(c.require("point"));
      kin::V2 at = vec2(c.require("at"));
      add(c, name, PinSpec{Frame2{p.x, p.y, Slot::constant(0)},
                           Frame2{Slot::constant(at.x), Slot::constant(at.y), Slot::constant(0)}, {0, 0}, {0, 0}});
    } else if (type == "point_on_line") {
      c.expect_map({"type", "name", "point", "line"});
      auto [a, b] = segment(c.require("line"));
      add(c, name, PointOnLineSpec{point(c.require("point")), a, b, 1.0});
    } else if (type == "constant_angle") {
      c.expect_map({"type", "name", "segments", "angle"});
      auto segs = c.require("segments");
      if (!segs.is_sequence() || segs.size() != 2) segs.fail("expected two segments [[A, B], [C, D]]");
      auto [a, b] = segment(segs.at(0));
      auto [cc, d] = segment(segs.at(1));
      add(c, name, ConstantAngleSpec{a, b, cc, d, number(c.require("angle")), 1.0});
    } else if (type == "segment_angle") {
      c.expect_map({"type", "name", "segment", "angle"});
      auto [a, b] = segment(c.require("segment"));
      add(c, name, SegmentAngleSpec{a, b, Slot::coordinate(coordinate(c.require("angle")))});
    } else if (type == "polar") {
      c.expect_map({"type", "name", "point", "origin", "length", "angle"});
      add(c, name, PolarSpec{point(c.require("point")), point(c.require("origin")), number(c.require("length")),
                             slot(c.require("angle"))});
    } else if (type == "revolute") {
      c.expect_map({"type", "name", "between"});
      auto between = c.require("between");
      if (!between.is_sequence() || between.size() != 2) between.fail("a revolute joins two attachments");
      auto [fa, sa] = attachment(between.at(0));
      auto [fb, sb] = attachment(between.at(1));
      add(c, name, PinSpec{fa, fb, sa, sb});
    } else if (type == "prismatic") {
      c.expect_map({"type", "name", "between", "axis", "angle"});
      auto between = c.require("between");
      if (!between.is_sequence() || between.size() != 2) between.fail("a prismatic pair joins two attachments");
      auto [fa, sa] = attachment(between.at(0));
      auto [fb, sb] = attachment(between.at(1));
      if (!fa.psi.is_coordinate() && !fb.psi.is_coordinate() && !between.at(0).field("body").present())
        between.fail("a prismatic pair needs bodies");
      PrismaticSpec spec{fa, fb, sa, sb, {1, 0}, 0.0};
      if (auto ax = c.field("axis"); ax.present()) spec.axis = vec2(ax);
      if (auto an = c.field("angle"); an.present()) spec.angle = number(an);
      if (spec.axis.x == 0.0 && spec.axis.y == 0.0) c.field("axis").fail("the axis must not be zero");
      add(c, name, spec);
    } else if (type == "loop") {
      c.expect_map({"type", "name", "links", "closure"});
      LoopSpec spec;
      for (const auto& l : c.require("links").items()) {
        l.expect_map({"length", "angles", "offset"});
        LoopSpec::Link link;
        link.length = slot(l.require("length"));
        if (auto o = l.field("offset"); o.present()) link.offset = number(o);
        if (auto as = l.field("angles"); as.present()) {
          for (const auto& a : as.items()) {
            std::string s = a.text();
            double sign = 1.0;
            if (!s.empty() && (s[0] == '-' || s[0] == '+')) sign = s[0] == '-' ? -1.0 : 1.0, s = s.substr(1);
            Index j = builder_.find_coordinate(s);
            if (j < 0) a.fail("unknown coordinate '" + s + "'");
            link.terms.push_back({Slot::coordinate(j), sign});
          }
        }
        spec.links.push_back(std::move(link));
      }
      if (spec.links.empty()) c.require("links").fail("a loop needs at least one link");
      if (auto cl = c.field("closure"); cl.present()) spec.closure = vec2(cl);
      add(c, name, std::move(spec));
    } else if (type == "equation") {
      c.expect_map({"type", "name", "expr", "unit"});
      EquationSpec spec{compile(c.require("expr"), true), std::nullopt, unit(c.field("unit"))};
      add(c, name, std::move(spec));
    } else {
      c.require("type").fail("unknown constraint type '" + type +
                             "' (distance, fixed_point, point_on_line, constant_angle, segment_angle, polar, "
                             "revolute, prismatic, loop, equation)");
    }
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
  const Index k = entry_at(c, s, points3_);
  if (k < 0) c.fail("unknown point '" + s + "'");
  return points3_[k];
}

template <class C>
Point3 SceneReader::vector3(const C& c) const {
  const std::string s = c.name();
  const Index k = entry_at(c, s, vectors_);
  if (k < 0) c.fail("unknown vector '" + s + "'");
  return vectors_[k];
}

template <class C>
Frame3 SceneReader::body3(const C& c) const {
  const std::string s = c.name();
  if (s == kGround) return Frame3::ground();
  const Index k = entry_at(c, s, bodies3_);
  if (k < 0) c.fail("unknown body '" + s + "'");
  return bodies3_[k];
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
  if (!c.is_map()) c.fail("expected {body: NAME, at: [x, y, z], axis: [x, y, z], ref: [x, y, z]} or {point: NAME, vector: NAME}");
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

template <class Spec, class C>
void SceneReader::add_joint3(const C& c, const std::string& name, const std::string& type) {
  c.expect_map({"type", "name", "between"});
  Spec spec;
  std::tie(spec.a, spec.b) = sides3(c, type);
  if (!name.empty()) joints3_[name] = Joint3{type, spec.a, spec.b};
  add(c, name, std::move(spec));
}

template <class C>
void SceneReader::read_constraint_3d(const C& c, const std::string& type, const std::string& name) {
  try {
    if (type == "distance") {
      c.expect_map({"type", "name", "points", "between", "length"});
      SpatialDistanceSpec spec;
      if (c.field("points").present() == c.field("between").present())
        c.fail("a distance has either 'points' (natural points) or 'between' (attachments)");
      if (auto pts = c.field("points"); pts.present()) {
        if (!pts.is_sequence() || pts.size() != 2) pts.fail("a distance joins two points [A, B]");
        spec.ends[0] = Attachment3::natural(point3(pts.at(0)));
        spec.ends[1] = Attachment3::natural(point3(pts.at(1)));
      } else {
        auto [a, b] = sides3(c, "distance");
        spec.ends[0] = Attachment3::body_point(a.frame, a.at);
        spec.ends[1] = Attachment3::body_point(b.frame, b.at);
      }
      spec.length = positive(c.require("length"));
      add(c, name, spec);
    } else if (type == "fixed_point") {
      c.expect_map({"type", "name", "point", "at"});
      SphericalSpec spec;
      spec.a = JointSide3::natural_point(point3(c.require("point")));
      spec.b = JointSide3::body(Frame3::ground(), vec3(c.require("at")));
      add(c, name, std::move(spec));
    } else if (type == "dot") {
      c.expect_map({"type", "name", "directions", "value"});
      auto dirs = c.require("directions");
      if (!dirs.is_sequence() || dirs.size() != 2) dirs.fail("a dot product has two directions [D1, D2]");
      DotSpec spec;
      std::tie(spec.ends[0], spec.ends[1]) = dot_direction(dirs.at(0), spec.end_units[0]);
      std::tie(spec.ends[2], spec.ends[3]) = dot_direction(dirs.at(1), spec.end_units[1]);
      spec.value = number(c.require("value"));
      add(c, name, spec);
    } else if (type == "spherical") {
      add_joint3<SphericalSpec>(c, name, type);
    } else if (type == "revolute") {
      add_joint3<SpatialRevoluteSpec>(c, name, type);
    } else if (type == "prismatic") {
      add_joint3<SpatialPrismaticSpec>(c, name, type);
    } else if (type == "cylindrical") {
      add_joint3<CylindricalSpec>(c, name, type);
    } else if (type == "universal") {
      add_joint3<UniversalSpec>(c, name, type);
    } else if (type == "planar") {
      add_joint3<PlanarSpec>(c, name, type);
    } else if (type == "rigid") {
      add_joint3<RigidSpec>(c, name, type);
    } else if (type == "point_on_line") {
      add_joint3<SpatialPointOnLineSpec>(c, name, type);
    } else if (type == "point_on_plane") {
      add_joint3<PointOnPlaneSpec>(c, name, type);
    } else if (type == "equation") {
      c.expect_map({"type", "name", "expr", "unit"});
      add(c, name, EquationSpec{compile(c.require("expr"), true), std::nullopt, unit(c.field("unit"))});
    } else if (type == "polar" || type == "segment_angle" || type == "constant_angle" || type == "loop") {
      c.require("type").fail("'" + type + "' is a planar constraint; this scene has 'dimension: 3'");
    } else {
      c.require("type").fail("unknown constraint type '" + type +
                             "' (dimension 3: distance, fixed_point, dot, spherical, revolute, prismatic, "
                             "cylindrical, universal, planar, rigid, point_on_line, point_on_plane, equation)");
    }
  } catch (const Error& e) {
    c.fail(e.what());
  }
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
