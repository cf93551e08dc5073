// The coupler kind (kinds/coupler.hpp) beyond its finite-difference check (test_constraint_kinds.cpp): a gear pair
// on the notes' crank-slider (models/seed/crank_slider_geared.yaml) against its closed form, its row's unit and
// tolerance, its Grübler count, and the data it refuses.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

TEST(Coupler, GearOnTheCrankSliderTurnsAtMinusTheRatioOfItsRadii) {
  Scene scene = load_scene(test::model_path("seed/crank_slider_geared.yaml"));
  const Model& m = *scene.model;
  const Index th2 = m.coordinate_index("theta2"), th5 = m.coordinate_index("theta5");
  const Index xb = m.coordinate_index("xB");
  test::Trace tr;
  SweepSummary sum;
  ASSERT_EQ(test::sweep(m, scene.sweep, &tr, &sum), SolveStatus::kSuccess) << sum.message;
  ASSERT_EQ(tr.t.size(), 91u);
  const double ratio = 0.1 / 0.05, L2 = 0.3, L3 = 1.0;
  for (std::size_t k = 0; k < tr.t.size(); ++k) {
    const double t = tr.t[k], th = 2.0 * t;
    EXPECT_NEAR(tr.q[k](th2), th, 1e-12);
    EXPECT_NEAR(tr.q[k](th5), -ratio * th, 1e-10 * (1.0 + ratio * th));  // from 0.1 at the placement
    EXPECT_NEAR(tr.qd[k](th5), -ratio * 2.0, 1e-10);
    EXPECT_NEAR(tr.qdd[k](th5), 0.0, 1e-10);
    // the slider is untouched by the gear: x_B = L2 cos θ + sqrt(L3² − L2² sin² θ)
    EXPECT_NEAR(tr.q[k](xb), L2 * std::cos(th) + std::sqrt(L3 * L3 - L2 * L2 * std::sin(th) * std::sin(th)), 1e-9);
  }
}

TEST(Coupler, RowHasTheUnitOfItsFirstCoordinateAndCountsAsAHigherPair) {
  ModelBuilder b;  // two gears on ground pivots in reference-point coordinates, a rack on the x axis
  const Index x1 = b.add_coordinate("x1", 0), y1 = b.add_coordinate("y1", 0), p1 = b.add_coordinate("p1", 0);
  const Index x2 = b.add_coordinate("x2", 0.3), y2 = b.add_coordinate("y2", 0), p2 = b.add_coordinate("p2", 0);
  const Slot S0 = Slot::constant(0);
  b.add_body("gear1", Frame2{Slot::coordinate(x1), Slot::coordinate(y1), Slot::coordinate(p1)});
  b.add_body("gear2", Frame2{Slot::coordinate(x2), Slot::coordinate(y2), Slot::coordinate(p2)});
  b.add("pivot1", PinSpec{Frame2{Slot::coordinate(x1), Slot::coordinate(y1), Slot::coordinate(p1)},
                          Frame2{S0, S0, S0},
                          {0, 0},
                          {0, 0}});
  b.add("pivot2", PinSpec{Frame2{Slot::coordinate(x2), Slot::coordinate(y2), Slot::coordinate(p2)},
                          Frame2{Slot::constant(0.3), S0, S0},
                          {0, 0},
                          {0, 0}});
  b.add("mesh", CouplerSpec{Slot::coordinate(p1), Slot::coordinate(p2), 0.2, 0.1, 0.0});
  b.add_driver("motor", p1, MotionLaw::linear(0.0, 1.0));
  Model m = std::move(b).build();
  // 3 (3 − 1) − 2 − 2 − 1 = 1: the two gears turn together, one freedom, which the motor takes
  ASSERT_TRUE(m.grubler().has_value());
  EXPECT_EQ(*m.grubler(), 1);
  const Index mesh_row = m.constraints()[2].first_row;
  EXPECT_EQ(m.row_unit(mesh_row), Unit::kAngle);  // the pins' ψ are angles, and so is the row
  Workspace ws(m);
  ASSERT_EQ(solve_position(m, 0.7, NewtonOptions{}, ws), SolveStatus::kSuccess);
  EXPECT_NEAR(ws.q(p2), -2.0 * 0.7, 1e-12);
}

TEST(Coupler, RefusesCoefficientsOfZeroAndOneCoordinateTwice) {
  auto refused = [](CouplerSpec c) -> std::string {
    ModelBuilder b;
    b.add_coordinate("a", 0), b.add_coordinate("b", 0);
    try {
      b.add("c1", c);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  const Slot A = Slot::coordinate(0), B = Slot::coordinate(1);
  EXPECT_EQ(refused(CouplerSpec{A, B, 0.0, 1.0, 0.0}), "constraint 'c1': coupler: coefficients must not be zero");
  EXPECT_EQ(refused(CouplerSpec{A, B, 1.0, 0.0, 0.0}), "constraint 'c1': coupler: coefficients must not be zero");
  EXPECT_EQ(refused(CouplerSpec{A, A, 1.0, 2.0, 0.0}), "constraint 'c1': coupler: the two coordinates must differ");
  EXPECT_EQ(refused(CouplerSpec{A, Slot::constant(1.0), 1.0, 2.0, 0.0}),
            "constraint 'c1': coupler: relates two coordinates");
  EXPECT_EQ(refused(CouplerSpec{A, B, 1.0, 2.0, INFINITY}), "constraint 'c1': coupler: coefficients are not finite");
  EXPECT_EQ(refused(CouplerSpec{A, B, 1.0, 2.0, 0.5}), "");
}

}  // namespace
}  // namespace phiq
