// The losses a sweep writes (`output: losses`, OutputEfforts::losses): a four-bar's bearings each write μ r |F| of
// their pin's written reaction and that times their relative turn, and those powers close the motor's power balance
// (the links' kinetic energy's rate and gravity's power) at every row; a hoist's two gear stages write the power each
// loses, raising and lowering, against their efficiencies' closed forms; the CSV names and the HDF5 units; bad lists
// and plans are refused in one line. (A Stepper's and parallel chunks' losses: test_friction_losses.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "efforts_files.hpp"
#include "phiq/applied_loads.hpp"
#include "phiq/phiq.hpp"
#include "reaction_rows.hpp"
#include "scratch_path.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

const char kAllOut[] =
    "output: {velocities: true, accelerations: true, efforts: all, power: true, reactions: all, losses: all}\n";

TEST(LossOutputs, AFourBarsBearingsWriteMuRTimesTheirPinsLoadAndCloseItsPowerBalance) {
  const Scene s =
      parse_scene(test::model_file_text("dynamics/fourbar_pin_friction.yaml", "output:") + kAllOut, "friction.yaml");
  const test::ReactionRows rows = test::sweep_reactions(s);
  ASSERT_EQ(rows.q.size(), 73u);
  ASSERT_EQ(s.sweep.efforts.losses_at(), 14);
  ASSERT_EQ(s.sweep.efforts.size(), 22);
  const double mu = 0.15, r = 0.01, g = 9.81;
  struct Link {
    const char *x, *y, *psi;
    double mass, inertia;
  };
  const Link links[] = {{"x2", "y2", "psi2", 1.0, 1.0 * 0.4 * 0.4 / 12},
                        {"x3", "y3", "psi3", 2.0, 2.0 * 1.2 * 1.2 / 12},
                        {"x4", "y4", "psi4", 1.5, 1.5 * 1.0 * 1.0 / 12}};
  auto c = [&](const char* n) { return s.model->coordinate_index(n); };
  double most_lost = 0.0;
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    const Eigen::VectorXd &qd = rows.qd[k], &qdd = rows.qdd[k];
    const std::vector<double>& v = rows.values[k];
    const double turn[4] = {qd(c("psi2")), qd(c("psi3")) - qd(c("psi2")), qd(c("psi4")) - qd(c("psi3")), qd(c("psi4"))};
    double lost = 0.0;
    for (int j = 0; j < 4; ++j) {  // pins O, A, B, C: the reaction at 2 + 3j, the loss's friction and power at 14 + 2j
      const double friction = mu * r * std::hypot(v[2 + 3 * j], v[3 + 3 * j]) * std::fabs(friction_direction(turn[j]));
      EXPECT_NEAR(v[14 + 2 * j], friction, 1e-10 * friction + 1e-15) << "row " << k << ", pin " << j;
      EXPECT_NEAR(v[15 + 2 * j], v[14 + 2 * j] * std::fabs(turn[j]), 1e-13 * v[14 + 2 * j] * std::fabs(turn[j]) + 1e-15)
          << "row " << k << ", pin " << j;
      lost += v[15 + 2 * j];
    }
    // the motor's power: the links' kinetic energy's rate, against gravity, and what the bearings dissipate
    double stored = 0.0, scale = std::fabs(v[1]);
    for (const Link& l : links) {
      const double terms = l.mass * (qd(c(l.x)) * qdd(c(l.x)) + qd(c(l.y)) * qdd(c(l.y))) +
                           l.inertia * qd(c(l.psi)) * qdd(c(l.psi)) + l.mass * g * qd(c(l.y));
      stored += terms, scale += std::fabs(terms);
    }
    EXPECT_NEAR(v[1], stored + lost, 1e-10 * scale) << "row " << k;
    most_lost = std::max(most_lost, lost);
  }
  EXPECT_GT(most_lost, 0.5);  // watts: leaving the losses out of the balance fails it
}

TEST(LossOutputs, AHoistsGearStagesLoseWhatTheirEfficienciesSayRaisingAndLowering) {
  // models/dynamics/hoist_gear_losses.yaml: 20 kg on a rope; stages 0.97 / 0.96 (reverse) and 0.95 / 0.93. Raising,
  // the load takes P = m (g + ÿ) ẏ and the second stage loses P (1/η2 − 1), the first P/η2 (1/η1 − 1); lowering,
  // the second loses |P| (1 − η2'), the first |P| η2' (1 − η1')
  const Scene s =
      parse_scene(test::model_file_text("dynamics/hoist_gear_losses.yaml", "output:") + kAllOut, "hoist.yaml");
  ASSERT_EQ(s.sweep.efforts.losses.size(), 2u);
  const test::ReactionRows rows = test::sweep_reactions(s);
  const Index hook = s.model->coordinate_index("hook");
  const std::size_t at = static_cast<std::size_t>(s.sweep.efforts.losses_at());  // (after 3 pivots' reactions)
  int raising = 0, lowering = 0;
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    const std::vector<double>& v = rows.values[k];
    ASSERT_EQ(v.size(), at + 2);
    const double load = 20.0 * (9.81 + rows.qdd[k](hook)) * rows.qd[k](hook);
    const double first = load > 0 ? load / 0.95 * (1 / 0.97 - 1) : -load * 0.93 * (1 - 0.96);
    const double second = load > 0 ? load * (1 / 0.95 - 1) : -load * (1 - 0.93);
    EXPECT_NEAR(v[at], first, 1e-11 * std::fabs(load) + 1e-13) << "row " << k;
    EXPECT_NEAR(v[at + 1], second, 1e-11 * std::fabs(load) + 1e-13) << "row " << k;
    EXPECT_NEAR(v[1], load + v[at] + v[at + 1], 1e-11 * std::fabs(load) + 1e-13) << "row " << k;  // the motor's
    raising += load > 1.0, lowering += load < -1.0;
  }
  EXPECT_GT(raising, 30);
  EXPECT_GT(lowering, 30);
}

TEST(LossOutputs, TheirColumnsAreNamedAndTheirUnitsStated) {
  const Scene s = parse_scene(test::model_file_text("dynamics/fourbar_pin_friction.yaml", "output:") +
                                  "output: {coordinates: [psi2], losses: [C_bearing, A_bearing]}\n",
                              "friction.yaml");
  EXPECT_TRUE(s.sweep.efforts.constraints.empty());
  ASSERT_TRUE(s.sweep.efforts.active());  // the losses alone solve the multipliers
  CsvFormat f(*s.model, s.sweep);
  EXPECT_EQ(f.header(), "t,psi2,C_bearing.friction,C_bearing.loss,A_bearing.friction,A_bearing.loss\n");
  const std::filesystem::path path = test::scratch_path("losses.h5");
  const std::string csv = test::write_efforts_files(s, path.string());
  const CsvTable table = read_hdf5_table(path.string());
  ASSERT_EQ(table.rows.size(), 73u);
  EXPECT_EQ(table.rows.back(), parse_csv_table(csv, "r.csv").rows.back());
  EXPECT_GT(table.rows[10][2], 0.05);  // C's friction, N m: the bearing is loaded
  EXPECT_EQ(test::hdf5_strings(path.string(), "efforts", "units"), (std::vector<std::string>{"N m", "W", "N m", "W"}));
  std::filesystem::remove(path);
}

TEST(LossOutputs, BadListsAndPlansAreRefusedInOneLine) {
  const std::string base = test::model_file_text("dynamics/fourbar_pin_friction.yaml", "output:");
  for (const auto& [output, why] : std::vector<std::pair<std::string, std::string>>{
           {"losses: [O]", "output.losses[0]: unknown loss 'O': neither a bearing's torsional spring nor a gear"},
           {"losses: some", "output.losses: expected `all` or a list"},
           {"losses: [A_bearing, A_bearing]", "output.losses[1]: loss listed twice"}})
    EXPECT_HAS(test::scene_error(base + "output: {" + output + "}\n"), why);
  EXPECT_HAS(test::scene_error(test::model_file_text("dynamics/fourbar_pin_loads.yaml", "output:") +
                               "output: {losses: all}\n"),
             "output.losses: the scene has no bearing");
  // a plan built in code: a loss the loads do not have
  Scene s = parse_scene(base + "output: {losses: all}\n", "friction.yaml");
  s.sweep.efforts.losses.push_back({"ghost", 4, true, false});
  EXPECT_HAS(test::sweep_error(*s.model, s.sweep), "SweepOptions: loss 'ghost' (4) is not one of the loads' bearings");
}

}  // namespace
}  // namespace phiq
