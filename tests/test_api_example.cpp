// The README's C++ tour, compiled and checked, so that the README cannot drift from the API.
#include <gtest/gtest.h>

#include <cmath>

#include "phiq/phiq.hpp"

namespace {

TEST(ApiExample, ReadmeTourRunsAndMatchesTheClosedForm) {
  int rows = 0;
  double worst = 0.0;
  auto use = [&](double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
    const double th = 2 * t, s = std::sin(th);
    worst = std::max(worst, std::fabs(q(3) - (0.3 * std::cos(th) + std::sqrt(1 - 0.09 * s * s))));
    EXPECT_DOUBLE_EQ(qd(0), 2.0);
    EXPECT_NEAR(qdd(0), 0.0, 1e-12);
    ++rows;
  };
  // clang-format off
  // ---- begin README ----
  using namespace phiq;
  ModelBuilder b;                                       // the notes' crank-slider, q = [θ2, xA, yA, xB]
  Index th = b.add_coordinate("theta2", 0.0), xa = b.add_coordinate("xA", 0.3),
        ya = b.add_coordinate("yA", 0.0), xb = b.add_coordinate("xB", 1.3);
  b.add("crank", PolarSpec{{Slot::coordinate(xa), Slot::coordinate(ya)}, {}, 0.3, Slot::coordinate(th)});
  b.add("rod", DistanceSpec{{Slot::coordinate(xa), Slot::coordinate(ya)}, {Slot::coordinate(xb), {}}, 1.0});
  b.add_driver("motor", th, MotionLaw::linear(0.0, 2.0));
  Model model = std::move(b).build();                   // pattern + symbolic factorisation, once
  Stepper stepper(model);                               // keeps predictors and diagnostics across steps
  for (int k = 0; k <= 100; ++k)                       // the simulator's clock: t = k / 100
    if (const double t = 0.01 * k; stepper.step(t) == SolveStatus::kSuccess)
      use(t, stepper.q(), stepper.qd(), stepper.qdd()); // positions, velocities, accelerations
  // ---- end README ----
  // clang-format on
  EXPECT_EQ(rows, 101);
  EXPECT_LT(worst, 1e-10);
  // the sweep's work: the assembly, then one modified-Newton iteration and one factorisation per step (the loop of
  // solve_position / solve_velocity / solve_acceleration over these times took 300 and 401: tests/test_stepper.cpp)
  EXPECT_EQ(stepper.summary().counters.newton_iterations, 102);
  EXPECT_EQ(stepper.summary().counters.factorizations, 101);
}

}  // namespace
