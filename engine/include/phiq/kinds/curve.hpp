/// @file
/// A planar curve fixed in a body's frame, for the higher pairs (point on a curve, pin in a curved slot, cams):
/// a cubic spline through given points (closed: periodic; open: natural ends), a circle, or a straight segment.
/// The curve is c(s), s its parameter: the arc length on a circle and a segment, the chord length on a spline
/// (s_k = Σ |p_i+1 − p_i| up to point k), so that |c′| ≈ 1 everywhere and the parameter is a length the tolerance
/// tests read as one. Evaluation gives c and its first three derivatives in s (γ of an offset curve or of a
/// tangency needs the third).
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// A curve in a body's local frame. Immutable once made: the kinds share it (shared_ptr<const Curve>) between the
/// copies of a spec and the threads that evaluate them.
class Curve {
 public:
  /// A cubic spline through `points` (at least 4, no two consecutive the same), parameterised by chord length.
  /// `closed`: periodic (C² through the first point again; a last point equal to the first is dropped), else
  /// natural ends (c″ = 0 at both). Throws phiq::Error naming the bad point.
  static std::shared_ptr<const Curve> spline(std::vector<kin::V2> points, bool closed);
  /// A circle of `radius` > 0 about `centre`, s the arc length from the point at angle 0, counter-clockwise.
  static std::shared_ptr<const Curve> circle(kin::V2 centre, double radius);
  /// The straight segment from a to b, s the distance from a (open, s in [0, |b − a|]).
  static std::shared_ptr<const Curve> line(kin::V2 a, kin::V2 b);
  /// A closed spline through the points (r_k cos θ_k, r_k sin θ_k) of a table of radius against angle (a cam
  /// profile): angles strictly increasing over less than one turn, radii positive.
  static std::shared_ptr<const Curve> radius_table(const std::vector<double>& angles, const std::vector<double>& radii);

  /// The same curve, datum by datum (shape, ends, knots and every piece's coefficients): what makes two curves read
  /// from one scene at different parameter values the same (DistanceSpec::operator==).
  bool operator==(const Curve&) const = default;
  /// Whether the curve is closed (periodic in s with period length()).
  bool closed() const { return closed_; }
  /// The parameter's range is [0, length()]: the period of a closed curve, the end of an open one.
  double length() const { return length_; }
  /// c(s), c′(s), c″(s), c‴(s) into d[0..3]. A closed curve wraps s; an open one continues its end pieces beyond
  /// [0, length()] (a spline's end cubics, the segment's line), so that Newton iterates may step past an end and
  /// back; the sweep stops a motion that stays past it (Model::outside_domain).
  void evaluate(double s, kin::V2 d[4]) const;
  /// The parameter of the point of the curve nearest to p (an open curve's within [0, length()]).
  double nearest(kin::V2 p) const;
  /// The parameter of the point of the curve farthest in direction m (largest c · m): where a line of normal m
  /// touches a convex curve.
  double extreme(kin::V2 m) const;
  /// Whether the curve turns one way only (c′ × c″ of one sign, zeros allowed): a convex closed curve, which a
  /// flat-faced follower touches at one point.
  bool convex() const;
  /// The largest distance of a point of the curve from the origin of its frame (for the sketch and scales).
  double reach() const { return reach_; }

 private:
  enum class Shape { kSpline, kCircle, kLine };
  Curve() = default;
  void finish();  // reach_
  // The piece of a spline that holds s (already wrapped or not), and s's offset within it.
  std::size_t piece(double s, double& u) const;
  // Samples of the curve: (parameter, point), some per piece, for the searches of nearest() and extreme().
  std::vector<std::pair<double, kin::V2>> samples() const;
  double wrap(double s) const;

  Shape shape_ = Shape::kLine;
  bool closed_ = false;
  double length_ = 0.0, reach_ = 0.0;
  kin::V2 centre_{0, 0}, dir_{1, 0};  // circle: centre; line: start and unit direction
  double radius_ = 0.0;
  // spline: knots s_k, and per piece k the cubic c(s_k + u) = a + b u + c u² + d u³ (each a V2)
  std::vector<double> knots_;
  std::vector<kin::V2> a_, b_, c_, d_;
};

/// A curve fixed in a body's frame (or in the ground's): what the higher pairs run on.
struct CurveOn {
  Frame2 frame;                        ///< the body that carries the curve: x, y (m), ψ (rad); constants for ground
  std::shared_ptr<const Curve> curve;  ///< the curve in that frame's local coordinates (m)
  /// The same curve (by what it holds, not by address: each model reads its own).
  bool same_curve(const CurveOn& o) const { return curve == o.curve || (curve && o.curve && *curve == *o.curve); }
  /// The same frame and the same curve (same_curve()).
  bool operator==(const CurveOn& o) const { return frame == o.frame && same_curve(o); }
};

/// @cond internal
namespace detail {
/// The curve offset by ρ along its right normal, p = c + ρ n, and its first two derivatives in s, into d[0..2]
/// (PointOnCurveSpec has the formulas). ρ = 0 is the curve itself. With `normal`, also n, n′ = κ u and
/// n″ = κ′ u − κ² n into normal[0..2] (p's rate along ρ), from the same evaluation of the curve.
inline void offset_curve(const Curve& curve, double s, double rho, kin::V2 d[3], kin::V2* normal = nullptr) {
  kin::V2 c[4];
  curve.evaluate(s, c);
  d[0] = c[0], d[1] = c[1], d[2] = c[2];
  if (rho == 0.0 && !normal) return;
  const double g2 = kin::dot(c[1], c[1]), g = std::sqrt(g2);
  const kin::V2 u = (1.0 / g) * c[1], n = -1.0 * kin::perp(u);  // the right normal: outwards on a CCW profile
  const double k = kin::cross(c[1], c[2]) / g2;                 // the tangent's turn per unit s
  const double dk = kin::cross(c[1], c[3]) / g2 - 2.0 * kin::cross(c[1], c[2]) * kin::dot(c[1], c[2]) / (g2 * g2);
  if (normal) normal[0] = n, normal[1] = k * u, normal[2] = dk * u - (k * k) * n;
  if (rho == 0.0) return;
  d[0] = c[0] + rho * n;
  d[1] = c[1] + (rho * k) * u;
  d[2] = c[2] + rho * (dk * u - (k * k) * n);
}
inline bool datum_rate(CurveOn& rate, const std::array<const CurveOn*, 4>& v, double h) {
  for (const CurveOn* o : v)
    if (!o->same_curve(rate)) return false;
  return datum_rate(rate.frame, {&v[0]->frame, &v[1]->frame, &v[2]->frame, &v[3]->frame}, h);
}
/// The time derivatives V, V′, V″ of V = R(ψ_b) v(s(t)) of a vector v(s) carried by frame b along a curve, from the
/// world vectors R_b v, R_b v′, R_b v″ (`w`) and the motion (ω, α of ψ_b, ṡ, s̈):
///   V′ = ω V⊥ + ṡ R_b v′,   V″ = α V⊥ − ω² V + 2 ω ṡ (R_b v′)⊥ + s̈ R_b v′ + ṡ² R_b v″.
inline void carried_along_curve(const kin::V2 w[3], double omega, double alpha, double sd, double sdd, kin::V2 out[3]) {
  out[0] = w[0];
  out[1] = omega * kin::perp(w[0]) + sd * w[1];
  out[2] = alpha * kin::perp(w[0]) - (omega * omega) * w[0] + (2.0 * omega * sd) * kin::perp(w[1]) + sdd * w[1] +
           (sd * sd) * w[2];
}
/// "" when s is on the curve (any s of a closed curve); else which end of the open curve s has passed, and by
/// how much. A parameter within 10⁻⁹ of the curve's length past an end is taken as at the end (the motion may
/// stop exactly there, and Newton lands within its tolerance).
inline std::string outside_curve(const Curve& curve, double s) {
  const double l = curve.length(), slack = 1e-9 * l;
  if (curve.closed() || (s >= -slack && s <= l + slack)) return "";
  return "the curve parameter s = " + shortest(s) + " m has left the open curve " +
         (s < 0.0 ? "past its start (s = 0)" : "past its end (s = " + shortest(l) + " m)");
}

/// Reads a curve field of a scene entry: `{body: B, spline: [[x, y], …], closed: true}`, `{body: B, circle:
/// {centre: [x, y], radius: r}}`, `{body: B, line: [[x, y], [x, y]]}` or `{body: B, profile: [[angle, radius],
/// …]}` (a cam's radius against angle, rad, closed). A curve's bad data fails on the field, naming the entry.
template <class Fields>
CurveOn read_curve(const Fields& entry, const char* field) {
  const Fields f = entry.sub(field);
  f.expect({"body", "spline", "closed", "circle", "line", "profile"});
  CurveOn out{f.body("body"), nullptr};
  const int forms = f.present("spline") + f.present("circle") + f.present("line") + f.present("profile");
  if (forms != 1) f.fail("", "a curve is one of spline, circle, line or profile");
  if (f.present("closed") && !f.present("spline")) f.fail("closed", "only a spline is closed or open");
  const std::string who = entry.type() + (entry.name().empty() ? "" : " '" + entry.name() + "'") + ": ";
  const char* which = f.present("spline")   ? "spline"
                      : f.present("circle") ? "circle"
                      : f.present("line")   ? "line"
                                            : "profile";
  try {
    if (f.present("spline")) {
      out.curve = Curve::spline(f.vec2_list("spline"), f.present("closed") && f.flag("closed"));
    } else if (f.present("circle")) {
      const Fields c = f.sub("circle");
      c.expect({"centre", "radius"});
      out.curve = Curve::circle(c.present("centre") ? c.vec2("centre") : kin::V2{0, 0}, c.positive("radius"));
    } else if (f.present("line")) {
      const std::vector<kin::V2> p = f.vec2_list("line");
      if (p.size() != 2) f.fail("line", who + "a line is [[x, y], [x, y]]");
      out.curve = Curve::line(p[0], p[1]);
    } else {
      std::vector<double> angles, radii;
      for (const kin::V2 e : f.vec2_list("profile")) angles.push_back(e.x), radii.push_back(e.y);
      out.curve = Curve::radius_table(angles, radii);
    }
  } catch (const Error& e) {
    f.fail(which, who + e.what());
  }
  return out;
}
}  // namespace detail
/// @endcond

}  // namespace phiq
