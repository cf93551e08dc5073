// Emitters of scene text for the generators (`phiq generate`, tools/README.md). Every piece of scene syntax a
// generator writes (a coordinate, a point, a body, one constraint of each kind, a driver, the footer) is written by
// one member function here, so that a change of syntax, such as the compact "indexed family" form of the scale
// issue, is a change of this file only. The indexed families (`for i in A..B`) the generators now write are built
// by the generators themselves and written with raw() (generate_linkages.cpp, generate_chain3d.cpp).
// Names are systematic: a family and up to two indices (Name).
#pragma once

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

namespace phiq::tools::emit {

// A systematic name: `family`, `family<i>` or `family<i>_<j>` (an index < 0 is absent).
struct Name {
  std::string_view family;
  std::int64_t i = -1, j = -1;
};

// A component of a point or a body: a coordinate name, or a constant.
struct Component {
  Name name{};
  double value = 0.0;
  bool constant = false;
  Component(Name n) : name(n) {}  // NOLINT(google-explicit-constructor): reads as the coordinate it names
  static Component of(double v) {
    Component c{Name{}};
    c.value = v;
    c.constant = true;
    return c;
  }
};

// A point reference in a constraint: a named point, or constant coordinates [x, y].
struct PointRef {
  Name name{};
  double x = 0.0, y = 0.0;
  bool constant = false;
  PointRef(Name n) : name(n) {}  // NOLINT(google-explicit-constructor): reads as the point it names
  static PointRef at(double x, double y) {
    PointRef p{Name{}};
    p.x = x;
    p.y = y;
    p.constant = true;
    return p;
  }
};

// One side of a revolute or prismatic pair: a point fixed in a body's frame (`ground` is a body).
struct Attach {
  Name body;
  double x = 0.0, y = 0.0;
};

// The scene text, built in one string (reserve it: generators write up to 10^6 elements).
class SceneText {
 public:
  explicit SceneText(std::size_t reserve_bytes) { s_.reserve(reserve_bytes); }

  void comment(std::string_view line) { w("# ", line, '\n'); }
  void field(std::string_view key, std::string_view value) { w(key, ": ", value, '\n'); }
  void section(std::string_view key) { w(key, ":\n"); }
  // Text written as given (indexed families, built by the generator: generate_linkages.cpp).
  void raw(std::string_view text) { put(text); }

  // Under `coordinates:`.
  void coordinate(Name n, double initial) { w("  ", n, ": ", initial, '\n'); }
  // Under `points:`.
  void point(Name n, Component x, Component y) { w("  ", n, ": [", x, ", ", y, "]\n"); }
  // Under `bodies:`.
  void body(Name n, Component x, Component y, Component psi) { w("  ", n, ": [", x, ", ", y, ", ", psi, "]\n"); }

  // Under `constraints:`, one line each.
  void distance(Name n, PointRef a, PointRef b, double length) {
    w("  - {name: ", n, ", type: distance, points: [", a, ", ", b, "], length: ", length, "}\n");
  }
  void point_on_line(Name n, PointRef p, PointRef a, PointRef b) {
    w("  - {name: ", n, ", type: point_on_line, point: ", p, ", line: [", a, ", ", b, "]}\n");
  }
  void segment_angle(Name n, PointRef a, PointRef b, Name angle) {
    w("  - {name: ", n, ", type: segment_angle, segment: [", a, ", ", b, "], angle: ", angle, "}\n");
  }
  void revolute(Name n, Attach a, Attach b) { w("  - {name: ", n, ", type: revolute, between: [", a, ", ", b, "]}\n"); }
  // Body b slides along body a's x axis (axis [1, 0]) without turning relative to it.
  void prismatic(Name n, Attach a, Attach b) {
    w("  - {name: ", n, ", type: prismatic, between: [", a, ", ", b, "]}\n");
  }

  // Under `drivers:`: coordinate = initial + rate · t.
  void linear_driver(Name n, Name coordinate, double initial, double rate) {
    driver(n, "coordinate", coordinate, initial, rate);
  }
  // Under `drivers:` (dimension 3): the angle of the revolute joint `joint` = initial + rate · t.
  void joint_driver(Name n, Name joint, double initial, double rate) { driver(n, "joint", joint, initial, rate); }

  // The footer: the sweep and the outputs.
  void time(double start, double end, std::int64_t steps) {
    w("time: {start: ", start, ", end: ", end, ", steps: ", steps, "}\n");
  }
  void output(bool velocities, bool accelerations) {
    w("output: {velocities: ", std::string_view(velocities ? "true" : "false"),
      ", accelerations: ", std::string_view(accelerations ? "true" : "false"), "}\n");
  }

  std::string take() { return std::move(s_); }

 private:
  template <class... A>
  void w(const A&... a) {
    (put(a), ...);
  }

  // A driver of `what` (coordinate or joint) with a linear law.
  void driver(Name n, std::string_view key, Name what, double initial, double rate) {
    w("  - {name: ", n, ", ", key, ": ", what, ", law: {type: linear, initial: ", initial, ", rate: ", rate, "}}\n");
  }

  void put(char c) { s_.push_back(c); }
  void put(std::string_view v) { s_.append(v); }
  template <std::size_t N>
  void put(const char (&v)[N]) {  // a literal: its length is known
    s_.append(v, N - 1);
  }
  void put(std::int64_t v) {
    char buf[24];
    auto r = std::to_chars(buf, buf + sizeof buf, v);
    s_.append(buf, r.ptr);
  }
  // Shortest decimal that reads back to the same double (-0 written as 0).
  void put(double v) {
    if (v == 0.0) v = 0.0;
    char buf[32];
    auto r = std::to_chars(buf, buf + sizeof buf, v);
    s_.append(buf, r.ptr);
  }
  void put(Name n) {
    put(n.family);
    if (n.i >= 0) put(n.i);
    if (n.j >= 0) w('_', n.j);
  }
  void put(const Component& c) { c.constant ? put(c.value) : put(c.name); }
  void put(const PointRef& p) {
    if (!p.constant) return put(p.name);
    w('[', p.x, ", ", p.y, ']');
  }
  void put(const Attach& a) { w("{body: ", a.body, ", at: [", a.x, ", ", a.y, "]}"); }

  std::string s_;
};

}  // namespace phiq::tools::emit
