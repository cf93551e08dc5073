// MJCF (MuJoCo) files read as phiq scenes (phiq/import_model.hpp), tests/data/mjcf/: the four-bar closed by a
// `connect` equality, the slider-crank in degrees, a gear pair by a joint equality's polycoef, and every joint type
// with default classes. The URDF four-bar, the scene written by hand and closed forms hold the imports; `phiq
// convert` writes the text a direct read solves; what is not mapped is listed once; bad input is one line, FILE:LINE.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "cli_test_support.hpp"
#include "import_test_support.hpp"
#include "phiq/rank_analysis.hpp"

namespace phiq {
namespace {

using test::file_text, test::import_data, test::import_sweep;

ImportOptions MjcfDrive(const std::string& joint, const std::string& law, double end, int steps) {
  ImportOptions o;
  o.drives = {{joint, law}};
  o.t_end = end, o.steps = steps;
  return o;
}

std::string MjcfError(const std::string& text) {
  try {
    (void)import_mjcf(text, "bad.xml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

int MjcfLineOf(const std::string& text, const std::string& what) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find(what)), '\n'));
}

TEST(MjcfImport, FourBarClosedByConnectEqualsTheURDFAndTheSceneWrittenByHand) {
  const std::string path = import_data("mjcf/fourbar.xml");
  const ModelImport imported = import_mjcf(file_text(path), path, MjcfDrive("crank_joint", "2*pi*t", 1, 40));
  EXPECT_EQ(imported.bodies, 3);
  EXPECT_EQ(imported.joints, 4);
  EXPECT_EQ(imported.loops, 1);
  const test::ImportRun mjcf = import_sweep(imported.yaml, path);
  ASSERT_EQ(mjcf.status, SolveStatus::kSuccess) << mjcf.message;
  const test::ImportRun hand = import_sweep(test::kFourbarByHand, "fourbar_by_hand.yaml");
  ASSERT_EQ(hand.status, SolveStatus::kSuccess) << hand.message;
  const std::string urdf_path = import_data("urdf/fourbar.urdf");
  ImportOptions o = MjcfDrive("crank_joint", "2*pi*t", 1, 40);
  const test::ImportRun urdf = import_sweep(import_urdf(file_text(urdf_path), urdf_path, o).yaml, urdf_path);
  ASSERT_EQ(urdf.status, SolveStatus::kSuccess) << urdf.message;
  ASSERT_EQ(mjcf.trace.q.size(), 41u);
  for (std::size_t k = 0; k < mjcf.trace.q.size(); ++k) {
    const double t = mjcf.trace.t[k];
    const Eigen::Vector3d tip = test::import_point(mjcf.model(), mjcf.trace.q[k], "coupler", {0.5, 0, 0});
    EXPECT_LT((tip - test::fourbar_rocker_tip(M_PI / 3 + 2 * M_PI * t)).norm(), 1e-10) << "t = " << t;
    EXPECT_LT((tip - test::import_point(urdf.model(), urdf.trace.q[k], "coupler_tip")).norm(), 1e-12) << t;
    for (const char* body : {"crank", "coupler", "rocker"}) {
      EXPECT_LT((test::import_point(mjcf.model(), mjcf.trace.q[k], body) -
                 test::import_point(hand.model(), hand.trace.q[k], body))
                    .norm(),
                1e-12)
          << body << " at t = " << t;
      EXPECT_LT((test::import_rotation(mjcf.model(), mjcf.trace.q[k], body) -
                 test::import_rotation(hand.model(), hand.trace.q[k], body))
                    .norm(),
                1e-12)
          << body << " at t = " << t;
    }
  }
  // geoms as shapes (half-sizes doubled, a capsule from its fromto), the inertial as mass, the rest listed once
  EXPECT_NE(imported.yaml.find("{type: box, size: [0.5, 0.02, 0.01], at: [0.25, 0, 0]"), std::string::npos);
  EXPECT_NE(imported.yaml.find("{type: capsule, radius: 0.01, length: 0.2, at: [0.1, 0, 0]"), std::string::npos);
  EXPECT_NE(imported.yaml.find("{body: rocker, mass: 0.5, center_of_mass: [0.2, 0, 0]"), std::string::npos);
  EXPECT_NE(imported.yaml.find("{body: ground, shapes: [{type: plane, size: [2, 2]}]}"), std::string::npos);
  const std::string text = file_text(path);
  EXPECT_NE(imported.yaml.find("limits:\n  - {joint: coupler_joint, range: [-3, 3]}\n"), std::string::npos);
  for (const char* what : {"<option", "<site", "solref=", "<actuator"}) {
    const std::string line = path + ":" + std::to_string(MjcfLineOf(text, what)) + ": ";
    EXPECT_EQ(std::count_if(imported.skipped.begin(), imported.skipped.end(),
                            [&](const std::string& s) { return s.rfind(line, 0) == 0; }),
              1)
        << what;
  }
  EXPECT_EQ(imported.skipped.size(), 4u);
}

// A parallel mechanism: the five-bar's two cranks driven, its end effector where both distal links reach, in MJCF
// (closed by `connect`) and URDF (by `closing_effector`) alike.
TEST(MjcfImport, FiveBarParallelRobotPlacesItsEffectorAsTheClosedFormAndTheURDF) {
  ImportOptions o;
  o.drives = {{"motor1", "0.3*t"}, {"motor2", "-0.2*t"}}, o.t_end = 1, o.steps = 20;
  const std::string path = import_data("mjcf/five_bar.xml"), urdf_path = import_data("urdf/five_bar.urdf");
  const test::ImportRun mjcf = import_sweep(import_mjcf(file_text(path), path, o).yaml, path);
  ASSERT_EQ(mjcf.status, SolveStatus::kSuccess) << mjcf.message;
  const ModelImport urdf_import = import_urdf(file_text(urdf_path), urdf_path, o);
  EXPECT_EQ(urdf_import.loops, 1);
  const test::ImportRun urdf = import_sweep(urdf_import.yaml, urdf_path);
  ASSERT_EQ(urdf.status, SolveStatus::kSuccess) << urdf.message;
  ASSERT_EQ(mjcf.trace.q.size(), 21u);
  ASSERT_EQ(urdf.trace.q.size(), 21u);
  for (std::size_t k = 0; k < mjcf.trace.q.size(); ++k) {
    const double t = mjcf.trace.t[k];
    const Eigen::Vector3d E = test::import_point(mjcf.model(), mjcf.trace.q[k], "distal1", {0.4, 0, 0});
    EXPECT_LT((E - test::five_bar_effector(1.9 + 0.3 * t, 1.2 - 0.2 * t)).norm(), 1e-10) << "t = " << t;
    EXPECT_LT((E - test::import_point(urdf.model(), urdf.trace.q[k], "tip")).norm(), 1e-12) << "t = " << t;
    EXPECT_LT((test::import_point(mjcf.model(), mjcf.trace.q[k], "distal2", {0.4, 0, 0}) - E).norm(), 1e-12);
  }
}

TEST(MjcfImport, SliderCrankInDegreesSlidesAsItsClosedFormSays) {
  const std::string path = import_data("mjcf/slider_crank.xml");
  const ModelImport imported = import_mjcf(file_text(path), path, MjcfDrive("crank_joint", "2*pi*t", 1, 36));
  const test::ImportRun r = import_sweep(imported.yaml, path);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double theta = M_PI / 4 + 2 * M_PI * r.trace.t[k];
    const Eigen::Vector3d slider = test::import_point(r.model(), r.trace.q[k], "slider");
    EXPECT_NEAR(slider.x(), test::slider_crank_x(theta), 1e-10) << "t = " << r.trace.t[k];
    EXPECT_LT((test::import_point(r.model(), r.trace.q[k], "rod", {0.35, 0, 0}) - slider).norm(), 1e-12);
  }
  // the slider driven instead: the crank follows (on its branch, near its start)
  const test::ImportRun back =
      import_sweep(import_mjcf(file_text(path), path, MjcfDrive("slider_joint", "-0.02*t", 1, 10)).yaml, path);
  ASSERT_EQ(back.status, SolveStatus::kSuccess) << back.message;
  for (std::size_t k = 0; k < back.trace.q.size(); ++k) {
    const double theta = test::import_yaw(back.model(), back.trace.q[k], "crank");
    EXPECT_NEAR(test::slider_crank_x(theta), 0.413493408138707 - 0.02 * back.trace.t[k], 1e-12);
  }
}

TEST(MjcfImport, JointEqualityIsACouplerOfTheTwoAngles) {
  const std::string path = import_data("mjcf/gears.xml");
  const ModelImport imported = import_mjcf(file_text(path), path, MjcfDrive("wheel1_joint", "t", 3, 30));
  EXPECT_EQ(imported.couplers, 1);
  const test::ImportRun r = import_sweep(imported.yaml, path);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    EXPECT_NEAR(test::import_yaw(r.model(), r.trace.q[k], "wheel2"), 0.1 - 0.5 * t, 1e-12);
  }
  // mass from the geoms at their density: MuJoCo's default 1000 kg/m³ and the file's 7800
  EXPECT_NE(imported.yaml.find("{body: wheel1, density: 1000, shapes: [{type: cylinder, radius: 0.1, length: 0.02"),
            std::string::npos);
  EXPECT_NE(imported.yaml.find("{body: wheel2, density: 7800,"), std::string::npos);
}

// Default classes, childclass, degrees with eulerseq zyx, two hinges in one body, ball, slide, free and a welded body.
TEST(MjcfImport, EveryJointTypeLeavesItsFreedomsAndDefaultsApply) {
  const std::string path = import_data("mjcf/joint_zoo.xml");
  const ModelImport imported = import_mjcf(file_text(path), path);
  const Scene scene = parse_scene(imported.yaml, path);
  const Eigen::VectorXd q = scene.model->initial_positions();
  EXPECT_EQ(analyse_rank(*scene.model, q, 0.0).dof, 12);  // 2 hinges, ball 3, slide 1, free 6; the hand welded
  Eigen::VectorXd phi(scene.model->num_equations());
  scene.model->residual(q.data(), 0.0, phi.data());
  EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 1e-12);
  // the class's hinge axis (0 1 0) for `pitch`, the shoulder turned by euler="30 0 0" about z first (zyx)
  const Eigen::Matrix3d Rs = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT((test::import_rotation(*scene.model, q, "shoulder") - Rs).norm(), 1e-12);
  const Eigen::Matrix3d Rf = Rs * Eigen::AngleAxisd(M_PI / 9, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_LT((test::import_rotation(*scene.model, q, "forearm") - Rf).norm(), 1e-12);
  EXPECT_LT(
      (test::import_point(*scene.model, q, "forearm") - (Eigen::Vector3d(0, 0, 1) + Rs * Eigen::Vector3d(0, 0, -0.3)))
          .norm(),
      1e-12);
  EXPECT_NE(imported.yaml.find("{type: capsule, radius: 0.02, length: 0.2, colour: [0.8, 0.2, 0.2, 1]}"),
            std::string::npos);
  for (const char* what : {"<light>", "<contact>", "<tendon>", "<sensor>", "<joint damping>"})
    EXPECT_EQ(std::count_if(imported.skipped.begin(), imported.skipped.end(),
                            [&](const std::string& s) { return s.find(std::string(": ") + what) != s.npos; }),
              1)
        << what;
}

TEST(MjcfImport, BadInputIsOneLineNamingFileAndLine) {
  const std::string good = file_text(import_data("mjcf/gears.xml"));
  ASSERT_EQ(MjcfError(good), "");
  auto starts = [](const std::string& error, const std::string& start) {
    EXPECT_EQ(error.rfind(start, 0), 0u) << error << "\nexpected to start with: " << start;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  };
  const std::string cut = good.substr(0, good.find("<equality>"));
  starts(MjcfError(cut), "bad.xml:");
  EXPECT_NE(MjcfError(cut).find("truncated"), std::string::npos);
  const std::string poly = test::replace_first(good, "0.1 -0.5 0 0 0", "0.1 -0.5 0.2 0 0");
  starts(MjcfError(poly), "bad.xml:" + std::to_string(MjcfLineOf(good, "<joint joint1")) +
                              ": <joint> equality 'joint_line" + std::to_string(MjcfLineOf(good, "<joint joint1")) +
                              "': polycoef of degree 2");
  const std::string twist =
      test::replace_first(good, "<joint name=\"wheel2_joint\"", "<joint name=\"wheel2_joint\" type=\"twist\"");
  starts(MjcfError(twist), "bad.xml:" + std::to_string(MjcfLineOf(good, "<joint name=\"wheel2_joint\"")) +
                               ": joint 'wheel2_joint' has type 'twist'");
  const std::string ghost = test::replace_first(good, "joint2=\"wheel1_joint\"", "joint2=\"ghost\"");
  starts(MjcfError(ghost),
         "bad.xml:" + std::to_string(MjcfLineOf(good, "<joint joint1")) + ": <joint> equality: joint2 'ghost'");
  const std::string tendon = test::replace_first(good, "<joint joint1", "<tendon tendon1=\"t\"/><joint joint1");
  starts(MjcfError(tendon), "bad.xml:" + std::to_string(MjcfLineOf(good, "<joint joint1")) + ": <tendon> equality");
  const std::string include = test::replace_first(good, "<worldbody>", "<include file=\"more.xml\"/><worldbody>");
  EXPECT_EQ(MjcfError(include), "bad.xml:" + std::to_string(MjcfLineOf(good, "<worldbody>")) +
                                    ": <include file=\"more.xml\">: more.xml: cannot open the scene file: No such file "
                                    "or directory");
  const std::string cls =
      test::replace_first(good, "<joint name=\"wheel1_joint\"", "<joint class=\"nope\" name=\"wheel1_joint\"");
  starts(MjcfError(cls), "bad.xml:" + std::to_string(MjcfLineOf(good, "wheel1_joint")) + ": class 'nope'");
  starts(MjcfError("<robot/>"), "bad.xml:1: an MJCF file's root element is <mujoco>");
  const std::string connect = file_text(import_data("mjcf/fourbar.xml"));
  starts(MjcfError(test::replace_first(connect, "body2=\"coupler\"", "body2=\"ghost\"")),
         "bad.xml:" + std::to_string(MjcfLineOf(connect, "<connect")) + ": body2 'ghost' is not a body of the file");
}

TEST(MjcfImport, EveryTruncationIsRefusedInOneLineOrLoads) {
  const std::string text = file_text(import_data("mjcf/joint_zoo.xml"));
  int refused = 0;
  for (std::size_t cut = 0; cut < text.size(); cut = text.find('\n', cut + 1)) {
    ModelImport imported;
    try {
      imported = import_mjcf(text.substr(0, cut), "bad.xml");
    } catch (const SceneError& e) {
      ++refused;
      EXPECT_EQ(std::string(e.what()).rfind("bad.xml:", 0), 0u) << e.what();
      continue;
    }
    EXPECT_NO_THROW((void)parse_scene(imported.yaml, "bad.xml")) << "cut at " << cut;
  }
  EXPECT_GT(refused, 30);
}

}  // namespace

namespace test {

TEST_F(Cli, MjcfConvertWritesTheTextADirectReadSolves) {
  const std::string model = import_data("mjcf/slider_crank.xml");
  const Result convert =
      run("convert " + model + " -o " + (dir_ / "sc.yaml").string() + " --drive crank_joint=2*pi*t --time 0 1 20");
  ASSERT_EQ(convert.code, 0) << convert.err;
  ImportOptions o;
  o.drives = {{"crank_joint", "2*pi*t"}}, o.t_end = 1, o.steps = 20;
  EXPECT_EQ(slurp(dir_ / "sc.yaml"), import_mjcf(file_text(model), model, o).yaml);
  const Result ran = run("run " + (dir_ / "sc.yaml").string() + " -o " + (dir_ / "sc.csv").string());
  ASSERT_EQ(ran.code, 0) << ran.err;
  const Result check = run("check " + model);
  ASSERT_EQ(check.code, 0) << check.err;
  EXPECT_NE(check.out.find("dof           1 (1 not driven)"), std::string::npos) << check.out;
  const fs::path bad =
      write("bad.xml", "<mujoco><worldbody><body><joint type=\"screw\"/></body></worldbody></mujoco>\n");
  const Result r = run("convert " + bad.string() + " -o " + (dir_ / "out.yaml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(one_phiq_line(r.err));
  EXPECT_NE(r.err.find("bad.xml:1: joint 'body_1_joint_0' has type 'screw'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.yaml"));
}

}  // namespace test
}  // namespace phiq
