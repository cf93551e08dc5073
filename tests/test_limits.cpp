// A scene's `limits` (OutputLimit, sweep/limit_watch.cpp, scene/read_limits.cpp): the stretches of rows where a
// crank-slider's stroke and its rate leave their ranges, against the closed form row by row (first and last row,
// count, worst value); a driver's effort's, against the efforts the sweep writes; a spatial joint's angle over more
// than a turn (unwrapped); the same warnings on any thread count and when rows are not written; a robot's joint
// limits from URDF, MJCF and SDF (range, velocity, effort); a Stepper's steps, each listing the limits outside and
// warning where a stretch begins; and the bad input the reader refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <tuple>

#include "phiq/import_model.hpp"
#include "phiq/phiq.hpp"
#include "phiq/stepper.hpp"
#include "phiq/text.hpp"
#include "sensitivity_support.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// One `limit` warning read back: its limit, side, first and last row's times, rows and worst value.
struct LimitStretch {
  std::string name;
  bool above = false;
  double from = 0.0, to = 0.0, worst = 0.0;
  int rows = 0;
};

std::vector<LimitStretch> limit_stretches(const SweepSummary& sum) {
  std::vector<LimitStretch> out;
  const std::regex many(R"(^(\S+): .* is (above|below) its \S+ \S+ from t = (\S+) to t = (\S+) \((\d+) rows\), )"
                        R"(at (?:most|least) (\S+) \(t = \S+\)$)");
  const std::regex one(R"(^(\S+): .* is (above|below) its \S+ \S+ at t = (\S+), at (?:most|least) (\S+)$)");
  for (const SweepWarning& w : sum.warnings) {
    if (w.kind != "limit") continue;
    std::smatch m;
    LimitStretch s;
    if (std::regex_match(w.message, m, many)) {
      s = {m[1], m[2] == "above", std::stod(m[3]), std::stod(m[4]), std::stod(m[6]), std::stoi(m[5])};
    } else if (std::regex_match(w.message, m, one)) {
      s = {m[1], m[2] == "above", std::stod(m[3]), std::stod(m[3]), std::stod(m[4]), 1};
    } else {
      ADD_FAILURE() << "not a limit's message: " << w.message;
      continue;
    }
    EXPECT_NEAR(w.t, s.from, 1e-9 * std::max(1.0, w.t));  // (ten digits written)
    out.push_back(s);
  }
  return out;
}

// The stretches of the rows (t_k, v_k) outside [lo, hi], in order.
std::vector<LimitStretch> expected_stretches(const std::string& name, const std::vector<double>& t,
                                             const std::vector<double>& v, double lo, double hi) {
  std::vector<LimitStretch> out;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const bool above = v[k] > hi, outside = above || v[k] < lo;
    if (!outside) continue;
    const bool goes_on = k > 0 && !out.empty() && out.back().to == t[k - 1] && out.back().above == above &&
                         (above ? v[k - 1] > hi : v[k - 1] < lo);
    if (!goes_on) out.push_back({name, above, t[k], t[k], v[k], 0});
    LimitStretch& s = out.back();
    s.to = t[k], ++s.rows;
    if (above ? v[k] > s.worst : v[k] < s.worst) s.worst = v[k];
  }
  return out;
}

void expect_same_stretches(const std::vector<LimitStretch>& got, const std::vector<LimitStretch>& want,
                           double tolerance) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    SCOPED_TRACE(want[i].name + " " + std::to_string(want[i].from));
    EXPECT_EQ(got[i].name, want[i].name);
    EXPECT_EQ(got[i].above, want[i].above);
    EXPECT_NEAR(got[i].from, want[i].from, 1e-9);  // (ten digits written)
    EXPECT_NEAR(got[i].to, want[i].to, 1e-9);
    EXPECT_EQ(got[i].rows, want[i].rows);
    EXPECT_NEAR(got[i].worst, want[i].worst, tolerance * std::max(1.0, std::fabs(want[i].worst)));
  }
}

// One stretch as read back: its side, first and last row's times, rows and worst value.
void expect_stretch(const LimitStretch& s, bool above, double from, double to, int rows, double worst) {
  EXPECT_EQ(s.above, above);
  EXPECT_NEAR(s.from, from, 1e-9);
  EXPECT_NEAR(s.to, to, 1e-9);
  EXPECT_EQ(s.rows, rows);
  EXPECT_NEAR(s.worst, worst, 1e-9);
}

// The warnings a scene's sweep gives, with `threads` threads and every `every` rows written.
SweepSummary limit_sweep(const Scene& s, int threads, Index every, std::vector<std::vector<double>>* efforts = nullptr,
                         std::vector<double>* times = nullptr) {
  SweepOptions o = s.sweep;
  o.threads = threads, o.every = every, o.chunk_steps = 7;
  Workspace ws(*s.model);
  SweepSummary sum;
  EXPECT_EQ(run_sweep(
                *s.model, o, ws,
                [&](const StepView& v) {
                  if (efforts && v.efforts) efforts->emplace_back(v.efforts, v.efforts + 1);
                  if (times) times->push_back(v.t);
                  return true;
                },
                &sum),
            SolveStatus::kSuccess);
  return sum;
}

const std::string kLimitedCrankSlider = test::crank_slider_scene(
    "",
    "parts:\n  rod: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 1.2, inertia: 0.1}\n"
    "loads: {gravity: [0, -9.81], forces: [{part: rod, at: [1, 0], force: [-20, 0]}]}\n"
    "time: {start: 0, end: pi, steps: 90}\n"
    "output: {velocities: true, accelerations: true, efforts: all}\n"
    "limits:\n"
    "  - {name: stroke, of: xB, range: [0.75, 1.25], rate: [-0.5, 0.5]}\n"
    "  - {effort: motor, range: [-5, 5]}\n");

TEST(Limits, ACrankSlidersStrokeAndItsRateLeaveTheirRangesWhereTheClosedFormSays) {
  // xB = L2 cos θ + √(L3² − L2² sin² θ), θ = 2t; ẋB = −2 L2 sin θ (1 + L2 cos θ / √(L3² − L2² sin² θ))
  const Scene s = parse_scene(kLimitedCrankSlider, "limited.yaml");
  std::vector<double> t, x, xd;
  for (Index k = 0; k <= 90; ++k) {
    const double tk = s.sweep.time_of(k), th = 2 * tk, r = std::sqrt(1.0 - 0.09 * std::sin(th) * std::sin(th));
    t.push_back(tk), x.push_back(0.3 * std::cos(th) + r),
        xd.push_back(-0.6 * std::sin(th) * (1 + 0.3 * std::cos(th) / r));
  }
  std::vector<std::vector<double>> efforts;
  std::vector<double> times;
  const SweepSummary sum = limit_sweep(s, 1, 1, &efforts, &times);
  std::vector<LimitStretch> got = limit_stretches(sum), stroke, rate, effort;
  for (const LimitStretch& g : got) (g.name == "motor" ? effort : stroke).push_back(g);
  // the stroke's value and rate stretches interleave in time: split them by their worst values' size
  for (auto it = stroke.begin(); it != stroke.end();)
    if (std::fabs(it->worst) < 0.7)
      rate.push_back(*it), it = stroke.erase(it);
    else
      ++it;
  expect_same_stretches(stroke, expected_stretches("stroke", t, x, 0.75, 1.25), 1e-9);
  expect_same_stretches(rate, expected_stretches("stroke", t, xd, -0.5, 0.5), 1e-9);
  EXPECT_EQ(stroke.size(), 3u);  // above at the start and the end, below around θ = π
  EXPECT_EQ(rate.size(), 2u);
  std::vector<double> tau;
  for (const auto& e : efforts) tau.push_back(e[0]);
  expect_same_stretches(effort, expected_stretches("motor", times, tau, -5, 5), 1e-9);
  EXPECT_EQ(effort.size(), 2u);
  // the same warnings on two threads (parallel chunks of 7 rows), and with every third row written (the stroke's
  // checked at every row; an effort at the written rows only, where it is computed)
  const SweepSummary two = limit_sweep(s, 2, 1);
  ASSERT_EQ(two.warnings.size(), sum.warnings.size());
  for (std::size_t i = 0; i < sum.warnings.size(); ++i) EXPECT_EQ(two.warnings[i].message, sum.warnings[i].message);
  efforts.clear(), times.clear();
  const SweepSummary thirds = limit_sweep(s, 2, 3, &efforts, &times);
  got = limit_stretches(thirds);
  std::vector<LimitStretch> every_row, written;
  for (const LimitStretch& g : got) (g.name == "motor" ? written : every_row).push_back(g);
  EXPECT_EQ(every_row.size(), 5u);
  tau.clear();
  for (const auto& e : efforts) tau.push_back(e[0]);
  expect_same_stretches(written, expected_stretches("motor", times, tau, -5, 5), 1e-9);
}

TEST(Limits, AStepperSaysEachStretchAtItsFirstStepAndListsTheLimitsOutsideAtEvery) {
  // the crank-slider's limits stepped over the sweep's grid: each step lists the limits outside there (closed forms
  // of the stroke and its rate, the effort the step delivers), and warns where a stretch begins, where the sweep's
  // stretches begin
  const Scene s = parse_scene(kLimitedCrankSlider, "limited.yaml");
  StepperOptions o;
  static_cast<SolverSettings&>(o) = s.sweep;
  o.velocities = o.accelerations = true;
  o.efforts = s.sweep.efforts, o.limits = s.sweep.limits;
  ASSERT_EQ(o.limits.size(), 3u);  // stroke, its rate, the motor's effort
  Stepper stepper(*s.model, o);
  std::vector<double> begun;
  std::size_t outside = 0;
  for (Index k = 0; k <= 90; ++k) {
    const double tk = s.sweep.time_of(k), th = 2 * tk, r = std::sqrt(1.0 - 0.09 * std::sin(th) * std::sin(th));
    const double x = 0.3 * std::cos(th) + r, xd = -0.6 * std::sin(th) * (1 + 0.3 * std::cos(th) / r);
    StepSummary sum;
    ASSERT_EQ(stepper.step(tk, &sum), SolveStatus::kSuccess) << sum.message;
    const double tau = stepper.efforts()[0];
    const auto listed = [&](const std::string& name) {
      return static_cast<int>(std::count(sum.limits.begin(), sum.limits.end(), name));
    };
    EXPECT_EQ(listed("stroke"), (x < 0.75 || x > 1.25) + (xd < -0.5 || xd > 0.5)) << tk;
    EXPECT_EQ(listed("motor"), tau < -5 || tau > 5 ? 1 : 0) << tk;
    outside += sum.limits.size();
    for (const SweepWarning& w : sum.warnings)
      if (w.kind == "limit") {
        EXPECT_EQ(w.t, tk);
        begun.push_back(tk);
      }
    // the same step again re-delivers the state: the same list, no warning
    StepSummary again;
    ASSERT_EQ(stepper.step(tk, &again), SolveStatus::kSuccess);
    EXPECT_EQ(again.limits, sum.limits);
    EXPECT_TRUE(again.warnings.empty());
  }
  std::vector<double> want;
  for (const LimitStretch& g : limit_stretches(limit_sweep(s, 1, 1))) want.push_back(g.from);
  std::sort(want.begin(), want.end());
  std::sort(begun.begin(), begun.end());
  ASSERT_EQ(begun.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(begun[i], want[i], 1e-9);
  EXPECT_GT(outside, 20u);
}

TEST(Limits, ASpatialJointsAngleIsLimitedOverItsTurns) {
  // the RSSR's crank turns at 1 rad/s from 0 to 10 rad: above 8 rad from the first row past 8 on, which an angle
  // taken within a turn never is
  const std::string text = test::model_file_text("spatial/rssr.yaml", "time:") +
                           "time: {start: 0, end: 10, steps: 100}\n"
                           "output: {velocities: true}\n"
                           "limits:\n"
                           "  - {joint: crank_hinge, range: [-1, 8], rate: [-0.5, 0.99]}\n";
  const Scene s = parse_scene(text, "rssr_limits.yaml");
  for (int threads : {1, 2}) {
    const std::vector<LimitStretch> got = limit_stretches(limit_sweep(s, threads, 1));
    ASSERT_EQ(got.size(), 2u);
    expect_stretch(got[0], true, 0.0, 10.0, 101, 1.0);  // the rate, 1 > 0.99 at every row
    expect_stretch(got[1], true, 8.1, 10.0, 20, 10.0);
  }
}

// A pendulum (2 kg at 0.4 m from a hinge along x at height 1, I = 0.03 about its centre) in each robot format, its
// hinge limited: URDF and SDF to [−0.5, 0.6] rad, 0.9 rad/s, 6 N·m; MJCF to [−30°, 40°] with ref = 10°, so
// [−40°, 30°] of the angle from the file's pose. Driven through θ = 0.5 t + 0.3 t², t in [0, 1] (10 steps).
TEST(Limits, ARobotsJointLimitsComeFromEachFormat) {
  const std::string urdf =
      "<robot name=\"pendulum\">\n<link name=\"base\"/>\n<link name=\"arm\">\n<inertial><origin xyz=\"0 0.4 0\"/>"
      "<mass value=\"2\"/><inertia ixx=\"0.03\" iyy=\"0.01\" izz=\"0.03\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
      "</inertial>\n</link>\n<joint name=\"hinge\" type=\"revolute\"><parent link=\"base\"/><child link=\"arm\"/>"
      "<origin xyz=\"0 0 1\"/><axis xyz=\"1 0 0\"/><limit lower=\"-0.5\" upper=\"0.6\" effort=\"6\" "
      "velocity=\"0.9\"/></joint>\n</robot>\n";
  const std::string mjcf =
      "<mujoco model=\"pendulum\">\n<worldbody>\n<body name=\"arm\" pos=\"0 0 1\"><joint name=\"hinge\" "
      "type=\"hinge\" axis=\"1 0 0\" range=\"-30 40\" ref=\"10\"/><inertial pos=\"0 0.4 0\" mass=\"2\" "
      "diaginertia=\"0.03 0.01 0.03\"/></body>\n</worldbody>\n</mujoco>\n";
  const std::string sdf =
      "<?xml version=\"1.0\"?>\n<sdf version=\"1.9\">\n<world name=\"w\">\n<model name=\"pendulum\">\n<link "
      "name=\"arm\"><pose>0 0 1 0 0 0</pose><inertial><pose>0 0.4 0 0 0 0</pose><mass>2</mass><inertia><ixx>0.03"
      "</ixx><iyy>0.01</iyy><izz>0.03</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>\n"
      "<joint name=\"hinge\" type=\"revolute\"><parent>world</parent><child>arm</child><axis><xyz>1 0 0</xyz>"
      "<limit><lower>-0.5</lower><upper>0.6</upper><effort>6</effort><velocity>0.9</velocity></limit></axis>"
      "</joint>\n</model>\n</world>\n</sdf>\n";
  ImportOptions o;
  o.drives = {{"hinge", "0.5*t + 0.3*t^2"}};
  o.t_end = 1, o.steps = 10, o.forces = true, o.rates = true;
  for (const std::string format : {"urdf", "mjcf", "sdf"}) {
    SCOPED_TRACE(format);
    const ModelImport m = format == "urdf"   ? import_urdf(urdf, "pendulum.urdf", o)
                          : format == "mjcf" ? import_mjcf(mjcf, "pendulum.xml", o)
                                             : import_sdf(sdf, "pendulum.sdf", o);
    const Scene s = parse_scene(m.yaml, "pendulum.yaml");
    const double g = format == "sdf" ? 9.8 : 9.81, hi = format == "mjcf" ? M_PI / 6 : 0.6;
    std::vector<double> t, angle, rate, effort;
    for (int k = 0; k <= 10; ++k) {
      const double tk = 0.1 * k, th = 0.5 * tk + 0.3 * tk * tk;
      // τ = I_O θ̈ + m g l cos θ (the arm along y, gravity along −z)
      t.push_back(tk), angle.push_back(th), rate.push_back(0.5 + 0.6 * tk);
      effort.push_back((0.03 + 2 * 0.4 * 0.4) * 0.6 + 2 * g * 0.4 * std::cos(th));
    }
    std::vector<LimitStretch> got = limit_stretches(limit_sweep(s, 1, 1)), value, speed, torque;
    for (const LimitStretch& x : got)
      (x.name == "hinge_effort" ? torque : std::fabs(x.worst - 1.1) < 1e-6 ? speed : value).push_back(x);
    expect_same_stretches(value, expected_stretches("hinge", t, angle, format == "mjcf" ? -2 * M_PI / 9 : -0.5, hi),
                          1e-9);
    EXPECT_EQ(value.size(), 1u);
    if (format == "mjcf") {  // (MJCF states no speed of a joint; its actuators an effort)
      // a range limits its joint with limited="true", or "auto" (the default) under the compiler's autolimits
      for (const auto& [limited, compiler, limits] : {std::tuple{"", "", true},
                                                      {"limited=\"true\" ", "<compiler autolimits=\"false\"/>", true},
                                                      {"limited=\"false\" ", "", false},
                                                      {"", "<compiler autolimits=\"false\"/>", false},
                                                      {"limited=\"auto\" ", "<compiler autolimits=\"true\"/>", true}}) {
        std::string text = test::replace_first(mjcf, "range=", std::string(limited) + "range=");
        text = test::replace_first(text, "<worldbody>", std::string(compiler) + "<worldbody>");
        SCOPED_TRACE(text);
        EXPECT_EQ(import_mjcf(text, "pendulum.xml", o).yaml.find("{joint: hinge, range:") != std::string::npos, limits);
      }
      // a motor on the hinge with gear 2 and forcerange ±3: ±6 N·m at the joint, its driver's effort's limit; the
      // joint's own actuatorfrcrange, bounding every actuator on it, stands over it
      const std::string motor = test::replace_first(
          mjcf, "</worldbody>",
          "</worldbody>\n<actuator><motor joint=\"hinge\" gear=\"2\" forcerange=\"-3 3\"/></actuator>");
      const ModelImport actuated = import_mjcf(motor, "pendulum.xml", o);
      EXPECT_NE(actuated.yaml.find("- {name: hinge_effort, effort: drive_hinge, range: [-6, 6]}"), std::string::npos)
          << actuated.yaml;
      std::vector<LimitStretch> rated;
      for (const LimitStretch& x : limit_stretches(limit_sweep(parse_scene(actuated.yaml, "motor.yaml"), 1, 1)))
        if (x.name == "hinge_effort") rated.push_back(x);
      expect_same_stretches(rated, expected_stretches("hinge_effort", t, effort, -6, 6), 1e-9);
      EXPECT_EQ(rated.size(), 1u);
      EXPECT_NE(import_mjcf(test::replace_first(motor, "ref=", "actuatorfrcrange=\"-5 7\" ref="), "pendulum.xml", o)
                    .yaml.find("- {name: hinge_effort, effort: drive_hinge, range: [-5, 7]}"),
                std::string::npos);
      continue;
    }
    expect_same_stretches(speed, expected_stretches("hinge", t, rate, -0.9, 0.9), 1e-9);
    expect_same_stretches(torque, expected_stretches("hinge_effort", t, effort, -6, 6), 1e-9);
    EXPECT_EQ(speed.size(), 1u);
    EXPECT_EQ(torque.size(), 1u);
  }
}

TEST(Limits, APointsCoordinateAndItsRateAreLimitedWhereTheClosedFormSays) {
  // the crank-slider's crank tip A, y = 0.3 sin 2t, ẏ = 0.6 cos 2t (a natural point); the RSSR's crank tip, a body
  // point in space, x = a cos t (a = 0.2, the crank at 1 rad/s)
  std::string text = kLimitedCrankSlider;
  text.erase(text.find("limits:"));
  const Scene planar =
      parse_scene(text + "limits: [{point: A, axis: y, range: [-0.2, 0.2], rate: [-0.5, 0.5]}]\n", "point_limits.yaml");
  std::vector<double> t, y, yd;
  for (Index k = 0; k <= 90; ++k) {
    const double tk = planar.sweep.time_of(k);
    t.push_back(tk), y.push_back(0.3 * std::sin(2 * tk)), yd.push_back(0.6 * std::cos(2 * tk));
  }
  std::vector<LimitStretch> value, rate;
  for (const LimitStretch& g : limit_stretches(limit_sweep(planar, 2, 1)))
    (std::fabs(std::fabs(g.worst) - 0.6) < 1e-6 ? rate : value).push_back(g);
  expect_same_stretches(value, expected_stretches("A.y", t, y, -0.2, 0.2), 1e-9);
  expect_same_stretches(rate, expected_stretches("A.y", t, yd, -0.5, 0.5), 1e-9);
  EXPECT_EQ(value.size(), 2u);
  const Scene spatial = parse_scene(
      test::model_file_text("spatial/rssr.yaml", "time:") +
          "time: {start: 0, end: 6, steps: 60}\n"
          "limits: [{name: tip, point: {name: T, body: crank, at: [a, 0, 0]}, axis: x, range: [-0.1, 0.1]}]\n",
      "rssr_point.yaml");
  std::vector<double> ts, x;
  for (Index k = 0; k <= 60; ++k) ts.push_back(0.1 * static_cast<double>(k)), x.push_back(0.2 * std::cos(0.1 * k));
  const std::vector<LimitStretch> tip = limit_stretches(limit_sweep(spatial, 1, 1));
  expect_same_stretches(tip, expected_stretches("tip", ts, x, -0.1, 0.1), 1e-9);
  EXPECT_EQ(tip.size(), 3u);
}

TEST(Limits, AStretchOpenWhenTheSweepFailsIsSaidToItsLastRow) {
  // models/hard/crank_rocker_rocker_driven.yaml, driven past its dead point, fails at step 44 (t = 0.44): the rocker
  // angle ψ = 2.2 + t is above 2.505 from t = 0.31 on, a stretch still open at the last row delivered, t = 0.43
  const Scene s = parse_scene(test::model_file_text("hard/crank_rocker_rocker_driven.yaml") +
                                  "limits: [{name: swing, of: psi, range: [2, 2.505]}]\n",
                              "dead_point.yaml");
  Workspace ws(*s.model);
  SweepSummary sum;
  EXPECT_NE(run_sweep(
                *s.model, s.sweep, ws, [](const StepView&) { return true; }, &sum),
            SolveStatus::kSuccess);
  ASSERT_EQ(sum.failed_step, 44);
  const std::vector<LimitStretch> got = limit_stretches(sum);
  ASSERT_EQ(got.size(), 1u);
  expect_stretch(got[0], true, 0.31, 0.43, 13, 2.63);
}

TEST(Limits, BadLimitsAreRefusedInOneLineNamingTheField) {
  auto error = [](const std::string& limits) {
    std::string text = kLimitedCrankSlider;
    text.erase(text.find("limits:"));
    return test::scene_error(text + "limits:\n" + limits);
  };
  EXPECT_HAS(error("  - {of: xB, range: [1.25, 0.75]}\n"), "limits[0].range: must be [lo, hi] with lo < hi");
  EXPECT_HAS(error("  - {of: xB}\n"), "limits[0]: a limit has a `range: [lo, hi]`, a `rate: [lo, hi]` or both");
  EXPECT_HAS(error("  - {of: xB, effort: motor, range: [0, 1]}\n"), "limits[0]: a limit bounds one of");
  EXPECT_HAS(error("  - {effort: motor, rate: [0, 1]}\n"), "limits[0].rate: an effort's limit is its `range`");
  EXPECT_HAS(error("  - {effort: crank, range: [0, 1]}\n"),
             "limits[0].effort: driver 'crank''s effort is not computed: list it in `output: efforts`");
  EXPECT_HAS(error("  - {effort: pump, range: [0, 1]}\n"), "limits[0].effort: unknown driver 'pump'");
  EXPECT_HAS(error("  - {joint: crank, range: [0, 1]}\n"), "limits[0].joint: a joint's limit is a spatial joint's");
  EXPECT_HAS(error("  - {of: der(xB), range: [0, 1]}\n"), "limits[0].of:");
  EXPECT_HAS(error("  - {of: xB, range: [0, 2]}\n  - {of: xB, range: [0, 3]}\n"),
             "limits[1]: a second limit named 'xB'");
  EXPECT_HAS(error("  - {point: A, axis: z, range: [0, 1]}\n"), "limits[0].axis: must be x, y, not 'z'");
  EXPECT_HAS(error("  - {point: A, range: [0, 1]}\n"), "limits[0]: `axis: x, y or z` goes with `point`, and only");
  EXPECT_HAS(error("  - {point: Q, axis: x, range: [0, 1]}\n"), "limits[0].point: unknown point 'Q'");
}

}  // namespace
}  // namespace phiq
