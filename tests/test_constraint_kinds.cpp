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
// Model::phi_t and Model::gamma the same way. The equation kind's checks: test_equation_kinds.cpp.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
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
#include "phiq/scene.hpp"
#include "phiq/sweep.hpp"
#include "phiq/types.hpp"
#include "constraint_check.hpp"

namespace {

// ---- expressions ----------------------------------------------------------------------------------------------

std::shared_ptr<const phiq::CompiledExpression> CompileOfT(const std::string& text) {
  return phiq::CompiledExpression::compile(text, [](const std::string& name) -> std::optional<phiq::NameBinding> {
    if (name == "t") return phiq::NameBinding{phiq::NameBinding::Kind::kTime};
    return std::nullopt;
  });
}

// ---- Slot: one word that is a coordinate index or a constant --------------------------------------------------

TEST(Slot, CoordinatesAndConstantsRoundTripThroughOneWord) {
  static_assert(sizeof(Slot) == 8);
  const double q[] = {10.0, 11.0, 12.0};
  const double qd[] = {-1.0, -2.0, -3.0};
  for (Index i : {Index{0}, Index{1}, Index{2}}) {
    const Slot s = S(i);
    EXPECT_TRUE(s.is_coordinate());
    EXPECT_EQ(s.coord(), i);
    EXPECT_EQ(s.value(), 0.0);
    EXPECT_EQ(s.of(q), q[i]);
    EXPECT_EQ(s.rate(qd), qd[i]);
  }
  const Index largest = (Index{1} << 50) - 1;
  EXPECT_EQ(S(largest).coord(), largest);
  EXPECT_THROW(S(-1), phiq::Error);
  EXPECT_THROW(S(largest + 1), phiq::Error);
  // every double is its own constant, bit for bit, including the signed zero, the extremes and infinities
  for (double v : {0.0, -0.0, 1.5, -7.25e300, 4.9e-324, -std::numeric_limits<double>::max(),
                   std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
    const Slot c = C(v);
    EXPECT_FALSE(c.is_coordinate()) << v;
    EXPECT_EQ(c.coord(), -1);
    EXPECT_EQ(std::signbit(c.value()), std::signbit(v));
    EXPECT_EQ(c.value(), v);
    EXPECT_EQ(c.of(q), v);
    EXPECT_EQ(c.rate(qd), 0.0);
  }
  EXPECT_FALSE(Slot().is_coordinate());
  EXPECT_EQ(Slot().value(), 0.0);
  EXPECT_FALSE(std::signbit(Slot().value()));
  // any NaN, whatever its payload (one carrying the coordinate tag's bits included), stays a NaN constant
  std::uint64_t tagged = 0xFFFC000000000005ULL;
  double tagged_nan;
  std::memcpy(&tagged_nan, &tagged, sizeof tagged_nan);
  for (double v : {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN(), tagged_nan}) {
    const Slot c = C(v);
    EXPECT_FALSE(c.is_coordinate());
    EXPECT_TRUE(std::isnan(c.value()));
  }
}

TEST(Slot, ModelBuilderRejectsNonFiniteConstantsAndUnknownCoordinates) {
  phiq::ModelBuilder b;
  b.add_coordinate("x", 1.0);
  b.add_coordinate("y", 0.0);
  auto distance = [](Slot ax) { return phiq::DistanceSpec{{ax, C(0.0)}, {S(0), S(1)}, 1.0}; };
  EXPECT_NO_THROW(b.add("ok", distance(C(0.0))));
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    try {
      b.add("bad", distance(C(bad)));
      ADD_FAILURE() << "constant " << bad << " accepted";
    } catch (const phiq::Error& e) {
      EXPECT_NE(std::string(e.what()).find("constraint 'bad': constant is not finite"), std::string::npos) << e.what();
    }
  }
  // a kind's own check names the constraint too (a large programmatic model has thousands of distances)
  try {
    b.add("rod", phiq::DistanceSpec{{C(0.0), C(0.0)}, {S(0), S(1)}, -1.0});
    ADD_FAILURE() << "negative length accepted";
  } catch (const phiq::Error& e) {
    EXPECT_EQ(std::string(e.what()), "constraint 'rod': distance: length must be positive and finite");
  }
  try {
    b.add("far", distance(S(2)));
    ADD_FAILURE() << "coordinate 2 of 2 accepted";
  } catch (const phiq::Error& e) {
    EXPECT_NE(std::string(e.what()).find("coordinate index 2 out of range (2 coordinates)"), std::string::npos)
        << e.what();
  }
}

// ---- DistanceSpec ---------------------------------------------------------------------------------------------

TEST(ConstraintKinds, DistanceWithConstantComponent) {
  phiq::DistanceSpec d{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), C(0.4)}, 1.7};
  CheckSpec(d, 3, Opts(101));
}

TEST(ConstraintKinds, DistanceAlongItsData) {
  // a ground point and the length move; a moving point's slots are no data
  const phiq::DistanceSpec d{phiq::Point2{C(0.3), C(-0.2)}, phiq::Point2{S(0), S(1)}, 1.7};
  const phiq::DistanceSpec rate{phiq::Point2{C(0.5), C(1.5)}, phiq::Point2{C(0.0), C(0.0)}, -0.8};
  CheckDataDerivative(d, rate, 2, 111);
  // two moving points, the length only
  const phiq::DistanceSpec m{phiq::Point2{S(3), S(1)}, phiq::Point2{S(0), S(4)}, 0.35};
  const phiq::DistanceSpec length_only{phiq::Point2{C(0.0), C(0.0)}, phiq::Point2{C(0.0), C(0.0)}, 1.0};
  CheckDataDerivative(m, length_only, 5, 112);
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

TEST(ConstraintKinds, PinAlongItsData) {
  // a body pinned to ground: the ground frame's position and angle and both local points move
  const phiq::PinSpec p{
      phiq::Frame2{S(0), S(1), S(2)}, phiq::Frame2{C(1.0), C(-0.5), C(0.3)}, {0.45, 0.25}, {0.2, 0.4}};
  const phiq::PinSpec rate{
      phiq::Frame2{C(0), C(0), C(0)}, phiq::Frame2{C(0.6), C(-1.2), C(0.9)}, {1.1, -0.3}, {0.5, 0.7}};
  CheckDataDerivative(p, rate, 3, 231);
  // two bodies, their arms move
  const phiq::PinSpec q{phiq::Frame2{S(0), S(1), S(2)}, phiq::Frame2{S(3), S(4), S(5)}, {0.3, -0.2}, {-0.5, 0.1}};
  const phiq::PinSpec arms{phiq::Frame2{C(0), C(0), C(0)}, phiq::Frame2{C(0), C(0), C(0)}, {1.0, 0.0}, {-0.4, 0.8}};
  CheckDataDerivative(q, arms, 6, 232);
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
  phiq::PrismaticSpec p{
      phiq::Frame2{S(0), S(1), S(2)}, phiq::Frame2{S(3), S(4), S(5)}, {0.3, 0.1}, {-0.2, 0.5}, {0.6, 0.8}, 0.4};
  CheckSpec(p, 6, Opts(301));
}

TEST(ConstraintKinds, PrismaticWithGroundSide) {
  // a is ground (the axis does not turn)
  phiq::PrismaticSpec g{phiq::Frame2{C(0.5), C(-0.2), C(0.3)},
                        phiq::Frame2{S(0), S(1), S(2)},
                        {0.2, -0.1},
                        {0.25, 0.15},
                        {0.8, -0.6},
                        -0.3};
  CheckSpec(g, 3, Opts(302));
  // b is ground (the axis turns with a)
  phiq::PrismaticSpec h{
      phiq::Frame2{S(1), S(2), S(0)}, phiq::Frame2{C(-1.0), C(0.4), C(0.9)}, {-0.35, 0.2}, {0.1, 0.3}, {0.0, 1.0}, 0.9};
  CheckSpec(h, 3, Opts(303));
}

TEST(ConstraintKinds, PrismaticAlongItsData) {
  // a slider on a ground guide: the guide's frame (position and angle), both local points, the axis and the angle
  const phiq::PrismaticSpec g{phiq::Frame2{C(0.5), C(-0.2), C(0.3)},
                              phiq::Frame2{S(0), S(1), S(2)},
                              {0.2, -0.1},
                              {0.25, 0.15},
                              {0.8, -0.6},
                              -0.3};
  const phiq::PrismaticSpec everything{
      phiq::Frame2{C(0.7), C(-0.4), C(1.1)}, phiq::Frame2{C(0), C(0), C(0)}, {0.6, 0.9}, {-0.3, 1.2}, {0.5, 0.4}, 0.8};
  CheckDataDerivative(g, everything, 3, 311);
  // two moving bodies (the axis turns with a): the arms and the axis move
  const phiq::PrismaticSpec p{
      phiq::Frame2{S(0), S(1), S(2)}, phiq::Frame2{S(3), S(4), S(5)}, {0.3, 0.1}, {-0.2, 0.5}, {0.6, 0.8}, 0.4};
  const phiq::PrismaticSpec arms{
      phiq::Frame2{C(0), C(0), C(0)}, phiq::Frame2{C(0), C(0), C(0)}, {-0.9, 0.4}, {0.7, 0.2}, {-0.8, 0.6}, 0.0};
  CheckDataDerivative(p, arms, 6, 312);
  // b on a ground frame that moves, a's guide turning
  const phiq::PrismaticSpec h{
      phiq::Frame2{S(1), S(2), S(0)}, phiq::Frame2{C(-1.0), C(0.4), C(0.9)}, {-0.35, 0.2}, {0.1, 0.3}, {0.0, 1.0}, 0.9};
  const phiq::PrismaticSpec ground{phiq::Frame2{C(0), C(0), C(0)},
                                   phiq::Frame2{C(0.3), C(-0.8), C(-0.6)},
                                   {0.0, 0.0},
                                   {0.5, -0.5},
                                   {0.0, 0.0},
                                   -0.2};
  CheckDataDerivative(h, ground, 3, 313);
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

TEST(ConstraintKinds, PointOnLineAlongItsData) {
  // a slider's guide through two fixed points that move with the parameter (an offset), its reference length too
  phiq::PointOnLineSpec g{phiq::Point2{S(0), S(1)}, phiq::Point2{C(0.1), C(0.2)}, phiq::Point2{C(1.3), C(0.5)}};
  g.ref = 1.24;
  phiq::PointOnLineSpec rate{phiq::Point2{C(0.0), C(0.0)}, phiq::Point2{C(0.0), C(1.0)}, phiq::Point2{C(0.0), C(1.0)}};
  rate.ref = 0.3;
  CheckDataDerivative(g, rate, 2, 411);
  // a fixed point on a moving line
  phiq::PointOnLineSpec f{phiq::Point2{C(0.4), C(-0.2)}, phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}};
  f.ref = 0.8;
  phiq::PointOnLineSpec moves{phiq::Point2{C(-0.7), C(1.1)}, phiq::Point2{C(0.0), C(0.0)},
                              phiq::Point2{C(0.0), C(0.0)}};
  moves.ref = 0.0;
  CheckDataDerivative(f, moves, 4, 412);
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

TEST(ConstraintKinds, ConstantAngleAlongItsData) {
  // a moving segment at a fixed angle to a ground segment whose ends move; the angle and the row's scale too
  phiq::ConstantAngleSpec c{phiq::Point2{C(0.1), C(0.2)}, phiq::Point2{C(1.1), C(-0.3)}, phiq::Point2{S(0), S(1)},
                            phiq::Point2{S(2), S(3)}};
  c.angle = 0.7, c.ref = 1.3;
  phiq::ConstantAngleSpec rate{phiq::Point2{C(0.4), C(-0.6)}, phiq::Point2{C(-0.2), C(0.9)},
                               phiq::Point2{C(0.0), C(0.0)}, phiq::Point2{C(0.0), C(0.0)}};
  rate.angle = 1.1, rate.ref = -0.5;
  CheckDataDerivative(c, rate, 4, 511);
  // two moving segments sharing a point: the angle only
  phiq::ConstantAngleSpec m{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}, phiq::Point2{S(0), S(1)},
                            phiq::Point2{S(4), S(5)}};
  m.angle = 2.1, m.ref = 0.8;
  phiq::ConstantAngleSpec turn{phiq::Point2{C(0.0), C(0.0)}, phiq::Point2{C(0.0), C(0.0)}, phiq::Point2{C(0.0), C(0.0)},
                               phiq::Point2{C(0.0), C(0.0)}};
  turn.angle = 1.0, turn.ref = 0.0;
  CheckDataDerivative(m, turn, 6, 512);
}

// ---- SegmentAngleSpec -----------------------------------------------------------------------------------------

TEST(ConstraintKinds, SegmentAngle) {
  phiq::SegmentAngleSpec s{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}, S(4)};
  CheckSpec(s, 5, Opts(601));
  // from a fixed point
  phiq::SegmentAngleSpec f{phiq::Point2{C(0.2), C(-0.1)}, phiq::Point2{S(1), S(2)}, S(0)};
  CheckSpec(f, 3, Opts(602));
}

TEST(ConstraintKinds, SegmentAngleAlongItsData) {
  // from a fixed point that moves, θ a coordinate
  const phiq::SegmentAngleSpec f{phiq::Point2{C(0.2), C(-0.1)}, phiq::Point2{S(1), S(2)}, S(0)};
  const phiq::SegmentAngleSpec pivot{phiq::Point2{C(0.8), C(-1.3)}, phiq::Point2{C(0.0), C(0.0)}, C(0.0)};
  CheckDataDerivative(f, pivot, 3, 611);
  // a constant θ that turns with the parameter, both ends moving
  const phiq::SegmentAngleSpec c{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}, C(0.6)};
  const phiq::SegmentAngleSpec turns{phiq::Point2{C(0.0), C(0.0)}, phiq::Point2{C(0.0), C(0.0)}, C(-0.9)};
  CheckDataDerivative(c, turns, 4, 612);
}

// ---- PolarSpec ------------------------------------------------------------------------------------------------

TEST(ConstraintKinds, Polar) {
  phiq::PolarSpec p{phiq::Point2{S(0), S(1)}, phiq::Point2{C(0.1), C(-0.3)}, 0.3, S(2)};
  CheckSpec(p, 3, Opts(701));
  // moving origin, negative length
  phiq::PolarSpec m{phiq::Point2{S(3), S(1)}, phiq::Point2{S(0), S(4)}, -0.8, S(2)};
  CheckSpec(m, 5, Opts(702));
}

TEST(ConstraintKinds, PolarAlongItsData) {
  // the length and the fixed origin move, the angle a coordinate
  const phiq::PolarSpec p{phiq::Point2{S(0), S(1)}, phiq::Point2{C(0.1), C(-0.3)}, 0.3, S(2)};
  const phiq::PolarSpec rate{phiq::Point2{C(0.0), C(0.0)}, phiq::Point2{C(0.7), C(-1.1)}, 2.0, C(0.0)};
  CheckDataDerivative(p, rate, 3, 711);
  // a constant angle that moves with the parameter, a negative length
  const phiq::PolarSpec c{phiq::Point2{S(0), S(1)}, phiq::Point2{S(2), S(3)}, -0.8, C(0.4)};
  const phiq::PolarSpec turns{phiq::Point2{C(0.0), C(0.0)}, phiq::Point2{C(0.0), C(0.0)}, 0.5, C(1.3)};
  CheckDataDerivative(c, turns, 4, 712);
}

// ---- LoopSpec -------------------------------------------------------------------------------------------------

// A loop with every kind of link: a slider, negative signs, offsets, a constant angle term, a fixed link.
phiq::LoopSpec SliderLoop() {
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
  return loop;
}

TEST(ConstraintKinds, LoopWithSliderNegativeSignsAndOffsets) { CheckSpec(SliderLoop(), 3, Opts(801)); }

TEST(ConstraintKinds, LoopAlongItsData) {
  // every datum a loop has: constant lengths, offsets, a constant angle term, the terms' factors, the closure; a
  // slider's travel (a coordinate) is no datum
  using Link = phiq::LoopSpec::Link;
  const phiq::LoopSpec loop = SliderLoop();
  phiq::LoopSpec rate;
  rate.links = {
      Link{C(0.8), 0.2, {{C(0.0), 0.0}}},
      Link{C(-0.5), 0.7, {{C(0.0), 0.3}, {C(0.0), 0.0}}},
      Link{C(0.0), -0.4, {{C(0.0), 0.0}, {C(0.0), 0.0}, {C(0.0), -0.2}}},
      Link{C(1.1), 0.0, {{C(0.6), 0.4}, {C(0.0), 0.0}}},
      Link{C(0.3), 0.9, {}},
  };
  rate.closure = {-0.7, 0.4};
  CheckDataDerivative(loop, rate, 3, 811);
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

TEST(ConstraintKinds, DriverAlongItsData) {
  // the law moves along its rate (any law: MotionLaw::rate_along's are polynomials, harmonics' rates, tables, sums)
  const phiq::CoordinateDriverSpec d{S(1), phiq::MotionLaw::harmonic(0.3, 0.8, 2.5, 0.4)};
  const phiq::CoordinateDriverSpec rate{C(0.0), phiq::MotionLaw::polynomial({0.2, -0.7, 0.3, 0.1})};
  CheckDataDerivative(d, rate, 3, 911);
  const phiq::CoordinateDriverSpec e{S(0), phiq::MotionLaw::polynomial({0.1, 2.0})};
  const phiq::CoordinateDriverSpec faster{C(0.0), phiq::MotionLaw::harmonic(0.1, 0.5, 1.5, -0.2)};
  CheckDataDerivative(e, faster, 2, 912);
}

// ---- CouplerSpec ----------------------------------------------------------------------------------------------

TEST(ConstraintKinds, CouplerOfTwoCoordinates) {
  // a q_i + b q_j = c with the first coefficient negative (the row is divided by |a|), one coordinate unused
  phiq::CouplerSpec c{S(2), S(0), -0.3, 1.7, 0.25};
  CheckSpec(c, 3, Opts(1101));
  phiq::CouplerSpec gear{S(0), S(1), 0.1, 0.05, 0.0};  // an external gear pair, pitch radii 0.1 and 0.05
  // along its data: the coefficients (a negative a too) and the constant
  CheckDataDerivative(c, phiq::CouplerSpec{S(2), S(0), 0.4, -0.9, 1.3}, 3, 1111);
  CheckDataDerivative(gear, phiq::CouplerSpec{S(0), S(1), 0.02, -0.01, 0.0}, 2, 1112);
  CheckSpec(gear, 2, Opts(1102));
}

TEST(ModelPlumbing, CrankSliderJacobianPhiTAndGamma) {
  phiq::ModelBuilder b;
  const Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", 0.3), ya = b.add_coordinate("yA", 0.0),
              xb = b.add_coordinate("xB", 1.3);
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
  auto g = phiq::CompiledExpression::compile("s - 0.3*cos(psi2) - 0.2*t*psi3",
                                             [&](const std::string& name) -> std::optional<phiq::NameBinding> {
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
