// URDF meshes named `package://PACKAGE/FILE` (phiq/import_model.hpp): found in a folder above the URDF (written
// relative to it) or on ROS_PACKAGE_PATH (written absolute); those found nowhere listed once as not mapped, or
// refused when the shapes are what is asked for (ImportOptions::need_geometry, `phiq animate`).
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "cli_test_support.hpp"  // test::TestFolder
#include "import_test_support.hpp"

namespace phiq {
namespace {

namespace fs = std::filesystem;

// A workspace in a folder of its own: mypkg/urdf/robot.urdf with mypkg/meshes/arm.stl beside it, and
// ws/otherpkg/meshes/hand.stl for ROS_PACKAGE_PATH (test::TestFolder puts ROS_PACKAGE_PATH back at the end).
class UrdfPackages : public test::TestFolder {
 protected:
  void SetUp() override {
    TestFolder::SetUp();
    const char* stl =
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
        "endfacet\nendsolid t\n";
    for (const char* mesh : {"mypkg/meshes/arm.stl", "ws/otherpkg/meshes/hand.stl"}) write(mesh, stl);
    urdf_ = write("mypkg/urdf/robot.urdf", kRobot).string();
    set_env("ROS_PACKAGE_PATH", "/nonexistent:" + (dir_ / "ws").string() + "/");
  }
  static constexpr const char* kRobot = R"(<robot name="packaged">
  <link name="base"/>
  <link name="arm">
    <visual><geometry><mesh filename="package://mypkg/meshes/arm.stl"/></geometry></visual>
  </link>
  <link name="hand">
    <visual><geometry><mesh filename="package://otherpkg/meshes/hand.stl" scale="0.001 0.001 0.001"/></geometry></visual>
    <visual><geometry><mesh filename="package://ghost/a.stl"/></geometry></visual>
  </link>
  <link name="finger">
    <visual><geometry><mesh filename="package://ghost/b.stl"/></geometry></visual>
  </link>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
  <joint name="wrist" type="fixed"><parent link="arm"/><child link="hand"/><origin xyz="1 0 0"/></joint>
  <joint name="knuckle" type="fixed"><parent link="hand"/><child link="finger"/><origin xyz="0.1 0 0"/></joint>
</robot>
)";
  std::string urdf_;
};

TEST_F(UrdfPackages, MeshesAreFoundAboveTheFileAndOnTheRosPackagePathAndTheMissingListedOnce) {
  const ModelImport imported = import_urdf(test::file_text(urdf_), urdf_);
  EXPECT_NE(imported.yaml.find("{type: mesh, file: \"../meshes/arm.stl\", scale: 1"), std::string::npos)
      << imported.yaml;
  const std::string hand = (dir_ / "ws/otherpkg/meshes/hand.stl").lexically_normal().string();
  EXPECT_NE(imported.yaml.find("{type: mesh, file: \"" + hand + "\", scale: 0.001"), std::string::npos)
      << imported.yaml;
  const std::string missing = urdf_ +
                              ":8: <visual> mesh of a package not found (2 in all): its package is neither "
                              "on ROS_PACKAGE_PATH nor a folder above the file (the link is drawn without)";
  EXPECT_EQ(std::count(imported.skipped.begin(), imported.skipped.end(), missing), 1);
  EXPECT_EQ(imported.skipped.size(), 1u) << imported.skipped.front();
  // the scene reads both meshes: one triangle each
  const Scene scene = parse_scene(imported.yaml, urdf_);
  EXPECT_EQ(scene.model->num_coordinates(), 3 * 7);
  // without the workspace on ROS_PACKAGE_PATH the hand's mesh is missing too: 3 in all
  unsetenv("ROS_PACKAGE_PATH");
  const ModelImport without = import_urdf(test::file_text(urdf_), urdf_);
  ASSERT_EQ(without.skipped.size(), 1u);
  EXPECT_EQ(without.skipped.front().rfind(urdf_ + ":7: <visual> mesh of a package not found (3 in all)", 0), 0u)
      << without.skipped.front();
}

TEST_F(UrdfPackages, AMissingPackageIsRefusedWhenTheShapesAreAskedFor) {
  // `phiq animate` draws the shapes: exit 2, its one line, nothing written
  const fs::path out = dir_ / "robot.html", err = dir_ / "stderr.txt";
  const std::string command =
      std::string(PHIQ_CLI) + " animate " + urdf_ + " -o " + out.string() + " 2>" + err.string();
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << status;
  EXPECT_EQ(test::file_text(err.string()), "phiq: animate: " + urdf_ +
                                               ":8: <visual> mesh 'package://ghost/a.stl': its package is neither "
                                               "on ROS_PACKAGE_PATH nor a folder above the file\n");
  EXPECT_FALSE(fs::exists(out));
  ImportOptions drawn;
  drawn.need_geometry = true;
  try {
    (void)import_urdf(test::file_text(urdf_), urdf_, drawn);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), urdf_ +
                                         ":8: <visual> mesh 'package://ghost/a.stl': its package is neither on "
                                         "ROS_PACKAGE_PATH nor a folder above the file");
  }
}

}  // namespace
}  // namespace phiq
