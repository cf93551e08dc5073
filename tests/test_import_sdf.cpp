// SDF files read as phiq scenes through libsdformat (phiq/import_model.hpp), tests/data/sdf/: the four-bar, whose
// loop SDF closes natively, against its closed form and the scene written by hand; the joint types phiq reads; bad
// input one line naming FILE:LINE.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "cli_test_support.hpp"
#include "import_test_support.hpp"
#include "import/sdf_module.hpp"
#include "phiq/rank_analysis.hpp"

#include <dlfcn.h>

namespace phiq {
namespace {

using test::file_text, test::import_data, test::import_sweep;

std::string SdfError(const std::string& text) {
  try {
    (void)import_sdf(text, "bad.sdf");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

int SdfLineOf(const std::string& text, const std::string& what) {
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find(what)), '\n'));
}

TEST(SdfImport, FourBarClosedNativelyFollowsItsClosedFormAndTheSceneWrittenByHand) {
  const std::string path = import_data("sdf/fourbar.sdf");
  ImportOptions o;
  o.drives = {{"crank_joint", "2*pi*t"}}, o.t_end = 1, o.steps = 40;
  const ModelImport imported = import_sdf(file_text(path), path, o);
  EXPECT_EQ(imported.bodies, 3);
  EXPECT_EQ(imported.joints, 4);
  EXPECT_EQ(imported.loops, 1);
  const test::ImportRun sdf = import_sweep(imported.yaml, path);
  ASSERT_EQ(sdf.status, SolveStatus::kSuccess) << sdf.message;
  const test::ImportRun hand = import_sweep(test::kFourbarByHand, "fourbar_by_hand.yaml");
  ASSERT_EQ(hand.status, SolveStatus::kSuccess) << hand.message;
  ASSERT_EQ(sdf.trace.q.size(), 41u);
  for (std::size_t k = 0; k < sdf.trace.q.size(); ++k) {
    const double t = sdf.trace.t[k];
    const Eigen::Vector3d tip = test::import_point(sdf.model(), sdf.trace.q[k], "coupler", {0.5, 0, 0});
    EXPECT_LT((tip - test::fourbar_rocker_tip(M_PI / 3 + 2 * M_PI * t)).norm(), 1e-10) << "t = " << t;
    for (const char* body : {"crank", "coupler", "rocker"}) {
      EXPECT_LT((test::import_point(sdf.model(), sdf.trace.q[k], body) -
                 test::import_point(hand.model(), hand.trace.q[k], body))
                    .norm(),
                1e-12)
          << body << " at t = " << t;
      EXPECT_LT((test::import_rotation(sdf.model(), sdf.trace.q[k], body) -
                 test::import_rotation(hand.model(), hand.trace.q[k], body))
                    .norm(),
                1e-12)
          << body << " at t = " << t;
    }
  }
  EXPECT_NE(imported.yaml.find("{body: rocker, mass: 0.5, center_of_mass: [0.2, 0, 0]"), std::string::npos);
  const std::string text = file_text(path);
  EXPECT_NE(imported.yaml.find("limits:\n  - {joint: coupler_joint, range: [-3, 3]}\n"), std::string::npos);
  for (const char* what : {"<sensor", "<plugin"}) {
    const std::string line = path + ":" + std::to_string(SdfLineOf(text, what)) + ": ";
    EXPECT_EQ(std::count_if(imported.skipped.begin(), imported.skipped.end(),
                            [&](const std::string& s) { return s.rfind(line, 0) == 0; }),
              1)
        << what;
  }
  EXPECT_EQ(imported.skipped.size(), 2u);
}

TEST(SdfImport, EveryJointTypeLeavesItsFreedoms) {
  const std::string path = import_data("sdf/joint_zoo.sdf");
  const ModelImport imported = import_sdf(file_text(path), path);
  for (const char* kind : {"type: rigid", "type: prismatic", "type: spherical", "type: universal", "type: revolute"})
    EXPECT_NE(imported.yaml.find(kind), std::string::npos) << kind;
  const Scene scene = parse_scene(imported.yaml, path);
  const Eigen::VectorXd q = scene.model->initial_positions();
  EXPECT_EQ(analyse_rank(*scene.model, q, 0.0).dof, 13);  // prismatic 1, ball 3, universal 2, continuous 1, free 6
  Eigen::VectorXd phi(scene.model->num_equations());
  scene.model->residual(q.data(), 0.0, phi.data());
  EXPECT_LT(phi.lpNorm<Eigen::Infinity>(), 1e-12);
}

// A nested model's links and joints (arm::link, arm::wrist) placed by the model's pose: shoulder at angle t, wrist
// at 2t; arm::link turns about its origin (1, 0.5, 0), arm::tip 0.5 m from it.
TEST(SdfImport, NestedModelIsPlacedByItsPoseAndItsJointsScoped) {
  const std::string path = import_data("sdf/nested_arm.sdf");
  ImportOptions o;
  o.drives = {{"shoulder", "t"}, {"arm::wrist", "2*t"}}, o.t_end = 1, o.steps = 10;
  const ModelImport imported = import_sdf(file_text(path), path, o);
  EXPECT_EQ(imported.bodies, 3);
  EXPECT_EQ(imported.joints, 3);
  EXPECT_EQ(imported.loops, 0);
  const test::ImportRun r = import_sweep(imported.yaml, path);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 11u);
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    const Eigen::VectorXd& q = r.trace.q[k];
    EXPECT_LT((test::import_point(r.model(), q, "arm__link") - Eigen::Vector3d(1, 0.5, 0)).norm(), 1e-10) << t;
    EXPECT_LT((test::import_point(r.model(), q, "arm__tip") -
               Eigen::Vector3d(1 - 0.5 * std::sin(t), 0.5 + 0.5 * std::cos(t), 0))
                  .norm(),
              1e-10)
        << t;
    EXPECT_NEAR(test::import_yaw(r.model(), q, "arm__link"), std::remainder(M_PI / 2 + t, 2 * M_PI), 1e-10) << t;
    EXPECT_NEAR(test::import_yaw(r.model(), q, "arm__tip"), std::remainder(M_PI / 2 + 3 * t, 2 * M_PI), 1e-10) << t;
  }
}

TEST(SdfImport, BadInputIsOneLineNamingFileAndLine) {
  const std::string good = file_text(import_data("sdf/fourbar.sdf"));
  ASSERT_EQ(SdfError(good), "");
  auto starts = [](const std::string& error, const std::string& start) {
    EXPECT_EQ(error.rfind(start, 0), 0u) << error << "\nexpected to start with: " << start;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  };
  starts(SdfError(good.substr(0, good.find("<joint name=\"rocker_joint\""))), "bad.sdf");
  const std::string screw = test::replace_first(good, "type=\"continuous\"", "type=\"screw\"");
  starts(SdfError(screw),
         "bad.sdf:" + std::to_string(SdfLineOf(good, "type=\"continuous\"")) + ": joint 'crank_joint'");
  starts(SdfError(test::replace_first(good, "<child>rocker</child>", "<child>ghost</child>")), "bad.sdf");
  EXPECT_NE(SdfError(test::replace_first(good, "<child>rocker</child>", "<child>ghost</child>")).find("ghost"),
            std::string::npos);
}

}  // namespace

namespace test {

TEST_F(Cli, SdfConvertWritesTheTextADirectReadSolves) {
  const std::string model = import_data("sdf/fourbar.sdf");
  const Result convert =
      run("convert " + model + " -o " + (dir_ / "fb.yaml").string() + " --drive crank_joint=2*pi*t --time 0 1 10");
  ASSERT_EQ(convert.code, 0) << convert.err;
  ImportOptions o;
  o.drives = {{"crank_joint", "2*pi*t"}}, o.t_end = 1, o.steps = 10;
  EXPECT_EQ(slurp(dir_ / "fb.yaml"), import_sdf(file_text(model), model, o).yaml);
  const Result check = run("check " + model);
  ASSERT_EQ(check.code, 0) << check.err;
  EXPECT_NE(check.out.find("dof           1 (1 not driven)"), std::string::npos) << check.out;
}

// A model pulled in by <include><uri>model://arm</uri>, found in a resource folder (the variable libsdformat does not
// search itself, GZ_SIM_RESOURCE_PATH: phiq's find-file callback), placed by the include's pose and turned by the
// main file's hinge; its element phiq does not map listed at its own file and line. Found in no folder: one line
// naming the file, the <include>'s line and the URI, exit 2, nothing written.
TEST_F(Cli, SdfIncludeIsFoundOnTheResourcePathsOrRefusedInOneLine) {
  write("models/arm/model.config",
        "<?xml version=\"1.0\"?>\n<model><name>arm</name><sdf version=\"1.8\">model.sdf</sdf></model>\n");
  const fs::path arm = write("models/arm/model.sdf",
                             "<?xml version=\"1.0\"?>\n<sdf version=\"1.8\">\n<model name=\"arm\">\n"
                             "<link name=\"link\">\n<pose>0.5 0 0 0 0 0</pose>\n<gravity>false</gravity>\n</link>\n"
                             "</model>\n</sdf>\n");
  const std::string main_text =
      "<?xml version=\"1.0\"?>\n<sdf version=\"1.8\">\n<model name=\"robot\">\n<link name=\"base\"/>\n"
      "<joint name=\"fix\" type=\"fixed\"><parent>world</parent><child>base</child></joint>\n"
      "<include>\n<uri>model://arm</uri>\n<pose>0 0 1 0 0 0</pose>\n</include>\n"
      "<joint name=\"hinge\" type=\"revolute\"><parent>base</parent><child>arm::link</child>"
      "<pose relative_to=\"base\">0 0 1 0 0 0</pose><axis><xyz>0 0 1</xyz></axis></joint>\n</model>\n</sdf>\n";
  const std::string model = write("robot.sdf", main_text).string();
  for (const char* variable : {"SDF_PATH", "GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH"})
    set_env(variable, (dir_ / "none").string());
  set_env("GZ_SIM_RESOURCE_PATH", "/nonexistent:" + (dir_ / "models").string());
  ImportOptions o;
  o.drives = {{"hinge", "t"}}, o.t_end = 1, o.steps = 4;
  const ModelImport imported = import_sdf(main_text, model, o);
  EXPECT_EQ(imported.bodies, 2);
  EXPECT_EQ(imported.joints, 2);
  const std::string gravity = arm.string() + ":6: <link><gravity>: not kinematics, or drawn from the visuals";
  EXPECT_EQ(std::count(imported.skipped.begin(), imported.skipped.end(), gravity), 1) << imported.skipped.front();
  const ImportRun r = import_sweep(imported.yaml, model);
  ASSERT_EQ(r.status, SolveStatus::kSuccess) << r.message;
  ASSERT_EQ(r.trace.q.size(), 5u);
  for (std::size_t k = 0; k < r.trace.q.size(); ++k) {
    const double t = r.trace.t[k];
    const Eigen::Vector3d at(0.5 * std::cos(t), 0.5 * std::sin(t), 1);
    EXPECT_LT((import_point(r.model(), r.trace.q[k], "arm__link") - at).norm(), 1e-10) << "t = " << t;
  }
  // no folder holds it
  set_env("GZ_SIM_RESOURCE_PATH", (dir_ / "none").string());
  const Result refused = run("convert " + model + " -o " + (dir_ / "out.yaml").string());
  EXPECT_EQ(refused.code, 2);
  EXPECT_EQ(refused.err, "phiq: " + model +
                             ":7: <include> model://arm: found in no folder of SDF_PATH, GZ_SIM_RESOURCE_PATH or "
                             "IGN_GAZEBO_RESOURCE_PATH (each a list of folders, separated by ':', that hold the "
                             "model's folder)\n");
  EXPECT_FALSE(fs::exists(dir_ / "out.yaml"));
}

// What `ldd` lists for the file: every shared library a process of it maps at start.
std::string SdfStartLibraries(const std::string& file) {
  std::string out;
  if (FILE* p = popen(("ldd " + file).c_str(), "r")) {
    char buf[4096];
    for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    pclose(p);
  }
  return out;
}

// libsdformat (and ignition-math, whose header compiles a regex in every file's static initialiser) is mapped only
// by a process that reads an SDF file: the module, found beside the build or by PHIQ_SDF_MODULE, carries it.
TEST_F(Cli, SdfIsReadByAModuleOnlyAnSdfFileLoads) {
  const std::string cli = SdfStartLibraries(PHIQ_CLI), module = SdfStartLibraries(PHIQ_SDF_MODULE_FILE);
  ASSERT_NE(cli.find("libyaml-cpp"), std::string::npos) << cli;
  EXPECT_EQ(cli.find("sdformat"), std::string::npos) << cli;
  EXPECT_EQ(cli.find("ignition"), std::string::npos) << cli;
  EXPECT_NE(module.find("libsdformat12"), std::string::npos) << module;

  void* handle = dlopen(PHIQ_SDF_MODULE_FILE, RTLD_NOW | RTLD_LOCAL);
  ASSERT_NE(handle, nullptr) << dlerror();
  auto entry = reinterpret_cast<decltype(&phiq_sdf_reader)>(dlsym(handle, "phiq_sdf_reader"));
  ASSERT_NE(entry, nullptr);
  using detail::mechanism::Mechanism, detail::mechanism::kSdfModuleAbi;
  EXPECT_EQ(entry(kSdfModuleAbi + 1, sizeof(Mechanism)), nullptr);
  EXPECT_EQ(entry(kSdfModuleAbi, sizeof(Mechanism) + 8), nullptr);
  EXPECT_NE(entry(kSdfModuleAbi, sizeof(Mechanism)), nullptr);

  const std::string model = import_data("sdf/fourbar.sdf");
  const Result missing = run_prefixed("PHIQ_SDF_MODULE=" + (dir_ / "none.so").string() + " ", "check " + model);
  EXPECT_EQ(missing.code, 2);
  EXPECT_TRUE(one_phiq_line(missing.err));
  EXPECT_NE(missing.err.find(model + ": reading SDF needs phiq's SDFormat module: libphiq_sdf.so not found"),
            std::string::npos)
      << missing.err;
  const Result foreign =
      run_prefixed("PHIQ_SDF_MODULE=" + write("fake.so", "not ELF").string() + " ", "check " + model);
  EXPECT_EQ(foreign.code, 2);
  EXPECT_TRUE(one_phiq_line(foreign.err));
  EXPECT_NE(foreign.err.find("cannot load"), std::string::npos) << foreign.err;
  EXPECT_EQ(missing.out + foreign.out, "");
}

}  // namespace test
}  // namespace phiq
