// URDF files read as phiq scenes (phiq/import_model.hpp), tests/data/urdf/: a four-bar closed by a `closing_*` joint,
// a slider-crank, a gear pair by `mimic`, and every joint type. Closed forms and the four-bar written by hand hold the
// imports; `phiq convert` writes the very text a direct read solves; bad input is one line naming FILE:LINE.
#include <gtest/gtest.h>

#include <pthread.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "cli_test_support.hpp"
#include "import_test_support.hpp"
#include "phiq/rank_analysis.hpp"

namespace phiq {
namespace {

using test::file_text, test::import_data, test::import_sweep;

ImportOptions UrdfDrive(const std::string& joint, const std::string& law, double end, int steps) {
  ImportOptions o;
  o.drives = {{joint, law}};
  o.t_end = end, o.steps = steps;
  return o;
}

std::string UrdfError(const std::string& text, const ImportOptions& o = {}) {
  try {
    (void)import_urdf(text, "bad.urdf", o);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

int UrdfLineOf(const std::string& text, const std::string& what) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find(what)), '\n'));
}

TEST(UrdfImport, FourBarClosedByItsClosingJointFollowsItsClosedFormAndTheSceneWrittenByHand) {
  const std::string path = import_data("urdf/fourbar.urdf");
  const ModelImport imported = import_urdf(file_text(path), path, UrdfDrive("crank_joint", "2*pi*t", 1, 40));
  EXPECT_EQ(imported.bodies, 4);  // crank, coupler, coupler_tip, rocker (base is the ground)
  EXPECT_EQ(imported.joints, 5);
  EXPECT_EQ(imported.loops, 1);
  const test::ImportRun urdf = import_sweep(imported.yaml, path);
  ASSERT_EQ(urdf.status, SolveStatus::kSuccess) << urdf.message;
  const test::ImportRun hand = import_sweep(test::kFourbarByHand, "fourbar_by_hand.yaml");
  ASSERT_EQ(hand.status, SolveStatus::kSuccess) << hand.message;
  ASSERT_EQ(urdf.trace.q.size(), 41u);
  ASSERT_EQ(hand.trace.q.size(), 41u);
  for (std::size_t k = 0; k < urdf.trace.q.size(); ++k) {
    const double t = urdf.trace.t[k];
    const Eigen::Vector3d tip = test::import_point(urdf.model(), urdf.trace.q[k], "coupler_tip");
    EXPECT_LT((tip - test::fourbar_rocker_tip(M_PI / 3 + 2 * M_PI * t)).norm(), 1e-10) << "t = " << t;
    const Eigen::Vector3d by_hand = test::import_point(hand.model(), hand.trace.q[k], "coupler", {0.5, 0, 0});
    EXPECT_LT((tip - by_hand).norm(), 1e-12) << "t = " << t;
    for (const char* body : {"crank", "coupler", "rocker"}) {
      EXPECT_LT((test::import_point(urdf.model(), urdf.trace.q[k], body) -
                 test::import_point(hand.model(), hand.trace.q[k], body))
                    .norm(),
                1e-12)
          << body << " at t = " << t;
      EXPECT_LT((test::import_rotation(urdf.model(), urdf.trace.q[k], body) -
                 test::import_rotation(hand.model(), hand.trace.q[k], body))
                    .norm(),
                1e-12)
          << body << " at t = " << t;
    }
  }
  // the inertial and the shapes as parts; what is not mapped listed once per kind, with its first line
  EXPECT_NE(imported.yaml.find("part_crank: {body: crank, mass: 0.4, center_of_mass: [0.1, 0, 0]"), std::string::npos);
  EXPECT_NE(imported.yaml.find("{type: cylinder, radius: 0.01, length: 0.5"), std::string::npos);
  EXPECT_NE(imported.yaml.find("colour: [0.6, 0.6, 0.65, 1]"), std::string::npos);
  const std::string text = file_text(path);
  auto listed = [&](const std::string& start) {
    return std::count_if(imported.skipped.begin(), imported.skipped.end(),
                         [&](const std::string& s) { return s.rfind(start, 0) == 0; });
  };
  // the joints' <limit>s as the scene's limits; their velocity checked only with velocities solved (--rates)
  for (const char* joint : {"coupler_joint", "rocker_joint"})
    EXPECT_NE(imported.yaml.find("- {joint: " + std::string(joint) + ", range: [-3, 3]}"), std::string::npos) << joint;
  EXPECT_EQ(listed(path + ":" + std::to_string(UrdfLineOf(text, "<joint name=\"coupler_joint\"")) +
                   ": a joint's velocity limit (2 in all): checked with --rates"),
            1);
  // the crank joint's <dynamics damping> a damper on its angle (its efforts' load), not a thing left out: on the
  // angle's coordinate, a rotation_angle of the joint, which counts its turns
  EXPECT_NE(imported.yaml.find("- {name: crank_joint_spring, coordinate: crank_joint_angle, stiffness: 0, "
                               "free_angle: 0, damping: 0.1}"),
            std::string::npos);
  EXPECT_NE(imported.yaml.find("type: rotation_angle, joint: crank_joint, angle: crank_joint_angle}"),
            std::string::npos);
  EXPECT_EQ(listed(path + ":" + std::to_string(UrdfLineOf(text, "<collision")) + ": <collision>:"), 1);
  EXPECT_EQ(listed(path + ":" + std::to_string(UrdfLineOf(text, "<transmission")) + ": <transmission>:"), 1);
  EXPECT_EQ(imported.skipped.size(), 3u);
  EXPECT_NE(imported.yaml.find("# Converted by phiq from " + path + " (URDF): lengths in metres"), std::string::npos);
}

TEST(UrdfImport, SliderCrankSlidesAsItsClosedFormSays) {
  const std::string path = import_data("urdf/slider_crank.urdf");
  const ModelImport imported = import_urdf(file_text(path), path, UrdfDrive("crank_joint", "2*pi*t", 1, 36));
  const test::ImportRun r = import_sweep(imported.yaml, path);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 37u);
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double theta = M_PI / 4 + 2 * M_PI * r.trace.t[k];
    const Eigen::Vector3d slider = test::import_point(r.model(), r.trace.q[k], "slider");
    EXPECT_NEAR(slider.x(), test::slider_crank_x(theta), 1e-10) << "t = " << r.trace.t[k];
    EXPECT_NEAR(slider.y(), 0.0, 1e-12);
    EXPECT_LT((test::import_point(r.model(), r.trace.q[k], "rod_tip") - slider).norm(), 1e-12);
  }
}

TEST(UrdfImport, MimicJointIsACouplerOfTheTwoAngles) {
  const std::string path = import_data("urdf/gears.urdf");
  const ModelImport imported = import_urdf(file_text(path), path, UrdfDrive("wheel1_joint", "t", 3, 30));
  EXPECT_EQ(imported.couplers, 1);
  EXPECT_NE(imported.yaml.find("type: coupler, coordinates: [wheel2_joint_angle, wheel1_joint_angle], "
                               "coefficients: [1, 0.5], constant: 0.1"),
            std::string::npos)
      << imported.yaml;
  const test::ImportRun r = import_sweep(imported.yaml, path);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    EXPECT_NEAR(test::import_yaw(r.model(), r.trace.q[k], "wheel1"), t, 1e-12);
    EXPECT_NEAR(test::import_yaw(r.model(), r.trace.q[k], "wheel2"), 0.1 - 0.5 * t, 1e-12);
  }
}

// A mimic of a prismatic joint: the rack's travel (an `equation` over the bodies' coordinates) coupled to the
// pinion's angle, along a rack turned 0.2 rad about z.
TEST(UrdfImport, MimicOfAPrismaticJointCouplesItsTravel) {
  const std::string path = import_data("urdf/rack_pinion.urdf");
  const test::ImportRun r =
      import_sweep(import_urdf(file_text(path), path, UrdfDrive("pinion_joint", "2*t", 2, 20)).yaml, path);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  const Eigen::Vector3d along(std::cos(0.2), std::sin(0.2), 0);
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    const Eigen::Vector3d rack = test::import_point(r.model(), r.trace.q[k], "rack");
    EXPECT_LT((rack - (Eigen::Vector3d(0.1, 0, 0) + (0.05 * 2 * t + 0.01) * along)).norm(), 1e-12) << "t = " << t;
  }
}

// Every joint type, each with the freedoms URDF gives it: fixed 0, prismatic 1, planar 3, continuous 1, revolute 1
// (about an oblique axis), floating 6.
TEST(UrdfImport, EveryJointTypeLeavesItsFreedoms) {
  const std::string path = import_data("urdf/joint_zoo.urdf");
  const ModelImport imported = import_urdf(file_text(path), path);
  EXPECT_EQ(imported.joints, 6);
  for (const char* kind : {"type: rigid", "type: prismatic", "type: planar", "type: revolute"})
    EXPECT_NE(imported.yaml.find(kind), std::string::npos) << kind;
  const Scene scene = parse_scene(imported.yaml, path);
  const Eigen::VectorXd q = scene.model->initial_positions();
  const RankReport rank = analyse_rank(*scene.model, q, 0.0);
  EXPECT_EQ(rank.dof, 12);
  EXPECT_TRUE(rank.redundant_rows.empty());
  Eigen::VectorXd phi(scene.model->num_equations());
  scene.model->residual(q.data(), 0.0, phi.data());
  EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 1e-12);  // the tree's placement satisfies every joint
  // the inertial turned by its rpy: the arm's inertia about its centre in the link's axes
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d I = R * Eigen::Vector3d(0.03, 0.03, 0.004).asDiagonal() * R.transpose();
  EXPECT_NE(imported.yaml.find("center_of_mass: [0, 0, 0.2], inertia: [[0.03, 0, 0], [0, " + shortest(I(1, 1))),
            std::string::npos)
      << imported.yaml;
  // its package:// mesh: no folder `zoo` above it (nor on ROS_PACKAGE_PATH), so listed once
  EXPECT_EQ(std::count_if(imported.skipped.begin(), imported.skipped.end(),
                          [](const std::string& s) {
                            return s.find(
                                       ":16: <visual> mesh of a package not found: its package is neither on "
                                       "ROS_PACKAGE_PATH nor a folder above the file") != s.npos;
                          }),
            1);
}

// The oblique revolute and the prismatic of the zoo, driven: the arm turns about its axis (1, 1, 1) in the joint
// frame, the carriage travels along its axis (0, 2, 0) normalised, as URDF's joint positions say.
TEST(UrdfImport, JointPositionsAreURDFsAngleAboutAndTravelAlongTheAxis) {
  const std::string path = import_data("urdf/joint_zoo.urdf");
  std::string text = file_text(path);
  for (const char* free_joint : {"puck_joint", "wheel_joint", "drone_joint"}) {
    const std::size_t at = text.find("<joint name=\"" + std::string(free_joint) + "\"");
    text.erase(at, text.find("</joint>", at) + 8 - at);
  }
  for (const char* link : {"<link name=\"puck\"/>", "<link name=\"wheel\"/>", "<link name=\"drone\"/>"})
    text.erase(text.find(link), std::string(link).size());
  ImportOptions o = UrdfDrive("arm_joint", "0.7*t", 1, 10);
  o.drives.emplace_back("carriage_joint", "0.25*t");
  const test::ImportRun r = import_sweep(import_urdf(text, path, o).yaml, path);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  const Eigen::Matrix3d mount =
      (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    const Eigen::Matrix3d arm = mount * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                                Eigen::AngleAxisd(0.7 * t, Eigen::Vector3d(1, 1, 1).normalized()).toRotationMatrix();
    EXPECT_LT((test::import_rotation(r.model(), r.trace.q[k], "arm") - arm).norm(), 1e-12) << t;
    const Eigen::Vector3d carriage = Eigen::Vector3d(0, 0, 1) + mount * Eigen::Vector3d(0, 0.25 * t, 0);
    EXPECT_LT((test::import_point(r.model(), r.trace.q[k], "carriage") - carriage).norm(), 1e-12) << t;
  }
}

TEST(UrdfImport, BadInputIsOneLineNamingFileAndLine) {
  const std::string good = file_text(import_data("urdf/fourbar.urdf"));
  ASSERT_EQ(UrdfError(good), "");
  auto starts = [](const std::string& error, const std::string& start) {
    EXPECT_EQ(error.rfind(start, 0), 0u) << error << "\nexpected to start with: " << start;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  };
  // truncated: the XML reader names the line of the element left open
  const std::string cut = good.substr(0, good.find("<joint name=\"rocker_joint\""));
  starts(UrdfError(cut), "bad.urdf:" + std::to_string(UrdfLineOf(cut, "<robot")) + ": malformed XML");
  EXPECT_NE(UrdfError(cut).find("truncated"), std::string::npos);
  // an unknown joint type
  const std::string hinge = test::replace_first(good, "type=\"revolute\"", "type=\"hinge\"");
  starts(UrdfError(hinge), "bad.urdf:" + std::to_string(UrdfLineOf(good, "<joint name=\"coupler_joint\"")) +
                               ": joint 'coupler_joint' has type 'hinge'");
  // a joint naming a missing link, at its <child> line
  const std::string ghost = test::replace_first(good, "<child link=\"rocker\"/>", "<child link=\"ghost\"/>");
  starts(UrdfError(ghost), "bad.urdf:" + std::to_string(UrdfLineOf(good, "<child link=\"rocker\"/>")) +
                               ": joint 'rocker_joint': child link 'ghost' is not in the file");
  // a loop not declared by the convention: a link with two parents, and a cycle
  const std::string two = test::replace_first(good, "name=\"closing_tip\"", "name=\"tip_pin\"");
  starts(UrdfError(two), "bad.urdf:" + std::to_string(UrdfLineOf(good, "name=\"closing_tip\"")) +
                             ": joint 'tip_pin': link 'coupler_tip' already has a parent (joint 'tip'");
  const std::string cycle = R"(<robot name="c"><link name="base"/><link name="a"/><link name="b"/>
<joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
<joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint></robot>)";
  starts(UrdfError(cycle), "bad.urdf:2: joints ab, ba form a cycle");
  // a joint hanging from a cycle leads into it and is not on it: the cycle is named by its own first joint
  const std::string below = test::replace_first(cycle, "<joint name=\"ab\"",
                                                "<link name=\"z\"/><joint name=\"az\" type=\"fixed\"><parent "
                                                "link=\"a\"/><child link=\"z\"/></joint>\n<joint name=\"ab\"");
  starts(UrdfError(below), "bad.urdf:3: joints ab, ba form a cycle");
  // elements nested deeper than tinyxml2 reads: said as such, not as a truncated file
  std::string deep = "<robot name=\"d\">\n";
  for (int i = 0; i < 120; ++i) deep += "<link name=\"l" + std::to_string(i) + "\">";
  starts(UrdfError(deep), "bad.urdf:2: elements nested more than 100 deep, the most the XML reader (tinyxml2) reads");
  // a mimic of a joint that does not exist
  const std::string gears = file_text(import_data("urdf/gears.urdf"));
  starts(UrdfError(test::replace_first(gears, "joint=\"wheel1_joint\"", "joint=\"wheel9\"")),
         "bad.urdf:" + std::to_string(UrdfLineOf(gears, "<mimic")) + ": joint 'wheel2_joint' mimics 'wheel9'");
  // a driver of a joint the file does not have, or of one phiq drives no measure of
  starts(UrdfError(good, UrdfDrive("elbow", "t", 1, 1)), "bad.urdf: --drive elbow: the model has no joint 'elbow'");
  starts(UrdfError(good, UrdfDrive("tip", "t", 1, 1)),
         "bad.urdf:" + std::to_string(UrdfLineOf(good, "<joint name=\"tip\"")) + ": --drive tip: a rigid joint");
  starts(UrdfError("<robot name=\"r\"><link name=\"only\"/></robot>"), "bad.urdf: the model has no moving link");
}

// Every prefix of a file: refused in one line naming the file and a line, or converted to a scene that loads.
// Runs `work` on a thread of `bytes` of stack: a reader that recursed once per link would overflow it.
void OnAStackOf(std::size_t bytes, const std::function<void()>& work) {
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, bytes);
  pthread_t thread;
  auto run = [](void* w) -> void* {
    (*static_cast<const std::function<void()>*>(w))();
    return nullptr;
  };
  ASSERT_EQ(pthread_create(&thread, &attr, run, const_cast<std::function<void()>*>(&work)), 0);
  pthread_join(thread, nullptr);
  pthread_attr_destroy(&attr);
}

// A serial chain of 10 000 links, as deep as it is long, read on 1 MiB of stack (100 bytes a link): each link placed
// 1 m along x from its parent, the last at 10 000 m. The reader walked the tree by recursion (a stack overflow at
// 30 000 links on the main thread's 8 MiB) and checked it for cycles in O(N^2) time; both are linear now.
TEST(UrdfImport, ASerialChainOfTenThousandLinksIsReadOnASmallStack) {
  constexpr int kLinks = 10000;
  std::string text = "<robot name=\"chain\"><link name=\"base\"/>\n";
  for (int i = 0; i < kLinks; ++i) {
    const std::string link = "l" + std::to_string(i), parent = i ? "l" + std::to_string(i - 1) : "base";
    text += "<link name=\"" + link + "\"/><joint name=\"j" + std::to_string(i) +
            "\" type=\"continuous\"><parent link=\"" + parent + "\"/><child link=\"" + link +
            "\"/><origin xyz=\"1 0 0\"/><axis xyz=\"0 0 1\"/></joint>\n";
  }
  std::string yaml;
  OnAStackOf(std::size_t{1} << 20, [&] { yaml = import_urdf(text + "</robot>\n", "chain.urdf").yaml; });
  EXPECT_NE(yaml.find("\n  l0: {at: [1, 0, 0],"), std::string::npos);
  EXPECT_NE(yaml.find("\n  l9999: {at: [10000, 0, 0],"), std::string::npos);
  EXPECT_EQ(std::count(yaml.begin(), yaml.end(), '\n') > 2 * kLinks, true);
}

TEST(UrdfImport, EveryTruncationIsRefusedInOneLineOrLoads) {
  const std::string text = file_text(import_data("urdf/fourbar.urdf"));
  int refused = 0;
  for (std::size_t cut = 0; cut < text.size(); cut = text.find('\n', cut + 1)) {
    ModelImport imported;
    try {
      imported = import_urdf(text.substr(0, cut), "bad.urdf");
    } catch (const SceneError& e) {
      ++refused;
      EXPECT_EQ(std::string(e.what()).rfind("bad.urdf:", 0), 0u) << e.what();
      continue;
    }
    EXPECT_NO_THROW((void)parse_scene(imported.yaml, "bad.urdf")) << "cut at " << cut;
  }
  EXPECT_GT(refused, 50);
}

}  // namespace

namespace test {

TEST_F(Cli, UrdfConvertWritesTheTextADirectReadSolves) {
  const std::string model = import_data("urdf/fourbar.urdf");
  const Result convert =
      run("convert " + model + " -o " + (dir_ / "fourbar.yaml").string() + " --drive crank_joint=2*pi*t --time 0 1 40");
  ASSERT_EQ(convert.code, 0) << convert.err;
  EXPECT_NE(convert.err.find("phiq: not mapped: " + model + ":"), std::string::npos) << convert.err;
  ImportOptions o;
  o.drives = {{"crank_joint", "2*pi*t"}}, o.t_end = 1, o.steps = 40;
  EXPECT_EQ(slurp(dir_ / "fourbar.yaml"), import_urdf(file_text(model), model, o).yaml);
  const Result ran = run("run " + (dir_ / "fourbar.yaml").string() + " -o " + (dir_ / "fourbar.csv").string());
  ASSERT_EQ(ran.code, 0) << ran.err;
  EXPECT_EQ(count(slurp(dir_ / "fourbar.csv"), "\n"), 42u);
  // `phiq run` of the file with the same drivers and grid: the same bytes
  const Result direct =
      run("run -q " + model + " --drive crank_joint=2*pi*t --time 0 1 40 -o " + (dir_ / "direct.csv").string());
  ASSERT_EQ(direct.code, 0) << direct.err;
  EXPECT_EQ(slurp(dir_ / "direct.csv"), slurp(dir_ / "fourbar.csv"));
  // without drivers: `phiq check` on the file itself reports its one freedom
  const Result check = run("check " + model);
  ASSERT_EQ(check.code, 0) << check.err;
  EXPECT_NE(check.out.find("dof           1 (1 not driven)"), std::string::npos) << check.out;
  // an inconsistent loop (a door's third hinge 1 cm off the axis of the first): refused, the conflicting joints named
  const fs::path door = write("door.urdf", R"(<robot name="door">
  <link name="frame"/><link name="door"/><link name="pin3"/>
  <joint name="hinge1" type="continuous"><parent link="frame"/><child link="door"/><axis xyz="0 0 1"/></joint>
  <joint name="pin" type="fixed"><parent link="door"/><child link="pin3"/><origin xyz="0 0 2"/></joint>
  <joint name="closing_hinge3" type="revolute"><parent link="frame"/><child link="pin3"/><origin xyz="0.01 0 2"/>
    <axis xyz="0 0 1"/></joint>
</robot>
)");
  const Result conflict = run("check " + door.string());
  EXPECT_EQ(conflict.code, 1);
  EXPECT_NE(conflict.out.find("consistent    no: conflicting hinge1, pin, closing_hinge3"), std::string::npos)
      << conflict.out;
  const Result refused =
      run("convert " + door.string() + " -o " + (dir_ / "door.yaml").string() + " --drive hinge1=t --time 0 1 2");
  ASSERT_EQ(refused.code, 0) << refused.err;
  const Result door_run = run("run " + (dir_ / "door.yaml").string() + " -o " + (dir_ / "door.csv").string());
  EXPECT_EQ(door_run.code, 1);
  EXPECT_NE(door_run.err.find("conflicting constraints: hinge1, pin, closing_hinge3"), std::string::npos)
      << door_run.err;
  EXPECT_FALSE(fs::exists(dir_ / "door.csv"));
  // bad arguments and files: one line, exit 2, nothing written
  const std::string out = " -o " + (dir_ / "out.csv").string();
  const Result no_law = run("run " + model + " --drive crank_joint" + out);
  EXPECT_EQ(no_law.code, 2);
  EXPECT_EQ(no_law.err, "phiq: run: --drive crank_joint: not JOINT=EXPR\n");
  const Result no_joint = run("run " + model + " --drive elbow=t --time 0 1 2" + out);
  EXPECT_EQ(no_joint.code, 2);
  EXPECT_EQ(no_joint.err, "phiq: " + model + ": --drive elbow: the model has no joint 'elbow'\n");
  const Result scene = run("run " + (dir_ / "fourbar.yaml").string() + " --time 0 1 2" + out);
  EXPECT_EQ(scene.code, 2);
  EXPECT_EQ(scene.err, "phiq: run: --drive and --time are for URDF, MJCF and SDF: a scene has its drivers and time\n");
  EXPECT_FALSE(fs::exists(dir_ / "out.csv"));
  for (const std::string& args : {"convert " + model + " --drive crank_joint", "convert " + model + " --drive elbow=t",
                                  "convert " + (dir_ / "none.urdf").string(), "run " + (dir_ / "none.urdf").string()}) {
    SCOPED_TRACE(args);
    const Result r = run(args + " -o " + (dir_ / "out.yaml").string());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(one_phiq_line(r.err));
    EXPECT_FALSE(fs::exists(dir_ / "out.yaml"));
  }
}

}  // namespace test
}  // namespace phiq
