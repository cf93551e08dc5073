// Helpers shared by the test files.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"

namespace phiq::test {

inline std::string model_path(const std::string& rel) { return std::string(PHIQ_MODELS_DIR) + "/" + rel; }

// All rows of a sweep, kept in memory.
struct Trace {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q, qd, qdd;
};

inline SolveStatus sweep(const Model& model, const SweepOptions& opt, Trace* trace, SweepSummary* summary = nullptr,
                         Workspace* ws_in = nullptr) {
  Workspace local(model);
  Workspace& ws = ws_in ? *ws_in : local;
  return run_sweep(
      model, opt, ws,
      [&](const StepView& s) {
        trace->t.push_back(s.t);
        trace->q.push_back(s.q);
        if (s.qd) trace->qd.push_back(*s.qd);
        if (s.qdd) trace->qdd.push_back(*s.qdd);
        return true;
      },
      summary);
}

// The notes' crank-slider built in code: q = [theta2, xA, yA, xB], L2 = 0.3, L3 = 1.0, theta2 = theta0 + omega t,
// from a rough placement.
inline Model crank_slider_model(double omega = 1.0, double theta0 = 0.0,
                                LinearSolverKind lu = LinearSolverKind::kUmfpack) {
  ModelBuilder b;
  Index th = b.add_coordinate("theta2", theta0), xa = b.add_coordinate("xA", 0.25),
        ya = b.add_coordinate("yA", 0.05), xb = b.add_coordinate("xB", 1.2);
  auto S = Slot::coordinate;
  auto C = Slot::constant;
  b.add("crank", PolarSpec{{S(xa), S(ya)}, {C(0), C(0)}, 0.3, S(th)});
  b.add("rod", DistanceSpec{{S(xa), S(ya)}, {S(xb), C(0)}, 1.0});
  b.add_driver("motor", th, MotionLaw::linear(theta0, omega));
  b.set_linear_solver(lu);
  return std::move(b).build();
}

// Difference of two angles, wrapped to (-pi, pi].
inline double angle_diff(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

}  // namespace phiq::test
