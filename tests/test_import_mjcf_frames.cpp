// MJCF's `include`, `frame`, site-based `connect` and `weld`, and `weld relpose` (phiq/import_model.hpp),
// tests/data/mjcf/: the four-bar of fourbar.xml written again with them follows the same closed form and the same
// positions; welds hold their free bodies where their closed forms say; bad includes, frames and sites are one line
// naming the file (the included one where it is at fault) and line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "import_test_support.hpp"

namespace phiq {
namespace {

using test::import_data, test::import_sweep, test::import_text;

ImportOptions MjcfFramesDrive(const std::string& joint, const std::string& law, double end, int steps) {
  ImportOptions o;
  o.drives = {{joint, law}};
  o.t_end = end, o.steps = steps;
  return o;
}

int MjcfFramesLineOf(const std::string& text, const std::string& what) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find(what)), '\n'));
}

// A folder of its own for files that include each other, removed at the end.
class MjcfIncludeFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("phiq_mjcf_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const std::filesystem::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  std::string error_of(const std::string& path) {
    try {
      (void)import_mjcf(import_text(path), path);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "";
  }
  std::filesystem::path dir_;
};

TEST(MjcfFrames, FourBarThroughIncludeFramesAndSitesIsTheFourBar) {
  const std::string path = import_data("mjcf/fourbar_frames.xml"), plain = import_data("mjcf/fourbar.xml");
  const ImportOptions drive = MjcfFramesDrive("crank_joint", "2*pi*t", 1, 40);
  const ModelImport imported = import_mjcf(import_text(path), path, drive);
  EXPECT_EQ(imported.bodies, 3);
  EXPECT_EQ(imported.joints, 4);
  EXPECT_EQ(imported.loops, 1);
  // the included file's sites, listed once at its first one's line
  const std::string world = import_data("mjcf/fourbar_frames_world.xml");
  const std::string sites = world + ":" + std::to_string(MjcfFramesLineOf(import_text(world), "<site")) +
                            ": <site> (2 in all): no kinematics: phiq outputs points instead";
  EXPECT_EQ(std::count(imported.skipped.begin(), imported.skipped.end(), sites), 1) << imported.yaml;
  EXPECT_NE(imported.yaml.find("{type: box, size: [0.5, 0.02, 0.01], at: [0.25, 0, 0]"), std::string::npos);
  const test::ImportRun framed = import_sweep(imported.yaml, path);
  ASSERT_EQ(framed.status, SolveStatus::kSuccess) << framed.message;
  const test::ImportRun reference = import_sweep(import_mjcf(import_text(plain), plain, drive).yaml, plain);
  ASSERT_EQ(reference.status, SolveStatus::kSuccess) << reference.message;
  ASSERT_EQ(framed.trace.q.size(), 41u);
  for (std::size_t k = 0; k < framed.trace.q.size(); ++k) {
    const double t = framed.trace.t[k];
    const Eigen::Vector3d tip = test::import_point(framed.model(), framed.trace.q[k], "coupler", {0.5, 0, 0});
    EXPECT_LT((tip - test::fourbar_rocker_tip(M_PI / 3 + 2 * M_PI * t)).norm(), 1e-10) << "t = " << t;
    for (const char* body : {"crank", "coupler", "rocker"}) {
      EXPECT_LT((test::import_point(framed.model(), framed.trace.q[k], body) -
                 test::import_point(reference.model(), reference.trace.q[k], body))
                    .norm(),
                1e-12)
          << body << " at t = " << t;
      EXPECT_LT((test::import_rotation(framed.model(), framed.trace.q[k], body) -
                 test::import_rotation(reference.model(), reference.trace.q[k], body))
                    .norm(),
                1e-12)
          << body << " at t = " << t;
    }
  }
}

// tip: relpose (0.5, 0, 0.1), turned π/2, in the arm's frame; cap: its site (0, 0, 0.2) on the arm's at (1, 0, 0),
// turned π/2; the arm at angle t: both where Rz(t) puts them, wherever they started.
TEST(MjcfFrames, WeldsByRelposeAndBySitesHoldTheirBodiesAsTheClosedFormSays) {
  const std::string path = import_data("mjcf/weld_relpose.xml");
  const ModelImport imported = import_mjcf(import_text(path), path, MjcfFramesDrive("arm_joint", "t", 1, 10));
  EXPECT_EQ(imported.bodies, 3);
  EXPECT_EQ(imported.joints, 5);  // the hinge, two free joints, two welds
  EXPECT_EQ(imported.loops, 2);
  const test::ImportRun r = import_sweep(imported.yaml, path);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 11u);
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d turned = Eigen::AngleAxisd(t + M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::VectorXd& q = r.trace.q[k];
    EXPECT_LT((test::import_point(r.model(), q, "tip") - Rz * Eigen::Vector3d(0.5, 0, 0.1)).norm(), 1e-10) << t;
    EXPECT_LT((test::import_rotation(r.model(), q, "tip") - turned).norm(), 1e-10) << t;
    EXPECT_LT(
        (test::import_point(r.model(), q, "cap") - (Rz * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(0, 0, 0.2))).norm(),
        1e-10)
        << t;
    EXPECT_LT((test::import_rotation(r.model(), q, "cap") - turned).norm(), 1e-10) << t;
  }
}

TEST_F(MjcfIncludeFiles, BadIncludesFramesAndSitesAreOneLineNamingTheirFileAndLine) {
  const std::string body = "<body name=\"b\"><joint name=\"j\"/><site name=\"s\"/></body>";
  // an include that is not there: the including file's line
  const std::string missing =
      write("missing.xml", "<mujoco>\n<worldbody>\n<include file=\"none.xml\"/>\n</worldbody>\n</mujoco>\n");
  EXPECT_EQ(
      error_of(missing).rfind(missing + ":3: <include file=\"none.xml\">: " + (dir_ / "none.xml").string() + ": ", 0),
      0u)
      << error_of(missing);
  // a malformed included file: its own line; one that is no <mujoco>
  write("broken.xml", "<mujoco>\n<worldbody>\n<body>\n</mujoco>\n");
  const std::string broken = write("main.xml", "<mujoco>\n  <include file=\"broken.xml\"/>\n</mujoco>\n");
  EXPECT_EQ(error_of(broken).rfind((dir_ / "broken.xml").string() + ":", 0), 0u) << error_of(broken);
  EXPECT_NE(error_of(broken).find("malformed XML"), std::string::npos) << error_of(broken);
  write("robot.xml", "<robot/>\n");
  const std::string robot = write("robot_main.xml", "<mujoco>\n<include file=\"robot.xml\"/>\n</mujoco>\n");
  EXPECT_EQ(error_of(robot), (dir_ / "robot.xml").string() + ":1: an included MJCF file's root element is <mujoco>");
  // a cycle: a includes b, b includes a
  const std::string a = write("a.xml", "<mujoco>\n<include file=\"b.xml\"/>\n</mujoco>\n");
  write("b.xml", "<mujoco>\n\n<include file=\"a.xml\"/>\n</mujoco>\n");
  EXPECT_EQ(error_of(a),
            (dir_ / "b.xml").string() + ":3: <include file=\"a.xml\">: includes itself (through 2 file(s))");
  // an included file's faults name it: a joint in a frame, a site no element has, a second site of a name
  write("parts.xml", "<mujoco>\n<worldbody>\n<frame>\n<joint name=\"loose\"/>\n</frame>\n</worldbody>\n</mujoco>\n");
  const std::string framed = write("framed.xml", "<mujoco>\n<include file=\"parts.xml\"/>\n</mujoco>\n");
  EXPECT_EQ(error_of(framed), (dir_ / "parts.xml").string() +
                                  ":4: <joint> inside a <frame>: phiq reads a body's joints and inertial as its own "
                                  "children");
  const std::string ghost = write("ghost.xml", "<mujoco>\n<worldbody>" + body +
                                                   "</worldbody>\n<equality>\n<connect site1=\"s\" site2=\"ghost\"/>\n"
                                                   "</equality>\n</mujoco>\n");
  EXPECT_EQ(error_of(ghost), ghost + ":4: site2 'ghost' is not a site of the file");
  const std::string mixed = write("mixed.xml", "<mujoco>\n<worldbody>" + body +
                                                   "</worldbody>\n<equality>\n<weld site1=\"s\" site2=\"s\" "
                                                   "anchor=\"0 0 1\"/>\n</equality>\n</mujoco>\n");
  EXPECT_EQ(error_of(mixed), mixed + ":4: <weld> names sites and anchor: MuJoCo takes one or the other");
  const std::string twice =
      write("twice.xml", "<mujoco>\n<worldbody>\n<site name=\"s\"/>\n<site name=\"s\"/>\n</worldbody>\n</mujoco>\n");
  EXPECT_EQ(error_of(twice), twice + ":4: a second site named 's'");
}

}  // namespace
}  // namespace phiq
