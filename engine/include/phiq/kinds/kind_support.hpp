/// @file
/// What every constraint kind header needs besides the basic types: planar vector helpers (kin::V2), the
/// Grübler–Kutzbach role of a constraint (JointCount), the description of a kind's scene form (SceneForm), and the
/// checks kinds share when a constraint is added.
#pragma once

#include <cmath>
#include <algorithm>
#include <array>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "phiq/motion_law.hpp"
#include "phiq/types.hpp"

namespace phiq {

struct CurveOn;

/// What a joint is drawn as in the mechanism's sketch (mechanism_sketch.hpp), as a kind's sketch() says.
enum class JointMark {
  kRevolute,   ///< a pin: a circle (planar), a hinge (spatial)
  kPrismatic,  ///< a slider: a block at `at` on its guide along `axis`
  kSpherical,  ///< a ball joint (and the other spatial joints, drawn as a ball)
  kPoint,      ///< the end of a natural-coordinate link (a natural point, moving or fixed)
};

/// What a spatial joint puts on the bodies it joins among their derived parts (drawn_parts.hpp), as its sketch()
/// says (the sketch's `joint_parts3`).
enum class JointForm {
  kBall,    ///< a ball on each side (spherical, and the joints that have no axis of their own to draw)
  kHinge,   ///< a shaft along the axis on side b, a fork about it on side a (revolute)
  kShaft,   ///< a shaft along the axis on side b, a sleeve about it on side a (cylindrical, screw)
  kCross,   ///< a cylinder along each side's own axis through the joint point: together, the cross (universal)
  kSlider,  ///< a block on side b, a guide along the axis on side a (prismatic)
};

namespace kin {
struct V2 {
  double x, y;
  bool operator==(const V2&) const = default;
};
inline V2 operator+(V2 a, V2 b) { return {a.x + b.x, a.y + b.y}; }
inline V2 operator-(V2 a, V2 b) { return {a.x - b.x, a.y - b.y}; }
inline V2 operator*(double s, V2 a) { return {s * a.x, s * a.y}; }
inline double dot(V2 a, V2 b) { return a.x * b.x + a.y * b.y; }
inline double cross(V2 a, V2 b) { return a.x * b.y - a.y * b.x; }
inline V2 perp(V2 a) { return {-a.y, a.x}; }  // rotation by +90°
inline V2 rotate(double psi, V2 s) {
  double c = std::cos(psi), n = std::sin(psi);
  return {c * s.x - n * s.y, n * s.x + c * s.y};
}
inline V2 pos(const Point2& p, const double* q) { return {p.x.of(q), p.y.of(q)}; }
inline V2 vel(const Point2& p, const double* qd) { return {p.x.rate(qd), p.y.rate(qd)}; }
/// |s| when the frame moves (any of x, y, ψ is a coordinate), 0 for a fixed frame (see PinSpec).
inline double moving_arm(const Frame2& f, V2 s) {
  const bool fixed = !f.x.is_coordinate() && !f.y.is_coordinate() && !f.psi.is_coordinate();
  return fixed ? 0.0 : std::hypot(s.x, s.y);
}
// |b − a| at the placement q0 (the initial guesses), for the reference scales of rows set when a constraint is added.
inline double initial_length(const Point2& a, const Point2& b, const double* q0) {
  V2 d = pos(b, q0) - pos(a, q0);
  return std::hypot(d.x, d.y);
}
// Two points made of constants only that are the same point: a segment or line between them has no direction
// anywhere, so a constraint on it holds for no position or for all (points that move may meet at a placement).
inline bool same_fixed_point(const Point2& a, const Point2& b) {
  return !a.x.is_coordinate() && !a.y.is_coordinate() && !b.x.is_coordinate() && !b.y.is_coordinate() &&
         a.x.value() == b.x.value() && a.y.value() == b.y.value();
}
/// A planar frame is a body's (ψ a coordinate) or ground (all constants); else a natural point.
inline bool body_or_ground(const Frame2& f) {
  return f.psi.is_coordinate() || (!f.x.is_coordinate() && !f.y.is_coordinate());
}
}  // namespace kin

namespace detail {
/// Throws phiq::Error(what) unless `ok`: the kinds' checks of their data when a constraint is added (the model
/// prefixes the constraint's name).
inline void require(bool ok, const char* what) {
  if (!ok) throw Error(what);
}
}  // namespace detail

/// What a constraint counts for in the Grübler–Kutzbach formula (Model::grubler()). Every kind says it
/// (`joint_count()`): kinds/registry.hpp refuses a kind without it at compile time.
struct JointCount {
  /// The role of the constraint in the count.
  enum class Role {
    kOther,    ///< not a joint between bodies (natural coordinates, equations, …): the count is not defined
    kJoint,    ///< a joint between bodies or ground: removes `freedoms`
    kDriver,   ///< a driver: not counted
    kBodyOwn,  ///< a body's own constraint (Euler-parameter normalisation): not counted
  };
  Role role = Role::kOther;  ///< its role
  int dimension = 0;         ///< 2 (planar joint) or 3 (spatial joint), for kJoint
  int freedoms = 0;          ///< freedoms the joint removes, for kJoint

  /// Not a joint: the count is not defined for a model that has one.
  static JointCount other() { return {}; }
  /// A driver: not counted.
  static JointCount driver() { return {Role::kDriver, 0, 0}; }
  /// A joint of `dimension` (2 or 3) removing `freedoms`.
  static JointCount joint(int dimension, int freedoms) { return {Role::kJoint, dimension, freedoms}; }
};

/// @page scene_fields The scene vocabulary of the kinds
/// A kind read from the `constraints` section of a scene has `template <class Fields> static Spec read(const
/// Fields& f)`. `f` is one entry of the list (scene/kind_fields.hpp implements it over the YAML cursor and over
/// family members alike); each call names the field it reads and fails with the file, line and field path:
/// `type()`; `expect({fields})` (the fields allowed); `present(field)`; `fail(field, message)` (`""`: the entry);
/// `number`, `positive`, `slot` (a coordinate or a constant), `coordinate` (an index), `vec2`, `point`, `segment`,
/// `two_segments`, `attachments` (two planar attachments {frame, at, body}), `items` (a list of entries, each with
/// the same vocabulary), `signed_coordinates`, `coordinate_pair`, `number_pair`, `expression`, `unit`; in space
/// `point3`, `point3_pair`, `vec3`, `sides3` (two JointSide3), `two_directions` ({head, tail, unit} each).

/// Whether a kind differentiates its equations along its own data (DistanceSpec::data_derivative()): it lists the
/// data in data_members() and supplies data_derivative(). The sensitivities to a parameter that reaches such a
/// constraint read its derivatives there in one evaluation instead of differencing four models.
template <class K>
concept DataDifferentiable = requires(const K k, const double* q, double* out) {
  K::data_members();
  k.data_derivative(k, 0, q, q, q, 0.0, out);
};

/// @cond internal
namespace detail {
// C(k, i) for k, i ≤ 2: Leibniz's rule for the time derivatives of a product, up to the second (the kinds'
// derivatives along their data, data_derivative()).
inline constexpr double kBinomial[3][3] = {{1, 0, 0}, {1, 1, 0}, {1, 2, 1}};
// The time derivative of order `order` (0, 1, 2) of the rate along a design parameter of u = R(ψ) s, a vector
// carried by a frame of angle slot `psi`, whose rates are ψ̂ (`psi_rate`: a constant angle's; 0 for a coordinate,
// which is no datum) and ŝ; ω = ψ̇, α = ψ̈ (the kinds' data_derivative()):
//   order 0: R ŝ + ψ̂ u⊥,   1: ω (R ŝ)⊥ − ψ̂ ω u,   2: α (R ŝ)⊥ − ω² R ŝ − ψ̂ (α u + ω² u⊥).
inline kin::V2 turned_data_derivative(const Slot& psi, const kin::V2& s, const Slot& psi_rate, const kin::V2& s_rate,
                                      int order, const double* q, const double* qd, const double* qdd) {
  const double angle = psi.of(q), psid = psi_rate.of(q);
  const kin::V2 u = kin::rotate(angle, s), ud = kin::rotate(angle, s_rate);
  if (order == 0) return ud + psid * kin::perp(u);
  const double w = psi.rate(qd);
  if (order == 1) return w * kin::perp(ud) - (psid * w) * u;
  const double al = psi.rate(qdd);
  return al * kin::perp(ud) - (w * w) * ud - psid * (al * u + (w * w) * kin::perp(u));
}
// The same of a point r + R(ψ) s of frame f, its rates `rf` (constant slots) and `rs`: r̂ joins order 0.
inline kin::V2 point_data_derivative(const Frame2& f, const kin::V2& s, const Frame2& rf, const kin::V2& rs, int order,
                                     const double* q, const double* qd, const double* qdd) {
  const kin::V2 turned = turned_data_derivative(f.psi, s, rf.psi, rs, order, q, qd, qdd);
  return order == 0 ? kin::V2{rf.x.of(q), rf.y.of(q)} + turned : turned;
}
// The fourth-order central difference of values at p − 2h, p − h, p + h, p + 2h, in pairs (exactly zero where the
// four agree): what every rate along a design parameter is made of (the data's here, the laws' coefficients, the
// rows a kind does not differentiate itself: sensitivity.cpp).
inline double central_difference(double m2, double m1, double p1, double p2, double h) {
  return ((m2 - p2) + 8.0 * (p1 - m1)) / (12.0 * h);
}
// The rates of a kind's data along a design parameter (DistanceSpec::data_derivative()), from its values in the
// four models at p − 2h, p − h, p + h, p + 2h by the fourth-order central difference (sensitivity.hpp): one datum
// of each type a kind lists in data_members(), `rate` holding the swept model's datum on entry. False where the
// datum is not data that moves: a coordinate in one model and another slot in the next.
inline bool datum_rate(double& rate, const std::array<const double*, 4>& v, double h) {
  rate = central_difference(*v[0], *v[1], *v[2], *v[3], h);
  return std::isfinite(rate);
}
// A constant's rate, as a constant slot; a coordinate's (the swept model's in the four), the constant 0: it is no
// datum.
inline bool datum_rate(Slot& rate, const std::array<const Slot*, 4>& v, double h) {
  if (rate.is_coordinate()) {
    for (const Slot* s : v)
      if (!(*s == rate)) return false;
    rate = Slot::constant(0.0);
    return true;
  }
  double x[4];
  for (std::size_t k = 0; k < 4; ++k) {
    if (v[k]->is_coordinate()) return false;
    x[k] = v[k]->value();
  }
  double r = 0.0;
  const bool ok = datum_rate(r, {&x[0], &x[1], &x[2], &x[3]}, h);
  rate = Slot::constant(r);
  return ok;
}
inline bool datum_rate(Point2& rate, const std::array<const Point2*, 4>& v, double h) {
  return datum_rate(rate.x, {&v[0]->x, &v[1]->x, &v[2]->x, &v[3]->x}, h) &&
         datum_rate(rate.y, {&v[0]->y, &v[1]->y, &v[2]->y, &v[3]->y}, h);
}
inline bool datum_rate(Frame2& rate, const std::array<const Frame2*, 4>& v, double h) {
  return datum_rate(rate.x, {&v[0]->x, &v[1]->x, &v[2]->x, &v[3]->x}, h) &&
         datum_rate(rate.y, {&v[0]->y, &v[1]->y, &v[2]->y, &v[3]->y}, h) &&
         datum_rate(rate.psi, {&v[0]->psi, &v[1]->psi, &v[2]->psi, &v[3]->psi}, h);
}
inline bool datum_rate(kin::V2& rate, const std::array<const kin::V2*, 4>& v, double h) {
  return datum_rate(rate.x, {&v[0]->x, &v[1]->x, &v[2]->x, &v[3]->x}, h) &&
         datum_rate(rate.y, {&v[0]->y, &v[1]->y, &v[2]->y, &v[3]->y}, h);
}
// −∂f/∂p, −∂f′/∂p or −∂f″/∂p (`order` 0, 1, 2) at t, of a law's rate along a parameter: the derivative along its
// law of a driver's row whose law enters as − f(t) (CoordinateDriverSpec::data_derivative()).
inline double minus_law_rate(const MotionLaw& rate, int order, double t) {
  const LawValue v = rate.evaluate(t);
  return -(order == 0 ? v.f : order == 1 ? v.df : v.ddf);
}
// A motion law's rate is the law ∂f/∂p (MotionLaw::rate_along); an optional law's, when all five have one.
inline bool datum_rate(MotionLaw& rate, const std::array<const MotionLaw*, 4>& v, double h) {
  rate = MotionLaw::rate_along(rate, v, h);
  return true;
}
inline bool datum_rate(std::optional<MotionLaw>& rate, const std::array<const std::optional<MotionLaw>*, 4>& v,
                       double h) {
  for (const auto* law : v)
    if (law->has_value() != rate.has_value()) return false;
  return !rate || datum_rate(*rate, {&**v[0], &**v[1], &**v[2], &**v[3]}, h);
}
// An expression's rate along a parameter (CompiledExpression::along_constants()): its constants' rates by the
// central difference, the expression differentiated along them exactly; `rate` null where none moves. False where
// the five were not compiled from one text against the same names, or its rate cannot be compiled.
inline bool expression_rate(const CompiledExpression& at, const std::array<const CompiledExpression*, 4>& v, double h,
                            std::shared_ptr<const CompiledExpression>& rate) {
  for (const CompiledExpression* e : v)
    if (!e || !e->same_source(at)) return false;
  std::vector<double> r(at.constants().size());
  for (std::size_t k = 0; k < r.size(); ++k) {
    r[k] =
        central_difference(v[0]->constants()[k], v[1]->constants()[k], v[2]->constants()[k], v[3]->constants()[k], h);
    if (!std::isfinite(r[k])) return false;
  }
  try {
    rate = at.along_constants(r);
  } catch (const Error&) {
    return false;
  }
  return true;
}
// A curve and the frame that carries it (kinds/curve.hpp, where it is defined): the frame's rates; false where the
// curve itself is not the same in the four (its shape moves: the constraint is differenced).
inline bool datum_rate(CurveOn& rate, const std::array<const CurveOn*, 4>& v, double h);
// An equation's expression: its rate, null where its constants do not move.
inline bool datum_rate(std::shared_ptr<const CompiledExpression>& rate,
                       const std::array<const std::shared_ptr<const CompiledExpression>*, 4>& v, double h) {
  if (!rate) return false;
  return expression_rate(*rate, {v[0]->get(), v[1]->get(), v[2]->get(), v[3]->get()}, h, rate);
}

// `rate` made of `at` with each datum of Spec::data_members() replaced by its rate along the parameter over the
// four specs `along` (ConstraintBlock::data_rates()). False when it has none: a datum is no data that moves, or a
// member the kind does not list differs between the specs (its equations' derivative along it is not the kind's).
template <class Spec>
bool spec_data_rate(const Spec& at, const std::array<const Spec*, 4>& along, double h, Spec& rate) {
  rate = at;
  bool ok = true;
  std::apply(
      [&](auto... m) {
        ((ok = ok && datum_rate(rate.*m, {&(along[0]->*m), &(along[1]->*m), &(along[2]->*m), &(along[3]->*m)}, h)),
         ...);
      },
      Spec::data_members());
  for (const Spec* s : along) {
    Spec other = *s;
    std::apply([&](auto... m) { ((other.*m = at.*m), ...); }, Spec::data_members());
    ok = ok && other == at;
  }
  return ok;
}

// A datum moved by s times its rate (ConstraintBlock::data_moved()): numbers, constant slots and the points, frames
// and vectors made of them; a coordinate slot is no datum and stays. Any other datum cannot be moved so: false.
inline bool datum_moved(double& d, const double& rate, double s) {
  d += s * rate;
  return true;
}
inline bool datum_moved(Slot& d, const Slot& rate, double s) {
  if (!d.is_coordinate()) d = Slot::constant(d.value() + s * rate.value());
  return true;
}
inline bool datum_moved(Point2& d, const Point2& rate, double s) {
  return datum_moved(d.x, rate.x, s) && datum_moved(d.y, rate.y, s);
}
inline bool datum_moved(Frame2& d, const Frame2& rate, double s) {
  return datum_moved(d.x, rate.x, s) && datum_moved(d.y, rate.y, s) && datum_moved(d.psi, rate.psi, s);
}
inline bool datum_moved(kin::V2& d, const kin::V2& rate, double s) {
  return datum_moved(d.x, rate.x, s) && datum_moved(d.y, rate.y, s);
}
template <class T>
bool datum_moved(T&, const T&, double) {
  return false;
}
// `spec` with each datum of Spec::data_members() moved by s times its rate in `rate` (spec_data_rate()'s).
template <class Spec>
bool spec_data_moved(const Spec& rate, double s, Spec& spec) {
  bool ok = true;
  std::apply([&](auto... m) { ((ok = ok && datum_moved(spec.*m, rate.*m, s)), ...); }, Spec::data_members());
  return ok;
}

// A planar pair (pin, prismatic) between bodies or ground removes 2 freedoms; with a natural point on either side
// it is no joint of the count.
inline JointCount planar_pair_joint_count(const Frame2& a, const Frame2& b) {
  if (!kin::body_or_ground(a) || !kin::body_or_ground(b)) return JointCount::other();
  return JointCount::joint(2, 2);
}
}  // namespace detail
/// @endcond

/// Where and how a scene writes a constraint of some kind: the section, the `type` (or the automatic entry), the
/// dimension, and a one-line YAML example as models/README.md documents it (tests check that the README shows
/// every example and that each loads in a scene).
struct SceneForm {
  const char* section;  ///< "constraints", "drivers", "bodies" or "vectors"
  const char* type;     ///< the `type` field (constraints), or what selects the kind in its section
  int dimension;        ///< 2 or 3
  const char* example;  ///< the documented YAML entry, one line
};

/// What a named spatial joint of some kind offers the rest of its scene: the coordinates it measures (the columns
/// of `output.joints`), those a joint driver may drive (`measure: angle | distance`), and whether it is a shaft
/// (it turns about its axis z_a: the shaft of a `spatial_gear`, the joint of a `rotation_angle`). A kind states
/// them beside its kKind as `static constexpr JointTraits kJoint{...}`; a kind that states none is no such joint.
/// kinds/registry.hpp derives from them the joint types the scene reader accepts and its messages' lists.
struct JointTraits {
  /// A joint's coordinates: its angle θ, the turn of x_b about z_a from x_a (c = x_a · x_b, s = y_a · x_b), and
  /// its distance d = z_a · (P_b − P_a), the travel along the axis.
  struct Coordinates {
    bool angle = false;     ///< θ (rad)
    bool distance = false;  ///< d (m)
    /// Whether it has either.
    constexpr bool any() const { return angle || distance; }
  };
  Coordinates measures;  ///< what `output.joints` writes of it (columns `J.angle`, `J.distance`)
  Coordinates drives;    ///< what a joint driver may drive (and, when only one, the driver's default measure)
  bool shaft = false;    ///< turns about its axis in its bearing (side a the housing, side b the shaft)
};

/// The joint traits of kind K: its kJoint, or none.
template <class K>
constexpr JointTraits joint_traits() {
  if constexpr (requires { K::kJoint; })
    return K::kJoint;
  else
    return JointTraits{};
}

}  // namespace phiq
