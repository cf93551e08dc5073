// MJCF's `include`, `frame`, site-based `connect` and `weld`, and `weld relpose` (phiq/import_model.hpp),
// tests/data/mjcf/: the four-bar of fourbar.xml written again with them follows the same closed form and the same
// positions; welds hold their free bodies where their closed forms say; bad includes, frames and sites are one line
// naming the file (the included one where it is at fault) and line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli_test_support.hpp"  // test::TestFolder
#include "import_test_support.hpp"

namespace phiq {
namespace {

using test::file_text, test::import_data, test::import_sweep;

ImportOptions MjcfFramesDrive(const std::string& joint, const std::string& law, double end, int steps) {
  ImportOptions o;
  o.drives = {{joint, law}};
  o.t_end = end, o.steps = steps;
  return o;
}

int MjcfFramesLineOf(const std::string& text, const std::string& what) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find(what)), '\n'));
}

// A folder of its own for files that include each other (test::TestFolder), removed at the end.
class MjcfIncludeFiles : public test::TestFolder {
 protected:
  std::string error_of(const std::string& path) {
    try {
      (void)import_mjcf(file_text(path), path);
    } catch (const SceneError& e) {
      return e.what();
    }
    return "";
  }
};

TEST(MjcfFrames, FourBarThroughIncludeFramesAndSitesIsTheFourBar) {
  const std::string path = import_data("mjcf/fourbar_frames.xml"), plain = import_data("mjcf/fourbar.xml");
  const ImportOptions drive = MjcfFramesDrive("crank_joint", "2*pi*t", 1, 40);
  const ModelImport imported = import_mjcf(file_text(path), path, drive);
  EXPECT_EQ(imported.bodies, 3);
  EXPECT_EQ(imported.joints, 4);
  EXPECT_EQ(imported.loops, 1);
  // the included file's sites, listed once at its first one's line
  const std::string world = import_data("mjcf/fourbar_frames_world.xml");
  const std::string sites = world + ":" + std::to_string(MjcfFramesLineOf(file_text(world), "<site")) +
                            ": <site> (2 in all): no kinematics: phiq outputs points instead";
  EXPECT_EQ(std::count(imported.skipped.begin(), imported.skipped.end(), sites), 1) << imported.yaml;
  EXPECT_NE(imported.yaml.find("{type: box, size: [0.5, 0.02, 0.01], at: [0.25, 0, 0]"), std::string::npos);
  const test::ImportRun framed = import_sweep(imported.yaml, path);
  ASSERT_EQ(framed.status, SolveStatus::kSuccess) << framed.message;
  const test::ImportRun reference = import_sweep(import_mjcf(file_text(plain), plain, drive).yaml, plain);
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

// An arm on a hinge and a slider on it, their joints and inertials inside nested <frame>s (positions and turns that
// compose), against the same model written with each frame's pose composed by hand (numbers printed to 17 digits):
// the same motion and the same efforts and reactions (`--forces`) to 1e-12.
std::string MjcfFramesArm(bool framed) {
  const Eigen::Quaterniond outer = Eigen::Quaterniond(0.9, 0.1, 0.3, -0.2).normalized();
  const Eigen::Quaterniond inner = Eigen::Quaterniond(0.8, -0.4, 0.1, 0.3).normalized();
  const Eigen::Quaterniond own = Eigen::Quaterniond(0.7, 0.2, -0.5, 0.1).normalized();  // the inertial's
  const Eigen::Vector3d outer_at(0.1, 0.2, -0.05), inner_at(0.03, -0.02, 0.04);
  const auto text = [](const Eigen::Vector3d& v) {
    char s[96];
    std::snprintf(s, sizeof s, "%.17g %.17g %.17g", v.x(), v.y(), v.z());
    return std::string(s);
  };
  const auto quat = [](const Eigen::Quaterniond& q) {
    char s[128];
    std::snprintf(s, sizeof s, "%.17g %.17g %.17g %.17g", q.w(), q.x(), q.y(), q.z());
    return std::string(s);
  };
  const Eigen::Vector3d hinge_at(0.05, 0, 0.02), hinge_axis(0, 0, 1), slide_axis(1, 0, 0), com(0.3, 0.01, 0);
  const std::string mass = "mass=\"2\" diaginertia=\"0.02 0.05 0.06\"";
  std::string arm, slider;
  if (framed) {
    arm = "<frame pos=\"" + text(outer_at) + "\" quat=\"" + quat(outer) + "\"><frame pos=\"" + text(inner_at) +
          "\" quat=\"" + quat(inner) + "\"><joint name=\"hinge\" pos=\"" + text(hinge_at) + "\" axis=\"" +
          text(hinge_axis) + "\"/></frame><inertial pos=\"" + text(com) + "\" quat=\"" + quat(own) + "\" " + mass +
          "/></frame>";
    slider = "<frame quat=\"" + quat(inner) + "\"><joint name=\"slide\" type=\"slide\" axis=\"" + text(slide_axis) +
             "\"/><inertial pos=\"0 0 0\" mass=\"0.5\" diaginertia=\"0.001 0.001 0.001\"/></frame>";
  } else {
    const Eigen::Vector3d at = outer_at + outer * (inner_at + inner * hinge_at);
    arm = "<joint name=\"hinge\" pos=\"" + text(at) + "\" axis=\"" + text(outer * inner * hinge_axis) +
          "\"/><inertial pos=\"" + text(outer_at + outer * com) + "\" quat=\"" + quat(outer * own) + "\" " + mass +
          "/>";
    slider = "<joint name=\"slide\" type=\"slide\" axis=\"" + text(inner * slide_axis) +
             "\"/><inertial pos=\"0 0 0\" mass=\"0.5\" diaginertia=\"0.001 0.001 0.001\"/>";
  }
  return "<mujoco>\n<compiler angle=\"radian\"/>\n<worldbody>\n<body name=\"arm\" pos=\"0 0 1\">" + arm +
         "<geom type=\"box\" size=\"0.3 0.02 0.02\"/>\n<body name=\"slider\" pos=\"0.4 0 0\">" + slider +
         "</body>\n</body>\n</worldbody>\n</mujoco>\n";
}

struct MjcfFramesRows {
  std::vector<Eigen::VectorXd> q;
  std::vector<std::vector<double>> forces;  // efforts, powers, reactions
};
MjcfFramesRows MjcfFramesSweep(const std::string& xml) {
  ImportOptions o = MjcfFramesDrive("hinge", "0.8*sin(2*t)", 1, 10);
  o.drives.emplace_back("slide", "0.1*t^2");
  o.forces = true;
  const ModelImport imported = import_mjcf(xml, "arm.xml", o);
  EXPECT_TRUE(imported.skipped.empty()) << imported.skipped.front();
  const Scene s = parse_scene(imported.yaml, "arm.xml");
  Workspace ws(*s.model);
  MjcfFramesRows r;
  const std::size_t n = static_cast<std::size_t>(s.sweep.efforts.size());
  EXPECT_EQ(n, 2u * 2 + 2 * 6);  // two drivers' efforts and powers, two joints' reactions
  EXPECT_EQ(run_sweep(
                *s.model, s.sweep, ws,
                [&](const StepView& v) {
                  r.q.push_back(v.q), r.forces.emplace_back(v.efforts, v.efforts + n);
                  return true;
                },
                nullptr),
            SolveStatus::kSuccess);
  return r;
}

TEST(MjcfFrames, JointsAndInertialsInFramesAreTheModelWithTheirPosesComposed) {
  const MjcfFramesRows framed = MjcfFramesSweep(MjcfFramesArm(true)), plain = MjcfFramesSweep(MjcfFramesArm(false));
  ASSERT_EQ(framed.q.size(), 11u);
  ASSERT_EQ(plain.q.size(), 11u);
  double largest = 0.0;
  for (std::size_t k = 0; k < framed.q.size(); ++k) {
    EXPECT_LT((framed.q[k] - plain.q[k]).lpNorm<Eigen::Infinity>(), 1e-12) << "row " << k;
    for (std::size_t i = 0; i < framed.forces[k].size(); ++i) {
      EXPECT_NEAR(framed.forces[k][i], plain.forces[k][i], 1e-12 * (1 + std::abs(plain.forces[k][i])))
          << "row " << k << ", value " << i;
      largest = std::max(largest, std::abs(plain.forces[k][i]));
    }
  }
  EXPECT_GT(largest, 0.1);  // the inertials load the joints: a frame's turn of an inertial would show
}

// tip: relpose (0.5, 0, 0.1), turned π/2, in the arm's frame; cap: its site (0, 0, 0.2) on the arm's at (1, 0, 0),
// turned π/2; the arm at angle t: both where Rz(t) puts them, wherever they started.
TEST(MjcfFrames, WeldsByRelposeAndBySitesHoldTheirBodiesAsTheClosedFormSays) {
  const std::string path = import_data("mjcf/weld_relpose.xml");
  const ModelImport imported = import_mjcf(file_text(path), path, MjcfFramesDrive("arm_joint", "t", 1, 10));
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
  // an included file's faults name it: a joint type MJCF has not (in a frame), a site no element has, a second site
  write("parts.xml",
        "<mujoco>\n<worldbody>\n<body>\n<frame>\n<joint name=\"loose\" type=\"twist\"/>\n</frame>\n</body>\n"
        "</worldbody>\n</mujoco>\n");
  const std::string framed = write("framed.xml", "<mujoco>\n<include file=\"parts.xml\"/>\n</mujoco>\n");
  EXPECT_EQ(error_of(framed),
            (dir_ / "parts.xml").string() + ":5: joint 'loose' has type 'twist': MJCF's are hinge, slide, ball, free");
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
