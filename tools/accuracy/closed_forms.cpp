#include "closed_forms.hpp"

#include "chain3d_geometry.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "phiq/text.hpp"

namespace phiq::tools {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Named parameters with defaults, in a fixed order (describe() lists them so, and the user overrides them by name).
class Params {
 public:
  Params(std::string kind, std::vector<std::pair<std::string, double>> defaults)
      : kind_(std::move(kind)), values_(std::move(defaults)) {}
  void set(const std::string& name, double value) {
    for (auto& [n, v] : values_)
      if (n == name) {
        v = value;
        return;
      }
    std::string known;
    for (auto& [n, v] : values_) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument(kind_ + ": unknown parameter '" + name + "' (" + known + ")");
  }
  double operator[](const std::string& name) const {
    for (auto& [n, v] : values_)
      if (n == name) return v;
    throw std::logic_error("closed form parameter " + name);
  }
  std::string describe() const {
    std::string s = kind_ + ":";
    for (std::size_t k = 0; k < values_.size(); ++k)
      s += (k ? "," : "") + values_[k].first + "=" + shortest(values_[k].second);
    return s;
  }

 private:
  std::string kind_;
  std::vector<std::pair<std::string, double>> values_;
};

// cos and sin of an angle's motion, by the chain rule: (cos θ)' = −sin θ ω, (cos θ)'' = −cos θ ω² − sin θ α.
Motion cos_of(const Motion& th) {
  const double c = std::cos(th.q), s = std::sin(th.q);
  return {c, -s * th.v, -c * th.v * th.v - s * th.a};
}
Motion sin_of(const Motion& th) {
  const double c = std::cos(th.q), s = std::sin(th.q);
  return {s, c * th.v, -s * th.v * th.v + c * th.a};
}

// "x12" -> ("x", 12); ("", -1) when the name does not end in a non-negative integer after a letter prefix.
std::pair<std::string, long> split_index(const std::string& name) {
  std::size_t k = 0;
  while (k < name.size() && !(name[k] >= '0' && name[k] <= '9')) ++k;
  if (k == 0 || k == name.size()) return {"", -1};
  long i = 0;
  auto r = std::from_chars(name.data() + k, name.data() + name.size(), i);
  if (r.ec != std::errc() || r.ptr != name.data() + name.size() || i < 0) return {"", -1};
  if (name.size() - k > 1 && name[k] == '0') return {"", -1};  // "x01" is not a generated name
  return {name.substr(0, k), i};
}

// The notes' crank-slider (models/seed/crank_slider_*.yaml): crank O–A of length L2 at θ = theta0 + omega·t, rod
// A–B of length L3, slider B on the x axis to the right of O. Link angles: θ and the rod's φ (A→B), with
// L2 sin θ + L3 sin φ = 0 (B on y = 0) and cos φ > 0.
class CrankSlider final : public ClosedForm {
 public:
  explicit CrankSlider(Params p) : p_(std::move(p)), L2_(p_["L2"]), L3_(p_["L3"]) {
    if (!(L2_ > 0 && L3_ > L2_)) throw std::invalid_argument("crank-slider: needs 0 < L2 < L3 (a full crank turn)");
  }
  std::string describe() const override { return p_.describe(); }

 protected:
  bool terms_of(const std::string& n, Binding& b) const override {
    if (n == "theta2")
      b = {{{Term::kAngle, 0, 1.0}}, true};
    else if (n == "xA")
      b = {{{Term::kCos, 0, L2_}}, false};
    else if (n == "yA")
      b = {{{Term::kSin, 0, L2_}}, false};
    else if (n == "xB")
      b = {{{Term::kCos, 0, L2_}, {Term::kCos, 1, L3_}}, false};
    else
      return false;
    return true;
  }
  void angles(double t, std::vector<Motion>& out) const override {
    const Motion th{p_["theta0"] + p_["omega"] * t, p_["omega"], 0.0};
    const double c = std::cos(th.q), s = std::sin(th.q);
    const double sphi = -L2_ * s / L3_, cphi = std::sqrt(1.0 - sphi * sphi);
    // L3 sin φ = −L2 sin θ, differentiated once and twice in t
    const double w = -L2_ * c * th.v / (L3_ * cphi);
    const double al = (L3_ * sphi * w * w - L2_ * (c * th.a - s * th.v * th.v)) / (L3_ * cphi);
    out = {th, {std::atan2(sphi, cphi), w, al}};
  }

 private:
  Params p_;
  double L2_, L3_;
};

// The seed four-bar (models/seed/fourbar_*.yaml): ground pivots O = (0, 0) and C = (L1, 0), crank O–A (L2) at
// θ2 = theta0 + omega·t, coupler A–B (L3), rocker C–B (L4). B is an intersection of the circle of radius L3 about A
// and of radius L4 about C (the classic closed-form loop solution); branch = +1 takes B to the left of A→C (above the
// ground line at θ2 = 0, the seed scenes' assembly), −1 the crossed one. Angles θ2, θ3 (A→B), θ4 (C→B); their rates
// from the loop L2 e^{iθ2} + L3 e^{iθ3} − L4 e^{iθ4} = L1 differentiated once and twice (a 2×2 system, Cramer's
// rule, singular only at the toggle positions θ3 = θ4 mod π, which a Grashof crank-rocker never reaches).
class FourBar final : public ClosedForm {
 public:
  explicit FourBar(Params p)
      : p_(std::move(p)), L1_(p_["L1"]), L2_(p_["L2"]), L3_(p_["L3"]), L4_(p_["L4"]), branch_(p_["branch"]) {
    if (!(L1_ > 0 && L2_ > 0 && L3_ > 0 && L4_ > 0)) throw std::invalid_argument("fourbar: lengths must be positive");
    if (branch_ != 1.0 && branch_ != -1.0) throw std::invalid_argument("fourbar: branch is 1 or -1");
  }
  std::string describe() const override { return p_.describe(); }

 protected:
  bool terms_of(const std::string& n, Binding& b) const override {
    using T = ClosedForm::Term;
    const T xA{T::kCos, 0, L2_}, yA{T::kSin, 0, L2_}, xB0{T::kConstant, -1, L1_}, xB{T::kCos, 2, L4_},
        yB{T::kSin, 2, L4_};
    // natural and mixed: points A, B and the crank angle
    if (n == "theta2" || n == "psi2")
      b = {{{T::kAngle, 0, 1.0}}, true};
    else if (n == "xA")
      b = {{xA}, false};
    else if (n == "yA")
      b = {{yA}, false};
    else if (n == "xB")
      b = {{xB0, xB}, false};
    else if (n == "yB")
      b = {{yB}, false};
    // reference point: each link's centre and its angle (the rocker's axis runs from C to B)
    else if (n == "x2")
      b = {{{T::kCos, 0, L2_ / 2}}, false};
    else if (n == "y2")
      b = {{{T::kSin, 0, L2_ / 2}}, false};
    else if (n == "x3")
      b = {{xA, {T::kCos, 1, L3_ / 2}}, false};
    else if (n == "y3")
      b = {{yA, {T::kSin, 1, L3_ / 2}}, false};
    else if (n == "psi3" && !relative_)
      b = {{{T::kAngle, 1, 1.0}}, true};
    else if (n == "x4")
      b = {{xB0, {T::kCos, 2, L4_ / 2}}, false};
    else if (n == "y4")
      b = {{{T::kSin, 2, L4_ / 2}}, false};
    else if (n == "psi4" && !relative_)
      b = {{{T::kAngle, 2, 1.0}}, true};
    // relative: joint angles, ψ3 = θ3 − θ2 at A and ψ4 = θ4 + π − θ3 at B (the third link runs B→C)
    else if (n == "psi3")
      b = {{{T::kAngle, 1, 1.0}, {T::kAngle, 0, -1.0}}, true};
    else if (n == "psi4")
      b = {{{T::kAngle, 2, 1.0}, {T::kConstant, -1, kPi}, {T::kAngle, 1, -1.0}}, true};
    else
      return false;
    return true;
  }
  // The relative formulation names its joint angles psi2..psi4 like the reference-point bodies' angles; it is the
  // one formulation without x2 or xA.
  void prepare(const std::vector<std::string>& coordinates) override {
    bool points = false;
    for (const auto& n : coordinates) points = points || n == "xA" || n == "x2";
    relative_ = !points;
  }
  void angles(double t, std::vector<Motion>& out) const override {
    const Motion th2{p_["theta0"] + p_["omega"] * t, p_["omega"], 0.0};
    const double c2 = std::cos(th2.q), s2 = std::sin(th2.q);
    const double ax = L2_ * c2, ay = L2_ * s2, dx = L1_ - ax, dy = -ay, d = std::hypot(dx, dy);
    const double along = (L3_ * L3_ - L4_ * L4_ + d * d) / (2 * d), h = std::sqrt(L3_ * L3_ - along * along);
    const double bx = ax + (along * dx - branch_ * h * dy) / d, by = ay + (along * dy + branch_ * h * dx) / d;
    const double th3 = std::atan2(by - ay, bx - ax), th4 = std::atan2(by, bx - L1_);
    const double c3 = std::cos(th3), s3 = std::sin(th3), c4 = std::cos(th4), s4 = std::sin(th4);
    // [−L3 s3, L4 s4; L3 c3, −L4 c4] [x3; x4] = r, for the rates (x = ω) and the accelerations (x = α)
    const double m11 = -L3_ * s3, m12 = L4_ * s4, m21 = L3_ * c3, m22 = -L4_ * c4, det = m11 * m22 - m12 * m21;
    auto solve = [&](double r1, double r2) {
      return std::pair{(r1 * m22 - m12 * r2) / det, (m11 * r2 - m21 * r1) / det};
    };
    const double w2 = th2.v, a2 = th2.a;
    const auto [w3, w4] = solve(L2_ * s2 * w2, -L2_ * c2 * w2);
    const auto [a3, a4] = solve(L2_ * (c2 * w2 * w2 + s2 * a2) + L3_ * c3 * w3 * w3 - L4_ * c4 * w4 * w4,
                                L2_ * (s2 * w2 * w2 - c2 * a2) + L3_ * s3 * w3 * w3 - L4_ * s4 * w4 * w4);
    out = {th2, {th3, w3, a3}, {th4, w4, a4}};
  }

 private:
  bool relative_ = false;  // the model is the relative formulation (ψ3, ψ4 are joint angles)
  Params p_;
  double L1_, L2_, L3_, L4_, branch_;
};

// IFToMM N four-bar as `phiq generate nfourbar` writes it: N + 1 unit cranks pinned at (i, 0), unit couplers. The
// exact solution is the parallelogram: every crank at the driven angle θ = from + (to − from)·t, so crank tip
// P_i = (i + cos θ, sin θ) and every coupler horizontal. Natural (x<i>, y<i>, theta) and reference-point (crank
// centres xc, yc, psi; coupler centres xk, yk, phi) coordinates.
class NFourBar final : public ClosedForm {
 public:
  explicit NFourBar(Params p) : p_(std::move(p)) {}
  std::string describe() const override { return p_.describe(); }

 protected:
  bool terms_of(const std::string& n, Binding& b) const override {
    using T = ClosedForm::Term;
    if (n == "theta") return b = {{{T::kAngle, 0, 1.0}}, true}, true;
    auto [prefix, i] = split_index(n);
    const double x = static_cast<double>(i);
    if (i < 0) return false;
    if (prefix == "x")
      b = {{{T::kConstant, -1, x}, {T::kCos, 0, 1.0}}, false};
    else if (prefix == "y")
      b = {{{T::kSin, 0, 1.0}}, false};
    else if (prefix == "xc")
      b = {{{T::kConstant, -1, x}, {T::kCos, 0, 0.5}}, false};
    else if (prefix == "yc")
      b = {{{T::kSin, 0, 0.5}}, false};
    else if (prefix == "psi")
      b = {{{T::kAngle, 0, 1.0}}, true};
    else if (prefix == "xk")
      b = {{{T::kConstant, -1, x + 0.5}, {T::kCos, 0, 1.0}}, false};
    else if (prefix == "yk")
      b = {{{T::kSin, 0, 1.0}}, false};
    else if (prefix == "phi")
      b = {{{T::kConstant, -1, 0.0}}, true};
    else
      return false;
    return true;
  }
  void angles(double t, std::vector<Motion>& out) const override {
    const double from = p_["from"], rate = p_["to"] - from;
    out = {{from + rate * t, rate, 0.0}};
  }

 private:
  Params p_;
};

// `phiq generate chain3d` (generate_chain3d.cpp, geometry in chain3d_geometry.hpp): N + 1 unit cranks on hinges of
// axis u, crank i pinned at O_i = i·o and at angle φ_i = θ + i·twist about u, θ = from + (to − from)·t, its tip
// P_i = O_i + cos φ_i e1 + sin φ_i e2 (o = e1 for twist 0, the parallelogram row; o = u otherwise). Natural (tips
// x<i>, y<i>, z<i> and theta) and reference-point (crank centres xc, yc, zc at half the radius; Euler parameters
// e0c … e3c = cos(φ_i/2) qa + sin(φ_i/2) qb) coordinates. Each is written in the angles θ (0) and θ/2 (1):
// cos(θ + β) = cos β cos θ − sin β sin θ.
class Chain3d final : public ClosedForm {
 public:
  explicit Chain3d(Params p) : p_(std::move(p)), g_(chain3d::geometry()), twist_(p_["twist"]) {}
  std::string describe() const override { return p_.describe(); }

 protected:
  bool terms_of(const std::string& n, Binding& b) const override {
    using T = ClosedForm::Term;
    if (n == "theta") return b = {{{T::kAngle, 0, 1.0}}, true}, true;
    // c · (cos(angle + β) a + sin(angle + β) b), one component: terms in cos and sin of `angle`
    auto rotating = [](int angle, double beta, double c, double a, double b) {
      const double cb = std::cos(beta), sb = std::sin(beta);
      return std::vector<T>{{T::kCos, angle, c * (cb * a + sb * b)}, {T::kSin, angle, c * (cb * b - sb * a)}};
    };
    if (n.size() > 3 && n[0] == 'e' && n[1] >= '0' && n[1] <= '3' && n[2] == 'c') {  // Euler parameter e<k>c<i>
      const long i = split_index(n.substr(2)).second;
      const auto k = static_cast<std::size_t>(n[1] - '0');
      if (i < 0) return false;
      b = {rotating(1, 0.5 * twist_ * static_cast<double>(i), 1.0, g_.qa[k], g_.qb[k]), false};
      return true;
    }
    // tips x<i>, y<i>, z<i>; crank centres xc<i>, yc<i>, zc<i> (half the radius)
    const auto [prefix, i] = split_index(n);
    if (i < 0 || prefix.size() > 2 || prefix[0] < 'x' || prefix[0] > 'z' || (prefix.size() == 2 && prefix[1] != 'c'))
      return false;
    const auto k = static_cast<std::size_t>(prefix[0] - 'x');
    const double x = static_cast<double>(i);
    b = {rotating(0, twist_ * x, prefix.size() == 2 ? 0.5 : 1.0, g_.e1[k], g_.e2[k]), false};
    b.terms.push_back({T::kConstant, -1, x * (twist_ == 0.0 ? g_.e1 : g_.u)[k]});
    return true;
  }
  void angles(double t, std::vector<Motion>& out) const override {
    const double from = p_["from"], rate = p_["to"] - from;
    const Motion th{from + rate * t, rate, 0.0};
    out = {th, {0.5 * th.q, 0.5 * th.v, 0.5 * th.a}};
  }

 private:
  Params p_;
  chain3d::Geometry g_;
  double twist_;
};

}  // namespace

void ClosedForm::bind(const std::vector<std::string>& coordinates) {
  prepare(coordinates);
  std::vector<Binding> b(coordinates.size());
  for (std::size_t j = 0; j < coordinates.size(); ++j)
    if (!terms_of(coordinates[j], b[j]))
      throw std::invalid_argument(describe().substr(0, describe().find(':')) + ": no coordinate '" + coordinates[j] +
                                  "' in this mechanism (a scene of another mechanism?)");
  bound_ = std::move(b);
}

void ClosedForm::evaluate(double t, double* q, double* v, double* a) const {
  angles(t, angles_);
  for (std::size_t j = 0; j < bound_.size(); ++j) {
    Motion m;
    for (const Term& term : bound_[j].terms) {
      Motion f;
      switch (term.kind) {
        case Term::kConstant:
          f = {1.0, 0.0, 0.0};
          break;
        case Term::kAngle:
          f = angles_[static_cast<std::size_t>(term.angle)];
          break;
        case Term::kCos:
          f = cos_of(angles_[static_cast<std::size_t>(term.angle)]);
          break;
        case Term::kSin:
          f = sin_of(angles_[static_cast<std::size_t>(term.angle)]);
          break;
      }
      m.q += term.coef * f.q, m.v += term.coef * f.v, m.a += term.coef * f.a;
    }
    q[j] = m.q, v[j] = m.v, a[j] = m.a;
  }
}

ClosedFormErrors::ClosedFormErrors(const ClosedForm& f, const double* scale)
    : f_(f), scale_(scale), rq_(f.size()), rv_(f.size()), ra_(f.size()) {}

double ClosedFormErrors::add(double t, const double* q, const double* qd, const double* qdd) {
  f_.evaluate(t, rq_.data(), rv_.data(), ra_.data());
  double row = 0.0;
  for (std::size_t j = 0; j < rq_.size(); ++j) {
    const double s = scale_ ? scale_[j] : 1.0;
    double d = q[j] - rq_[j];
    if (f_.is_angle(j)) d = std::remainder(d, 2.0 * kPi);
    row = std::max(row, std::fabs(d) / s);
    if (qd) v_error = std::max(v_error, std::fabs(qd[j] - rv_[j]) / s);
    if (qdd) a_error = std::max(a_error, std::fabs(qdd[j] - ra_[j]) / s);
  }
  q_error = std::max(q_error, row);
  return row;
}

std::unique_ptr<ClosedForm> make_closed_form(const std::string& spec) {
  const std::size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  std::unique_ptr<Params> p;
  if (kind == "crank-slider")
    p = std::make_unique<Params>(
        kind, std::vector<std::pair<std::string, double>>{{"L2", 0.3}, {"L3", 1.0}, {"theta0", 0.0}, {"omega", 2.0}});
  else if (kind == "fourbar")
    p = std::make_unique<Params>(
        kind,
        std::vector<std::pair<std::string, double>>{
            {"L1", 1.0}, {"L2", 0.4}, {"L3", 1.2}, {"L4", 1.0}, {"theta0", 0.0}, {"omega", 1.0}, {"branch", 1.0}});
  else if (kind == "nfourbar")
    p = std::make_unique<Params>(kind,
                                 std::vector<std::pair<std::string, double>>{{"from", kPi / 4}, {"to", 3 * kPi / 4}});
  else if (kind == "chain3d")
    p = std::make_unique<Params>(
        kind, std::vector<std::pair<std::string, double>>{{"from", kPi / 4}, {"to", 3 * kPi / 4}, {"twist", 0.0}});
  else
    throw std::invalid_argument("unknown closed form '" + kind + "' (crank-slider, fourbar, nfourbar, chain3d)");
  if (colon != std::string::npos) {
    const std::string rest = spec.substr(colon + 1);
    std::size_t start = 0;
    while (start <= rest.size()) {
      const std::size_t end = std::min(rest.find(',', start), rest.size());
      const std::string item = rest.substr(start, end - start);
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos) throw std::invalid_argument(kind + ": expected NAME=VALUE, got '" + item + "'");
      double v = 0;
      const char* b = item.data() + eq + 1;
      auto r = std::from_chars(b, item.data() + item.size(), v);
      if (r.ec != std::errc() || r.ptr != item.data() + item.size() || !std::isfinite(v))
        throw std::invalid_argument(kind + ": " + item.substr(0, eq) + ": not a finite number: '" +
                                    item.substr(eq + 1) + "'");
      p->set(item.substr(0, eq), v);
      start = end + 1;
    }
  }
  if (kind == "crank-slider") return std::make_unique<CrankSlider>(std::move(*p));
  if (kind == "fourbar") return std::make_unique<FourBar>(std::move(*p));
  if (kind == "chain3d") return std::make_unique<Chain3d>(std::move(*p));
  return std::make_unique<NFourBar>(std::move(*p));
}

std::string closed_form_for_scene_name(const std::string& n) {
  auto starts = [&](const char* s) { return n.rfind(s, 0) == 0; };
  if (starts("crank_slider")) return "crank-slider";
  if (starts("nfourbar_")) return "nfourbar";
  if (starts("chain3d_")) return "chain3d";
  if (starts("fourbar_")) return "fourbar";
  return "";
}

}  // namespace phiq::tools
