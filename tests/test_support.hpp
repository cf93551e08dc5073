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

// Difference of two angles, wrapped to (-pi, pi].
inline double angle_diff(double a, double b) { return std::remainder(a - b, 2.0 * M_PI); }

}  // namespace phiq::test
