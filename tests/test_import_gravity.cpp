// Gravity in imported models (phiq/import_model.hpp, ImportOptions::gravity): a one-link pendulum in URDF, MJCF and
// SDF driven at θ = 0.5 t + 0.3 t² about a horizontal hinge, whose motor torque is the closed form
// τ = I_O θ̈ − m l g · (0, −sin θ, cos θ) with the gravity each format states (MJCF's <option gravity>, SDF's world
// <gravity>) or its default (URDF: none stated, 0 0 −9.81; MuJoCo's 0 0 −9.81; SDFormat's 0 0 −9.8), and with
// --gravity overriding any of them (an .asmt file's ConstantGravity too); `phiq run` and `phiq convert` then
// `phiq run` give the same bytes, and a bad --gravity is one line, exit 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include "cli_test_support.hpp"
#include "import_test_support.hpp"
#include "phiq/import_asmt.hpp"
#include "phiq/import_model.hpp"
#include "phiq/phiq.hpp"

namespace phiq {
namespace {

// The pendulum: its hinge at (0, 0, 1) about x, its link along y with the centre of mass at l = 0.4, m = 2, the
// inertia about the centre diag(0.03, 0.01, 0.03): I_O = 0.03 + m l² about the hinge.
constexpr double kGravityMass = 2.0, kGravityArm = 0.4, kGravityIo = 0.03 + 2.0 * 0.4 * 0.4;
constexpr const char* kGravityLaw = "0.5*t + 0.3*t^2";

std::string gravity_urdf() {
  return "<robot name=\"pendulum\">\n<link name=\"base\"/>\n<link name=\"arm\">\n<inertial><origin xyz=\"0 0.4 0\"/>"
         "<mass value=\"2\"/><inertia ixx=\"0.03\" iyy=\"0.01\" izz=\"0.03\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
         "</inertial>\n</link>\n<joint name=\"hinge\" type=\"continuous\"><parent link=\"base\"/><child link=\"arm\"/>"
         "<origin xyz=\"0 0 1\"/><axis xyz=\"1 0 0\"/></joint>\n</robot>\n";
}

// `option`: the <option> element (or none).
std::string gravity_mjcf(const std::string& option) {
  return "<mujoco model=\"pendulum\">\n" + option +
         "\n<worldbody>\n<body name=\"arm\" pos=\"0 0 1\"><joint name=\"hinge\" type=\"hinge\" axis=\"1 0 0\"/>"
         "<inertial pos=\"0 0.4 0\" mass=\"2\" diaginertia=\"0.03 0.01 0.03\"/></body>\n</worldbody>\n</mujoco>\n";
}

// `world_gravity`: the world's <gravity> element ("" none); no world at all when `in_world` is false.
std::string gravity_sdf(bool in_world, const std::string& world_gravity) {
  const std::string model =
      "<model name=\"pendulum\">\n<link name=\"arm\"><pose>0 0 1 0 0 0</pose><inertial><pose>0 0.4 0 0 0 0</pose>"
      "<mass>2</mass><inertia><ixx>0.03</ixx><iyy>0.01</iyy><izz>0.03</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz>"
      "</inertia></inertial></link>\n<joint name=\"hinge\" type=\"revolute\"><parent>world</parent><child>arm</child>"
      "<axis><xyz>1 0 0</xyz></axis></joint>\n</model>\n";
  if (!in_world) return "<?xml version=\"1.0\"?>\n<sdf version=\"1.9\">\n" + model + "</sdf>\n";
  return "<?xml version=\"1.0\"?>\n<sdf version=\"1.9\">\n<world name=\"w\">\n" + world_gravity + "\n" + model +
         "</world>\n</sdf>\n";
}

ImportOptions gravity_options(std::optional<std::array<double, 3>> gravity = std::nullopt) {
  ImportOptions o;
  o.drives = {{"hinge", kGravityLaw}};
  o.t_end = 1, o.steps = 10, o.forces = true, o.gravity = gravity;
  return o;
}

ModelImport gravity_import(const std::string& format, const std::string& text, const ImportOptions& o) {
  if (format == "urdf") return import_urdf(text, "pendulum.urdf", o);
  if (format == "sdf") return import_sdf(text, "pendulum.sdf", o);
  return import_mjcf(text, "pendulum.xml", o);
}

// The largest difference between the one driver's effort at each row of the scene's sweep and exact(t); and the
// largest |exact| (so that a test of zeros would show).
std::pair<double, double> gravity_effort_error(const std::string& yaml, const std::function<double(double)>& exact) {
  const Scene s = parse_scene(yaml, "pendulum");
  Workspace ws(*s.model);
  double worst = 0.0, largest = 0.0;
  int rows = 0;
  EXPECT_EQ(run_sweep(
                *s.model, s.sweep, ws,
                [&](const StepView& v) {
                  worst = std::max(worst, std::abs(v.efforts[0] - exact(v.t)));
                  largest = std::max(largest, std::abs(exact(v.t)));
                  ++rows;
                  return true;
                },
                nullptr),
            SolveStatus::kSuccess);
  EXPECT_GT(rows, 10);
  return {worst, largest};
}

// The same for the pendulum with gravity g: τ = I_O θ̈ − m l g · (0, −sin θ, cos θ).
std::pair<double, double> gravity_torque_error(const ModelImport& imported, const Eigen::Vector3d& g) {
  return gravity_effort_error(imported.yaml, [&](double t) {
    const double theta = 0.5 * t + 0.3 * t * t, alpha = 0.6;
    return kGravityIo * alpha -
           kGravityMass * kGravityArm * g.dot(Eigen::Vector3d(0, -std::sin(theta), std::cos(theta)));
  });
}

struct GravityCase {
  std::string format, text;
  Eigen::Vector3d gravity;  // what the file states, or its format's default
  std::string from;         // what ModelImport::gravity says of where it comes from
};

TEST(ImportGravity, MotorTorqueOfAPendulumIsTheClosedFormWithEachFormatsGravity) {
  const std::vector<GravityCase> cases = {
      {"urdf", gravity_urdf(), {0, 0, -9.81}, "URDF states no gravity"},
      {"mjcf", gravity_mjcf(""), {0, 0, -9.81}, "MuJoCo's default"},
      {"mjcf",
       gravity_mjcf("<option timestep=\"0.002\" gravity=\"0 0.5 -3.7\"/>"),
       {0, 0.5, -3.7},
       "<option gravity> at pendulum.xml:2"},
      {"mjcf",
       gravity_mjcf("<option gravity=\"0 0 -3.7\"><flag gravity=\"disable\"/></option>"),
       {0, 0, 0},
       "<flag gravity=\"disable\"> at pendulum.xml:2"},
      {"sdf", gravity_sdf(true, "<gravity>0.2 0 -5</gravity>"), {0.2, 0, -5}, "the world's <gravity> at"},
      {"sdf", gravity_sdf(true, ""), {0, 0, -9.8}, "SDFormat's default: the world has no <gravity>"},
      {"sdf", gravity_sdf(false, ""), {0, 0, -9.8}, "the file has no <world>: SDFormat's default"},
  };
  for (const GravityCase& c : cases) {
    SCOPED_TRACE(c.format + ": " + c.from);
    const ModelImport imported = gravity_import(c.format, c.text, gravity_options());
    EXPECT_NE(imported.gravity.find(c.from), std::string::npos) << imported.gravity;
    EXPECT_NE(imported.yaml.find("# Gravity " + imported.gravity + "\n"), std::string::npos) << imported.yaml;
    EXPECT_EQ(imported.yaml.find("loads: {gravity:") != std::string::npos, !c.gravity.isZero()) << imported.yaml;
    const auto [error, largest] = gravity_torque_error(imported, c.gravity);
    EXPECT_LT(error, 1e-9);
    EXPECT_GT(largest, 0.2);
    // --gravity overrides the file's, whatever it says (once per format)
    if (&c != &cases[0] && &c != &cases[2] && &c != &cases[4]) continue;
    const Eigen::Vector3d other(1.5, 2, -4);
    const ModelImport overridden = gravity_import(c.format, c.text, gravity_options({{1.5, 2, -4}}));
    EXPECT_NE(overridden.gravity.find("[1.5, 2, -4] m/s²: --gravity"), std::string::npos) << overridden.gravity;
    EXPECT_LT(gravity_torque_error(overridden, other).first, 1e-9);
  }
  // the option's other settings are listed as not mapped, its gravity is not
  const ModelImport mjcf = gravity_import("mjcf", cases[2].text, gravity_options());
  ASSERT_EQ(mjcf.skipped.size(), 1u);
  EXPECT_EQ(mjcf.skipped[0].rfind("pendulum.xml:2: <option>: simulation settings other than gravity", 0), 0u)
      << mjcf.skipped[0];
  EXPECT_TRUE(gravity_import("mjcf", cases[1].text, gravity_options()).skipped.empty());
  // 0,0,0 turns it off: the inertia alone
  const ModelImport off = gravity_import("urdf", gravity_urdf(), gravity_options({{0, 0, 0}}));
  EXPECT_EQ(off.yaml.find("loads:"), std::string::npos);
  EXPECT_LT(gravity_torque_error(off, Eigen::Vector3d::Zero()).first, 1e-9);
}

// The joint's spring, damper, friction and rotor come with it: MJCF's stiffness, damping, springref (in degrees,
// from the joint's ref) and armature, URDF's <dynamics damping friction> and SDF's axis <dynamics> add
// k (θ − θ0) + c θ̇ + f sign θ̇ + J θ̈ to the pendulum's motor torque; a slide's own on its travel, an MJCF slider
// pushed along its axis; a spring wound through more than a turn.
TEST(ImportGravity, JointSpringsAndDampersLoadTheMotor) {
  const std::string mjcf =
      "<mujoco model=\"pendulum\">\n<worldbody>\n<body name=\"arm\" pos=\"0 0 1\"><joint name=\"hinge\" type=\"hinge\" "
      "axis=\"1 0 0\" stiffness=\"5\" damping=\"0.5\" springref=\"40\" ref=\"10\" armature=\"0.1\"/>"
      "<inertial pos=\"0 0.4 0\" mass=\"2\" diaginertia=\"0.03 0.01 0.03\"/></body>\n</worldbody>\n</mujoco>\n";
  std::string urdf = gravity_urdf();
  urdf.replace(urdf.find("<axis xyz=\"1 0 0\"/>"), 19,
               "<axis xyz=\"1 0 0\"/><dynamics damping=\"0.5\" friction=\"0.2\"/>");
  std::string sdf = gravity_sdf(true, "");
  sdf.replace(
      sdf.find("<xyz>1 0 0</xyz>"), 16,
      "<xyz>1 0 0</xyz><dynamics><damping>0.5</damping><friction>0.2</friction>"
      "<spring_reference>0.5235987755982988</spring_reference><spring_stiffness>5</spring_stiffness></dynamics>");
  const double theta0[3] = {30 * M_PI / 180, 0.0, M_PI / 6}, k[3] = {5.0, 0.0, 5.0}, rotor[3] = {0.1, 0.0, 0.0},
               friction[3] = {0.0, 0.2, 0.2};
  int c = 0;
  for (const auto& [format, text] : {std::pair<std::string, std::string>{"mjcf", mjcf}, {"urdf", urdf}, {"sdf", sdf}}) {
    SCOPED_TRACE(format);
    const ModelImport imported = gravity_import(format, text, gravity_options());
    EXPECT_NE(imported.yaml.find("torsional_springs:"), std::string::npos) << imported.yaml;
    const Eigen::Vector3d g(0, 0, format == "sdf" ? -9.8 : -9.81);
    const auto [error, largest] = gravity_effort_error(imported.yaml, [&](double t) {
      const double theta = 0.5 * t + 0.3 * t * t, rate = 0.5 + 0.6 * t, alpha = 0.6;
      return kGravityIo * alpha -
             kGravityMass * kGravityArm * g.dot(Eigen::Vector3d(0, -std::sin(theta), std::cos(theta))) +
             k[c] * (theta - theta0[c]) + 0.5 * rate + rotor[c] * alpha + friction[c];  // (θ̇ > 0)
    });
    EXPECT_LT(error, 1e-9);
    EXPECT_GT(largest, 0.2);
    for (const char* mapped : {"armature", "friction"})
      EXPECT_EQ(std::count_if(imported.skipped.begin(), imported.skipped.end(),
                              [&](const std::string& x) { return x.find(mapped) != x.npos; }),
                0)
          << mapped;
    ++c;
  }
  // a slide: k (d − d0) + c ḋ along its axis, d its travel from the file's pose
  const std::string slider =
      "<mujoco model=\"slider\">\n<option gravity=\"0 0 0\"/>\n<worldbody>\n<body name=\"block\" pos=\"0 0 1\">"
      "<joint name=\"slide\" type=\"slide\" axis=\"0 1 0\" stiffness=\"40\" damping=\"3\" springref=\"0.2\"/>"
      "<inertial pos=\"0 0 0\" mass=\"1.5\" diaginertia=\"0.01 0.01 0.01\"/></body>\n</worldbody>\n</mujoco>\n";
  ImportOptions o;
  o.drives = {{"slide", "0.5*t + 0.3*t^2"}};
  o.t_end = 1, o.steps = 10, o.forces = true;
  const ModelImport imported = import_mjcf(slider, "slider.xml", o);
  const auto [error, largest] = gravity_effort_error(imported.yaml, [&](double t) {
    const double d = 0.5 * t + 0.3 * t * t, rate = 0.5 + 0.6 * t;
    return 1.5 * 0.6 + 40 * (d - 0.2) + 3 * rate;
  });
  EXPECT_LT(error, 1e-9);
  EXPECT_GT(largest, 5.0);
  // a hinge's spring wound through a turn and a half, k θ over every turn (as MuJoCo's q − springref counts it),
  // with a rotor and a dry friction that turns with it; no gravity
  const std::string wound =
      "<mujoco model=\"wound\">\n<compiler angle=\"radian\"/>\n<option gravity=\"0 0 0\"/>\n<worldbody>\n"
      "<body name=\"arm\"><joint name=\"hinge\" type=\"hinge\" axis=\"0 0 1\" stiffness=\"5\" armature=\"0.3\" "
      "frictionloss=\"0.7\"/><inertial pos=\"0.4 0 0\" mass=\"2\" diaginertia=\"0.01 0.03 0.03\"/></body>\n"
      "</worldbody>\n</mujoco>\n";
  o.drives = {{"hinge", "6*t - t^2"}};
  o.t_end = 2, o.steps = 40;
  const ModelImport turned = import_mjcf(wound, "wound.xml", o);
  const auto [turned_error, turned_largest] = gravity_effort_error(turned.yaml, [&](double t) {
    const double theta = 6 * t - t * t, rate = 6 - 2 * t;  // 8 rad at t = 2, turning one way throughout
    return (0.03 + 2 * 0.4 * 0.4 + 0.3) * -2.0 + 5 * theta + 0.7 * (rate > 0 ? 1 : -1);
  });
  EXPECT_LT(turned_error, 1e-9);
  EXPECT_GT(turned_largest, 39.0);
}

// tests/data/asmt/pendulum.asmt (ConstantGravity 0 0 0) with its arm's centre (mass 1) at (1, 0, 0), turned by
// θ = 0.5 t about z: --gravity g gives the motor τ = −m (c × g)_z = −(cos θ g_y − sin θ g_x), c = (cos θ, sin θ, 0).
TEST(ImportGravity, AsmtGravityIsTheFilesUnlessGiven) {
  std::string text = test::file_text(test::import_data("asmt/pendulum.asmt"));
  const std::string still = "\t\t\t\tPosition3D\n\t\t\t\t\t0.0\t0.0\t0.0\t";
  ASSERT_NE(text.find(still), std::string::npos);
  text.replace(text.find(still), still.size(), "\t\t\t\tPosition3D\n\t\t\t\t\t1.0\t0.0\t0.0\t");
  ImportOptions o;
  o.forces = true;
  const AsmtImport own = import_asmt(text, "pendulum.asmt", o);
  EXPECT_NE(own.yaml.find("# Gravity [0, 0, 0] (length unit)/s²: none"), std::string::npos) << own.yaml;
  EXPECT_EQ(own.yaml.find("loads:"), std::string::npos);
  EXPECT_LT(gravity_effort_error(own.yaml, [](double) { return 0.0; }).first, 1e-9);
  o.gravity = {{1.5, -4, 3}};
  const AsmtImport given = import_asmt(text, "pendulum.asmt", o);
  EXPECT_NE(given.yaml.find("loads: {gravity: [1.5, -4, 3]}"), std::string::npos) << given.yaml;
  const auto [error, largest] =
      gravity_effort_error(given.yaml, [](double t) { return 4 * std::cos(0.5 * t) + 1.5 * std::sin(0.5 * t); });
  EXPECT_LT(error, 1e-9);
  EXPECT_GT(largest, 3.0);
}

}  // namespace

namespace test {

// `phiq run` of each format with --forces (and --gravity) writes what `phiq convert` then `phiq run` writes, the
// gravity stated on standard error; a bad --gravity, or one on a scene, is one line and exit 2, nothing written.
TEST_F(Cli, ImportGravityRunsDirectlyAndThroughConvertToTheSameBytesAndBadValuesAreRefused) {
  const fs::path urdf = write("pendulum.urdf", gravity_urdf()), mjcf = write("pendulum.xml", gravity_mjcf(""));
  const std::string drive = " --drive 'hinge=0.5*t+0.3*t^2' --time 0 1 10 --forces";
  for (const auto& [model, gravity] :
       {std::pair{urdf, std::string()}, std::pair{mjcf, std::string(" --gravity 0,1,-2.5")}}) {
    SCOPED_TRACE(model.string() + gravity);
    const Result direct = run("run " + model.string() + drive + gravity + " -o " + (dir_ / "direct.csv").string());
    ASSERT_EQ(direct.code, 0) << direct.err;
    EXPECT_NE(direct.err.find(gravity.empty() ? "phiq: gravity [0, 0, -9.81] m/s²: URDF states no gravity"
                                              : "phiq: gravity [0, 1, -2.5] m/s²: --gravity"),
              std::string::npos)
        << direct.err;
    const Result convert = run("convert " + model.string() + drive + gravity + " -o " + (dir_ / "s.yaml").string());
    ASSERT_EQ(convert.code, 0) << convert.err;
    EXPECT_NE(slurp(dir_ / "s.yaml")
                  .find(gravity.empty() ? "loads: {gravity: [0, 0, -9.81]}" : "loads: {gravity: [0, 1, -2.5]}"),
              std::string::npos);
    const Result via = run("run " + (dir_ / "s.yaml").string() + " -o " + (dir_ / "via.csv").string());
    ASSERT_EQ(via.code, 0) << via.err;
    EXPECT_EQ(slurp(dir_ / "direct.csv"), slurp(dir_ / "via.csv"));
    EXPECT_NE(slurp(dir_ / "via.csv").find("drive_hinge.effort"), std::string::npos);
  }
  for (const std::string bad : {"1,2", "1,2,3,4", "nan,0,0"}) {
    const Result r = run("run " + urdf.string() + drive + " --gravity " + bad + " -o " + (dir_ / "bad.csv").string());
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_TRUE(one_phiq_line(r.err)) << r.err;
    EXPECT_EQ(r.err, "phiq: run: --gravity " + bad + ": not X,Y,Z (three finite numbers, m/s²; 0,0,0: none)\n");
    EXPECT_FALSE(fs::exists(dir_ / "bad.csv"));
  }
  const Result on_scene =
      run("run " + (dir_ / "s.yaml").string() + " --gravity 0,0,-1 -o " + (dir_ / "bad.csv").string());
  EXPECT_EQ(on_scene.code, 2);
  EXPECT_EQ(on_scene.err,
            "phiq: run: --gravity is for .asmt, URDF, MJCF and SDF files: a scene's `loads.gravity` says it\n");
}

}  // namespace test
}  // namespace phiq
