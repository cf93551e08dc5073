// Scene loader: YAML (yaml-cpp) → ModelBuilder + SweepOptions, with every error located in the file.
#include "phiq/scene.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

namespace phiq {

namespace {

const char* const kGround = "ground";

// A YAML node with the dotted path that led to it, for messages.
class Cursor {
 public:
  Cursor(YAML::Node node, std::string path, const std::string* file, YAML::Mark parent_mark)
      : node_(std::move(node)), path_(std::move(path)), file_(file), parent_mark_(parent_mark) {}

  const YAML::Node& node() const { return node_; }
  const std::string& path() const { return path_; }
  bool present() const { return node_.IsDefined() && !node_.IsNull(); }
  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }

  [[noreturn]] void fail(const std::string& what) const {
    YAML::Mark m = node_.IsDefined() ? node_.Mark() : parent_mark_;
    if (m.line < 0) m = parent_mark_;
    std::ostringstream s;
    s << *file_;
    if (m.line >= 0) s << ":" << m.line + 1 << ":" << m.column + 1;
    s << ": " << (path_.empty() ? "(top level)" : path_) << ": " << what;
    throw SceneError(s.str());
  }

  // Map access: only the listed keys are allowed; duplicates are rejected.
  void expect_map(std::initializer_list<const char*> allowed) const {
    if (!node_.IsMap()) fail("expected a mapping (key: value)");
    std::set<std::string> seen;
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      Cursor key(it->first, path_, file_, node_.Mark());
      if (!it->first.IsScalar()) key.fail("keys must be plain names");
      const std::string k = it->first.Scalar();
      if (!seen.insert(k).second) Cursor(it->first, join(k), file_, node_.Mark()).fail("duplicate field '" + k + "'");
      bool ok = false;
      for (const char* a : allowed) ok = ok || k == a;
      if (!ok) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        Cursor(it->first, join(k), file_, node_.Mark()).fail("unknown field '" + k + "' (allowed: " + list + ")");
      }
    }
  }
  Cursor field(const char* key) const {
    // yaml-cpp's operator[] on a const node does not insert
    const YAML::Node& n = node_;
    return Cursor(n[key], join(key), file_, node_.Mark());
  }
  Cursor require(const char* key) const {
    Cursor c = field(key);
    if (!c.node_.IsDefined()) fail(std::string("missing field '") + key + "'");
    if (c.node_.IsNull()) c.fail("has no value");
    return c;
  }
  std::size_t size() const { return node_.size(); }
  Cursor at(std::size_t i) const {
    return Cursor(node_[i], path_ + "[" + std::to_string(i) + "]", file_, node_.Mark());
  }
  std::vector<Cursor> items() const {
    if (!node_.IsSequence()) fail("expected a list");
    std::vector<Cursor> v;
    for (std::size_t i = 0; i < node_.size(); ++i) v.push_back(at(i));
    return v;
  }
  // Ordered (key, value) pairs of a map whose keys are user names.
  std::vector<std::pair<std::string, Cursor>> entries() const {
    if (!node_.IsMap()) fail("expected a mapping (name: value)");
    std::vector<std::pair<std::string, Cursor>> v;
    std::set<std::string> seen;
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      if (!it->first.IsScalar()) Cursor(it->first, path_, file_, node_.Mark()).fail("names must be plain scalars");
      const std::string k = it->first.Scalar();
      Cursor value(it->second, join(k), file_, it->first.Mark());
      if (!seen.insert(k).second) Cursor(it->first, join(k), file_, node_.Mark()).fail("duplicate name '" + k + "'");
      v.emplace_back(k, value);
    }
    return v;
  }
  std::string text() const {
    if (!node_.IsScalar()) fail("expected a single value");
    return node_.Scalar();
  }
  std::string name() const {
    std::string s = text();
    if (!valid_name(s))
      fail("'" + s + "' is not a valid name (letters, digits and '_', not starting with a digit)");
    return s;
  }
  bool boolean() const {
    std::string s = text();
    if (s == "true" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "no" || s == "off") return false;
    fail("expected true or false, got '" + s + "'");
  }
  std::int64_t integer(std::int64_t lo, std::int64_t hi) const {
    std::string s = text();
    std::int64_t v = 0;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || p != s.data() + s.size()) fail("expected a whole number, got '" + s + "'");
    if (v < lo || v > hi) fail("must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    return v;
  }

  static bool valid_name(const std::string& s) {
    if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
    for (char c : s)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
    return true;
  }

  const std::string* file() const { return file_; }

 private:
  std::string join(const std::string& k) const { return path_.empty() ? k : path_ + "." + k; }
  YAML::Node node_;
  std::string path_;
  const std::string* file_;
  YAML::Mark parent_mark_;
};

// A YAML number as a double; nullopt when `s` is not a plain number (then it may be a constant expression).
// Throws SceneError-free Error for a number out of the range of a double: never hand those to the symbolic engine,
// which would try to represent 1e3082222222 exactly (found by the fuzzer: a hang in GMP).
std::optional<double> plain_number(const std::string& s) {
  if (s == ".nan" || s == ".NaN" || s == ".NAN") return std::numeric_limits<double>::quiet_NaN();
  if (s == ".inf" || s == ".Inf" || s == ".INF" || s == "+.inf") return std::numeric_limits<double>::infinity();
  if (s == "-.inf" || s == "-.Inf" || s == "-.INF") return -std::numeric_limits<double>::infinity();
  const char* b = s.data();
  const char* e = b + s.size();
  if (b != e && *b == '+') ++b;
  double v = 0.0;
  auto [p, ec] = std::from_chars(b, e, v);
  if (ec == std::errc() && p == e) return v;
  if (ec == std::errc::result_out_of_range && p == e) {
    // from_chars reports underflow and overflow alike: underflow is 0, overflow is not a finite number
    const auto epos = s.find_first_of("eE");
    const bool negative_exponent = epos != std::string::npos && epos + 1 < s.size() && s[epos + 1] == '-';
    if (negative_exponent) return 0.0;
    throw Error("'" + s.substr(0, 40) + (s.size() > 40 ? "..." : "") + "' is out of the range of a double");
  }
  return std::nullopt;
}

class SceneReader {
 public:
  SceneReader(const std::string& file) : file_(file) {}

  Scene read(const YAML::Node& root) {
    Cursor top(root, "", &file_, YAML::Mark());
    if (!root.IsDefined() || root.IsNull()) top.fail("the scene is empty");
    top.expect_map({"phiq", "name", "description", "parameters", "coordinates", "points", "bodies", "constraints",
                    "drivers", "time", "output", "solver"});
    if (auto v = top.field("phiq"); v.present() && v.integer(1, 1) != 1) v.fail("unsupported format version");

    Scene scene;
    scene.path = file_;
    if (auto n = top.field("name"); n.present()) scene.name = n.text();
    if (auto d = top.field("description"); d.present()) (void)d.text();

    read_parameters(top.field("parameters"));
    read_coordinates(top.require("coordinates"));
    if (auto p = top.field("points"); p.present()) read_points(p);
    if (auto b = top.field("bodies"); b.present()) read_bodies(b);
    read_solver(top.field("solver"), scene.sweep);  // before constraints: length scale, linear solver

    if (auto c = top.field("constraints"); c.present())
      for (const Cursor& item : c.items()) read_constraint(item);
    if (auto d = top.field("drivers"); d.present())
      for (const Cursor& item : d.items()) read_driver(item);

    read_time(top.require("time"), scene.sweep);
    read_output(top.field("output"), scene);

    try {
      scene.model = std::make_unique<Model>(std::move(builder_).build());
    } catch (const Error& e) {
      top.fail(e.what());
    }
    if (scene.model->num_equations() != scene.model->num_coordinates()) {
      top.fail("the model has " + std::to_string(scene.model->num_coordinates()) + " coordinates but " +
               std::to_string(scene.model->num_equations()) +
               " constraint equations (kinematic + drivers); the driven system must be square");
    }
    return scene;
  }

 private:
  // ---- names and numbers --------------------------------------------------------------------------------------
  std::optional<double> parameter(const std::string& name) const {
    auto it = parameters_.find(name);
    if (it == parameters_.end()) return std::nullopt;
    return it->second;
  }

  // A number: a YAML number, or a constant expression of parameters and pi ("L2/2", "2*pi").
  double number(const Cursor& c) const {
    if (!c.present()) c.fail("missing number");
    const std::string s = c.text();
    double v;
    std::optional<double> p;
    try {
      p = plain_number(s);
    } catch (const Error& e) {
      c.fail(e.what());
    }
    if (p) {
      v = *p;
    } else {
      try {
        v = evaluate_constant_expression(s, [&](const std::string& n) { return parameter(n); });
      } catch (const Error& e) {
        if (builder_.find_coordinate(s) >= 0)
          c.fail("'" + s + "' is a coordinate; a constant is expected here");
        c.fail(e.what());
      }
    }
    if (!std::isfinite(v)) c.fail("'" + s + "' is not a finite number");
    return v;
  }
  double positive(const Cursor& c) const {
    double v = number(c);
    if (!(v > 0.0)) c.fail("must be positive, got " + c.text());
    return v;
  }
  std::vector<double> numbers(const Cursor& c, std::size_t n) const {
    auto items = c.items();
    if (n && items.size() != n) c.fail("expected a list of " + std::to_string(n) + " numbers");
    std::vector<double> v;
    for (const Cursor& i : items) v.push_back(number(i));
    return v;
  }
  kin::V2 vec2(const Cursor& c) const {
    auto v = numbers(c, 2);
    return {v[0], v[1]};
  }

  Index coordinate(const Cursor& c) const {
    const std::string s = c.name();
    Index j = builder_.find_coordinate(s);
    if (j < 0) c.fail("unknown coordinate '" + s + "'");
    return j;
  }
  // A slot: a coordinate name or a constant (number or constant expression).
  Slot slot(const Cursor& c) const {
    if (c.is_scalar()) {
      Index j = builder_.find_coordinate(c.text());
      if (j >= 0) return Slot::coordinate(j);
    }
    return Slot::constant(number(c));
  }

  // ---- top-level sections -------------------------------------------------------------------------------------
  void read_parameters(const Cursor& c) {
    if (!c.present()) return;
    for (auto& [name, value] : c.entries()) {
      if (!Cursor::valid_name(name)) value.fail("'" + name + "' is not a valid parameter name");
      if (name == "t" || name == "pi") value.fail("'" + name + "' is reserved");
      parameters_[name] = number(value);  // may use the parameters above it
    }
  }

  void read_coordinates(const Cursor& c) {
    auto entries = c.entries();
    if (entries.empty()) c.fail("at least one coordinate is needed");
    for (auto& [name, value] : entries) {
      if (!Cursor::valid_name(name)) value.fail("'" + name + "' is not a valid coordinate name");
      if (name == "t" || name == "pi") value.fail("'" + name + "' is reserved");
      if (parameters_.count(name)) value.fail("'" + name + "' is already a parameter");
      builder_.add_coordinate(name, number(value));
    }
  }

  void check_new_entity(const Cursor& where, const std::string& name) const {
    if (!Cursor::valid_name(name)) where.fail("'" + name + "' is not a valid name");
    if (points_.count(name) || bodies_.count(name)) where.fail("duplicate point or body name '" + name + "'");
  }

  void read_points(const Cursor& c) {
    for (auto& [name, value] : c.entries()) {
      check_new_entity(value, name);
      if (value.size() != 2 || !value.is_sequence()) value.fail("a point is [x, y]");
      points_[name] = Point2{slot(value.at(0)), slot(value.at(1))};
    }
  }

  void read_bodies(const Cursor& c) {
    for (auto& [name, value] : c.entries()) {
      if (name == kGround) value.fail("'ground' is predefined (the fixed frame)");
      check_new_entity(value, name);
      if (value.size() != 3 || !value.is_sequence()) value.fail("a body is [x, y, psi]");
      bodies_[name] = Frame2{slot(value.at(0)), slot(value.at(1)), slot(value.at(2))};
    }
  }

  // A point reference: a point name or an inline [x, y].
  Point2 point(const Cursor& c) const {
    if (c.is_sequence()) {
      if (c.size() != 2) c.fail("an inline point is [x, y]");
      return Point2{slot(c.at(0)), slot(c.at(1))};
    }
    const std::string s = c.name();
    auto it = points_.find(s);
    if (it == points_.end()) c.fail("unknown point '" + s + "'");
    return it->second;
  }
  std::pair<Point2, Point2> segment(const Cursor& c) const {
    if (!c.is_sequence() || c.size() != 2) c.fail("a segment is [from, to]");
    return {point(c.at(0)), point(c.at(1))};
  }
  Frame2 body(const Cursor& c) const {
    const std::string s = c.name();
    if (s == kGround) return Frame2{Slot::constant(0), Slot::constant(0), Slot::constant(0)};
    auto it = bodies_.find(s);
    if (it == bodies_.end()) c.fail("unknown body '" + s + "'");
    return it->second;
  }
  // An attachment of a revolute or prismatic pair: {body: B, at: [x, y]} (local point) or {point: P}.
  std::pair<Frame2, kin::V2> attachment(const Cursor& c) const {
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

  void read_constraint(const Cursor& c) {
    if (!c.is_map()) c.fail("a constraint is a mapping with a 'type'");
    const std::string type = c.require("type").text();
    std::string name;
    if (auto n = c.field("name"); n.present()) name = n.name();
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
        Cursor segs = c.require("segments");
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
        Cursor between = c.require("between");
        if (!between.is_sequence() || between.size() != 2) between.fail("a revolute joins two attachments");
        auto [fa, sa] = attachment(between.at(0));
        auto [fb, sb] = attachment(between.at(1));
        add(c, name, PinSpec{fa, fb, sa, sb});
      } else if (type == "prismatic") {
        c.expect_map({"type", "name", "between", "axis", "angle"});
        Cursor between = c.require("between");
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
        for (const Cursor& l : c.require("links").items()) {
          l.expect_map({"length", "angles", "offset"});
          LoopSpec::Link link;
          link.length = slot(l.require("length"));
          if (auto o = l.field("offset"); o.present()) link.offset = number(o);
          if (auto as = l.field("angles"); as.present()) {
            for (const Cursor& a : as.items()) {
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

  void read_driver(const Cursor& c) {
    if (!c.is_map()) c.fail("a driver is a mapping with 'coordinate' or 'expr', and a 'law'");
    c.expect_map({"name", "coordinate", "expr", "unit", "law"});
    std::string name;
    if (auto n = c.field("name"); n.present()) name = n.name();
    MotionLaw law = motion_law(c.require("law"));
    const bool by_coordinate = c.field("coordinate").present(), by_expr = c.field("expr").present();
    if (by_coordinate == by_expr) c.fail("a driver has either 'coordinate' or 'expr'");
    try {
      if (by_coordinate) {
        if (c.field("unit").present()) c.field("unit").fail("'unit' goes with 'expr' (a coordinate has its own)");
        add(c, name, CoordinateDriverSpec{Slot::coordinate(coordinate(c.field("coordinate"))), std::move(law)});
      } else {
        add(c, name, EquationSpec{compile(c.field("expr"), false), std::move(law), unit(c.field("unit"))});
      }
    } catch (const Error& e) {
      c.fail(e.what());
    }
  }

  MotionLaw motion_law(const Cursor& c) const {
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
        c.expect_map({"type", "t", "values"});
        auto t = numbers(c.require("t"), 0), v = numbers(c.require("values"), 0);
        if (t.size() != v.size()) c.require("values").fail("needs as many values as times");
        if (t.size() < 2) c.require("t").fail("a table needs at least 2 points");
        for (std::size_t k = 1; k < t.size(); ++k)
          if (!(t[k] > t[k - 1])) c.require("t").at(k).fail("times must increase strictly");
        return MotionLaw::table(t, v);
      }
      if (type == "expression") {
        c.expect_map({"type", "f"});
        Cursor f = c.require("f");
        auto expr = CompiledExpression::compile(f.text(), [&](const std::string& n) -> std::optional<NameBinding> {
          if (n == "t") return NameBinding{NameBinding::Kind::kTime};
          if (auto p = parameter(n)) return NameBinding{NameBinding::Kind::kConstant, -1, *p};
          return std::nullopt;
        });
        return MotionLaw::expression(expr);
      }
    } catch (const Error& e) {
      c.fail(e.what());
    }
    c.require("type").fail("unknown law type '" + type + "' (linear, polynomial, harmonic, table, expression)");
  }

  std::shared_ptr<const CompiledExpression> compile(const Cursor& c, bool allow_time) const {
    try {
      return CompiledExpression::compile(
          c.text(),
          [&](const std::string& n) -> std::optional<NameBinding> {
            if (n == "t") return NameBinding{NameBinding::Kind::kTime};
            Index j = builder_.find_coordinate(n);
            if (j >= 0) return NameBinding{NameBinding::Kind::kCoordinate, j};
            if (auto p = parameter(n)) return NameBinding{NameBinding::Kind::kConstant, -1, *p};
            return std::nullopt;
          },
          allow_time);
    } catch (const Error& e) {
      c.fail(e.what());
    }
  }

  Unit unit(const Cursor& c) const {
    if (!c.present()) return Unit::kNone;
    const std::string s = c.text();
    if (s == "length") return Unit::kLength;
    if (s == "angle") return Unit::kAngle;
    if (s == "none") return Unit::kNone;
    c.fail("unit is length, angle or none, got '" + s + "'");
  }

  template <class Spec>
  void add(const Cursor& c, const std::string& name, Spec spec) {
    std::string label = name.empty() ? std::string(Spec::kKind) + "#" + std::to_string(++unnamed_) : name;
    if (!names_.insert(label).second) c.field("name").fail("duplicate constraint or driver name '" + label + "'");
    builder_.add(label, std::move(spec));
  }

  void read_time(const Cursor& c, SweepOptions& o) const {
    c.expect_map({"start", "end", "steps"});
    o.t_begin = number(c.require("start"));
    o.t_end = number(c.require("end"));
    o.steps = c.require("steps").integer(0, 1000000000);
    if (o.steps > 0 && o.t_end == o.t_begin) c.require("end").fail("end equals start but steps > 0");
  }

  void read_output(const Cursor& c, Scene& scene) const {
    scene.sweep.velocities = scene.sweep.accelerations = false;
    if (c.present()) {
      c.expect_map({"velocities", "accelerations", "coordinates"});
      if (auto v = c.field("velocities"); v.present()) scene.sweep.velocities = v.boolean();
      if (auto a = c.field("accelerations"); a.present()) scene.sweep.accelerations = a.boolean();
      if (auto cs = c.field("coordinates"); cs.present()) {
        std::set<Index> seen;
        for (const Cursor& i : cs.items()) {
          Index j = coordinate(i);
          if (!seen.insert(j).second) i.fail("coordinate listed twice");
          scene.output_coordinates.push_back(j);
        }
        return;
      }
    }
    for (Index j = 0; j < builder_.num_coordinates(); ++j) scene.output_coordinates.push_back(j);
  }

  void read_solver(const Cursor& c, SweepOptions& o) {
    if (!c.present()) return;
    c.expect_map({"tolerance", "max_iterations", "assembly_max_iterations", "line_search", "predictor",
                  "max_subdivisions", "length_scale", "linear_solver"});
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
    if (auto v = c.field("predictor"); v.present()) {
      static const std::map<std::string, Predictor> m = {{"auto", Predictor::kAuto},
                                                         {"previous", Predictor::kPrevious},
                                                         {"secant", Predictor::kSecant},
                                                         {"linear", Predictor::kLinear},
                                                         {"quadratic", Predictor::kQuadratic}};
      auto it = m.find(v.text());
      if (it == m.end()) v.fail("predictor is auto, previous, secant, linear or quadratic");
      o.predictor = it->second;
    }
    if (auto v = c.field("length_scale"); v.present()) builder_.set_length_scale(positive(v));
    if (auto v = c.field("linear_solver"); v.present()) {
      const std::string s = v.text();
      if (s == "umfpack") builder_.set_linear_solver(LinearSolverKind::kUmfpack);
      else if (s == "klu") builder_.set_linear_solver(LinearSolverKind::kKlu);
      else if (s == "dense") builder_.set_linear_solver(LinearSolverKind::kDense);
      else v.fail("linear_solver is umfpack, klu or dense");
    }
    predictor_field_ = c.field("predictor").present();
  }

  const std::string& file_;
  ModelBuilder builder_;
  std::unordered_map<std::string, double> parameters_;
  std::unordered_map<std::string, Point2> points_;
  std::unordered_map<std::string, Frame2> bodies_;
  std::set<std::string> names_;
  int unnamed_ = 0;
  bool predictor_field_ = false;

 public:
  bool predictor_given() const { return predictor_field_; }
};

// First pass over the YAML events, before any node tree is built: refuses what a scene never needs and what
// could exhaust memory or stack (deep nesting, aliases, several documents, too many nodes, huge values).
class ShapeGuard final : public YAML::EventHandler {
 public:
  ShapeGuard(const std::string& path, const SceneLimits& limits) : path_(path), limits_(limits) {}
  void OnDocumentStart(const YAML::Mark& m) override {
    if (++documents_ > 1) fail(m, "a scene is one YAML document (found a second '---')");
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t) override { count(m); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override {
    fail(m, "YAML aliases (*name) are not supported in scenes");
  }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string& value) override {
    count(m);
    if (value.size() > limits_.max_scalar_bytes)
      fail(m, "a value of " + std::to_string(value.size()) + " bytes; the limit is " +
                  std::to_string(limits_.max_scalar_bytes));
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    enter(m);
  }
  void OnSequenceEnd() override { --depth_; }
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    enter(m);
  }
  void OnMapEnd() override { --depth_; }

 private:
  void count(const YAML::Mark& m) {
    if (++nodes_ > limits_.max_nodes)
      fail(m, "more than " + std::to_string(limits_.max_nodes) + " values; the scene is too large");
  }
  void enter(const YAML::Mark& m) {
    count(m);
    if (++depth_ > limits_.max_depth)
      fail(m, "nested more than " + std::to_string(limits_.max_depth) + " levels deep");
  }
  [[noreturn]] void fail(const YAML::Mark& m, const std::string& what) const {
    throw SceneError(path_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) + ": " + what);
  }
  const std::string& path_;
  const SceneLimits& limits_;
  int documents_ = 0, depth_ = 0;
  std::size_t nodes_ = 0;
};

std::string yaml_error(const std::string& path, const YAML::Exception& e) {
  std::ostringstream s;
  s << path;
  if (e.mark.line >= 0) s << ":" << e.mark.line + 1 << ":" << e.mark.column + 1;
  s << ": YAML syntax error: " << e.msg;
  return s.str();
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& path, const SceneLimits& limits) {
  if (text.size() > limits.max_file_bytes)
    throw SceneError(path + ": the scene is " + std::to_string(text.size() >> 20) + " MiB; the limit is " +
                     std::to_string(limits.max_file_bytes >> 20) + " MiB");
  if (text.find('\0') != std::string::npos) throw SceneError(path + ": the scene is not text (contains a NUL byte)");
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    ShapeGuard guard(path, limits);
    while (parser.HandleNextDocument(guard)) {
    }
  } catch (const YAML::Exception& e) {
    throw SceneError(yaml_error(path, e));
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw SceneError(yaml_error(path, e));
  }
  SceneReader reader(path);
  Scene scene = reader.read(root);
  // A predictor that needs derivatives the scene does not output would compute extra work silently: refuse.
  if (reader.predictor_given()) {
    const Predictor p = scene.sweep.predictor;
    if ((p == Predictor::kQuadratic && !scene.sweep.accelerations) ||
        (p == Predictor::kLinear && !(scene.sweep.velocities || scene.sweep.accelerations)))
      throw SceneError(path + ": solver.predictor: '" + to_string(p) +
                       "' needs the derivatives it extrapolates with in the output (velocities / accelerations)");
  }
  return scene;
}

Scene load_scene(const std::string& path, const SceneLimits& limits) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path + ": cannot open the scene file");
  // size first: a huge file is refused before it is read into memory
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw SceneError(path + ": cannot read the scene file (not a regular file?)");
  if (static_cast<std::uint64_t>(size) > limits.max_file_bytes)
    throw SceneError(path + ": the scene is " + std::to_string(size >> 20) + " MiB; the limit is " +
                     std::to_string(limits.max_file_bytes >> 20) + " MiB");
  in.seekg(0, std::ios::beg);
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), size);
  if (in.gcount() != size) throw SceneError(path + ": cannot read the scene file");
  return parse_scene(text, path, limits);
}

}  // namespace phiq
