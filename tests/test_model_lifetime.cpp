// A Workspace follows its Model where it moves (Model's move constructor and assignment re-point the anchor the
// workspaces hold) and refuses to work once it is destroyed; constraint and row lookup by name on Model.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// Position, velocity and acceleration at t from the workspace's current q, as an embedding loop solves them.
struct Solved {
  Eigen::VectorXd q, qd, qdd;
};
Solved solve_at(const Model& m, double t, Workspace& ws) {
  PositionSummary ps;
  EXPECT_EQ(solve_position(m, t, {}, ws, &ps), SolveStatus::kSuccess) << ps.BriefReport();
  LinearSummary ls;
  EXPECT_EQ(solve_velocity(m, t, ws, &ls), SolveStatus::kSuccess) << ls.message;
  EXPECT_EQ(solve_acceleration(m, t, ws, &ls), SolveStatus::kSuccess) << ls.message;
  return {ws.q, ws.qd, ws.qdd};
}

TEST(ModelLifetime, WorkspacesFollowModelsOfAGrowingVector) {
  // Reference: the same solves with models that never move.
  std::vector<Solved> expected;
  for (int k = 0; k < 3; ++k) {
    const Model m = test::crank_slider_model(1.0 + k, 0.1 * k);
    Workspace ws(m);
    (void)solve_at(m, 0.0, ws);  // assembly at t = 0; the step compared is the next one
    expected.push_back(solve_at(m, 0.25, ws));
  }

  std::vector<Model> models;
  models.reserve(1);
  std::vector<Workspace> spaces;
  spaces.reserve(8);
  const Model* first_address = nullptr;
  for (int k = 0; k < 3; ++k) {
    models.push_back(test::crank_slider_model(1.0 + k, 0.1 * k));
    if (k == 0) first_address = &models[0];
    spaces.emplace_back(models.back());
    (void)solve_at(models.back(), 0.0, spaces.back());
  }
  // the vector grew past its capacity of 1: every model moved at least once since its workspace was made
  ASSERT_NE(&models[0], first_address);
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    EXPECT_EQ(&spaces[i].model(), &models[i]);
    const Solved s = solve_at(models[i], 0.25, spaces[i]);
    EXPECT_TRUE(test::same_bits(s.q, expected[i].q)) << k;
    EXPECT_TRUE(test::same_bits(s.qd, expected[i].qd)) << k;
    EXPECT_TRUE(test::same_bits(s.qdd, expected[i].qdd)) << k;
  }
  // and a sweep with a workspace made before the growth
  SweepOptions opt;
  opt.t_end = 1.0;
  opt.steps = 10;
  SweepSummary sum;
  EXPECT_EQ(run_sweep(models[1], opt, spaces[1], nullptr, &sum), SolveStatus::kSuccess) << sum.message;
}

TEST(ModelLifetime, WorkspaceOfADestroyedModelThrows) {
  auto m = std::make_unique<Model>(test::crank_slider_model());
  Workspace ws(*m);
  m.reset();
  const std::string gone = "the Model this Workspace was made for no longer exists";
  for (int call = 0; call < 3; ++call) {
    try {
      if (call == 0) (void)ws.model();
      if (call == 1) (void)solve_position(test::crank_slider_model(), 0.0, {}, ws);
      if (call == 2) (void)solve_velocity(test::crank_slider_model(), 0.0, ws);
      ADD_FAILURE() << "no error, call " << call;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(gone, 0), 0u) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
}

TEST(ModelLifetime, AssignedOverModelLeavesItsWorkspacesRefusingAndTheMovedFromModelHasNone) {
  Model a = test::crank_slider_model(1.0);
  Model b = test::crank_slider_model(2.0);
  Workspace wa(a), wb(b);
  a = std::move(b);  // a's old data is gone; b's workspaces now refer to a
  EXPECT_THROW((void)wa.model(), Error);
  EXPECT_EQ(&wb.model(), &a);
  EXPECT_EQ(solve_position(a, 0.0, {}, wb), SolveStatus::kSuccess);
  try {
    Workspace w(b);  // NOLINT(bugprone-use-after-move): the moved-from model is what is tested
    ADD_FAILURE() << "a workspace of a moved-from model";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("moved from"), std::string::npos) << e.what();
  }
  // a model moved into a new object (as std::vector does) takes its workspaces along
  Model c(std::move(a));
  EXPECT_EQ(&wb.model(), &c);
  EXPECT_EQ(solve_position(c, 0.1, {}, wb), SolveStatus::kSuccess);
}

TEST(ModelLifetime, ScaledJacobianRowsFollowTheModel) {
  std::vector<Model> models;
  models.push_back(test::crank_slider_model());
  ScaledJacobianRows rows(models[0], {0, 1});
  std::vector<double> before, after;
  rows.evaluate(models[0].initial_positions(), 0.0, before);
  models.push_back(test::crank_slider_model());  // grows: models[0] moves
  models.push_back(test::crank_slider_model());
  rows.evaluate(models[0].initial_positions(), 0.0, after);
  EXPECT_EQ(before, after);
  models.clear();
  EXPECT_THROW(rows.evaluate(Eigen::VectorXd::Zero(4), 0.0, after), Error);
}

TEST(ModelNames, ConstraintAndRowLookupRoundTrips) {
  const Model m = test::crank_slider_model();
  ASSERT_EQ(m.constraints().size(), 3u);
  for (std::size_t k = 0; k < m.constraints().size(); ++k) {
    const ConstraintInfo& c = m.constraints()[k];
    EXPECT_EQ(m.constraint_index(c.name), static_cast<Index>(k));
    EXPECT_EQ(m.find_constraint(c.name), static_cast<Index>(k));
    EXPECT_EQ(&m.constraint(c.name), &c);
  }
  EXPECT_EQ(m.constraint("rod").first_row, 2);  // crank: 2 rows, then rod
  EXPECT_EQ(m.constraint("rod").rows, 1);
  for (Index i = 0; i < m.num_equations(); ++i) EXPECT_EQ(m.row_index(m.row_name(i)), i) << m.row_name(i);
  EXPECT_EQ(m.row_index("crank[1]"), 1);
  for (Index j = 0; j < m.num_coordinates(); ++j) {
    EXPECT_EQ(m.find_coordinate(m.coordinate_names()[static_cast<std::size_t>(j)]), j);
    EXPECT_EQ(m.coordinate_index(m.coordinate_names()[static_cast<std::size_t>(j)]), j);
  }
  EXPECT_EQ(m.find_constraint("nope"), -1);
  EXPECT_EQ(m.find_coordinate("nope"), -1);
  auto message = [&](auto f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message([&] { (void)m.constraint_index("nope"); }), "unknown constraint 'nope'");
  EXPECT_EQ(message([&] { (void)m.row_index("crank"); }), "constraint 'crank' has 2 rows: name one as 'crank[k]'");
  EXPECT_EQ(message([&] { (void)m.row_index("crank[2]"); }), "no row of Φ is named 'crank[2]'");
  EXPECT_EQ(message([&] { (void)m.row_index("rod[0]"); }), "no row of Φ is named 'rod[0]'");
}

TEST(ModelNames, LookupOnALargeGeneratedModelAndItsReducedCopy) {
  const Model m = test::nfourbar_model(2000, 0.3, 1.0);
  const Model reduced = m.without_rows({});
  for (const Model* x : {&m, &reduced})
    for (std::size_t k = 0; k < m.constraints().size(); k += 97) {
      const ConstraintInfo& c = m.constraints()[k];
      EXPECT_EQ(x->constraint_index(c.name), static_cast<Index>(k));
      EXPECT_EQ(x->row_index(x->row_name(c.first_row)), c.first_row);
    }
}

}  // namespace
}  // namespace phiq
