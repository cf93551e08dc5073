// The curves of the higher pairs (kinds/curve.hpp): the cubic spline's fit (kinds/cubic_spline.hpp: open, or for a
// closed curve cyclic), evaluation, and the searches that give a curve parameter its initial guess.
#include "phiq/kinds/curve.hpp"

#include <algorithm>
#include <cmath>

#include "kinds/cubic_spline.hpp"
#include "phiq/text.hpp"

namespace phiq {

namespace {
constexpr double kTwoPi = 6.283185307179586476925286766559;
// Samples per spline piece for the coarse searches (a piece turns less than a quarter turn in a sensible profile;
// Newton refines from the best sample).
constexpr int kSamplesPerPiece = 16;
bool finite(kin::V2 p) { return std::isfinite(p.x) && std::isfinite(p.y); }
}  // namespace

std::shared_ptr<const Curve> Curve::spline(std::vector<kin::V2> p, bool closed) {
  for (std::size_t k = 0; k < p.size(); ++k)
    if (!finite(p[k])) throw Error("spline point " + std::to_string(k + 1) + " is not finite");
  if (closed && p.size() > 1 && p.front().x == p.back().x && p.front().y == p.back().y) p.pop_back();
  if (p.size() < 4) throw Error("a spline needs at least 4 distinct points (" + std::to_string(p.size()) + " given)");
  const std::size_t n = p.size(), pieces = closed ? n : n - 1;
  auto curve = std::shared_ptr<Curve>(new Curve());
  Curve& c = *curve;
  c.shape_ = Shape::kSpline;
  c.closed_ = closed;
  c.knots_.assign(pieces + 1, 0.0);
  std::vector<double> h(pieces);
  for (std::size_t k = 0; k < pieces; ++k) {
    const kin::V2 d = p[(k + 1) % n] - p[k];
    h[k] = std::hypot(d.x, d.y);
    if (!(h[k] > 0.0))
      throw Error("spline points " + std::to_string(k + 1) + " and " + std::to_string((k + 1) % n + 1) +
                  " are the same point");
    c.knots_[k + 1] = c.knots_[k] + h[k];
  }
  c.length_ = c.knots_.back();
  detail::CubicPieces<kin::V2> pieces_of = detail::cubic_spline(p, h, closed);  // (curve.hpp: a closed curve's cyclic)
  c.a_ = std::move(pieces_of.a), c.b_ = std::move(pieces_of.b), c.c_ = std::move(pieces_of.c),
  c.d_ = std::move(pieces_of.d);
  c.finish();
  return curve;
}

std::shared_ptr<const Curve> Curve::circle(kin::V2 centre, double radius) {
  if (!finite(centre)) throw Error("the circle's centre is not finite");
  if (!(std::isfinite(radius) && radius > 0.0)) throw Error("the circle's radius must be positive and finite");
  auto curve = std::shared_ptr<Curve>(new Curve());
  curve->shape_ = Shape::kCircle;
  curve->closed_ = true;
  curve->centre_ = centre, curve->radius_ = radius, curve->length_ = kTwoPi * radius;
  curve->finish();
  return curve;
}

std::shared_ptr<const Curve> Curve::line(kin::V2 a, kin::V2 b) {
  if (!finite(a) || !finite(b)) throw Error("the line's points are not finite");
  const kin::V2 d = b - a;
  const double l = std::hypot(d.x, d.y);
  if (!(l > 0.0)) throw Error("the line's two points are the same point");
  auto curve = std::shared_ptr<Curve>(new Curve());
  curve->shape_ = Shape::kLine;
  curve->centre_ = a, curve->dir_ = (1.0 / l) * d, curve->length_ = l;
  curve->finish();
  return curve;
}

std::shared_ptr<const Curve> Curve::radius_table(const std::vector<double>& angles, const std::vector<double>& radii) {
  if (angles.size() != radii.size()) throw Error("the profile has as many angles as radii");
  std::vector<kin::V2> p;
  for (std::size_t k = 0; k < angles.size(); ++k) {
    const std::string at = "profile entry " + std::to_string(k + 1);
    if (!std::isfinite(angles[k]) || !(std::isfinite(radii[k]) && radii[k] > 0.0))
      throw Error(at + ": the radius must be positive and the angle finite");
    if (k > 0 && !(angles[k] > angles[k - 1])) throw Error(at + ": the angles must increase");
    if (!(angles[k] - angles[0] < kTwoPi)) throw Error(at + ": the angles span less than one turn");
    p.push_back({radii[k] * std::cos(angles[k]), radii[k] * std::sin(angles[k])});
  }
  return spline(std::move(p), true);
}

void Curve::finish() {
  if (shape_ == Shape::kCircle) {
    reach_ = std::hypot(centre_.x, centre_.y) + radius_;
    return;
  }
  reach_ = 0.0;
  for (const auto& [s, p] : samples()) reach_ = std::max(reach_, std::hypot(p.x, p.y));
}

double Curve::wrap(double s) const {
  if (!closed_) return s;
  double w = std::fmod(s, length_);
  if (w < 0.0) w += length_;
  return w;
}

std::size_t Curve::piece(double s, double& u) const {
  // the last knot at or before s; an open curve's end pieces continue beyond its ends
  auto it = std::upper_bound(knots_.begin() + 1, knots_.end() - 1, s);
  const std::size_t k = static_cast<std::size_t>(it - knots_.begin()) - 1;
  u = s - knots_[k];
  return k;
}

void Curve::evaluate(double s, kin::V2 d[4]) const {
  switch (shape_) {
    case Shape::kLine:
      d[0] = centre_ + s * dir_, d[1] = dir_, d[2] = d[3] = {0, 0};
      return;
    case Shape::kCircle: {
      const double a = s / radius_, co = std::cos(a), si = std::sin(a);
      d[0] = centre_ + radius_ * kin::V2{co, si};
      d[1] = {-si, co};
      d[2] = (-1.0 / radius_) * kin::V2{co, si};
      d[3] = (1.0 / (radius_ * radius_)) * kin::V2{si, -co};
      return;
    }
    case Shape::kSpline: {
      double u = 0.0;
      const std::size_t k = piece(wrap(s), u);
      const kin::V2 a = a_[k], b = b_[k], c = c_[k], e = d_[k];
      d[0] = a + u * (b + u * (c + u * e));
      d[1] = b + u * (2.0 * c + (3.0 * u) * e);
      d[2] = 2.0 * c + (6.0 * u) * e;
      d[3] = 6.0 * e;
      return;
    }
  }
}

std::vector<std::pair<double, kin::V2>> Curve::samples() const {
  std::vector<std::pair<double, kin::V2>> out;
  const std::size_t pieces = shape_ == Shape::kSpline ? knots_.size() - 1 : 64;
  const std::size_t count = pieces * kSamplesPerPiece + (closed_ ? 0 : 1);
  kin::V2 d[4];
  for (std::size_t i = 0; i < count; ++i) {
    const double s = length_ * static_cast<double>(i) / static_cast<double>(pieces * kSamplesPerPiece);
    evaluate(s, d);
    out.emplace_back(s, d[0]);
  }
  return out;
}

namespace {
// Newton on f(s) = 0 from s, f and f′ given by `fd`, an open curve's s kept within [0, length]: a few iterations
// (the samples are close), stopped where it no longer moves.
template <class Fd>
double refine(double s, double length, bool closed, Fd fd) {
  for (int it = 0; it < 30; ++it) {
    auto [f, df] = fd(s);
    if (!(df > 0.0)) break;  // not a minimum's (or maximum's) basin here: the sample is the answer
    double next = s - f / df;
    if (!closed) next = std::clamp(next, 0.0, length);
    if (std::fabs(next - s) <= 1e-15 * std::max(1.0, length)) return next;
    s = next;
  }
  return s;
}
}  // namespace

double Curve::nearest(kin::V2 p) const {
  double best = 0.0, dmin = INFINITY;
  for (const auto& [s, c] : samples()) {
    const kin::V2 v = c - p;
    if (kin::dot(v, v) < dmin) dmin = kin::dot(v, v), best = s;
  }
  // stationary |c − p|²: (c − p)·c′ = 0, derivative |c′|² + (c − p)·c″
  const double s = refine(best, length_, closed_, [&](double x) {
    kin::V2 d[4];
    evaluate(x, d);
    return std::pair{kin::dot(d[0] - p, d[1]), kin::dot(d[1], d[1]) + kin::dot(d[0] - p, d[2])};
  });
  return closed_ ? wrap(s) : s;
}

double Curve::extreme(kin::V2 m) const {
  double best = 0.0, top = -INFINITY;
  for (const auto& [s, c] : samples())
    if (kin::dot(c, m) > top) top = kin::dot(c, m), best = s;
  // stationary c·m: c′·m = 0, a maximum where c″·m < 0
  const double s = refine(best, length_, closed_, [&](double x) {
    kin::V2 d[4];
    evaluate(x, d);
    return std::pair{-kin::dot(d[1], m), -kin::dot(d[2], m)};
  });
  return closed_ ? wrap(s) : s;
}

bool Curve::convex() const {
  if (shape_ != Shape::kSpline) return true;
  // c′ × c″ is quadratic in u on each piece: its sign at the samples tells (a turn the other way shorter than a
  // sample spacing is missed, which a cam profile through sensible points does not have)
  int sign = 0;
  kin::V2 d[4];
  for (const auto& [s, c] : samples()) {
    evaluate(s, d);
    const double k = kin::cross(d[1], d[2]);
    const double tiny = 1e-12 * kin::dot(d[1], d[1]) / std::max(reach_, 1e-300);
    if (std::fabs(k) <= tiny) continue;
    const int here = k > 0 ? 1 : -1;
    if (sign != 0 && here != sign) return false;
    sign = here;
  }
  return true;
}

}  // namespace phiq
