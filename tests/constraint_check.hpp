// Derivative checks shared by the constraint-kind tests (test_constraint_kinds.cpp, test_constraint_kinds_3d.cpp):
// a spec's Jacobian entries, Φt and γ against finite differences at random states, with the entry sequence of the
// pattern pass (q = 0) required at every state; and the same for a whole Model through its CSC pattern.
// Header-only, in an unnamed namespace: each test file gets its own copy.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "phiq/constraint_block.hpp"
#include "phiq/model.hpp"
#include "phiq/spatial_attachment.hpp"
#include "phiq/kinds/loop.hpp"
#include "phiq/kinds/spatial_joints.hpp"
#include "phiq/types.hpp"
#include "kind_checks.hpp"

namespace {

using phiq::Index;
using phiq::Slot;

// How the kinds' tests write a spec's slots: a coordinate's, a constant's; a spatial natural point and a body frame
// on consecutive coordinates (x, y, z; then the four Euler parameters).
inline Slot S(Index i) { return Slot::coordinate(i); }
inline Slot C(double v) { return Slot::constant(v); }
inline phiq::Point3 Nat(Index first) { return phiq::Point3{S(first), S(first + 1), S(first + 2)}; }
inline phiq::Frame3 Body(Index first) {
  return phiq::Frame3{S(first), S(first + 1), S(first + 2), S(first + 3), S(first + 4), S(first + 5), S(first + 6)};
}

// ---- tolerances and steps -------------------------------------------------------------------------------------

constexpr double kJacStep = 1e-6;    // relative step of the first differences (q and t)
constexpr double kJacTol = 1e-6;     // relative to max(1, |entry|)
constexpr double kGammaStep = 4e-3;  // step of the coarser second difference (Richardson with h and h/2)
// The path s ↦ (q + s q̇, t + s) moves faster with larger velocities, and the truncation error of the second difference
// grows with the sixth power of the speed: the step is taken per unit of path speed, so that every sample is
// differentiated equally well. (Samples differ between compilers: GCC and clang evaluate the random draws in
// function arguments in opposite orders; a clang sample with |q̇| ≈ 2.6 missed 1e-7 with a fixed step.)
double GammaStep(const std::vector<double>& qd) {
  double speed = 1.0;
  for (double v : qd) speed = std::max(speed, std::fabs(v));
  return kGammaStep / speed;
}
constexpr double kGammaTol = 1e-7;     // relative to max(1, |γ|)
constexpr double kSentinel = 7.25e77;  // written past the rows a kind owns; must survive

double Tol(double rel, double value) { return rel * std::max(1.0, std::fabs(value)); }

// ---- random states --------------------------------------------------------------------------------------------

struct State {
  std::vector<double> q, qd;
  double t = 0.0;
};

class StateGenerator {
 public:
  explicit StateGenerator(std::uint32_t seed) : rng_(seed) {}
  // q in [-2, 2], q̇ in [-3, 3], t in [0, 2]; t is moved at least `clearance` away from every kink (times where
  // a law's third derivative jumps, e.g. the interior knots of a spline), so that second differences are valid.
  State Next(int n, const std::vector<double>& kinks = {}, double clearance = 0.02) {
    std::uniform_real_distribution<double> uq(-2.0, 2.0), uv(-3.0, 3.0), ut(0.0, 2.0);
    State s;
    s.q.resize(static_cast<std::size_t>(n));
    s.qd.resize(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) s.q[j] = uq(rng_);
    for (int j = 0; j < n; ++j) s.qd[j] = uv(rng_);
    s.t = ut(rng_);
    for (bool moved = true; moved;) {
      moved = false;
      for (double k : kinks)
        if (std::fabs(s.t - k) < clearance) s.t += 2.5 * clearance, moved = true;
    }
    return s;
  }

 private:
  std::mt19937 rng_;
};

std::string Describe(const State& s) {
  // a stream, not string concatenation: GCC 12 warns falsely (-Wrestrict, PR 105329) on "literal" + std::string
  std::ostringstream out;
  out << "state: t = " << s.t << ", q = [";
  for (double v : s.q) out << ' ' << v;
  out << " ], qd = [";
  for (double v : s.qd) out << ' ' << v;
  out << " ]";
  return out.str();
}

// ---- spec-level evaluation ------------------------------------------------------------------------------------

struct Entry {
  int row;
  Index col;
  double value;
};

// The coordinate entries emitted through the sink, in order (constant slots are skipped, as every sink does).
template <class Spec>
std::vector<Entry> Entries(const Spec& spec, const double* q, double t) {
  std::vector<Entry> out;
  auto sink = [&](int row, const Slot& s, double v) {
    if (s.is_coordinate()) out.push_back({row, s.coord(), v});
  };
  spec.jacobian(q, t, sink);
  return out;
}

template <class Spec>
std::vector<double> Residual(const Spec& spec, const std::vector<double>& q, double t) {
  std::vector<double> phi(Spec::kRows, 0.0);
  spec.residual(q.data(), t, phi.data());
  return phi;
}

// Φ(q + s q̇, t + s)
template <class Spec>
std::vector<double> ResidualAlongPath(const Spec& spec, const State& st, double s) {
  std::vector<double> q(st.q.size());
  for (std::size_t j = 0; j < q.size(); ++j) q[j] = st.q[j] + s * st.qd[j];
  return Residual(spec, q, st.t + s);
}

// Richardson-extrapolated d²/ds² of f(s) at 0 (f returns one value per row): (4 D(h/2) − D(h)) / 3 with
// D(h) = (f(h) − 2 f(0) + f(−h)) / h². Error O(h⁴) instead of O(h²).
template <class F>
std::vector<double> SecondDerivative(F&& f, double h) {
  auto d = [&](double step) {
    std::vector<double> p = f(step), z = f(0.0), m = f(-step), out(z.size());
    for (std::size_t r = 0; r < z.size(); ++r) out[r] = (p[r] - 2.0 * z[r] + m[r]) / (step * step);
    return out;
  };
  std::vector<double> coarse = d(h), fine = d(0.5 * h), out(coarse.size());
  for (std::size_t r = 0; r < out.size(); ++r) out[r] = (4.0 * fine[r] - coarse[r]) / 3.0;
  return out;
}

struct CheckOptions {
  std::uint32_t seed = 20240607;
  bool time_dependent = false;  // what depends_on_time() must answer
  int samples = 6;
  std::vector<double> kinks;  // times the γ stencil must keep clear of
};

CheckOptions Opts(std::uint32_t seed, bool time_dependent = false, int samples = 6, std::vector<double> kinks = {}) {
  CheckOptions o;
  o.seed = seed;
  o.time_dependent = time_dependent;
  o.samples = samples;
  o.kinks = std::move(kinks);
  return o;
}

template <class Spec>
void CheckSpec(const Spec& spec, int n_coords, const CheckOptions& opt) {
  (void)phiq::test::FdCheckOf<Spec>::registered;  // tests/test_kind_registry.cpp: this kind has a check
  constexpr int m = Spec::kRows;
  const std::size_t n = static_cast<std::size_t>(n_coords);
  SCOPED_TRACE(std::string("kind '") + Spec::kKind + "'");
  EXPECT_EQ(spec.depends_on_time(), opt.time_dependent);
  ASSERT_LT(phiq::max_coordinate(spec), n_coords);

  // The pattern pass, as TypedBlock::build_pattern runs it.
  std::vector<double> zeros(static_cast<std::size_t>(phiq::max_coordinate(spec) + 1), 0.0);
  const std::vector<Entry> pattern = Entries(spec, zeros.data(), 0.0);
  ASSERT_FALSE(pattern.empty());

  StateGenerator gen(opt.seed), directions(opt.seed ^ 0x5bd1e995u);  // (apart: the states stay those of the seed)
  for (int k = 0; k < opt.samples; ++k) {
    const State st = gen.Next(n_coords, opt.kinks);
    SCOPED_TRACE("sample " + std::to_string(k) + ", " + Describe(st));
    const double* q = st.q.data();

    // Rows written: exactly [0, kRows), all finite.
    std::vector<double> phi(m + 2, kSentinel), pt(m + 2, kSentinel), gam(m + 2, kSentinel);
    spec.residual(q, st.t, phi.data());
    spec.phi_t(q, st.t, pt.data());
    spec.gamma(q, st.qd.data(), st.t, gam.data());
    for (int r = 0; r < m + 2; ++r) {
      if (r < m) {
        EXPECT_TRUE(std::isfinite(phi[r]) && std::isfinite(pt[r]) && std::isfinite(gam[r])) << "row " << r;
      } else {
        EXPECT_EQ(phi[r], kSentinel) << "residual writes past its rows";
        EXPECT_EQ(pt[r], kSentinel) << "phi_t writes past its rows";
        EXPECT_EQ(gam[r], kSentinel) << "gamma writes past its rows";
      }
    }

    // 1. Jacobian.
    const std::vector<Entry> entries = Entries(spec, q, st.t);
    ASSERT_EQ(entries.size(), pattern.size()) << "the entry set depends on the values";
    Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(m, n_coords);
    for (std::size_t e = 0; e < entries.size(); ++e) {
      ASSERT_EQ(entries[e].row, pattern[e].row) << "entry " << e << " changed row between calls";
      ASSERT_EQ(entries[e].col, pattern[e].col) << "entry " << e << " changed column between calls";
      ASSERT_GE(entries[e].row, 0);
      ASSERT_LT(entries[e].row, m);
      ASSERT_GE(entries[e].col, 0);
      ASSERT_LT(entries[e].col, n_coords);
      EXPECT_TRUE(std::isfinite(entries[e].value));
      jac(entries[e].row, entries[e].col) += entries[e].value;  // duplicates accumulate, as in the CSC slots
    }
    for (std::size_t j = 0; j < n; ++j) {
      const double h = kJacStep * std::max(1.0, std::fabs(st.q[j]));
      std::vector<double> qp = st.q, qm = st.q;
      qp[j] += h;
      qm[j] -= h;
      const std::vector<double> fp = Residual(spec, qp, st.t), fm = Residual(spec, qm, st.t);
      for (int r = 0; r < m; ++r) {
        const double fd = (fp[r] - fm[r]) / (qp[j] - qm[j]);
        EXPECT_NEAR(jac(r, static_cast<Index>(j)), fd, Tol(kJacTol, fd)) << "Phi_q(" << r << ", " << j << ")";
      }
    }

    // 2. Φt.
    if (opt.time_dependent) {
      const double h = kJacStep * std::max(1.0, std::fabs(st.t));
      const double tp = st.t + h, tm = st.t - h;
      const std::vector<double> fp = Residual(spec, st.q, tp), fm = Residual(spec, st.q, tm);
      for (int r = 0; r < m; ++r) {
        const double fd = (fp[r] - fm[r]) / (tp - tm);
        EXPECT_NEAR(pt[r], fd, Tol(kJacTol, fd)) << "Phi_t row " << r;
      }
    } else {
      const std::vector<double> later = Residual(spec, st.q, st.t + 0.37);
      for (int r = 0; r < m; ++r) {
        EXPECT_EQ(pt[r], 0.0) << "Phi_t row " << r << " of a time-independent constraint";
        EXPECT_EQ(later[r], phi[r]) << "residual row " << r << " changes with t";
      }
    }

    // 3. γ = −d²/ds² Φ(q + s q̇, t + s) at s = 0.
    const std::vector<double> dd =
        SecondDerivative([&](double s) { return ResidualAlongPath(spec, st, s); }, GammaStep(st.qd));
    for (int r = 0; r < m; ++r) EXPECT_NEAR(gam[r], -dd[r], Tol(kGammaTol, gam[r])) << "gamma row " << r;

    // 4. γ is a quadratic in q̇ whose derivative along v is −2 B v, B = ∂(Φq q̇ + Φt)/∂q: the direct sensitivities
    // read B v as [γ(q̇ − v) − γ(q̇ + v)] / 4 (sensitivity.hpp). Against the difference of Φq q̇ + Φt along v.
    const State dir = directions.Next(n_coords);
    std::vector<double> minus(st.qd), plus(st.qd), gm(m), gp(m);
    for (std::size_t j = 0; j < n; ++j) minus[j] -= dir.qd[j], plus[j] += dir.qd[j];
    spec.gamma(q, minus.data(), st.t, gm.data());
    spec.gamma(q, plus.data(), st.t, gp.data());
    auto velocity_term = [&](double e) {  // Φq(q + e v) q̇ + Φt(q + e v, t)
      std::vector<double> at(st.q), out(m, 0.0);
      for (std::size_t j = 0; j < n; ++j) at[j] += e * dir.qd[j];
      spec.phi_t(at.data(), st.t, out.data());
      auto sink = [&](int row, const Slot& slot, double value) {
        if (slot.is_coordinate()) out[row] += value * st.qd[slot.coord()];
      };
      spec.jacobian(at.data(), st.t, sink);
      return out;
    };
    const double e = 1e-4;
    const std::vector<double> f2 = velocity_term(-2 * e), f1 = velocity_term(-e), g1 = velocity_term(e),
                              g2 = velocity_term(2 * e);
    for (int r = 0; r < m; ++r) {
      const double fd = ((f2[r] - g2[r]) + 8.0 * (g1[r] - f1[r])) / (12.0 * e);
      EXPECT_NEAR((gm[r] - gp[r]) / 4.0, fd, Tol(kJacTol, fd)) << "B v from gamma, row " << r;
    }
  }
}

// ---- derivatives along a kind's own data (DataDifferentiable) ----------------------------------------------------

// A datum moved by e times its rate: numbers and constant slots move, coordinate slots are no data.
inline void MoveDatum(double& x, double r, double e) { x += e * r; }
inline void MoveDatum(Slot& x, const Slot& r, double e) {
  if (!x.is_coordinate()) x = Slot::constant(x.value() + e * r.value());
}
inline void MoveDatum(phiq::Point2& x, const phiq::Point2& r, double e) {
  MoveDatum(x.x, r.x, e), MoveDatum(x.y, r.y, e);
}
inline void MoveDatum(phiq::Frame2& x, const phiq::Frame2& r, double e) {
  MoveDatum(x.x, r.x, e), MoveDatum(x.y, r.y, e), MoveDatum(x.psi, r.psi, e);
}
inline void MoveDatum(phiq::kin::V2& x, const phiq::kin::V2& r, double e) {
  MoveDatum(x.x, r.x, e), MoveDatum(x.y, r.y, e);
}
// A curve's frame moves; the curve itself is no datum (a rate spec holds the swept spec's curve).
inline void MoveDatum(phiq::CurveOn& x, const phiq::CurveOn& r, double e) { MoveDatum(x.frame, r.frame, e); }
// A spatial attachment: its constants and its local vector (coordinates are no data).
inline void MoveDatum(phiq::Attachment3& x, const phiq::Attachment3& r, double e) {
  for (int k = 0; k < 3; ++k) MoveDatum(x.r[k], r.r[k], e);
  for (int k = 0; k < 4; ++k) MoveDatum(x.p[k], r.p[k], e);
  MoveDatum(x.s.x, r.s.x, e), MoveDatum(x.s.y, r.s.y, e), MoveDatum(x.s.z, r.s.z, e);
}
template <std::size_t N>
void MoveDatum(std::array<phiq::Attachment3, N>& x, const std::array<phiq::Attachment3, N>& r, double e) {
  for (std::size_t i = 0; i < N; ++i) MoveDatum(x[i], r[i], e);
}
// A joint's side as given is not read by its rows (its attachments are): it does not move; nor do the natural
// points that kinds keep beside their attachments.
inline void MoveDatum(phiq::JointSide3&, const phiq::JointSide3&, double) {}
inline void MoveDatum(phiq::Point3&, const phiq::Point3&, double) {}
// A loop's links: constant lengths and angle terms, offsets and factors (coordinates are no data).
inline void MoveDatum(std::vector<phiq::LoopSpec::Link>& x, const std::vector<phiq::LoopSpec::Link>& r, double e) {
  for (std::size_t i = 0; i < x.size(); ++i) {
    MoveDatum(x[i].length, r[i].length, e), MoveDatum(x[i].offset, r[i].offset, e);
    for (std::size_t j = 0; j < x[i].terms.size(); ++j)
      MoveDatum(x[i].terms[j].angle, r[i].terms[j].angle, e), MoveDatum(x[i].terms[j].sign, r[i].terms[j].sign, e);
  }
}
// The rates of a spatial attachment's data along a parameter, at random in [−1, 1]: r̂, p̂ (read where the
// attachment's slots are constants: a ground frame that moves and turns) and ŝ.
inline phiq::Attachment3 RandomAttachmentRate(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  phiq::Attachment3 r;
  for (Slot& k : r.r) k = Slot::constant(u(rng));
  for (Slot& k : r.p) k = Slot::constant(u(rng));
  r.s = phiq::kin3::V3{u(rng), u(rng), u(rng)};
  return r;
}
// Every attachment of `att` at random rates (the rate spec of a spatial kind's attachments).
template <std::size_t N>
void RandomizeAttachmentRates(std::array<phiq::Attachment3, N>& att, std::mt19937& rng) {
  for (phiq::Attachment3& a : att) a = RandomAttachmentRate(rng);
}
// A law moved along its rate (MotionLaw::rate_along: a law too): f + e ∂f/∂p.
inline void MoveDatum(phiq::MotionLaw& x, const phiq::MotionLaw& r, double e) {
  x = phiq::MotionLaw::sum({{1.0, x}, {e, r}});
}
inline void MoveDatum(std::optional<phiq::MotionLaw>& x, const std::optional<phiq::MotionLaw>& r, double e) {
  if (x && r) MoveDatum(*x, *r, e);
}
// An expression moves with the parameters its text reads (CompiledExpression::along_constants()), not by a step
// along its rate: a spec whose expression has a rate is checked against the spec made at p + e
// (CheckDataDerivativeOf()).
inline void MoveDatum(std::shared_ptr<const phiq::CompiledExpression>&,
                      const std::shared_ptr<const phiq::CompiledExpression>& r, double) {
  if (r) ADD_FAILURE() << "an expression's rate moves no copy of it: check it with CheckDataDerivativeOf()";
}
template <class Spec>
Spec MovedAlongData(const Spec& spec, const Spec& rate, double e) {
  Spec moved = spec;
  std::apply([&](auto... m) { (MoveDatum(moved.*m, rate.*m, e), ...); }, Spec::data_members());
  return moved;
}

// data_derivative() of every order against the fourth-order central difference of Φ, Φq q̇ + Φt and Φq q̈ − γ
// along moved(e), the spec at p + e (moved(0) is `spec`), at random states (q, q̇, q̈, t).
template <class Spec, class Moved>
void CheckDataDerivativeOf(const Spec& spec, const Spec& rate, const Moved& moved, int n_coords, std::uint32_t seed,
                           int samples = 6) {
  static_assert(phiq::DataDifferentiable<Spec>);
  (void)phiq::test::DataCheckOf<Spec>::registered;  // tests/test_kind_registry.cpp: this kind's check exists
  constexpr int m = Spec::kRows;
  SCOPED_TRACE(std::string("kind '") + Spec::kKind + "', derivatives along its data");
  StateGenerator gen(seed);
  for (int k = 0; k < samples; ++k) {
    const State st = gen.Next(n_coords), acc = gen.Next(n_coords);
    SCOPED_TRACE("sample " + std::to_string(k) + ", " + Describe(st));
    const double* q = st.q.data();
    auto term = [&](const Spec& s, int order) {  // Φ, Φq q̇ + Φt, Φq q̈ − γ
      std::vector<double> out(m, 0.0), g(m, 0.0);
      if (order == 0) {
        s.residual(q, st.t, out.data());
        return out;
      }
      const double* v = order == 1 ? st.qd.data() : acc.qd.data();
      auto sink = [&](int row, const Slot& slot, double value) {
        if (slot.is_coordinate()) out[row] += value * v[slot.coord()];
      };
      s.jacobian(q, st.t, sink);
      if (order == 1) {
        s.phi_t(q, st.t, g.data());
        for (int r = 0; r < m; ++r) out[r] += g[r];
      } else {
        s.gamma(q, st.qd.data(), st.t, g.data());
        for (int r = 0; r < m; ++r) out[r] -= g[r];
      }
      return out;
    };
    for (int order = 0; order < 3; ++order) {
      std::vector<double> exact(m + 1, kSentinel);
      spec.data_derivative(rate, order, q, st.qd.data(), acc.qd.data(), st.t, exact.data());
      EXPECT_EQ(exact[m], kSentinel) << "data_derivative writes past its rows";
      const double e = 1e-4;
      const auto f2 = term(moved(-2 * e), order), f1 = term(moved(-e), order), g1 = term(moved(e), order),
                 g2 = term(moved(2 * e), order);
      for (int r = 0; r < m; ++r) {
        const double fd = ((f2[r] - g2[r]) + 8.0 * (g1[r] - f1[r])) / (12.0 * e);
        EXPECT_NEAR(exact[r], fd, Tol(kJacTol, fd)) << "order " << order << ", row " << r;
      }
    }
  }
}

// CheckDataDerivativeOf() along spec + e·rate.
template <class Spec>
void CheckDataDerivative(const Spec& spec, const Spec& rate, int n_coords, std::uint32_t seed, int samples = 6) {
  CheckDataDerivativeOf(
      spec, rate, [&](double e) { return MovedAlongData(spec, rate, e); }, n_coords, seed, samples);
}

// ---- Model: blocks, pattern and CSC plumbing ------------------------------------------------------------------

// Structure of the CSC pattern, and every Model evaluation against differences of Model::residual.
void CheckModel(const phiq::Model& model, std::uint32_t seed, int samples = 6) {
  const Index n = model.num_coordinates(), m = model.num_equations();
  const phiq::CscPattern& pat = model.jacobian_pattern();
  ASSERT_EQ(pat.rows, m);
  ASSERT_EQ(pat.cols, n);
  ASSERT_EQ(static_cast<Index>(pat.col_ptr.size()), n + 1);
  ASSERT_EQ(pat.col_ptr.front(), 0);
  ASSERT_EQ(pat.col_ptr.back(), pat.nnz());
  for (Index j = 0; j < n; ++j) {
    ASSERT_LE(pat.col_ptr[j], pat.col_ptr[j + 1]);
    for (Index k = pat.col_ptr[j]; k < pat.col_ptr[j + 1]; ++k) {
      ASSERT_GE(pat.row_idx[k], 0);
      ASSERT_LT(pat.row_idx[k], m);
      if (k > pat.col_ptr[j]) {
        ASSERT_LT(pat.row_idx[k - 1], pat.row_idx[k]) << "rows not strictly ascending";
      }
    }
  }

  auto residual = [&](const std::vector<double>& q, double t) {
    std::vector<double> phi(static_cast<std::size_t>(m), kSentinel);
    model.residual(q.data(), t, phi.data());
    return phi;
  };

  StateGenerator gen(seed);
  for (int s = 0; s < samples; ++s) {
    const State st = gen.Next(static_cast<int>(n));
    SCOPED_TRACE("sample " + std::to_string(s) + ", " + Describe(st));

    const std::vector<double> phi = residual(st.q, st.t);
    for (Index r = 0; r < m; ++r) ASSERT_TRUE(std::isfinite(phi[r])) << "residual row " << r << " not written";

    // Φq from the CSC values, through col_ptr / row_idx.
    std::vector<double> values(static_cast<std::size_t>(pat.nnz()), kSentinel);
    model.jacobian(st.q.data(), st.t, values.data());
    Eigen::MatrixXd jac = Eigen::MatrixXd::Zero(m, n);
    for (Index j = 0; j < n; ++j)
      for (Index k = pat.col_ptr[j]; k < pat.col_ptr[j + 1]; ++k) jac(pat.row_idx[k], j) = values[k];
    for (Index j = 0; j < n; ++j) {
      const double h = kJacStep * std::max(1.0, std::fabs(st.q[j]));
      std::vector<double> qp = st.q, qm = st.q;
      qp[j] += h;
      qm[j] -= h;
      const std::vector<double> fp = residual(qp, st.t), fm = residual(qm, st.t);
      for (Index r = 0; r < m; ++r) {
        const double fd = (fp[r] - fm[r]) / (qp[j] - qm[j]);
        EXPECT_NEAR(jac(r, j), fd, Tol(kJacTol, fd))
            << "Phi_q(" << model.row_name(r) << ", " << model.coordinate_names()[j] << ")";
      }
    }

    // Φt.
    std::vector<double> pt(static_cast<std::size_t>(m), kSentinel);
    model.phi_t(st.q.data(), st.t, pt.data());
    {
      const double h = kJacStep * std::max(1.0, std::fabs(st.t));
      const std::vector<double> fp = residual(st.q, st.t + h), fm = residual(st.q, st.t - h);
      for (Index r = 0; r < m; ++r) {
        const double fd = (fp[r] - fm[r]) / ((st.t + h) - (st.t - h));
        EXPECT_NEAR(pt[r], fd, Tol(kJacTol, fd)) << "Phi_t(" << model.row_name(r) << ")";
      }
    }

    // γ.
    std::vector<double> gam(static_cast<std::size_t>(m), kSentinel);
    model.gamma(st.q.data(), st.qd.data(), st.t, gam.data());
    const std::vector<double> dd = SecondDerivative(
        [&](double h) {
          std::vector<double> q(st.q.size());
          for (std::size_t j = 0; j < q.size(); ++j) q[j] = st.q[j] + h * st.qd[j];
          return residual(q, st.t + h);
        },
        GammaStep(st.qd));
    for (Index r = 0; r < m; ++r)
      EXPECT_NEAR(gam[r], -dd[r], Tol(kGammaTol, gam[r])) << "gamma(" << model.row_name(r) << ")";
  }
}

}  // namespace
