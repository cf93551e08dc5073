// A spatial mechanism as a robot description gives it (URDF, MJCF): bodies placed in the world at the model's pose,
// joints between two bodies' local frames, couplers between joints' coordinates. The readers (urdf_reader.cpp,
// mjcf_reader.cpp) fill it, each element with its file line; write_mechanism_scene() (mechanism_scene.cpp) writes it
// as the text of a phiq scene (models/README.md), so that `phiq convert` and a direct read are one text.
#pragma once

#include <Eigen/Dense>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "phiq/import_model.hpp"

namespace tinyxml2 {
class XMLDocument;
}

namespace phiq::detail::mechanism {

struct Pose {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // the frame's axes as columns
  Pose operator*(const Pose& b) const { return Pose{p + R * b.p, R * b.R}; }
  Pose inverse() const { return Pose{-R.transpose() * p, R.transpose()}; }
};

// A shape of phiq's parts (models/README.md, Parts), placed in its body's frame.
struct Shape {
  std::string type;                                // box, sphere, cylinder, capsule, plane, mesh
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // box: the full edges; plane: x, y
  double radius = 0.0, length = 0.0, scale = 1.0;
  std::string file;  // a mesh's file, as phiq's scene names it (relative to the scene's folder or absolute)
  Pose at;
  std::optional<Eigen::Vector4d> rgba;
};

struct Body {
  std::string name;  // the file's
  int line = 0;
  std::string file;  // the file of `line` when not Mechanism::path (an MJCF <include>d file)
  Pose world;        // at the model's pose
  bool has_mass = false;
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      // in the body's frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the centre of mass, in the body's axes
  std::optional<double> density;                      // mass from the shapes at this density (when !has_mass)
  std::vector<Shape> shapes;
  static Body named(std::string name, int line, const Pose& world = Pose{}) {
    Body b;
    b.name = std::move(name), b.line = line, b.world = world;
    return b;
  }
};

// One side of a joint: a point, an axis and a reference direction in its body's frame.
struct Side {
  int body = 0;  // index in Mechanism::bodies; 0 is the ground
  Eigen::Vector3d at = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::UnitZ(), ref = Eigen::Vector3d::UnitX();
};

struct Joint {
  std::string name;  // the file's
  int line = 0;
  std::string file;  // as Body::file
  std::string kind;  // phiq's: revolute, prismatic, rigid, spherical, planar, cylindrical; "" for a free body
  Side parent, child;
  bool closing = false;  // closes a loop (not a tree edge)
  // A spring-damper on a revolute's angle or a prismatic's travel (both 0 at the file's pose): stiffness
  // (N·m/rad, N/m), damping (N·m·s/rad, N·s/m), its free value (rad, m), a dry friction (N·m, N) and a rotor's
  // inertia turning with it (kg·m², kg: MuJoCo's armature): the scene's torsional spring on it.
  double stiffness = 0.0, damping = 0.0, free = 0.0, friction = 0.0, armature = 0.0;
  // Its range of motion in the same terms (none unless lower < upper), its motor's speed limit (rad/s or m/s; 0:
  // none) and effort range (N·m or N; none unless effort_lower < effort_upper): the scene's `limits` (the effort's
  // where the joint is driven).
  double lower = 0.0, upper = 0.0, velocity = 0.0, effort_lower = 0.0, effort_upper = 0.0;
};

// joint = multiplier · other + offset (a URDF mimic, an MJCF joint equality), or joint = offset when other < 0.
struct Coupler {
  std::string name;  // of the element, for messages and the constraint's name
  int line = 0;
  int joint = -1, other = -1;  // indices in Mechanism::joints
  double multiplier = 1.0, offset = 0.0;
  std::string file;  // as Body::file
};

struct Mechanism {
  std::string path, format, name, units;  // format: "URDF", "MJCF"; units: the comment stating them
  std::vector<Body> bodies;               // bodies[0]: the ground (the root link, the worldbody)
  std::vector<Joint> joints;
  std::vector<Coupler> couplers;
  std::vector<std::string> skipped;  // "FILE:LINE: what: why", once each
  // Gravity (m/s²) as the file states it or as the format's default is, and where it comes from, for the scene's
  // comment ("<option gravity> at FILE:LINE", "URDF states none: the conventional value").
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};
  std::string gravity_from;
  // Elements not mapped, by what they are: the first line, how many, why (written once each as `skipped`).
  struct Unmapped {
    int line = 0, count = 0;
    std::string why, file;  // file: as Body::file
  };
  std::map<std::string, Unmapped> unmapped;
  void skip(const std::string& what, int line, const std::string& why, const std::string& file = "") {
    Unmapped& u = unmapped[what];
    if (u.count++ == 0) u.line = line, u.why = why, u.file = file;
  }
  // The file an element's line is in.
  const std::string& file_of(const std::string& file) const { return file.empty() ? path : file; }
};

// The phiq scene of a mechanism, with the drivers and time grid of `options`. Throws SceneError naming the file for
// a driver of an unknown joint or one that no driver measure fits.
std::string write_mechanism_scene(Mechanism& m, const ImportOptions& options);

// The gravity the scene of `m` holds (options.gravity, else the file's or its format's) and "[X, Y, Z] m/s²: where
// it comes from". Throws SceneError naming the file for a gravity given that is not finite.
std::pair<Eigen::Vector3d, std::string> gravity_used(const Mechanism& m, const ImportOptions& options);

// What an import made of `m` (whose joints beyond a spanning tree number `loops`): its counts, its scene
// (write_mechanism_scene()) and what was not mapped. Throws as write_mechanism_scene().
ModelImport mechanism_import(Mechanism& m, int loops, const ImportOptions& options);

// A unit vector perpendicular to `axis` (which need not be unit): the reference direction of a joint frame.
Eigen::Vector3d perpendicular(const Eigen::Vector3d& axis);

// Rotation of an axis-angle (axis need not be unit).
Eigen::Matrix3d axis_angle(const Eigen::Vector3d& axis, double angle);

// "PATH:LINE: what" as a SceneError ("PATH: what" for line 0).
[[noreturn]] void refuse(const std::string& path, int line, const std::string& what);

// Refuses a document tinyxml2 could not parse, at its error's line: "malformed XML", or elements nested deeper than
// tinyxml2 reads (a well-formed file, named as such).
[[noreturn]] void refuse_xml(const std::string& path, const tinyxml2::XMLDocument& doc);

}  // namespace phiq::detail::mechanism
