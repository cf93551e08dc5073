/// @file
/// The spatial joints (spherical, revolute, prismatic, cylindrical, universal, planar, rigid, point on line, point
/// on plane): a family of kinds, one row table each, evaluated by one set of formulas; each with its equation,
/// derivatives, validation, joint count, sketch and scene form. The contract is documented on DistanceSpec, and
/// kinds/registry.hpp lists every kind.
///
/// Every joint is written with one device (kinds/spatial_rows.hpp): each row is w (X · Y − c), X and Y sums of
/// attachments or a constant unit axis, so that the Jacobian, Φt, γ and the derivatives along the data of every
/// joint come from one set of formulas; a joint is its table of rows (joint3 below).
///
/// A joint joins two sides (JointSide3): a body with a local point `at`, a local axis z and a local reference
/// direction x ⟂ z (y = z × x completes the joint frame); or ground; or a natural point, with a natural unit vector
/// as its axis. Rows that need x or y of a side (the alignment of two axes, the lock of a rotation) need a body or
/// ground on that side: a natural vector fixes no perpendicular direction.
///
/// Rows are lengths (point gaps, offsets of a point from a line or a plane) or angles (x_a · z_b ≈ the
/// misalignment of two axes, in radians), so that one tolerance serves any size of mechanism (models/README.md).
#pragma once

#include <cmath>
#include <array>
#include <tuple>
#include <cstdint>
#include <optional>
#include <string_view>

#include "phiq/spatial_attachment.hpp"
#include "phiq/kinds/kind_support.hpp"
#include "phiq/kinds/reaction_site.hpp"
#include "phiq/kinds/spatial_rows.hpp"

namespace phiq {

/// One side of a spatial joint, as given: a body (or ground) with a local point and a local axis and reference
/// direction, or a natural point with an optional natural unit vector. Build it with the factories.
struct JointSide3 {
  bool operator==(const JointSide3&) const = default;  ///< datum by datum
  Frame3 frame = Frame3::ground();  ///< the body; for a natural point, x, y, z are the point and p is constant
  kin3::V3 at;                      ///< the joint point in the body's frame (m); 0 for a natural point
  kin3::V3 axis{0, 0, 1};           ///< the joint axis z in the body's frame (normalised by setup)
  std::optional<kin3::V3> ref;      ///< the reference direction x in the body's frame (its part ⟂ z is used);
                                    ///< default: x, or y when the axis is within 25° of x
  bool natural = false;             ///< a natural point (and vector): no perpendicular directions
  std::optional<Point3> vector;     ///< a natural side's axis: a natural unit vector

  /// A body side.
  static JointSide3 body(const Frame3& f, kin3::V3 at, kin3::V3 axis = {0, 0, 1},
                         std::optional<kin3::V3> ref = std::nullopt) {
    JointSide3 s;
    s.frame = f, s.at = at, s.axis = axis, s.ref = ref;
    return s;
  }
  /// A natural point, with an optional natural unit vector as axis.
  static JointSide3 natural_point(const Point3& p, std::optional<Point3> vector = std::nullopt) {
    JointSide3 s;
    s.frame = Frame3{p.x, p.y, p.z, Slot::constant(1), Slot::constant(0), Slot::constant(0), Slot::constant(0)};
    s.natural = true, s.vector = vector;
    return s;
  }
};

namespace detail3 {
/// Indices of the attachments of a joint (SpatialJointSpec::att): the two points, then the joint frames' x, y, z.
enum Attach : std::int8_t { kPa = 0, kPb, kXa, kYa, kZa, kXb, kYb, kZb, kCount };
/// The attachments a joint's rows read, in the order of their indices (`index[i]`: the Attach index of the i-th),
/// and the rows with their terms renumbered into that list: a joint stores only those (a point on a plane reads 3
/// of the 8), since every evaluation streams them.
template <int kRows>
struct CompactRows {
  int count = 0;
  std::int8_t index[kCount] = {};
  RowDef rows[kRows] = {};
};
template <int kRows>
constexpr CompactRows<kRows> compact_rows(const RowDef (&defs)[kRows]) {
  bool used[kCount] = {};
  for (const RowDef& d : defs)
    for (const Term& t : {d.x, d.y}) {
      if (t.plus >= 0) used[t.plus] = true;
      if (t.minus >= 0) used[t.minus] = true;
    }
  CompactRows<kRows> c;
  std::int8_t position[kCount] = {};
  for (int k = 0; k < kCount; ++k)
    if (used[k]) position[k] = static_cast<std::int8_t>(c.count), c.index[c.count++] = static_cast<std::int8_t>(k);
  auto renumber = [&](Term t) {
    if (t.plus >= 0) t.plus = position[t.plus];
    if (t.minus >= 0) t.minus = position[t.minus];
    return t;
  };
  for (int r = 0; r < kRows; ++r) c.rows[r] = RowDef{renumber(defs[r].x), renumber(defs[r].y), defs[r].unit};
  return c;
}

/// The reference direction of a body side, in its body's frame, from which a joint angle is measured: `s.ref` when
/// the scene states it, else x, or y when the axis lies within 25° of x (so that its part perpendicular to the axis
/// is well defined). phiq check reports which one each joint angle driver uses (Scene::joint_angles).
kin3::V3 reference_direction(const JointSide3& s);

/// A body side's joint frame at q, as unit vectors in world axes: z its axis, x its reference direction's part
/// perpendicular to it, y = z × x (ReactionSite::axes). A natural side's stays world axes (it has no frame).
/// Pre-condition: the side is valid (its joint set up).
void joint_axes(const JointSide3& s, const double* q, kin3::V3 axes[3]);
/// The ReactionSite of a joint between sides a and b (a spatial joint's, a screw's): on side a's body, or on b's
/// when a is fixed, at side a's joint point; its axes that side's joint frame (joint_axes()).
ReactionSite joint_reaction_site(const JointSide3& a, const JointSide3& b, const double* q);

/// The attachments of a joint between sides a and b that `index[0 … count − 1]` name (Attach indices, ascending:
/// CompactRows::index), in that order in the first `count` entries; an attachment of constants only is folded
/// into its value (Attachment3::fold_constant). Normalises the axes, makes the reference directions perpendicular.
/// Throws phiq::Error (naming `kind`) for a zero or non-finite axis, a reference along the axis, non-finite
/// points, and rows that need the perpendicular directions of a natural side or the axis of a natural point without
/// a vector.
std::array<Attachment3, kCount> joint_attachments(const JointSide3& a, const JointSide3& b, const std::int8_t* index,
                                                  int count, const char* kind);
/// Validates the sides and fills `att` with the attachments the rows of `c` read: the setup() of every joint and
/// joint driver (`att` has c.count entries).
template <int kRows, std::size_t N>
void set_up_attachments(const JointSide3& a, const JointSide3& b, const CompactRows<kRows>& c, const char* kind,
                        std::array<Attachment3, N>& att) {
  const std::array<Attachment3, kCount> all = joint_attachments(a, b, c.index, c.count, kind);
  std::copy_n(all.begin(), N, att.begin());
}
/// The longer arm |at| of the sides whose body moves (the characteristic length of a joint; see PinSpec).
inline double joint_arm(const JointSide3& a, const JointSide3& b) {
  const double la = a.frame.is_fixed() ? 0.0 : kin3::norm(a.at), lb = b.frame.is_fixed() ? 0.0 : kin3::norm(b.at);
  return std::max(la, lb);
}
/// Draws a joint: the arms of the bodies it joins, `mark` at its point (on ground when a side is ground), and its
/// `form` on the bodies' derived parts.
template <class Sketch>
void sketch_joint(const JointSide3& a, const JointSide3& b, JointMark mark, JointForm form, Sketch& sk) {
  const Attachment3 pa = Attachment3::body_point(a.frame, a.at), pb = Attachment3::body_point(b.frame, b.at);
  sk.arm3(pa);
  sk.arm3(pb);
  sk.joint3(pa, pb, mark);
  sk.joint_parts3(a, b, form);
}
/// Reports the slots of a side: its position (lengths), Euler parameters and vector (unitless).
template <class F>
void side_slots(const JointSide3& s, F& f) {
  f(s.frame.x, Unit::kLength), f(s.frame.y, Unit::kLength), f(s.frame.z, Unit::kLength);
  f(s.frame.e0, Unit::kNone), f(s.frame.e1, Unit::kNone), f(s.frame.e2, Unit::kNone), f(s.frame.e3, Unit::kNone);
  if (s.vector) f(s.vector->x, Unit::kNone), f(s.vector->y, Unit::kNone), f(s.vector->z, Unit::kNone);
}
}  // namespace detail3

/// A joint's side, as given, is not what its rows read: its attachments (`att`, derived from the sides) are, and
/// they carry the side's rates (a side that turns from a body to ground changes their slots and is refused there).
/// Its reaction's site reads the side (joint_reaction_site()), which a bearing's load along a parameter moves
/// (ConstraintBlock::data_moved()): the rates of its frame's constants, its point, axis, reference and vector; false
/// where a reference or vector is given in some of the four models only.
inline bool datum_rate(JointSide3& rate, const std::array<const JointSide3*, 4>& v, double h) {
  auto slot = [&](Slot& r, Slot Frame3::*m) {
    return detail::datum_rate(r, {&(v[0]->frame.*m), &(v[1]->frame.*m), &(v[2]->frame.*m), &(v[3]->frame.*m)}, h);
  };
  bool ok = true;
  for (Slot Frame3::*m : {&Frame3::x, &Frame3::y, &Frame3::z, &Frame3::e0, &Frame3::e1, &Frame3::e2, &Frame3::e3})
    ok = slot(rate.frame.*m, m) && ok;
  auto vector = [&](kin3::V3& r, auto get) {
    for (double kin3::V3::*c : {&kin3::V3::x, &kin3::V3::y, &kin3::V3::z})
      ok = detail::datum_rate(r.*c, {&(get(*v[0]).*c), &(get(*v[1]).*c), &(get(*v[2]).*c), &(get(*v[3]).*c)}, h) && ok;
  };
  vector(rate.at, [](const JointSide3& x) -> const kin3::V3& { return x.at; });
  vector(rate.axis, [](const JointSide3& x) -> const kin3::V3& { return x.axis; });
  for (const JointSide3* x : v) ok = ok && x->ref.has_value() == rate.ref.has_value() && x->vector == rate.vector;
  if (ok && rate.ref) vector(*rate.ref, [](const JointSide3& x) -> const kin3::V3& { return *x.ref; });
  return ok;
}
/// A side moved by s times its rates (datum_rate() above; a natural side's vector is the model's, as its slots).
inline bool datum_moved(JointSide3& side, const JointSide3& rate, double s) {
  for (Slot Frame3::*m : {&Frame3::x, &Frame3::y, &Frame3::z, &Frame3::e0, &Frame3::e1, &Frame3::e2, &Frame3::e3})
    detail::datum_moved(side.frame.*m, rate.frame.*m, s);
  auto move = [&](kin3::V3& x, const kin3::V3& r) { x = {x.x + s * r.x, x.y + s * r.y, x.z + s * r.z}; };
  move(side.at, rate.at), move(side.axis, rate.axis);
  if (side.ref && rate.ref) move(*side.ref, *rate.ref);
  return true;
}
/// A spatial joint between two sides, its rows given by `Traits` (one struct per joint type below). The sides
/// are data; setup() (called by ModelBuilder::add, or by hand before evaluating a spec built in code) validates
/// them and derives the attachments the rows read.
template <class Traits>
struct SpatialJointSpec {
  /// @copydoc DistanceSpec::operator==
  bool operator==(const SpatialJointSpec&) const = default;
  static constexpr int kRows = Traits::kRows;  ///< the freedoms the joint removes
  /// @copydoc DistanceSpec::kKind
  static constexpr const char* kKind = Traits::kKind;
  /// What a named joint of this type measures and may be driven by (JointTraits): `Traits::kJoint`, or nothing.
  static constexpr JointTraits kJoint = joint_traits<Traits>();
  /// @var a
  /// @brief Side a: its joint frame carries the axis of one-sided rows (lines, planes).
  JointSide3 a, b;  ///< side b
  /// The rows' attachments and the rows renumbered into them (detail3::compact_rows).
  static constexpr auto kCompact = detail3::compact_rows(Traits::kRowDefs);
  std::array<Attachment3, kCompact.count> att{};  ///< derived by setup(): the attachments the rows read

  /// Validates the sides and derives `att`. Throws phiq::Error.
  void setup() { detail3::set_up_attachments(a, b, kCompact, kKind, att); }
  /// @copydoc DistanceSpec::depends_on_time
  bool depends_on_time() const { return false; }
  /// @copydoc DistanceSpec::row_unit
  /// Point gaps and offsets from lines and planes are lengths; products of axes are angles.
  Unit row_unit(int r, const std::vector<Unit>&) const { return Traits::kRowDefs[r].unit; }
  /// @copydoc DistanceSpec::characteristic_length
  /// For a joint: the longer arm |at| of a moving side.
  double characteristic_length() const { return detail3::joint_arm(a, b); }
  /// @copydoc DistanceSpec::for_each_slot
  /// A joint reports the frame (and vector) slots of side a, then of side b.
  template <class F>
  void for_each_slot(F&& f) const {
    detail3::side_slots(a, f), detail3::side_slots(b, f);
  }
  /// The values its reaction has (ConstraintBlock::reaction_width()): Fx, Fy, Fz, Mx, My, Mz of a spatial joint.
  static constexpr int kReactionWidth = 6;
  /// The reaction (ReactionSite): on side a's body, or on b's when a is fixed, at side a's joint point; its axes
  /// that side's joint frame.
  ReactionSite reaction_site(const double* q) const { return detail3::joint_reaction_site(a, b, q); }
  /// @copydoc DistanceSpec::residual
  void residual(const double* q, double, double* phi) const {
    for (int r = 0; r < kRows; ++r) phi[r] = detail3::row_value(att.data(), kCompact.rows[r], q, 1.0, 0.0);
  }
  /// @copydoc DistanceSpec::jacobian
  template <class Sink>
  void jacobian(const double* q, double, Sink& s) const {
    for (int r = 0; r < kRows; ++r) detail3::row_jacobian(att.data(), kCompact.rows[r], q, s, r, 1.0);
  }
  /// @copydoc DistanceSpec::phi_t
  void phi_t(const double*, double, double* out) const {
    for (int r = 0; r < kRows; ++r) out[r] = 0.0;
  }
  /// @copydoc DistanceSpec::gamma
  void gamma(const double* q, const double* qd, double, double* out) const {
    for (int r = 0; r < kRows; ++r) out[r] = detail3::row_gamma(att.data(), kCompact.rows[r], q, qd, 1.0);
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the sides, through the attachments the rows
  /// read (a side's local point, axis and reference direction, a ground frame's place).
  static constexpr auto data_members() {
    return std::tuple{&SpatialJointSpec::a, &SpatialJointSpec::b, &SpatialJointSpec::att};
  }
  /// Derivatives along the data (DistanceSpec::data_derivative()): each row's, X · Y differentiated along its
  /// attachments' rates (detail3::row_data_derivative(): exact, the attachments being quadratic in the Euler
  /// parameters and linear in the local vectors).
  void data_derivative(const SpatialJointSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double, double* out) const {
    for (int r = 0; r < kRows; ++r)
      out[r] = detail3::row_data_derivative(att.data(), rate.att.data(), kCompact.rows[r], order, q, qd, qdd);
  }

  /// @copydoc DistanceSpec::joint_count
  /// A joint between bodies or ground removes kRows freedoms; with a natural side the count is undefined.
  JointCount joint_count() const {
    if (a.natural || b.natural) return JointCount::other();
    return JointCount::joint(3, Traits::kRows);
  }
  /// @copydoc DistanceSpec::prepare
  /// For a joint: setup().
  void prepare(const double* /*q0*/) { setup(); }
  /// @copydoc DistanceSpec::sketch
  /// A spatial joint draws the arms of the bodies it joins, and a mark at its point (a hinge for a revolute, a
  /// block for a prismatic pair, a ball for the others), on ground when a side is ground; on the bodies' parts a
  /// shaft and a fork (revolute), a shaft and a sleeve (cylindrical), the cross (universal), a block on a guide
  /// (prismatic), a ball (the others).
  template <class Sketch>
  void sketch(Sketch& sk) const {
    const std::string_view kind = Traits::kKind;
    const JointMark mark = kind == "revolute"    ? JointMark::kRevolute
                           : kind == "prismatic" ? JointMark::kPrismatic
                                                 : JointMark::kSpherical;
    const JointForm form = kind == "revolute"      ? JointForm::kHinge
                           : kind == "prismatic"   ? JointForm::kSlider
                           : kind == "cylindrical" ? JointForm::kShaft
                           : kind == "universal"   ? JointForm::kCross
                                                   : JointForm::kBall;
    detail3::sketch_joint(a, b, mark, form, sk);
  }
  /// @copydoc DistanceSpec::kScene
  static constexpr const auto& kScene = Traits::kScene;
  /// @copydoc DistanceSpec::read
  /// The spherical joint also reads `fixed_point` (a natural point held at a place).
  template <class Fields>
  static SpatialJointSpec read(const Fields& f) {
    SpatialJointSpec spec;
    if (f.type() == "fixed_point") {
      f.expect({"type", "name", "point", "at"});
      spec.a = JointSide3::natural_point(f.point3("point"));
      spec.b = JointSide3::body(Frame3::ground(), f.vec3("at"));
      return spec;
    }
    if (f.present("axis"))  // where a planar prismatic writes it
      f.fail("axis",
             "in dimension 3 a joint's axis is given on each side, in that body's frame: between: "
             "[{body: A, axis: [x, y, z]}, {body: B, axis: [x, y, z]}]");
    f.expect({"type", "name", "between"});
    std::tie(spec.a, spec.b) = f.sides3("between");
    return spec;
  }
};

namespace joint3 {
using detail3::Axis;
using detail3::RowDef;
using detail3::T;
using namespace detail3;                   // the attachment indices kPa …
inline constexpr Unit kL = Unit::kLength;  ///< shorthand for the row tables: a length row
inline constexpr Unit kA = Unit::kAngle;   ///< shorthand for the row tables: an angle row

/// Spherical joint (ball): the points coincide.   Φ = P_a − P_b   (3 rows, lengths)
struct Spherical {
  static constexpr int kRows = 3;                    ///< rows: the freedoms it removes
  static constexpr const char* kKind = "spherical";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "spherical", 3, "- {name: base, type: spherical, between: [{body: ground}, {body: B1}]}"},
      {"constraints", "fixed_point", 3, "- {name: fixP, type: fixed_point, point: P, at: [1, 2, 3]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {
      {Axis(0), T(kPa, kPb), kL}, {Axis(1), T(kPa, kPb), kL}, {Axis(2), T(kPa, kPb), kL}};
};
/// Revolute joint: spherical, and the axes parallel.
///   Φ = [P_a − P_b;  x_a · z_b;  y_a · z_b]   (5 rows: 3 lengths, 2 angles)
struct Revolute {
  static constexpr int kRows = 5;                   ///< rows: the freedoms it removes
  static constexpr const char* kKind = "revolute";  ///< scene type and diagnostics name
  /// its angle: output, driven, and a shaft
  static constexpr JointTraits kJoint{.measures = {.angle = true}, .drives = {.angle = true}, .shaft = true};
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {{"constraints", "revolute", 3,
                                          "- {name: hinge, type: revolute, between: [{body: ground, at: [0, 0, 1], "
                                          "axis: [0, 0, 1]}, {body: door, at: [0, 0, 1]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{Axis(0), T(kPa, kPb), kL},
                                             {Axis(1), T(kPa, kPb), kL},
                                             {Axis(2), T(kPa, kPb), kL},
                                             {T(kXa), T(kZb), kA},
                                             {T(kYa), T(kZb), kA}};
};
/// Cylindrical joint: the axes parallel, and P_b on the line of a (through P_a along z_a).
///   Φ = [x_a · z_b;  y_a · z_b;  x_a · (P_b − P_a);  y_a · (P_b − P_a)]   (4 rows: 2 angles, 2 lengths)
struct Cylindrical {
  static constexpr int kRows = 4;                      ///< rows: the freedoms it removes
  static constexpr const char* kKind = "cylindrical";  ///< scene type and diagnostics name
  /// its angle and its distance: output, driven (one each), and a shaft
  static constexpr JointTraits kJoint{
      .measures = {.angle = true, .distance = true}, .drives = {.angle = true, .distance = true}, .shaft = true};
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {{"constraints", "cylindrical", 3,
                                          "- {name: cyl, type: cylindrical, between: [{body: ground, axis: [1, 0, "
                                          "0]}, {body: screw, axis: [1, 0, 0]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {
      {T(kXa), T(kZb), kA}, {T(kYa), T(kZb), kA}, {T(kXa), T(kPb, kPa), kL}, {T(kYa), T(kPb, kPa), kL}};
};
/// Prismatic joint: cylindrical, and no rotation about the axis (x_b stays along x_a).
///   Φ = [x_a · z_b;  y_a · z_b;  x_a · (P_b − P_a);  y_a · (P_b − P_a);  y_a · x_b]   (5 rows)
struct Prismatic {
  static constexpr int kRows = 5;                    ///< rows: the freedoms it removes
  static constexpr const char* kKind = "prismatic";  ///< scene type and diagnostics name
  /// its distance: output and driven
  static constexpr JointTraits kJoint{.measures = {.distance = true}, .drives = {.distance = true}};
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {{"constraints", "prismatic", 3,
                                          "- {name: slide, type: prismatic, between: [{body: ground, axis: [1, 0, 0]}, "
                                          "{body: slider, axis: [1, 0, 0]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kXa), T(kZb), kA},
                                             {T(kYa), T(kZb), kA},
                                             {T(kXa), T(kPb, kPa), kL},
                                             {T(kYa), T(kPb, kPa), kL},
                                             {T(kYa), T(kXb), kA}};
};
/// Universal (Hooke) joint: spherical, and the two axes kept perpendicular (the cross).
///   Φ = [P_a − P_b;  z_a · z_b]   (4 rows: 3 lengths, 1 angle)
struct Universal {
  static constexpr int kRows = 4;                    ///< rows: the freedoms it removes
  static constexpr const char* kKind = "universal";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {{"constraints", "universal", 3,
                                          "- {name: cross, type: universal, between: [{body: s1, axis: [1, 0, 0]}, "
                                          "{body: s2, axis: [0, 1, 0]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {
      {Axis(0), T(kPa, kPb), kL}, {Axis(1), T(kPa, kPb), kL}, {Axis(2), T(kPa, kPb), kL}, {T(kZa), T(kZb), kA}};
};
/// Planar joint: the normals parallel, and P_b in the plane of a (through P_a, normal z_a).
///   Φ = [x_a · z_b;  y_a · z_b;  z_a · (P_b − P_a)]   (3 rows: 2 angles, 1 length)
struct Planar {
  static constexpr int kRows = 3;                 ///< rows: the freedoms it removes
  static constexpr const char* kKind = "planar";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "planar", 3, "- {name: on_table, type: planar, between: [{body: ground}, {body: puck}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kXa), T(kZb), kA}, {T(kYa), T(kZb), kA}, {T(kZa), T(kPb, kPa), kL}};
};
/// Rigid joint (weld): the points coincide and the joint frames stay aligned (x_b ∥ x_a, y_b ∥ y_a, z_b ∥ z_a).
///   Φ = [P_a − P_b;  x_a · y_b;  y_a · z_b;  z_a · x_b]   (6 rows: 3 lengths, 3 angles)
struct Rigid {
  static constexpr int kRows = 6;                ///< rows: the freedoms it removes
  static constexpr const char* kKind = "rigid";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {
      {"constraints", "rigid", 3, "- {name: weld, type: rigid, between: [{body: frame, at: [1, 0, 0]}, {body: arm}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{Axis(0), T(kPa, kPb), kL}, {Axis(1), T(kPa, kPb), kL},
                                             {Axis(2), T(kPa, kPb), kL}, {T(kXa), T(kYb), kA},
                                             {T(kYa), T(kZb), kA},       {T(kZa), T(kXb), kA}};
};
/// Point on line: P_b on the line of a (through P_a along z_a).
///   Φ = [x_a · (P_b − P_a);  y_a · (P_b − P_a)]   (2 rows, lengths)
struct PointOnLine {
  static constexpr int kRows = 2;                        ///< rows: the freedoms it removes
  static constexpr const char* kKind = "point_on_line";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {{"constraints", "point_on_line", 3,
                                          "- {name: axis2, type: point_on_line, between: [{body: ground, axis: [1, "
                                          "0, 0]}, {body: s2, at: [0, 0, 1]}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kXa), T(kPb, kPa), kL}, {T(kYa), T(kPb, kPa), kL}};
};
/// Point on plane: P_b in the plane of a (through P_a, normal z_a).
///   Φ = z_a · (P_b − P_a)   (1 row, a length)
struct PointOnPlane {
  static constexpr int kRows = 1;                         ///< rows: the freedoms it removes
  static constexpr const char* kKind = "point_on_plane";  ///< scene type and diagnostics name
  /// its scene forms (SceneForm)
  static constexpr SceneForm kScene[] = {{"constraints", "point_on_plane", 3,
                                          "- {name: plane0, type: point_on_plane, between: [{body: ground, "
                                          "axis: [1, 2, 2]}, {point: P0}]}"}};
  /// The rows, each w (X · Y − c) with w = 1, c = 0, and its unit.
  static constexpr RowDef kRowDefs[kRows] = {{T(kZa), T(kPb, kPa), kL}};
};
}  // namespace joint3

using SphericalSpec = SpatialJointSpec<joint3::Spherical>;             ///< scene type `spherical` (dimension 3)
using SpatialRevoluteSpec = SpatialJointSpec<joint3::Revolute>;        ///< scene type `revolute` (dimension 3)
using CylindricalSpec = SpatialJointSpec<joint3::Cylindrical>;         ///< scene type `cylindrical`
using SpatialPrismaticSpec = SpatialJointSpec<joint3::Prismatic>;      ///< scene type `prismatic` (dimension 3)
using UniversalSpec = SpatialJointSpec<joint3::Universal>;             ///< scene type `universal`
using PlanarSpec = SpatialJointSpec<joint3::Planar>;                   ///< scene type `planar`
using RigidSpec = SpatialJointSpec<joint3::Rigid>;                     ///< scene type `rigid`
using SpatialPointOnLineSpec = SpatialJointSpec<joint3::PointOnLine>;  ///< scene type `point_on_line` (dim. 3)
using PointOnPlaneSpec = SpatialJointSpec<joint3::PointOnPlane>;       ///< scene type `point_on_plane`

}  // namespace phiq
