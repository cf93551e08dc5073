// FreeCAD Assembly / OndselSolver `.asmt` files read as phiq scenes (phiq/import_asmt.hpp). OndselSolver's four
// sample files (PHIQ_ASMT_SAMPLES, outside the repository; skipped, saying so, when absent) load with exact counts,
// assemble and run; where they store a TimeSeries, phiq's part placements are compared with it. phiq's own files
// (tests/data/asmt/) have closed forms: a driven pendulum's tip on its circle, a slider-crank, a rack and pinion.
// Bad input is one line naming FILE:LINE; `phiq run FILE.asmt` and `phiq convert` + `phiq run` give the same bytes.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "cli_test_support.hpp"
#include "phiq/import_asmt.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

std::string AsmtSample(const std::string& name) { return std::string(PHIQ_ASMT_SAMPLES) + "/" + name; }
std::string AsmtOwn(const std::string& name) { return std::string(PHIQ_SOURCE_DIR) + "/tests/data/asmt/" + name; }
bool AsmtSamplesPresent() { return std::filesystem::exists(AsmtSample("Gears.asmt")); }
#define PHIQ_NEED_ASMT_SAMPLES()                                                       \
  if (!AsmtSamplesPresent())                                                           \
  GTEST_SKIP() << "OndselSolver's sample .asmt files are not at " << PHIQ_ASMT_SAMPLES \
               << " (../shared/asmt beside the clone; cmake -DPHIQ_ASMT_SAMPLES=DIR)"

// The scene of an .asmt file swept as `phiq run` sweeps it (prepared: assembled, redundant rows left out), every
// row kept.
struct AsmtRun {
  Scene scene;
  test::Trace trace;
  SolveStatus status = SolveStatus::kSuccess;
  std::string message;
};
AsmtRun AsmtSweep(const std::string& path, double tolerance = 1e-10, bool velocities = false) {
  AsmtRun r;
  r.scene = load_scene(path);
  r.scene.sweep.velocities = velocities;
  r.scene.sweep.newton.tolerance = r.scene.sweep.assembly.tolerance = tolerance;
  SquareScene square;
  const SolveStatus prepared = prepare_scene(*r.scene.model, r.scene.sweep.t_begin, r.scene.sweep.assembly, &square);
  if (prepared != SolveStatus::kSuccess) {
    r.status = prepared, r.message = square.assembly.message;
    return r;
  }
  const Model& m = square.model(*r.scene.model);
  Workspace ws(m);
  ws.q = square.start;
  SweepSummary summary;
  r.status = test::sweep(m, r.scene.sweep, &r.trace, &summary, &ws);
  r.message = summary.message;
  return r;
}

// A body's rotation matrix from its Euler parameters in q.
Eigen::Matrix3d AsmtBodyRotation(const Model& m, const Eigen::VectorXd& q, const std::string& body) {
  const Index e0 = m.coordinate_index(body + "_e0");
  return Eigen::Quaterniond(q(e0), q(e0 + 1), q(e0 + 2), q(e0 + 3)).normalized().toRotationMatrix();
}
Eigen::Vector3d AsmtBodyPosition(const Model& m, const Eigen::VectorXd& q, const std::string& body) {
  const Index x = m.coordinate_index(body + "_x");
  return q.segment<3>(x);
}

TEST(AsmtImport, SampleFilesConvertWithTheirExactCounts) {
  PHIQ_NEED_ASMT_SAMPLES();
  struct Expected {
    const char* file;
    int parts, joints, motions;
    Index coordinates, equations;
  };
  // Coordinates: 7 a part; a gear adds two natural points (6) and two orbit angles, a rack and pinion three
  // points (9) and a turn. Equations: joints' rows (rigid 6, revolute 5, cylindrical 4, prismatic 5; a gear 2 + 6
  // pins + coupler 1; a rack-pinion 1 + 9 pins + 1), one normalisation a part, and one row a motion.
  const Expected cases[] = {{"Gears.asmt", 2, 3, 1, 2 * 7 + 8, 5 + 5 + 9 + 2 + 1},
                            {"parm.asmt", 4, 5, 1, 4 * 7, 6 + 4 * 5 + 4 + 1},
                            {"Schmidt_Coupling_Ass_1-1.asmt", 12, 17, 0, 12 * 7, 3 * 6 + 9 * 5 + 5 * 4 + 12},
                            {"rackPinion.asmt", 5, 6, 0, 5 * 7 + 10, 6 + 3 * 5 + 5 + 11 + 5}};
  for (const Expected& c : cases) {
    SCOPED_TRACE(c.file);
    const AsmtImport imported = import_asmt(test::file_text(AsmtSample(c.file)), c.file);
    EXPECT_EQ(imported.parts, c.parts);
    EXPECT_EQ(imported.joints, c.joints);
    EXPECT_EQ(imported.motions, c.motions);
    const Scene scene = load_scene(AsmtSample(c.file));
    EXPECT_EQ(scene.model->body_names().size(), static_cast<std::size_t>(c.parts));
    EXPECT_EQ(scene.model->num_coordinates(), c.coordinates);
    EXPECT_EQ(scene.model->num_equations(), c.equations);
    EXPECT_EQ(scene.sweep.steps, std::string(c.file) == "Gears.asmt" || std::string(c.file) == "parm.asmt" ? 100 : 10);
    // what is not mapped is listed once each, in the scene's text too
    std::vector<std::string> sorted = imported.skipped;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
    for (const std::string& why : imported.skipped) {
      EXPECT_EQ(why.rfind(std::string(c.file) + ":", 0), 0u) << why;
      EXPECT_NE(imported.yaml.find(why), std::string::npos) << why;
    }
    EXPECT_NE(imported.yaml.find("millimetres"), std::string::npos);
  }
}

TEST(AsmtImport, DrivenSampleFilesRunWithEveryRowHeld) {
  PHIQ_NEED_ASMT_SAMPLES();
  for (const char* file : {"Gears.asmt", "parm.asmt"}) {
    SCOPED_TRACE(file);
    const AsmtRun r = AsmtSweep(AsmtSample(file));
    ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
    ASSERT_EQ(r.trace.q.size(), static_cast<std::size_t>(r.scene.sweep.steps + 1));
    Eigen::VectorXd phi(r.scene.model->num_equations());
    for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
      r.scene.model->residual(r.trace.q[k].data(), r.trace.t[k], phi.data());
      EXPECT_LE(scaled_residual(*r.scene.model, phi), 1e-9) << "t = " << r.trace.t[k];
    }
  }
}

// The two files without motions: the rack and pinion assembles (3 freedoms: the pinion and two free wheels) and
// its run is refused for its undriven freedoms, as any phiq scene's; the Schmidt coupling's stored placement
// breaks its revolutes by up to 7e-6 rad, and with its 11 redundant rows phiq finds no assembly near it
// (OndselSolver drops the rows): refused naming the cylindrical joints c12 and c13, not solved by dropping rows.
TEST(AsmtImport, SampleFilesWithoutMotionsAssembleOrAreRefusedByName) {
  PHIQ_NEED_ASMT_SAMPLES();
  {
    const Scene scene = load_scene(AsmtSample("rackPinion.asmt"));
    Eigen::VectorXd q = scene.model->initial_positions();
    AssemblySummary summary;
    ASSERT_EQ(assemble(*scene.model, 0.0, {}, q, &summary), SolveStatus::kSuccess) << summary.message;
    EXPECT_EQ(summary.rank.rank, 42);
    EXPECT_LE(summary.moved, 1e-12);  // the file's placement holds already
    SquareScene square;
    EXPECT_EQ(prepare_scene(*scene.model, 0.0, scene.sweep.assembly, &square), SolveStatus::kNotSquare);
    EXPECT_NE(square.assembly.message.find("3 degree(s) of freedom not driven"), std::string::npos)
        << square.assembly.message;
  }
  const Scene scene = load_scene(AsmtSample("Schmidt_Coupling_Ass_1-1.asmt"));
  Eigen::VectorXd q = scene.model->initial_positions();
  AssemblySummary summary;
  EXPECT_EQ(assemble(*scene.model, 0.0, {}, q, &summary), SolveStatus::kNotConverged);
  EXPECT_NE(summary.message.find("'c13[3]'"), std::string::npos) << summary.message;
  EXPECT_NE(summary.message.find("'c12["), std::string::npos) << summary.message;
}

// The rotation Rx(a) Ry(b) Rz(c) of the TimeSeries' Bryant angles.
Eigen::Matrix3d AsmtBryant(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

// The largest differences between phiq's part placements and the file's TimeSeries, phiq solved to `tolerance`:
// positions (file units), and rotations since the first output time (R(t) R(t0)ᵀ). Rotations are compared as
// motions because OndselSolver's first output of Gears.asmt has Part2 turned by π from the file's own placement
// (its TimeSeries' Input column, Bryantz 3.14159265203, then 2.2e-16 at t = 0: a gear's other branch), which phiq
// keeps; the absolute rotation at t0 is compared with that Input column instead.
struct AsmtSeriesDifference {
  double position = 0.0, motion = 0.0, placement = 0.0;
};
AsmtSeriesDifference AsmtTimeSeriesDifference(const std::string& file, double tolerance) {
  const std::string path = AsmtSample(file), text = test::file_text(path);
  const AsmtTimeSeries series = read_asmt_time_series(text, path);
  const AsmtRun r = AsmtSweep(path, tolerance);
  EXPECT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  EXPECT_EQ(series.time.size(), r.trace.t.size());
  AsmtSeriesDifference d;
  const Model& m = *r.scene.model;
  for (const AsmtPartSeries& part : series.parts) {
    auto at = [&](int row, std::size_t k) { return part.columns[static_cast<std::size_t>(row)][k]; };
    const Eigen::Matrix3d R0 = AsmtBryant(at(3, 0), at(4, 0), at(5, 0));
    const Eigen::Matrix3d P0 = AsmtBodyRotation(m, r.trace.q[0], part.name);
    for (std::size_t k = 0; k < series.time.size() && k < r.trace.t.size(); ++k) {
      EXPECT_NEAR(series.time[k], r.trace.t[k], 1e-14);
      const Eigen::Vector3d p(at(0, k), at(1, k), at(2, k));
      d.position = std::max(d.position, (AsmtBodyPosition(m, r.trace.q[k], part.name) - p).cwiseAbs().maxCoeff());
      const Eigen::Matrix3d R = AsmtBryant(at(3, k), at(4, k), at(5, k)) * R0.transpose();
      const Eigen::Matrix3d P = AsmtBodyRotation(m, r.trace.q[k], part.name) * P0.transpose();
      d.motion = std::max(d.motion, (P - R).cwiseAbs().maxCoeff());
    }
  }
  // the placement at t0 against the file's own parts (its RotationMatrix, what the Input column holds)
  const Scene unswept = load_scene(path);
  for (const AsmtPartSeries& part : series.parts)
    d.placement = std::max(d.placement, (AsmtBodyRotation(m, r.trace.q[0], part.name) -
                                         AsmtBodyRotation(m, unswept.model->initial_positions(), part.name))
                                            .cwiseAbs()
                                            .maxCoeff());
  return d;
}

// At phiq's default tolerance (1e-10, relative) the placements agree to within it; solved to 1e-13 they agree
// within the TimeSeries' 14 stored digits, which is what the file can tell.
TEST(AsmtImport, GearsFollowTheirTimeSeries) {
  PHIQ_NEED_ASMT_SAMPLES();
  for (double tolerance : {1e-10, 1e-13}) {
    const AsmtSeriesDifference d = AsmtTimeSeriesDifference("Gears.asmt", tolerance);
    std::printf("Gears.asmt, tolerance %g: positions within %.3g, rotations within %.3g, t0 placement within %.3g\n",
                tolerance, d.position, d.motion, d.placement);
    EXPECT_LE(d.position, 10 * tolerance);  // 1e-13: 7.8e-16 (commit of this test)
    EXPECT_LE(d.motion, 10 * tolerance);    // 1e-10: 6.0e-11, 1e-13: 4.5e-14
    EXPECT_LE(d.placement, 1e-14);          // 8.0e-15
  }
}

// Gears.asmt's stored velocities (its README: consistent, unlike parm.asmt's): each part's VX, VY, VZ against q̇ of
// its reference point, OmegaX, OmegaY, OmegaZ (world frame) against 2 E(e) ė of its Euler parameters.
TEST(AsmtImport, GearsVelocitiesFollowTheirTimeSeries) {
  PHIQ_NEED_ASMT_SAMPLES();
  const std::string path = AsmtSample("Gears.asmt");
  const AsmtTimeSeries series = read_asmt_time_series(test::file_text(path), path);
  const AsmtRun r = AsmtSweep(path, 1e-13, true);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.qd.size(), series.time.size());
  double dv = 0.0, dw = 0.0;
  for (const AsmtPartSeries& part : series.parts) {
    ASSERT_EQ(part.labels[9], "OmegaX");
    const Index x = r.scene.model->coordinate_index(part.name + "_x"), e = x + 3;
    for (std::size_t k = 0; k < series.time.size(); ++k) {
      auto at = [&](int row) { return part.columns[static_cast<std::size_t>(row)][k]; };
      const Eigen::VectorXd &q = r.trace.q[k], &qd = r.trace.qd[k];
      dv = std::max(dv, (qd.segment<3>(x) - Eigen::Vector3d(at(6), at(7), at(8))).cwiseAbs().maxCoeff());
      Eigen::Matrix<double, 3, 4> E;
      E << -q(e + 1), q(e), -q(e + 3), q(e + 2), -q(e + 2), q(e + 3), q(e), -q(e + 1), -q(e + 3), -q(e + 2), q(e + 1),
          q(e);
      const Eigen::Vector3d omega = 2 * E * qd.segment<4>(e);
      dw = std::max(dw, (omega - Eigen::Vector3d(at(9), at(10), at(11))).cwiseAbs().maxCoeff());
    }
  }
  std::printf("Gears.asmt velocities: reference points within %.3g, angular velocities within %.3g\n", dv, dw);
  EXPECT_LE(dv, 1e-9);
  EXPECT_LE(dw, 1e-9);
}

TEST(AsmtImport, ParallelogramFollowsItsTimeSeries) {
  PHIQ_NEED_ASMT_SAMPLES();
  for (double tolerance : {1e-10, 1e-13}) {
    const AsmtSeriesDifference d = AsmtTimeSeriesDifference("parm.asmt", tolerance);
    std::printf("parm.asmt, tolerance %g: positions within %.3g, rotations within %.3g, t0 placement within %.3g\n",
                tolerance, d.position, d.motion, d.placement);
    EXPECT_LE(d.position, 10 * tolerance);  // 1e-10: 2.7e-11, 1e-13: 1.4e-13 (the stored 14 digits: 1e-11)
    EXPECT_LE(d.motion, 10 * tolerance);    // 1e-10: 2.8e-11, 1e-13: 5.1e-14
    EXPECT_LE(d.placement, 1e-14);          // 1.5e-16
  }
}

TEST(AsmtImport, DrivenPendulumTipRunsOnItsCircle) {
  const AsmtRun r = AsmtSweep(AsmtOwn("pendulum.asmt"));
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 17u);  // t 0..4 step 0.25
  double worst = 0.0;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k], theta = 0.5 * t;
    const Eigen::Vector3d tip = AsmtBodyPosition(*r.scene.model, r.trace.q[k], "Arm") +
                                AsmtBodyRotation(*r.scene.model, r.trace.q[k], "Arm") * Eigen::Vector3d(2, 0, 0);
    worst = std::max(worst, (tip - Eigen::Vector3d(2 * std::cos(theta), 2 * std::sin(theta), 0)).norm());
  }
  EXPECT_LE(worst, 1e-10);
}

TEST(AsmtImport, SliderCrankFollowsItsClosedForm) {
  const AsmtRun r = AsmtSweep(AsmtOwn("slider_crank.asmt"));
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 21u);
  const Model& m = *r.scene.model;
  double worst = 0.0;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double theta = 2 * M_PI * r.trace.t[k], rc = 1.0, l = 3.0;
    const double xb = rc * std::cos(theta) + std::sqrt(l * l - std::pow(rc * std::sin(theta), 2));
    const Eigen::VectorXd& q = r.trace.q[k];
    worst = std::max(worst, (AsmtBodyPosition(m, q, "Slider") - Eigen::Vector3d(xb, 0, 0)).norm());
    worst = std::max(
        worst, (AsmtBodyPosition(m, q, "Rod") - rc * Eigen::Vector3d(std::cos(theta), std::sin(theta), 0)).norm());
    const Eigen::Vector3d b = AsmtBodyPosition(m, q, "Rod") + AsmtBodyRotation(m, q, "Rod") * Eigen::Vector3d(l, 0, 0);
    worst = std::max(worst, (b - Eigen::Vector3d(xb, 0, 0)).norm());
  }
  EXPECT_LE(worst, 1e-10);
}

TEST(AsmtImport, RackTravelsPitchRadiusTimesThePinionsTurn) {
  const AsmtRun r = AsmtSweep(AsmtOwn("rack_pinion_driven.asmt"));
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 21u);
  double worst = 0.0;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k)
    worst = std::max(worst, std::abs(AsmtBodyPosition(*r.scene.model, r.trace.q[k], "Rack").x() - 0.5 * r.trace.t[k]));
  EXPECT_LE(worst, 1e-10);
}

TEST(AsmtImport, DrivenScrewRisesItsPitchPerTurn) {
  const AsmtRun r = AsmtSweep(AsmtOwn("screw_driven.asmt"));
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 13u);
  double worst = 0.0;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    const Eigen::Vector3d nut = AsmtBodyPosition(*r.scene.model, r.trace.q[k], "Nut");
    worst = std::max(worst, (nut - Eigen::Vector3d(0, 0, 1 + 0.5 * t / (2 * M_PI))).norm());
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    worst = std::max(worst, (AsmtBodyRotation(*r.scene.model, r.trace.q[k], "Nut") - turn).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, 1e-10);
}

// tests/data/asmt/general_motion.asmt: a block's marker J moved by a general motion from a turned ground marker I
// (Rz(2.3) Ry(0.6) Rx(0.3), at (0.5, −0.5, 1)): J's origin at (cos t, sin t, t/2) in I's axes, J's axes turned by
// Rx(0.1 t) Ry(0.2) Rz(0.3 t) (RotationOrder 1 2 3) from I's; J sits in the block at (0.1, 0.2, 0.3), turned Rz(0.25).
TEST(AsmtImport, GeneralMotionPlacesItsMarkerAsItsExpressionsSay) {
  const AsmtRun r = AsmtSweep(AsmtOwn("general_motion.asmt"), 1e-12);  // (at 1e-10: within 1.1e-10)
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 21u);
  using Eigen::AngleAxisd, Eigen::Vector3d;
  const Eigen::Matrix3d ri =
      (AngleAxisd(2.3, Vector3d::UnitZ()) * AngleAxisd(0.6, Vector3d::UnitY()) * AngleAxisd(0.3, Vector3d::UnitX()))
          .toRotationMatrix();
  const Eigen::Matrix3d in_block = AngleAxisd(0.25, Vector3d::UnitZ()).toRotationMatrix();
  double worst = 0.0;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    const Vector3d marker = Vector3d(0.5, -0.5, 1) + ri * Vector3d(std::cos(t), std::sin(t), 0.5 * t);
    const Eigen::Matrix3d axes = ri * (AngleAxisd(0.1 * t, Vector3d::UnitX()) * AngleAxisd(0.2, Vector3d::UnitY()) *
                                       AngleAxisd(0.3 * t, Vector3d::UnitZ()))
                                          .toRotationMatrix();
    const Eigen::Matrix3d body = axes * in_block.transpose();
    const Vector3d origin = marker - body * Vector3d(0.1, 0.2, 0.3);
    worst = std::max(worst, (AsmtBodyRotation(*r.scene.model, r.trace.q[k], "Block") - body).cwiseAbs().maxCoeff());
    worst = std::max(worst, (AsmtBodyPosition(*r.scene.model, r.trace.q[k], "Block") - origin).norm());
  }
  EXPECT_LE(worst, 1e-10);
}

// tests/data/asmt/joint_zoo.asmt: one part per joint type on a ground marker, each placed (with turned markers,
// offsets, an angle and a distance) so that OndselSolver's definition of its joint holds exactly. phiq's rows must
// vanish there and leave each part the freedoms its joint leaves: Σ (6 − removed) = 0 fixed + 1 revolute + 2
// cylindrical + 1 translational + 3 spherical + 2 universal + 3 planar + 5 point-in-plane + 4 point-in-line + 4
// line-in-plane + 4 parallel + 5 perpendicular + 5 angle + 3 no-rotation + 5 sph-sph = 47.
Eigen::VectorXd AsmtResidualAtPlacement(const std::string& text) {
  const Scene scene = parse_scene(import_asmt(text, "zoo.asmt").yaml, "zoo.asmt");
  Eigen::VectorXd phi(scene.model->num_equations());
  scene.model->residual(scene.model->initial_positions().data(), 0.0, phi.data());
  return phi;
}

TEST(AsmtImport, EveryJointTypeHoldsAtItsPlacementAndLeavesItsFreedoms) {
  const std::string text = test::file_text(AsmtOwn("joint_zoo.asmt"));
  const AsmtImport imported = import_asmt(text, "zoo.asmt");
  EXPECT_EQ(imported.parts, 15);
  EXPECT_EQ(imported.joints, 15);
  const Scene scene = parse_scene(imported.yaml, "zoo.asmt");
  // rows: 6+5+4+5+3+4+3+1+2 = 33 of the direct kinds; line-in-plane 1 + 1 dot, parallel 2 dots, perpendicular
  // 1, angle 1, no-rotation 3, sph-sph 1: 10; the dots' 11 natural points on the parts (o, z; o, z; o, z; o, z;
  // o, x, y: a ground marker's are constants) pinned by 3 rows each; 15 normalisations
  EXPECT_EQ(scene.model->num_equations(), 33 + 10 + 3 * 11 + 15);
  EXPECT_EQ(scene.model->num_coordinates(), 15 * 7 + 3 * 11);
  EXPECT_LE(AsmtResidualAtPlacement(text).cwiseAbs().maxCoeff(), 1e-14);
  Eigen::VectorXd q = scene.model->initial_positions();
  AssemblySummary summary;
  ASSERT_EQ(assemble(*scene.model, 0.0, {}, q, &summary), SolveStatus::kSuccess) << summary.message;
  EXPECT_EQ(summary.rank.rank, scene.model->num_equations());  // no row redundant
  EXPECT_EQ(summary.rank.dof, 47);
  EXPECT_LE(summary.moved, 1e-13);
  // the offsets, the angle and the distance are read, each with its sign: moved by 0.1, its row is off by what
  // OndselSolver's definition gives
  const std::pair<std::string, double> moved[] = {
      {"offset\n\t\t\t\t\t0.3\n", 0.1},                                       // planar: z_I·(P_J − P_I) − offset
      {"offset\n\t\t\t\t\t-0.2\n", 0.1},                                      // point in plane
      {"theIzJz\n\t\t\t\t\t0.7\n", std::cos(0.7) - std::cos(0.8)},            // z_I·z_J − cos θ
      {"distanceIJ\n\t\t\t\t\t1.5\n", (1.5 * 1.5 - 1.6 * 1.6) / (2 * 1.6)}};  // (|d|² − L²)/2L
  for (const auto& [field, expected] : moved) {
    SCOPED_TRACE(field);
    const std::size_t at = field.rfind('\t') + 1;
    const double value = std::stod(field.substr(at));
    const std::string changed = field.substr(0, at) + shortest(value + (value < 0 ? -0.1 : 0.1)) + "\n";
    ASSERT_NE(text.find(field), std::string::npos);
    const Eigen::VectorXd phi = AsmtResidualAtPlacement(test::replace_first(text, field, changed));
    EXPECT_NEAR(phi.cwiseAbs().maxCoeff(), std::abs(expected), 1e-12);
  }
}

// tests/data/asmt/compound_joints.asmt: OndselSolver's compound joints, each on a ground marker at a placement that
// holds it: x² + y² = distanceIJ² of J's origin in I's frame (CylSph; 1 freedom removed), with z axes parallel
// (RevCyl; 3) and J's origin in I's x-y plane (RevRev; 4); a constant-velocity joint (origins together,
// x_I·y_J + y_I·x_J = 0; 4): 5 + 3 + 2 + 2 freedoms left.
TEST(AsmtImport, CompoundJointsHoldAtTheirPlacementAndLeaveTheirFreedoms) {
  const std::string text = test::file_text(AsmtOwn("compound_joints.asmt"));
  const Scene scene = parse_scene(import_asmt(text, "compound.asmt").yaml, "compound.asmt");
  // 4 parts; natural points on the parts: CylSph J's origin, RevCyl's, RevRev's and the CV joint's J origin, x and
  // y tips (10 points, each pinned by 3 rows); rows 1 + 3 + 4 + 4; 4 normalisations
  EXPECT_EQ(scene.model->num_coordinates(), 4 * 7 + 10 * 3);
  EXPECT_EQ(scene.model->num_equations(), 4 + 10 * 3 + 1 + 3 + 4 + 4);
  EXPECT_LE(AsmtResidualAtPlacement(text).cwiseAbs().maxCoeff(), 1e-14);
  Eigen::VectorXd q = scene.model->initial_positions();
  AssemblySummary summary;
  ASSERT_EQ(assemble(*scene.model, 0.0, {}, q, &summary), SolveStatus::kSuccess) << summary.message;
  EXPECT_EQ(summary.rank.rank, scene.model->num_equations());
  EXPECT_EQ(summary.rank.dof, 12);
  // the first distanceIJ (CylSph's) made 1.1: its row (x² + y² − L²)/2L
  const std::string field = "distanceIJ\n\t\t\t\t\t1.0\n";
  const Eigen::VectorXd phi = AsmtResidualAtPlacement(test::replace_first(text, field, "distanceIJ\n\t\t\t\t\t1.1\n"));
  EXPECT_NEAR(phi.cwiseAbs().maxCoeff(), (1.1 * 1.1 - 1.0) / 2.2, 1e-12);
}

// tests/data/asmt/cv_shafts.asmt: shafts on revolutes 30° apart joined by a constant-velocity joint; the first
// turned at 1 rad/s, x_I·y_J + y_I·x_J = (1 − cos β) sin(θ1 + θ2) = 0 turns the second by −t about its own axis.
TEST(AsmtImport, ConstantVelocityJointTurnsTheSecondShaftAtTheSameRate) {
  const AsmtRun r = AsmtSweep(AsmtOwn("cv_shafts.asmt"));
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 25u);
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitY()).toRotationMatrix();
  double worst = 0.0;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    const Eigen::Matrix3d expected = tilt * Eigen::AngleAxisd(-t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    worst =
        std::max(worst, (AsmtBodyRotation(*r.scene.model, r.trace.q[k], "Shaft2") - expected).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, 1e-10);
}

// Names phiq or YAML would read otherwise become names of their own: `#` and `-` as `_`, a leading digit prefixed,
// YAML's null and booleans and phiq's `t` suffixed, a name taken twice numbered.
TEST(AsmtImport, NamesBecomePhiqNames) {
  std::string text = test::file_text(AsmtOwn("slider_crank.asmt"));
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"CrankPin", "Yes"},
                                 {"RodPin", "2nd_rod_a"},
                                 {"Crank", "null"},
                                 {"Rod", "2nd#rod-a"},
                                 {"Slider", "t"}})
    for (std::size_t at = 0; (at = text.find(from, at)) != std::string::npos; at += to.size())
      text.replace(at, from.size(), to);
  const Scene scene = parse_scene(import_asmt(text, "names.asmt").yaml, "names.asmt");
  EXPECT_EQ(scene.model->body_names(), (std::vector<std::string>{"null_", "n_2nd_rod_a", "t_"}));
  EXPECT_GE(scene.model->coordinate_index("t__x"), 0);
}

// The one-line message of an .asmt text (empty when it converts and loads).
std::string AsmtError(const std::string& text) {
  try {
    const AsmtImport imported = import_asmt(text, "bad.asmt");
    (void)parse_scene(imported.yaml, "bad.asmt");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(AsmtImport, BadInputIsOneLineNamingFileAndLine) {
  const std::string good = test::file_text(AsmtOwn("slider_crank.asmt"));
  ASSERT_EQ(AsmtError(good), "");
  // truncated inside the joints: the joint's MarkerJ is missing
  const std::size_t cut = good.find("MarkerJ", good.find("TranslationalJoint"));
  const std::string truncated_error = AsmtError(good.substr(0, cut));
  EXPECT_EQ(truncated_error.rfind("bad.asmt:", 0), 0u) << truncated_error;
  EXPECT_NE(truncated_error.find("has no MarkerJ"), std::string::npos) << truncated_error;
  EXPECT_NE(truncated_error.find("truncated"), std::string::npos) << truncated_error;
  // truncated before the simulation settings
  const std::string no_time = AsmtError(good.substr(0, good.find("\tSimulationParameters")));
  EXPECT_NE(no_time.find("has no SimulationParameters"), std::string::npos) << no_time;
  // an unknown joint type, named with its line
  const std::string wobble = test::replace_first(good, "SphericalJoint", "WobbleJoint");
  const int wobble_line =
      1 + static_cast<int>(std::count(good.begin(), good.begin() + good.find("SphericalJoint"), '\n'));
  EXPECT_EQ(AsmtError(wobble).rfind("bad.asmt:" + std::to_string(wobble_line) + ": joint type 'WobbleJoint'", 0), 0u)
      << AsmtError(wobble);
  // a marker on a part that does not exist, named at its MarkerI line
  const std::string ghost = test::replace_first(good, "/SliderCrank/Crank/A", "/SliderCrank/Ghost/A");
  const int ghost_line =
      1 + static_cast<int>(std::count(good.begin(), good.begin() + good.find("/SliderCrank/Crank/A"), '\n'));
  EXPECT_EQ(AsmtError(ghost),
            "bad.asmt:" + std::to_string(ghost_line) + ": marker '/SliderCrank/Ghost/A' is on an unknown part 'Ghost'");
  // a motion's expression phiq cannot parse, named at its line
  const std::string unclosed = test::replace_first(good, "2.0d*pi*time", "2.0d*pi*(time");
  const int unclosed_line = 1 + static_cast<int>(std::count(good.begin(), good.begin() + good.find("2.0d*pi"), '\n'));
  EXPECT_EQ(AsmtError(unclosed).rfind("bad.asmt:" + std::to_string(unclosed_line) + ": the motion's expression", 0), 0u)
      << AsmtError(unclosed);
  for (const std::string& e : {truncated_error, no_time, AsmtError(wobble), AsmtError(ghost), AsmtError(unclosed)})
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

// Every prefix of a file, cut at each line and inside it: refused by the reader with one line naming the file and a
// line, or converted to a scene that loads; never another exception, never a crash.
TEST(AsmtImport, EveryTruncationIsRefusedInOneLineOrLoads) {
  for (const char* file : {"slider_crank.asmt", "rack_pinion_driven.asmt", "compound_joints.asmt"}) {
    SCOPED_TRACE(file);
    const std::string text = test::file_text(AsmtOwn(file));
    int refused = 0;
    for (std::size_t cut = 0; cut < text.size(); cut = text.find('\n', cut + 1)) {
      for (const std::size_t at : {cut, std::min(cut + 3, text.size())}) {
        AsmtImport imported;
        try {
          imported = import_asmt(text.substr(0, at), "bad.asmt");
        } catch (const SceneError& e) {
          ++refused;
          EXPECT_EQ(std::string(e.what()).rfind("bad.asmt:", 0), 0u) << e.what();
          EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
          continue;
        }
        EXPECT_NO_THROW((void)parse_scene(imported.yaml, "bad.asmt")) << "cut at " << at;
      }
    }
    EXPECT_GT(refused, 100);
  }
}

}  // namespace

namespace test {

// With `--rates --forces` (the slider-crank: its parts have mass), the direct run and the converted scene's write the
// velocities, accelerations, the motor's effort and the joints' reactions, the same bytes; without, positions alone.
TEST_F(Cli, AsmtRunsDirectlyAndThroughConvertToTheSameBytes) {
  for (const std::string& model : {AsmtOwn("slider_crank.asmt"), AsmtOwn("rack_pinion_driven.asmt")}) {
    SCOPED_TRACE(model);
    const bool outputs = model.find("slider") != std::string::npos;
    const std::string flags = outputs ? " --rates --forces" : "";
    const Result direct = run("run " + model + flags + " -o " + (dir_ / "direct.csv").string());
    ASSERT_EQ(direct.code, 0) << direct.err;
    const Result convert = run("convert " + model + flags + " -o " + (dir_ / "scene.yaml").string());
    ASSERT_EQ(convert.code, 0) << convert.err;
    const Result via = run("run " + (dir_ / "scene.yaml").string() + " -o " + (dir_ / "via.csv").string());
    ASSERT_EQ(via.code, 0) << via.err;
    const std::string a = slurp(dir_ / "direct.csv"), b = slurp(dir_ / "via.csv");
    EXPECT_GT(a.size(), 100u);
    EXPECT_EQ(a, b);
    const std::string header = a.substr(0, a.find('\n'));
    for (const char* column : {"Crank_x.v,", "Crank_x.a,", "Motor.effort", "CrankPin.Fx,"})
      EXPECT_EQ(header.find(column) != std::string::npos, outputs) << column << " in " << header;
  }
  // the flags are for imported files: a scene's `output` says what it writes
  const Result scene = run("run " + (dir_ / "scene.yaml").string() + " --rates -o " + (dir_ / "out.csv").string());
  EXPECT_EQ(scene.code, 2);
  EXPECT_EQ(scene.err,
            "phiq: run: --rates is for .asmt, URDF, MJCF and SDF files: a scene's `output` says what it "
            "writes\n");
  // a bad file, or none: one line naming it, exit 2, nothing written
  const fs::path bad = write("bad.asmt", "OndselSolver\nAssembly\n\tName\n");
  for (const std::string& command : {"convert " + bad.string() + " -o ", "run " + bad.string() + " -o ",
                                     "run " + (dir_ / "none.asmt").string() + " -o "}) {
    SCOPED_TRACE(command);
    const Result r = run(command + (dir_ / "out.yaml").string());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(one_phiq_line(r.err));
    EXPECT_NE(r.err.find(".asmt:"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out.yaml"));
  }
}

}  // namespace test
}  // namespace phiq
