#include "phiq/motion_law.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unsupported/Eigen/Splines>

#include "kinds/cubic_spline.hpp"
#include "phiq/kinds/kind_support.hpp"
#include "phiq/text.hpp"

namespace phiq {

struct MotionLaw::Impl {
  virtual ~Impl() = default;
  virtual LawValue evaluate(double t) const = 0;
  virtual double begin() const { return -std::numeric_limits<double>::infinity(); }
  virtual double end() const { return std::numeric_limits<double>::infinity(); }
  // The same law as `other` (of any kind: another kind is another law).
  virtual bool same(const Impl& other) const = 0;
  // The law's rate along a parameter (MotionLaw::rate_along), from its copies at p − 2h, p − h, p + h, p + 2h;
  // null where their data do not match this law's (other kinds, other structure): the caller differences the laws.
  virtual std::shared_ptr<const Impl> rate(const std::array<const Impl*, 4>& /*along*/, double /*h*/) const {
    return nullptr;
  }
};

namespace {

void require_finite(double v, const char* what) {
  if (!std::isfinite(v)) throw Error(std::string("motion law: ") + what + " is not finite");
}

// The weights of detail::central_difference() (kinds/kind_support.hpp), times h: MotionLaw::rate_along's fallback
// sums the four laws with them.
constexpr std::array<double, 4> kDifference{1.0 / 12.0, -8.0 / 12.0, 8.0 / 12.0, -1.0 / 12.0};
using detail::central_difference;
// The four copies as the type T, or nulls where one is another kind.
template <class T>
std::array<const T*, 4> copies_as(const std::array<const MotionLaw::Impl*, 4>& along) {
  std::array<const T*, 4> out{};
  for (std::size_t k = 0; k < 4; ++k) out[k] = dynamic_cast<const T*>(along[k]);
  return out;
}
template <class T>
bool all_of_kind(const std::array<const T*, 4>& c) {
  return c[0] && c[1] && c[2] && c[3];
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
  // f is linear in the coefficients: the rate is the polynomial of their rates.
  std::shared_ptr<const Impl> rate(const std::array<const Impl*, 4>& along, double h) const override {
    const auto o = copies_as<Polynomial>(along);
    if (!all_of_kind(o)) return nullptr;
    for (const Polynomial* p : o)
      if (p->c.size() != c.size()) return nullptr;
    auto r = std::make_shared<Polynomial>();
    r->c.resize(c.size());
    for (std::size_t k = 0; k < c.size(); ++k)
      r->c[k] = central_difference(o[0]->c[k], o[1]->c[k], o[2]->c[k], o[3]->c[k], h);
    return r;
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
  std::shared_ptr<const Impl> rate(const std::array<const Impl*, 4>& along, double h) const override;
};

// The rate of a harmonic law along its data's rates (ô, Â, ω̂, φ̂): with ϑ = ωt + φ, ϑ̂ = ω̂t + φ̂, s = sin ϑ, c = cos ϑ,
//   ∂f/∂p = ô + Â s + A c ϑ̂,   ∂f′/∂p = (Âω + Aω̂) c − Aω s ϑ̂,   ∂f″/∂p = −(Âω² + 2Aωω̂) s − Aω² c ϑ̂.
struct HarmonicRate final : MotionLaw::Impl {
  Harmonic at, rate;
  LawValue evaluate(double t) const override {
    const double th = at.omega * t + at.phase, thd = rate.omega * t + rate.phase;
    const double s = std::sin(th), c = std::cos(th), A = at.amplitude, w = at.omega;
    const double Ad = rate.amplitude, wd = rate.omega;
    return {rate.offset + Ad * s + A * c * thd, (Ad * w + A * wd) * c - A * w * s * thd,
            -(Ad * w * w + 2.0 * A * w * wd) * s - A * w * w * c * thd};
  }
  bool same(const MotionLaw::Impl& other) const override {
    const auto* o = dynamic_cast<const HarmonicRate*>(&other);
    return o && at.same(o->at) && rate.same(o->rate);
  }
};

std::shared_ptr<const MotionLaw::Impl> Harmonic::rate(const std::array<const Impl*, 4>& along, double h) const {
  const auto o = copies_as<Harmonic>(along);
  if (!all_of_kind(o)) return nullptr;
  auto r = std::make_shared<HarmonicRate>();
  r->at = *this;
  const auto d = [&](double Harmonic::*m) { return central_difference(o[0]->*m, o[1]->*m, o[2]->*m, o[3]->*m, h); };
  r->rate.offset = d(&Harmonic::offset);
  r->rate.amplitude = d(&Harmonic::amplitude);
  r->rate.omega = d(&Harmonic::omega);
  r->rate.phase = d(&Harmonic::phase);
  return r;
}

// A table that repeats with period P = t_n − t_0 (its last value its first): the cyclic C² cubic spline through
// the points, defined at every t (t taken modulo P into [t_0, t_n)). Per piece k, f = a + b s + c s² + d s³ with
// s = t − t_k.
struct PeriodicTable final : MotionLaw::Impl {
  std::vector<double> t, a, b, c, d;
  LawValue evaluate(double x) const override {
    const double period = t.back() - t.front();
    double s = std::fmod(x - t.front(), period);
    if (s < 0.0) s += period;
    const double u = t.front() + s;
    const auto k = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(
        std::upper_bound(t.begin(), t.end(), u) - t.begin() - 1, 0, static_cast<std::ptrdiff_t>(a.size()) - 1));
    const double h = u - t[k];
    return {a[k] + h * (b[k] + h * (c[k] + h * d[k])), b[k] + h * (2.0 * c[k] + 3.0 * h * d[k]),
            2.0 * c[k] + 6.0 * h * d[k]};
  }
  bool same(const MotionLaw::Impl& other) const override {
    const auto* o = dynamic_cast<const PeriodicTable*>(&other);
    return o && t == o->t && a == o->a && b == o->b && c == o->c && d == o->d;
  }
  // The coefficients are linear in the values: with the same times the rate is the table of their rates.
  std::shared_ptr<const Impl> rate(const std::array<const Impl*, 4>& along, double h) const override {
    const auto o = copies_as<PeriodicTable>(along);
    if (!all_of_kind(o)) return nullptr;
    for (const PeriodicTable* x : o)
      if (x->t != t) return nullptr;
    auto r = std::make_shared<PeriodicTable>(*this);
    auto rate_of = [&](std::vector<double> PeriodicTable::*m, std::vector<double>& out) {
      for (std::size_t k = 0; k < out.size(); ++k)
        out[k] = central_difference((o[0]->*m)[k], (o[1]->*m)[k], (o[2]->*m)[k], (o[3]->*m)[k], h);
    };
    rate_of(&PeriodicTable::a, r->a), rate_of(&PeriodicTable::b, r->b);
    rate_of(&PeriodicTable::c, r->c), rate_of(&PeriodicTable::d, r->d);
    return r;
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
  // With the same times, the interpolating spline's control points are linear in the values, and f in them: the
  // rate is the spline of the control points' rates. Times that move change the knots: null.
  std::shared_ptr<const Impl> rate(const std::array<const Impl*, 4>& along, double h) const override {
    const auto o = copies_as<Table>(along);
    if (!all_of_kind(o)) return nullptr;
    const auto knots = spline.knots();
    const auto ctrls = spline.ctrls();
    for (const Table* x : o)
      if (x->t0 != t0 || x->t1 != t1 || x->spline.knots().size() != knots.size() ||
          !(x->spline.knots().array() == knots.array()).all() || x->spline.ctrls().cols() != ctrls.cols())
        return nullptr;
    Spline::ControlPointVectorType rc(ctrls.rows(), ctrls.cols());
    for (Eigen::Index k = 0; k < ctrls.cols(); ++k)
      rc(0, k) = central_difference(o[0]->spline.ctrls()(0, k), o[1]->spline.ctrls()(0, k), o[2]->spline.ctrls()(0, k),
                                    o[3]->spline.ctrls()(0, k), h);
    auto r = std::make_shared<Table>();
    r->t0 = t0;
    r->t1 = t1;
    r->spline = Spline(knots, rc);
    return r;
  }
};

// f = Σ w_k f_k (MotionLaw::sum): defined where every term is.
struct Sum final : MotionLaw::Impl {
  std::vector<std::pair<double, std::shared_ptr<const MotionLaw::Impl>>> terms;
  LawValue evaluate(double t) const override {
    LawValue v;
    for (const auto& [w, f] : terms) {
      const LawValue x = f->evaluate(t);
      v.f += w * x.f, v.df += w * x.df, v.ddf += w * x.ddf;
    }
    return v;
  }
  double begin() const override {
    double b = -std::numeric_limits<double>::infinity();
    for (const auto& term : terms) b = std::max(b, term.second->begin());
    return b;
  }
  double end() const override {
    double e = std::numeric_limits<double>::infinity();
    for (const auto& term : terms) e = std::min(e, term.second->end());
    return e;
  }
  bool same(const MotionLaw::Impl& other) const override {
    const auto* o = dynamic_cast<const Sum*>(&other);
    if (!o || o->terms.size() != terms.size()) return false;
    for (std::size_t k = 0; k < terms.size(); ++k)
      if (terms[k].first != o->terms[k].first || !terms[k].second->same(*o->terms[k].second)) return false;
    return true;
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
  // f's rate along its constants (the parameters its text reads): the expression ∂f/∂p, exact; 0 where none moves.
  std::shared_ptr<const MotionLaw::Impl> rate(const std::array<const MotionLaw::Impl*, 4>& along,
                                              double h) const override {
    const auto c = copies_as<Expression>(along);
    std::shared_ptr<const CompiledExpression> r;
    if (!all_of_kind(c) ||
        !detail::expression_rate(*f, {c[0]->f.get(), c[1]->f.get(), c[2]->f.get(), c[3]->f.get()}, h, r))
      return nullptr;
    if (!r) {
      auto zero = std::make_shared<Polynomial>();
      zero->c = {0.0};
      return zero;
    }
    auto out = std::make_shared<Expression>();
    out->f = std::move(r);
    return out;
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

MotionLaw MotionLaw::table(std::vector<double> t, std::vector<double> values, bool periodic) {
  if (t.size() != values.size())
    throw Error("motion law: table has " + std::to_string(t.size()) + " times but " + std::to_string(values.size()) +
                " values");
  if (t.size() < 2) throw Error("motion law: table needs at least 2 points");
  for (std::size_t k = 0; k < t.size(); ++k) {
    require_finite(t[k], "table time");
    require_finite(values[k], "table value");
    if (k > 0 && !(t[k] > t[k - 1]))
      throw Error("motion law: table times must increase strictly (t[" + std::to_string(k) +
                  "] = " + significant(t[k], 12) + " after " + significant(t[k - 1], 12) + ")");
  }
  if (periodic) return periodic_table(t, values);
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

MotionLaw MotionLaw::periodic_table(const std::vector<double>& t, const std::vector<double>& values) {
  if (t.size() < 3) throw Error("motion law: a periodic table needs at least 3 points");
  if (values.back() != values.front())
    throw Error("motion law: a periodic table ends where it starts (its last value " + significant(values.back(), 12) +
                " is not its first, " + significant(values.front(), 12) + ")");
  // the cyclic C² cubic spline over the m = n − 1 pieces (kinds/cubic_spline.hpp, as a closed Curve's)
  const std::size_t m = t.size() - 1;
  std::vector<double> h(m);
  for (std::size_t k = 0; k < m; ++k) h[k] = t[k + 1] - t[k];
  detail::CubicPieces<double> pieces =
      detail::cubic_spline(std::vector<double>(values.begin(), values.end() - 1), h, true);
  auto impl = std::make_shared<PeriodicTable>();
  impl->t = t;
  impl->a = std::move(pieces.a), impl->b = std::move(pieces.b), impl->c = std::move(pieces.c),
  impl->d = std::move(pieces.d);
  MotionLaw law;
  law.impl_ = impl;
  law.description_ =
      "periodic table of " + std::to_string(t.size()) + " points, period " + significant(t.back() - t.front(), 12);
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

MotionLaw MotionLaw::sum(const std::vector<std::pair<double, MotionLaw>>& terms) {
  if (terms.empty()) throw Error("motion law: a sum needs at least one term");
  auto impl = std::make_shared<Sum>();
  std::string description;
  for (const auto& [w, law] : terms) {
    require_finite(w, "sum weight");
    if (!law.impl_) throw Error("motion law: a term of a sum has no law");
    impl->terms.emplace_back(w, law.impl_);
    description += (description.empty() ? "" : " + ") + significant(w, 12) + "*(" + law.description_ + ")";
  }
  MotionLaw law;
  law.impl_ = impl;
  law.description_ = description;
  return law;
}

MotionLaw MotionLaw::rate_along(const MotionLaw& at, const std::array<const MotionLaw*, 4>& along, double h) {
  if (!at.impl_ || !along[0]->impl_ || !along[1]->impl_ || !along[2]->impl_ || !along[3]->impl_)
    throw Error("motion law: the rate of a default-constructed law");
  MotionLaw law;
  law.impl_ =
      at.impl_->rate({along[0]->impl_.get(), along[1]->impl_.get(), along[2]->impl_.get(), along[3]->impl_.get()}, h);
  if (law.impl_) {
    law.description_ = "rate of " + at.description_;
    return law;
  }
  std::vector<std::pair<double, MotionLaw>> terms;
  for (std::size_t k = 0; k < 4; ++k) terms.emplace_back(kDifference[k] / h, *along[k]);
  return sum(terms);
}

LawValue MotionLaw::evaluate(double t) const {
  if (!impl_) throw Error("motion law: default-constructed law has no value");
  return impl_->evaluate(t);
}
double MotionLaw::domain_begin() const { return impl_ ? impl_->begin() : 0.0; }
double MotionLaw::domain_end() const { return impl_ ? impl_->end() : 0.0; }

}  // namespace phiq
