/// @file
/// A general equation written as text, optionally driven by a motion law. One constraint kind: its equation,
/// derivatives, validation, joint count, sketch and scene form (the contract is documented on DistanceSpec;
/// kinds/registry.hpp lists every kind).
#pragma once

#include <cmath>
#include <memory>
#include <optional>

#include "phiq/expression.hpp"
#include "phiq/motion_law.hpp"
#include "phiq/kinds/kind_support.hpp"

namespace phiq {

/// General equation written as text, optionally driven by a motion law:
///   Φ = g(q, t) − f(t)            (f ≡ 0 without a law)
/// with Φq, Φt and γ derived exactly from g (expression.hpp). `unit` says what g measures (for tolerances).
/// When g is an angle by its top-level form (CompiledExpression::angle_difference(): ±atan2 terms), Φ is g − f
/// wrapped to (−π, π]: atan2 jumps by 2π where its angle passes ±π, the wrapped difference does not, so such a
/// driver runs through any number of turns as the joint-angle drivers do. The wrap changes nothing within π of a
/// solution (the same Φq, Φt and γ), only the 2π jumps.
struct EquationSpec {
  static constexpr int kRows = 1;  ///< one row, in `unit`
  /// @copydoc DistanceSpec::kKind
  /// Scene type `equation` without a law; a scene driver given by `expr` is an equation with a law.
  static constexpr const char* kKind = "equation";
  /// g(q, t), compiled with its derivatives; never null (checked when the constraint is added). Immutable, so
  /// copies of the spec share it.
  std::shared_ptr<const CompiledExpression> g;
  std::optional<MotionLaw> law;  ///< f(t), in g's unit; none means f ≡ 0
  Unit unit = Unit::kNone;       ///< what g measures: the row's unit, for its tolerance (Unit::kNone: plain tol)
  /// @copydoc DistanceSpec::operator==
  /// Equations compare g by its program (CompiledExpression::operator==: a parameter is a constant of the tape).
  bool operator==(const EquationSpec& o) const {
    return unit == o.unit && law == o.law && (g == o.g || (g && o.g && *g == *o.g));
  }

  /// @copydoc DistanceSpec::depends_on_time
  /// An equation depends on time if it has a law or if g contains t.
  bool depends_on_time() const { return law.has_value() || g->depends_on_time(); }
  /// @copydoc DistanceSpec::row_unit
  /// An equation's row has the declared `unit`.
  Unit row_unit(int, const std::vector<Unit>&) const { return unit; }
  /// @copydoc DistanceSpec::characteristic_length
  /// An equation carries no length as data: 0.
  double characteristic_length() const { return 0.0; }
  /// @copydoc DistanceSpec::for_each_slot
  /// @par Equation
  /// An equation reads the coordinates g depends on (CompiledExpression::coordinates(), ascending), each with
  /// Unit::kNone: the text does not tell what they measure.
  template <class F>
  void for_each_slot(F&& f) const {
    for (Index i : g->coordinates()) f(Slot::coordinate(i), Unit::kNone);
  }
  /// @copydoc DistanceSpec::residual
  /// @par Equation
  /// For an equation: Φ = g(q, t) − f(t) (wrapped to (−π, π] when g is an angle, above). g is evaluated with
  /// thread-local scratch (see CompiledExpression).
  void residual(const double* q, double t, double* phi) const {
    const double d = g->value(q, t) - (law ? law->evaluate(t).f : 0.0);
    phi[0] = g->angle_difference() ? wrapped_angle(d) : d;
  }
  /// d wrapped to (−π, π] (d itself when |d| < π: std::remainder is exact).
  static double wrapped_angle(double d) {
    constexpr double kTwoPi = 2.0 * 3.14159265358979323846;
    const double r = std::remainder(d, kTwoPi);
    return r <= -0.5 * kTwoPi ? r + kTwoPi : r;
  }
  /// @copydoc DistanceSpec::jacobian
  /// @par Equation
  /// An equation emits one entry per coordinate of g, in ascending order, through a thread-local gradient buffer:
  /// concurrent calls from different threads are safe, but the sink must not call jacobian() of an EquationSpec.
  template <class Sink>
  void jacobian(const double* q, double t, Sink& s) const {
    thread_local std::vector<double> grad;
    const auto& cols = g->coordinates();
    grad.resize(cols.size());
    g->gradient(q, t, grad.data());
    for (std::size_t k = 0; k < cols.size(); ++k) s(0, Slot::coordinate(cols[k]), grad[k]);
  }
  /// @copydoc DistanceSpec::phi_t
  /// @par Equation
  /// For an equation: Φt = ∂g/∂t − f'(t), exact; thread-local scratch as for residual().
  void phi_t(const double* q, double t, double* out) const {
    out[0] = (g->depends_on_time() ? g->partial_t(q, t) : 0.0) - (law ? law->evaluate(t).df : 0.0);
  }
  /// @copydoc DistanceSpec::gamma
  /// @par Equation
  /// For an equation: γ of g, exact (CompiledExpression::gamma()), plus f''(t); thread-local scratch as for
  /// residual().
  void gamma(const double* q, const double* qd, double t, double* out) const {
    out[0] = g->gamma(q, qd, t) + (law ? law->evaluate(t).ddf : 0.0);
  }
  /// The data a parameter may move (DistanceSpec::data_members()): the expression's constants (the parameters its
  /// text reads, CompiledExpression::constants()) and the law.
  static constexpr auto data_members() { return std::tuple{&EquationSpec::g, &EquationSpec::law}; }
  /// Derivatives along the data (DistanceSpec::data_derivative()). `rate.g` is h = ∂g/∂p at fixed q and t
  /// (CompiledExpression::along_constants(), null where g's constants do not move), compiled as g is: the
  /// derivatives along p of Φ, Φq q̇ + Φt and Φq q̈ − γ are h, hq q̇ + ht and hq q̈ − γ(h), exact as g's own
  /// (∂/∂p commutes with the derivatives in q and t); minus the law's rate (CoordinateDriverSpec::data_derivative()).
  void data_derivative(const EquationSpec& rate, int order, const double* q, const double* qd, const double* qdd,
                       double t, double* out) const {
    double d = 0.0;
    if (const CompiledExpression* h = rate.g.get()) {
      if (order == 0) {
        d = h->value(q, t);
      } else {
        thread_local std::vector<double> grad;
        const auto& cols = h->coordinates();
        grad.resize(cols.size());
        h->gradient(q, t, grad.data());
        const double* v = order == 1 ? qd : qdd;
        for (std::size_t k = 0; k < cols.size(); ++k) d += grad[k] * v[cols[k]];
        if (order == 1)
          d += h->depends_on_time() ? h->partial_t(q, t) : 0.0;
        else
          d -= h->gamma(q, qd, t);
      }
    }
    out[0] = d + (rate.law ? detail::minus_law_rate(*rate.law, order, t) : 0.0);
  }

  /// @copydoc DistanceSpec::joint_count
  /// An equation with a law is a driver; without one, no joint (the count is undefined).
  JointCount joint_count() const { return law ? JointCount::driver() : JointCount::other(); }
  /// @copydoc DistanceSpec::prepare
  void prepare(const double* /*q0*/) const { detail::require(g != nullptr, "equation: no expression"); }
  /// @copydoc DistanceSpec::sketch
  /// An equation draws nothing: its text names no points.
  template <class Sketch>
  void sketch(Sketch&) const {}
  /// @copydoc DistanceSpec::kScene
  static constexpr SceneForm kScene[] = {
      {"constraints", "equation", 0, "- {name: crank_x, type: equation, expr: \"xA - L2*cos(theta2)\", unit: length}"},
      {"drivers", "expr", 0,
       "- {name: lift, expr: yA, unit: length, law: {type: harmonic, amplitude: 0.1, "
       "frequency: 1}}"}};
  /// @copydoc DistanceSpec::read
  /// (The driver form, `expr` under `drivers`, is read with the other drivers.)
  template <class Fields>
  static EquationSpec read(const Fields& f) {
    f.expect({"type", "name", "expr", "unit"});
    return EquationSpec{f.expression("expr"), std::nullopt, f.unit("unit")};
  }
};

}  // namespace phiq
