#include "phiq/motion_law.hpp"

#include <cmath>
#include <limits>
#include <unsupported/Eigen/Splines>

#include "phiq/text.hpp"

namespace phiq {

struct MotionLaw::Impl {
  virtual ~Impl() = default;
  virtual LawValue evaluate(double t) const = 0;
  virtual double begin() const { return -std::numeric_limits<double>::infinity(); }
  virtual double end() const { return std::numeric_limits<double>::infinity(); }
  // The same law as `other` (of any kind: another kind is another law).
  virtual bool same(const Impl& other) const = 0;
};

namespace {

void require_finite(double v, const char* what) {
  if (!std::isfinite(v)) throw Error(std::string("motion law: ") + what + " is not finite");
}

struct Polynomial final : MotionLaw::Impl {
  std::vector<double> c;
  LawValue evaluate(double t) const override {
    // Horner for f, f', f'' together.
    LawValue v;
    for (std::size_t k = c.size(); k-- > 0;) {
      v.ddf = v.ddf * t + 2.0 * v.df;
      v.df = v.df * t + v.f;
      v.f = v.f * t + c[k];
    }
    return v;
  }
  bool same(const MotionLaw::Impl& other) const override {
    const auto* o = dynamic_cast<const Polynomial*>(&other);
    return o && c == o->c;
  }
};

struct Harmonic final : MotionLaw::Impl {
  double offset, amplitude, omega, phase;
  LawValue evaluate(double t) const override {
    double s = std::sin(omega * t + phase), c = std::cos(omega * t + phase);
    return {offset + amplitude * s, amplitude * omega * c, -amplitude * omega * omega * s};
  }
  bool same(const MotionLaw::Impl& other) const override {
    const auto* o = dynamic_cast<const Harmonic*>(&other);
    return o && offset == o->offset && amplitude == o->amplitude && omega == o->omega && phase == o->phase;
  }
};

struct Table final : MotionLaw::Impl {
  using Spline = Eigen::Spline<double, 1>;
  double t0, t1;
  Spline spline;
  LawValue evaluate(double t) const override {
    if (!(t >= t0 && t <= t1)) {
      double nan = std::numeric_limits<double>::quiet_NaN();
      return {nan, nan, nan};
    }
    // The spline is parametrised on u = (t - t0) / (t1 - t0) in [0, 1]: chain rule for the derivatives.
    const double scale = 1.0 / (t1 - t0);
    const double u = std::clamp((t - t0) * scale, 0.0, 1.0);
    auto d = spline.derivatives(u, 2);
    return {d(0, 0), d(0, 1) * scale, d(0, 2) * scale * scale};
  }
  double begin() const override { return t0; }
  double end() const override { return t1; }
  bool same(const MotionLaw::Impl& other) const override {
    const auto* o = dynamic_cast<const Table*>(&other);
    const auto equal = [](const auto& a, const auto& b) {
      return a.rows() == b.rows() && a.cols() == b.cols() && (a.array() == b.array()).all();
    };
    return o && t0 == o->t0 && t1 == o->t1 && equal(spline.knots(), o->spline.knots()) &&
           equal(spline.ctrls(), o->spline.ctrls());
  }
};

struct Expression final : MotionLaw::Impl {
  std::shared_ptr<const CompiledExpression> f;
  LawValue evaluate(double t) const override {
    // f depends on t only: ḟ = ∂f/∂t, and γ of f (no coordinates) is −f_tt.
    return {f->value(nullptr, t), f->partial_t(nullptr, t), -f->gamma(nullptr, nullptr, t)};
  }
  bool same(const MotionLaw::Impl& other) const override {
    const auto* o = dynamic_cast<const Expression*>(&other);
    return o && (f == o->f || *f == *o->f);
  }
};

}  // namespace

bool MotionLaw::operator==(const MotionLaw& other) const {
  if (impl_ == other.impl_) return true;
  return impl_ && other.impl_ && impl_->same(*other.impl_);
}

MotionLaw MotionLaw::linear(double initial, double rate) {
  MotionLaw law = polynomial({initial, rate});
  law.description_ = "linear " + significant(initial, 12) + " + " + significant(rate, 12) + "*t";
  return law;
}

MotionLaw MotionLaw::polynomial(std::vector<double> coefficients) {
  if (coefficients.empty()) throw Error("motion law: polynomial needs at least one coefficient");
  for (double c : coefficients) require_finite(c, "polynomial coefficient");
  auto impl = std::make_shared<Polynomial>();
  impl->c = std::move(coefficients);
  MotionLaw law;
  law.impl_ = impl;
  law.description_ = "polynomial of degree " + std::to_string(impl->c.size() - 1);
  return law;
}

MotionLaw MotionLaw::harmonic(double offset, double amplitude, double frequency, double phase) {
  require_finite(offset, "offset");
  require_finite(amplitude, "amplitude");
  require_finite(frequency, "frequency");
  require_finite(phase, "phase");
  auto impl = std::make_shared<Harmonic>();
  *impl = Harmonic{};
  impl->offset = offset;
  impl->amplitude = amplitude;
  impl->omega = frequency;
  impl->phase = phase;
  MotionLaw law;
  law.impl_ = impl;
  law.description_ = "harmonic";
  return law;
}

MotionLaw MotionLaw::table(std::vector<double> t, std::vector<double> values) {
  if (t.size() != values.size())
    throw Error("motion law: table has " + std::to_string(t.size()) + " times but " +
                std::to_string(values.size()) + " values");
  if (t.size() < 2) throw Error("motion law: table needs at least 2 points");
  for (std::size_t k = 0; k < t.size(); ++k) {
    require_finite(t[k], "table time");
    require_finite(values[k], "table value");
    if (k > 0 && !(t[k] > t[k - 1]))
      throw Error("motion law: table times must increase strictly (t[" + std::to_string(k) +
                  "] = " + significant(t[k], 12) + " after " + significant(t[k - 1], 12) + ")");
  }
  auto impl = std::make_shared<Table>();
  impl->t0 = t.front();
  impl->t1 = t.back();
  const Eigen::Index n = static_cast<Eigen::Index>(t.size());
  Eigen::RowVectorXd u(n), y(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    u(k) = (t[k] - impl->t0) / (impl->t1 - impl->t0);
    y(k) = values[k];
  }
  const Eigen::DenseIndex degree = std::min<Eigen::DenseIndex>(3, n - 1);
  impl->spline = Eigen::SplineFitting<Table::Spline>::Interpolate(y, degree, u);
  MotionLaw law;
  law.impl_ = impl;
  law.description_ = "table of " + std::to_string(n) + " points on [" + significant(impl->t0, 12) + ", " +
                     significant(impl->t1, 12) + "]";
  return law;
}

MotionLaw MotionLaw::expression(std::shared_ptr<const CompiledExpression> f_of_t) {
  if (!f_of_t) throw Error("motion law: null expression");
  if (!f_of_t->coordinates().empty())
    throw Error("motion law \"" + f_of_t->text() + "\": a motion law may depend on t only");
  auto impl = std::make_shared<Expression>();
  impl->f = std::move(f_of_t);
  MotionLaw law;
  law.description_ = "f(t) = " + impl->f->text();
  law.impl_ = impl;
  return law;
}

LawValue MotionLaw::evaluate(double t) const {
  if (!impl_) throw Error("motion law: default-constructed law has no value");
  return impl_->evaluate(t);
}
double MotionLaw::domain_begin() const { return impl_ ? impl_->begin() : 0.0; }
double MotionLaw::domain_end() const { return impl_ ? impl_->end() : 0.0; }

}  // namespace phiq
