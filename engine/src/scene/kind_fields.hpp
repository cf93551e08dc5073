// The scene vocabulary a constraint kind reads itself with (kinds/kind_support.hpp, "The scene vocabulary of the
// kinds"): one entry of the `constraints` list, plain (Cursor) or a family member (TCursor), seen through the
// reader's tables of points, bodies and coordinates. Every read names its field, so that an error carries the
// file, line and field path; the wording of each message is the one the scene format documents.
#pragma once

#include <initializer_list>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "phiq/kinds/registry.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

template <class C>
class KindFields {
 public:
  KindFields(const SceneReader& reader, C entry, const std::string& type)
      : r_(reader), c_(std::move(entry)), type_(type) {}

  const std::string& type() const { return type_; }
  void expect(std::initializer_list<const char*> allowed) const { c_.expect_map(allowed); }
  bool present(const char* field) const { return c_.field(field).present(); }
  // `field` empty: the entry itself.
  [[noreturn]] void fail(const char* field, const std::string& what) const {
    if (*field == '\0') c_.fail(what);
    c_.field(field).fail(what);
  }

  double number(const char* field) const { return r_.number(c_.require(field)); }
  double positive(const char* field) const { return r_.positive(c_.require(field)); }
  Slot slot(const char* field) const { return r_.slot(c_.require(field)); }
  Index coordinate(const char* field) const { return r_.coordinate(c_.require(field)); }
  kin::V2 vec2(const char* field) const { return r_.vec2(c_.require(field)); }
  Point2 point(const char* field) const { return r_.point(c_.require(field)); }
  std::pair<Point2, Point2> segment(const char* field) const { return r_.segment(c_.require(field)); }
  std::pair<std::pair<Point2, Point2>, std::pair<Point2, Point2>> two_segments(const char* field) const {
    return pair_of(field, "expected two segments [[A, B], [C, D]]", [&](const C& n) { return r_.segment(n); });
  }

  // An attachment of a planar pair, and whether it was written {body: …} (not {point: …}).
  struct Attachment {
    Frame2 frame;
    kin::V2 at;
    bool body;
  };
  std::pair<Attachment, Attachment> attachments(const char* field, const char* arity_message) const {
    return pair_of(field, arity_message, [&](const C& n) {
      auto [frame, at] = r_.attachment(n);
      return Attachment{frame, at, n.field("body").present()};
    });
  }

  // The entries of a list field, each read with this same vocabulary.
  std::vector<KindFields> items(const char* field) const {
    std::vector<KindFields> out;
    for (const auto& item : c_.require(field).items()) out.emplace_back(r_, item, type_);
    return out;
  }
  // A mapping field (a curve: {body: …, spline: …}), read with this same vocabulary.
  KindFields sub(const char* field) const {
    auto v = c_.require(field);
    if (!v.is_map()) v.fail("expected a mapping (key: value)");
    return KindFields(r_, v, type_);
  }
  // A list of [x, y] (a spline's points), at least one.
  std::vector<kin::V2> vec2_list(const char* field) const {
    std::vector<kin::V2> out;
    for (const auto& item : c_.require(field).items()) out.push_back(r_.vec2(item));
    if (out.empty()) c_.field(field).fail("expected a list of [x, y]");
    return out;
  }
  bool flag(const char* field) const { return c_.require(field).boolean(); }
  // A body (or `ground`) by name.
  Frame2 body(const char* field) const { return r_.body(c_.require(field)); }
  // One attachment {body: B, at: [x, y]} or {point: P}.
  Attachment attachment(const char* field) const {
    const auto n = c_.require(field);
    auto [frame, at] = r_.attachment(n);
    return Attachment{frame, at, n.field("body").present()};
  }
  // The entry's name, for messages ("" when unnamed).
  std::string name() const {
    const auto n = c_.field("name");
    return n.present() ? n.text() : std::string();
  }

  // A list of coordinate names, each with an optional sign ("-psi3"): (index, ±1).
  std::vector<std::pair<Index, double>> signed_coordinates(const char* field) const {
    std::vector<std::pair<Index, double>> out;
    for (const auto& a : c_.field(field).items()) {
      std::string s = a.text();
      double sign = 1.0;
      if (!s.empty() && (s[0] == '-' || s[0] == '+')) sign = s[0] == '-' ? -1.0 : 1.0, s = s.substr(1);
      const Index j = r_.builder_.find_coordinate(s);
      if (j < 0) a.fail("unknown coordinate '" + s + "'");
      out.emplace_back(j, sign);
    }
    return out;
  }
  std::pair<Index, Index> coordinate_pair(const char* field) const {
    return pair_of(field, "expected two coordinates [q_i, q_j]", [&](const C& n) { return r_.coordinate(n); });
  }
  std::pair<double, double> number_pair(const char* field) const {
    return pair_of(field, "expected two numbers [a, b]", [&](const C& n) { return r_.number(n); });
  }
  std::shared_ptr<const CompiledExpression> expression(const char* field) const {
    return r_.compile(c_.require(field), true);
  }
  Unit unit(const char* field) const { return r_.unit(c_.field(field)); }
  // The scene's dimension, 2 or 3.
  int dimension() const { return r_.spatial_ ? 3 : 2; }
  bool boolean(const char* field) const { return c_.require(field).boolean(); }
  // The index of `field`'s text among `choices` (e.g. {"external", "internal"}).
  int choice(const char* field, std::initializer_list<const char*> choices) const {
    const auto v = c_.require(field);
    const std::string s = v.text();
    std::string list;
    int k = 0;
    for (const char* ch : choices) {
      if (s == ch) return k;
      list += (k++ ? ", " : "") + std::string(ch);
    }
    v.fail("expected one of " + list + ", got '" + s + "'");
  }
  // An angle (the transmissions): an angle coordinate, or in the plane a body's name for its ψ (ground: 0).
  Slot angle(const char* field) const { return angle_of(c_.require(field)); }
  std::pair<Slot, Slot> angle_pair(const char* field) const {
    return pair_of(field, "expected two bodies or angle coordinates [A, B]", [&](const C& n) { return angle_of(n); });
  }
  // `radii: [r1, r2]` or `teeth: [z1, z2]` (whole numbers), exactly one of them.
  std::pair<double, double> radii_or_teeth() const {
    const bool radii = present("radii"), teeth = present("teeth");
    if (radii == teeth) fail("", "give either 'radii: [r1, r2]' or 'teeth: [z1, z2]'");
    if (radii) return number_pair("radii");
    return pair_of("teeth", "expected two tooth counts [z1, z2]",
                   [&](const C& n) { return static_cast<double>(n.integer(1, 1000000)); });
  }

  // ---- dimension 3
  Point3 point3(const char* field) const { return r_.point3(c_.require(field)); }
  std::pair<Point3, Point3> point3_pair(const char* field, const char* arity_message) const {
    return pair_of(field, arity_message, [&](const C& n) { return r_.point3(n); });
  }
  kin3::V3 vec3(const char* field) const { return r_.vec3(c_.require(field)); }
  // The two sides of a joint, `between` (the message names the entry's type).
  std::pair<JointSide3, JointSide3> sides3(const char* /*between*/) const { return r_.sides3(c_, type_); }
  // One side of a spatial joint (the axis of a mixed coordinate).
  JointSide3 side3(const char* field) const { return r_.side3(c_.require(field)); }
  // The types of joint a shaft turns in (JointTraits::shaft), for messages: "revolute, cylindrical or screw".
  static std::string shaft_types() {
    return joint_type_list([](const JointTraits& t) { return t.shaft; });
  }
  // The sides of a named joint that turns about its axis (a shaft: JointTraits), declared above.
  std::pair<JointSide3, JointSide3> turning_joint(const char* field) const {
    return turning_joint_of(c_.require(field));
  }
  using Sides = std::pair<JointSide3, JointSide3>;
  std::pair<Sides, Sides> turning_joints(const char* field) const {
    const auto v = c_.require(field);
    if (!v.is_sequence() || v.size() != 2) v.fail("expected two joints [J1, J2]");
    if (v.at(0).name() == v.at(1).name()) v.fail("the two shafts must be different joints");
    return {turning_joint_of(v.at(0)), turning_joint_of(v.at(1))};
  }
  // A direction of a dot product: head − tail, and its unit (a segment's is a length, a vector's none).
  struct Direction {
    Attachment3 head, tail;
    Unit unit = Unit::kNone;
  };
  std::pair<Direction, Direction> two_directions(const char* field) const {
    return pair_of(field, "a dot product has two directions [D1, D2]", [&](const C& n) {
      Direction d;
      std::tie(d.head, d.tail) = r_.dot_direction(n, d.unit);
      return d;
    });
  }

 private:
  std::pair<JointSide3, JointSide3> turning_joint_of(const C& n) const {
    const std::string name = n.name();
    const auto it = r_.names_.joints3.find(name);
    if (it == r_.names_.joints3.end())
      n.fail("unknown joint '" + name + "' (a named spatial joint of 'constraints', above)");
    if (!it->second.traits.shaft)
      n.fail("joint '" + name + "' is a " + it->second.type + " joint: a shaft turns in a " + shaft_types() + " joint");
    return {it->second.a, it->second.b};
  }
  Slot angle_of(const C& n) const {
    const std::string s = n.name();
    if (!r_.spatial_) {
      if (s == kGround) return Slot::constant(0.0);
      if (const Index k = r_.entry_at(n, s, r_.names_.bodies); k >= 0) return r_.names_.bodies[k].psi;
    } else if (s == kGround || r_.entry_at(n, s, r_.names_.bodies3) >= 0) {
      n.fail("'" + s +
             "' is a body: in dimension 3 a transmission relates angle coordinates (define the body's "
             "rotation about its axis with a rotation_angle constraint)");
    }
    const Index j = r_.builder_.find_coordinate(s);
    if (j < 0) n.fail("unknown body or angle coordinate '" + s + "'");
    return Slot::coordinate(j);
  }
  // A field that is a list of exactly two entries, each read by `read` (the first, then the second).
  template <class Read>
  auto pair_of(const char* field, const char* arity_message, Read read) const {
    auto v = c_.require(field);
    if (!v.is_sequence() || v.size() != 2) v.fail(arity_message);
    auto first = read(v.at(0));
    return std::pair{first, read(v.at(1))};
  }

  const SceneReader& r_;
  C c_;
  const std::string& type_;
};

}  // namespace phiq::detail::scene
