// A sweep's rows with efforts and reactions, as `phiq run` sweeps them (the model with redundant rows left out):
// what the joint-reaction and gear-mesh tests read.
#pragma once

#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq::test {

struct ReactionRows {
  std::vector<Eigen::VectorXd> q, qd, qdd;
  std::vector<std::vector<double>> values;  // efforts, powers, reactions
};

// The rows of `s` (its output asks for velocities and accelerations), its summary into `sum` and the model swept
// (the scene's, its redundant rows left out; it outlives the call) into `swept`, when not null.
inline ReactionRows sweep_reactions(const Scene& s, SweepSummary* sum = nullptr, const Model** swept = nullptr) {
  ReactionRows r;
  static std::vector<SquareScene> kept;  // the reduced models the callers read after the sweep
  kept.emplace_back();
  SquareScene& square = kept.back();
  EXPECT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &square), SolveStatus::kSuccess);
  const Model& m = square.model(*s.model);
  if (swept) *swept = &m;
  Workspace ws(m);
  ws.q = square.start;
  const std::size_t n = static_cast<std::size_t>(s.sweep.efforts.size());
  EXPECT_EQ(run_sweep(
                m, s.sweep, ws,
                [&](const StepView& v) {
                  r.q.push_back(v.q), r.qd.push_back(*v.qd), r.qdd.push_back(*v.qdd);
                  r.values.emplace_back(v.efforts, v.efforts + n);
                  return true;
                },
                sum),
            SolveStatus::kSuccess);
  return r;
}

}  // namespace phiq::test
