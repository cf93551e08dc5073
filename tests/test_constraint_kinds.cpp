// Derivative checks of every constraint kind in constraint_kinds.hpp, and of the block / pattern plumbing of Model.
//
// For each kind, at several random states (q, q̇, t) from a fixed-seed generator:
//   1. Φq (assembled densely from the sink calls, duplicates accumulated) against central differences of Φ;
//      the sequence of (row, coordinate) entries must be the same at every state as in the pattern pass
//      (evaluated at q = 0, exactly as TypedBlock::build_pattern does), since the CSC slots rely on it;
//   2. Φt against central differences of Φ in t (time-dependent kinds), or exactly 0 and Φ independent of t;
//   3. γ: along q(s) = q + s q̇, time t + s (so q̈ = 0), d²/ds² Φ at s = 0 equals −γ; checked by a Richardson-
//      extrapolated central second difference.
// The last tests build Models through ModelBuilder and check Model::jacobian (CSC values through the pattern),
// Model::phi_t and Model::gamma the same way.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "phiq/constraint_block.hpp"
#include "phiq/constraint_kinds.hpp"
#include "phiq/expression.hpp"
#include "phiq/model.hpp"
#include "phiq/motion_law.hpp"
#include "phiq/types.hpp"

namespace {

using phiq::Index;
using phiq::Slot;

Slot S(Index i) { return Slot::coordinate(i); }
Slot C(double v) { return Slot::constant(v); }

// ---- tolerances and steps -------------------------------------------------------------------------------------

constexpr double kJacStep = 1e-6;     // relative step of the first differences (q and t)
constexpr double kJacTol = 1e-6;      // relative to max(1, |entry|)
constexpr double kGammaStep = 4e-3;   // step of the coarser second difference (Richardson with h and h/2)
constexpr double kGammaTol = 1e-7;    // relative to max(1, |γ|)
constexpr double kSentinel = 7.25e77; // written past the rows a kind owns; must survive

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
    if (s.is_coordinate()) out.push_back({row, s.coord, v});
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
  std::vector<double> kinks;    // times the γ stencil must keep clear of
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
  constexpr int m = Spec::kRows;
  const std::size_t n = static_cast<std::size_t>(n_coords);
  SCOPED_TRACE(std::string("kind '") + Spec::kKind + "'");
  EXPECT_EQ(spec.depends_on_time(), opt.time_dependent);
  ASSERT_LT(phiq::max_coordinate(spec), n_coords);

  // The pattern pass, as TypedBlock::build_pattern runs it.
  std::vector<double> zeros(static_cast<std::size_t>(phiq::max_coordinate(spec) + 1), 0.0);
  const std::vector<Entry> pattern = Entries(spec, zeros.data(), 0.0);
  ASSERT_FALSE(pattern.empty());

  StateGenerator gen(opt.seed);
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
        SecondDerivative([&](double s) { return ResidualAlongPath(spec, st, s); }, kGammaStep);
    for (int r = 0; r < m; ++r) EXPECT_NEAR(gam[r], -dd[r], Tol(kGammaTol, gam[r])) << "gamma row " << r;
  }
}

// ---- expressions ----------------------------------------------------------------------------------------------

std::shared_ptr<const phiq::CompiledExpression> CompileOfT(const std::string& text) {
  return phiq::CompiledExpression::compile(text, [](const std::string& name) -> std::optional<phiq::NameBinding> {
    if (name == "t") return phiq::NameBinding{phiq::NameBinding::Kind::kTime};
    return std::nullopt;
  });
}

// Coordinates theta2 = 0, xA = 1, yA = 2 (a 4th coordinate, 3, is left unused); constant L2 = 0.3; time t.
std::shared_ptr<const phiq::CompiledExpression> CompileCrank(const std::string& text) {
  return phiq::CompiledExpression::compile(text, [](const std::string& name) -> std::optional<phiq::NameBinding> {
    using K = phiq::NameBinding::Kind;
    if (name == "theta2") return phiq::NameBinding{K::kCoordinate, 0};
    if (name == "xA") return phiq::NameBinding{K::kCoordinate, 1};
    if (name == "yA") return phiq::NameBinding{K::kCoordinate, 2};
    if (name == "L2") return phiq::NameBinding{K::kConstant, -1, 0.3};
    if (name == "t") return phiq::NameBinding{K::kTime};
    return std::nullopt;
  });
}

// ---- DistanceSpec ---------------------------------------------------------------------------------------------

TEST(ConstraintKinds, DistanceWithConstantComponent) {
  phiq::DistanceSpec d{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), C(0.4)}, 1.7};
  CheckSpec(d, 3, Opts(101));
}

TEST(ConstraintKinds, DistanceBetweenMovingPoints) {
  // indices out of order, one coordinate (2) unused
  phiq::DistanceSpec d{phiq::Point2{S(3), S(1)}, phiq::Point2{S(0), S(4)}, 0.35};
  CheckSpec(d, 5, Opts(102));
}

// ---- PinSpec --------------------------------------------------------------------------------------------------

TEST(ConstraintKinds, PinBodyBody) {
  phiq::PinSpec p{phiq::Frame2{S(0), S(1), S(2)}, phiq::Frame2{S(3), S(4), S(5)}, {0.3, -0.2}, {-0.5, 0.1}};
  CheckSpec(p, 6, Opts(201));
}

TEST(ConstraintKinds, PinBodyGround) {
  // ground frame: constant position and orientation, with an arm (a constant offset)
  phiq::PinSpec p{phiq::Frame2{S(0), S(1), S(2)}, phiq::Frame2{C(1.0), C(-0.5), C(0.3)}, {0.45, 0.25}, {0.2, 0.4}};
  CheckSpec(p, 3, Opts(202));
  // ground on side a, body on side b
  phiq::PinSpec q{phiq::Frame2{C(-0.2), C(0.7), C(0.0)}, phiq::Frame2{S(2), S(0), S(1)}, {0.0, 0.0}, {-0.6, 0.3}};
  CheckSpec(q, 3, Opts(203));
}

TEST(ConstraintKinds, PinBodyNaturalPoint) {
  // body a (with arm) pinned to natural point (x3, x4): ψ constant, s = 0
  phiq::PinSpec p{phiq::Frame2{S(0), S(1), S(2)}, phiq::Frame2{S(3), S(4), C(0.0)}, {-0.4, 0.35}, {0.0, 0.0}};
  CheckSpec(p, 5, Opts(204));
  // natural point fixed to a constant point
  phiq::PinSpec f{phiq::Frame2{S(1), S(0), C(0.0)}, phiq::Frame2{C(0.5), C(-1.5), C(0.0)}, {0.0, 0.0}, {0.0, 0.0}};
  CheckSpec(f, 2, Opts(205));
}

// ---- PrismaticSpec --------------------------------------------------------------------------------------------

TEST(ConstraintKinds, PrismaticBothBodiesMoving) {
  phiq::PrismaticSpec p{phiq::Frame2{S(0), S(1), S(2)}, phiq::Frame2{S(3), S(4), S(5)}, {0.3, 0.1}, {-0.2, 0.5},
                        {0.6, 0.8}, 0.4};
  CheckSpec(p, 6, Opts(301));
}

TEST(ConstraintKinds, PrismaticWithGroundSide) {
  // a is ground (the axis does not turn)
  phiq::PrismaticSpec g{phiq::Frame2{C(0.5), C(-0.2), C(0.3)}, phiq::Frame2{S(0), S(1), S(2)}, {0.2, -0.1},
                        {0.25, 0.15}, {0.8, -0.6}, -0.3};
  CheckSpec(g, 3, Opts(302));
  // b is ground (the axis turns with a)
  phiq::PrismaticSpec h{phiq::Frame2{S(1), S(2), S(0)}, phiq::Frame2{C(-1.0), C(0.4), C(0.9)}, {-0.35, 0.2},
                        {0.1, 0.3}, {0.0, 1.0}, 0.9};
  CheckSpec(h, 3, Opts(303));
}

// ---- PointOnLineSpec ------------------------------------------------------------------------------------------

TEST(ConstraintKinds, PointOnLine) {
  phiq::PointOnLineSpec p{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}, phiq::Point2{S(4), C(0.7)}};
  p.ref = 1.3;  // set by the builder from the initial placement; any positive scale must be consistent
  CheckSpec(p, 5, Opts(401));
  // line through a fixed point
  phiq::PointOnLineSpec f{phiq::Point2{S(2), S(0)}, phiq::Point2{C(0.0), C(-0.3)}, phiq::Point2{S(1), S(3)}};
  f.ref = 0.6;
  CheckSpec(f, 4, Opts(402));
}

// ---- ConstantAngleSpec ----------------------------------------------------------------------------------------

TEST(ConstraintKinds, ConstantAngle) {
  phiq::ConstantAngleSpec c{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}, phiq::Point2{S(4), S(5)},
                            phiq::Point2{S(6), C(0.2)}};
  c.angle = 0.7;
  c.ref = 1.3;
  CheckSpec(c, 7, Opts(501));
}

TEST(ConstraintKinds, ConstantAngleSharedPointAccumulatesDuplicates) {
  // both segments start at the same point a = c: its coordinates get two entries each
  phiq::ConstantAngleSpec c{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}, phiq::Point2{S(0), S(1)},
                            phiq::Point2{S(4), S(5)}};
  c.angle = 2.1;
  c.ref = 0.8;
  CheckSpec(c, 6, Opts(502));
}

// ---- SegmentAngleSpec -----------------------------------------------------------------------------------------

TEST(ConstraintKinds, SegmentAngle) {
  phiq::SegmentAngleSpec s{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}, S(4)};
  CheckSpec(s, 5, Opts(601));
  // from a fixed point
  phiq::SegmentAngleSpec f{phiq::Point2{C(0.2), C(-0.1)}, phiq::Point2{S(1), S(2)}, S(0)};
  CheckSpec(f, 3, Opts(602));
}

// ---- PolarSpec ------------------------------------------------------------------------------------------------

TEST(ConstraintKinds, Polar) {
  phiq::PolarSpec p{phiq::Point2{S(0), S(1)}, phiq::Point2{C(0.1), C(-0.3)}, 0.3, S(2)};
  CheckSpec(p, 3, Opts(701));
  // moving origin, negative length
  phiq::PolarSpec m{phiq::Point2{S(3), S(1)}, phiq::Point2{S(0), S(4)}, -0.8, S(2)};
  CheckSpec(m, 5, Opts(702));
}

// ---- LoopSpec -------------------------------------------------------------------------------------------------

TEST(ConstraintKinds, LoopWithSliderNegativeSignsAndOffsets) {
  using Link = phiq::LoopSpec::Link;
  phiq::LoopSpec loop;
  loop.links = {
      Link{C(0.4), 0.0, {{S(0), 1.0}}},
      Link{C(1.2), 0.3, {{S(0), 1.0}, {S(1), -1.0}}},
      // a slider: the length is coordinate 2; coordinate 0 appears twice in the same link
      Link{S(2), -0.5, {{S(1), -1.0}, {S(0), 1.0}, {S(0), 1.0}}},
      // a constant angle term (its Jacobian entry falls on a constant and must be skipped)
      Link{C(0.7), 1.0, {{C(0.25), 1.0}, {S(1), 0.5}}},
      // a fixed link, no terms
      Link{C(0.35), -2.0, {}},
  };
  loop.closure = {0.9, -0.2};
  CheckSpec(loop, 3, Opts(801));
}

TEST(ConstraintKinds, LoopRelativeFourBar) {
  // the notes' form: running sums of relative angles ψ2, ψ2 + ψ3, ψ2 + ψ3 + ψ4 (ψ2 in every link)
  using Link = phiq::LoopSpec::Link;
  phiq::LoopSpec loop;
  loop.links = {
      Link{C(0.3), 0.0, {{S(0), 1.0}}},
      Link{C(1.0), 0.0, {{S(0), 1.0}, {S(1), 1.0}}},
      Link{C(0.8), 0.0, {{S(0), 1.0}, {S(1), 1.0}, {S(2), 1.0}}},
  };
  loop.closure = {1.1, 0.0};
  CheckSpec(loop, 3, Opts(802));
}

// ---- CoordinateDriverSpec -------------------------------------------------------------------------------------

TEST(ConstraintKinds, DriverLinear) {
  phiq::CoordinateDriverSpec d{S(1), phiq::MotionLaw::linear(0.2, 1.5)};
  CheckSpec(d, 3, Opts(901, true));
}

TEST(ConstraintKinds, DriverPolynomial) {
  phiq::CoordinateDriverSpec d{S(0), phiq::MotionLaw::polynomial({0.1, -0.4, 0.3, 0.25, -0.05})};
  CheckSpec(d, 2, Opts(902, true));
}

TEST(ConstraintKinds, DriverHarmonic) {
  phiq::CoordinateDriverSpec d{S(2), phiq::MotionLaw::harmonic(0.3, 0.8, 2.5, 0.4)};
  CheckSpec(d, 3, Opts(903, true));
}

TEST(ConstraintKinds, DriverTable) {
  // 6 points on [-0.5, 2.5] (covers the sampled t in [0, 2] with room for the stencils). Eigen's interpolating
  // cubic B-spline places its interior knots by knot averaging, at u = 0.4 and 0.6, i.e. t = 0.7 and 1.3: the
  // third derivative jumps there, so the γ stencil is kept clear of them.
  std::vector<double> ts = {-0.5, 0.1, 0.7, 1.3, 1.9, 2.5};
  std::vector<double> vs = {0.0, 0.4, 0.1, -0.6, -0.2, 0.5};
  phiq::CoordinateDriverSpec d{S(1), phiq::MotionLaw::table(ts, vs)};
  CheckSpec(d, 2, Opts(904, true, 8, {0.7, 1.3}));
}

TEST(ConstraintKinds, DriverExpression) {
  phiq::CoordinateDriverSpec d{S(0), phiq::MotionLaw::expression(CompileOfT("0.5*sin(2*t) + 0.1*t^3 - exp(-t)"))};
  CheckSpec(d, 2, Opts(905, true));
}

// ---- EquationSpec ---------------------------------------------------------------------------------------------

TEST(ConstraintKinds, EquationInCoordinatesAndTime) {
  auto g = CompileCrank("xA - L2*cos(theta2) + 0.1*t^2*yA + atan2(yA, xA + 3)");
  ASSERT_EQ(g->coordinates(), (std::vector<Index>{0, 1, 2}));
  ASSERT_TRUE(g->depends_on_time());
  phiq::EquationSpec e{g, std::nullopt, phiq::Unit::kLength};
  CheckSpec(e, 4, Opts(1001, true));
}

TEST(ConstraintKinds, EquationWithoutTime) {
  phiq::EquationSpec e{CompileCrank("xA^2 + yA^2 - L2^2*theta2*sin(theta2)"), std::nullopt, phiq::Unit::kNone};
  CheckSpec(e, 4, Opts(1002, false));
}

TEST(ConstraintKinds, EquationWithLaw) {
  // g independent of t, driven by a law
  phiq::EquationSpec e{CompileCrank("xA*yA - sin(theta2)"), phiq::MotionLaw::harmonic(0.1, 0.6, 1.7, -0.3),
                       phiq::Unit::kNone};
  CheckSpec(e, 4, Opts(1003, true));
  // g depending on t and a law as well
  phiq::EquationSpec f{CompileCrank("xA - L2*cos(theta2) + 0.1*t^2*yA + atan2(yA, xA + 3)"),
                       phiq::MotionLaw::polynomial({0.2, -0.3, 0.15, 0.04}), phiq::Unit::kLength};
  CheckSpec(f, 4, Opts(1004, true));
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
        EXPECT_NEAR(jac(r, j), fd, Tol(kJacTol, fd)) << "Phi_q(" << model.row_name(r) << ", "
                                                     << model.coordinate_names()[j] << ")";
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
        kGammaStep);
    for (Index r = 0; r < m; ++r)
      EXPECT_NEAR(gam[r], -dd[r], Tol(kGammaTol, gam[r])) << "gamma(" << model.row_name(r) << ")";
  }
}

TEST(ModelPlumbing, CrankSliderJacobianPhiTAndGamma) {
  phiq::ModelBuilder b;
  const Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", 0.3),
              ya = b.add_coordinate("yA", 0.0), xb = b.add_coordinate("xB", 1.3);
  b.add("crank", phiq::PolarSpec{phiq::Point2{S(xa), S(ya)}, phiq::Point2{C(0), C(0)}, 0.3, S(th)});
  b.add("coupler", phiq::DistanceSpec{phiq::Point2{S(xa), S(ya)}, phiq::Point2{S(xb), C(0.0)}, 1.0});
  b.add_driver("motor", th, phiq::MotionLaw::linear(0.0, 2.0));
  const phiq::Model model = std::move(b).build();

  ASSERT_EQ(model.num_coordinates(), 4);
  ASSERT_EQ(model.num_equations(), 4);
  EXPECT_TRUE(model.has_time_dependence());
  // crank: (0, xA) (0, θ) (1, yA) (1, θ); coupler: xA yA xB (its yB is a constant); motor: θ
  EXPECT_EQ(model.jacobian_pattern().nnz(), 8);
  CheckModel(model, 1101);
}

TEST(ModelPlumbing, RelativeFourBarAccumulatesDuplicateEntries) {
  // ψ2 is read by all three links of the loop: three entries per row land in one CSC slot.
  phiq::ModelBuilder b;
  const Index p2 = b.add_coordinate("psi2", 0.4), p3 = b.add_coordinate("psi3", 0.8),
              p4 = b.add_coordinate("psi4", 1.9), sx = b.add_coordinate("s", 0.2);
  using Link = phiq::LoopSpec::Link;
  phiq::LoopSpec loop;
  loop.links = {
      Link{C(0.3), 0.0, {{S(p2), 1.0}}},
      Link{C(1.0), 0.0, {{S(p2), 1.0}, {S(p3), 1.0}}},
      Link{C(0.8), 0.0, {{S(p2), 1.0}, {S(p3), 1.0}, {S(p4), 1.0}}},
  };
  loop.closure = {1.1, 0.0};
  b.add("loop", loop);
  b.add_driver("motor", p2, phiq::MotionLaw::harmonic(0.4, 0.5, 2.0, 0.1));
  auto g = phiq::CompiledExpression::compile(
      "s - 0.3*cos(psi2) - 0.2*t*psi3", [&](const std::string& name) -> std::optional<phiq::NameBinding> {
        using K = phiq::NameBinding::Kind;
        if (name == "t") return phiq::NameBinding{K::kTime};
        if (name == "psi2") return phiq::NameBinding{K::kCoordinate, p2};
        if (name == "psi3") return phiq::NameBinding{K::kCoordinate, p3};
        if (name == "s") return phiq::NameBinding{K::kCoordinate, sx};
        return std::nullopt;
      });
  b.add("output", phiq::EquationSpec{g, std::nullopt, phiq::Unit::kLength});
  const phiq::Model model = std::move(b).build();

  ASSERT_EQ(model.num_coordinates(), 4);
  ASSERT_EQ(model.num_equations(), 4);
  // loop: 2 rows × {ψ2, ψ3, ψ4}; motor: ψ2; output: s, ψ2, ψ3 — duplicates merged
  EXPECT_EQ(model.jacobian_pattern().nnz(), 10);
  CheckModel(model, 1201);
}

}  // namespace
