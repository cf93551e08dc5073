// The content of an `.asmt` file as its reader (asmt_reader.cpp) finds it, before it is written as a phiq scene
// (asmt_scene.cpp): parts with their markers, joints between markers, motions on joints and the time settings, each
// with the line it was read at, so that every message names FILE:LINE.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "phiq/import_model.hpp"  // ImportOptions: rates, forces

namespace phiq::detail::asmt {

struct Pose {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // the frame's axes as columns
};

// A marker: a frame fixed in its part (or, on the assembly, in the ground), composed with its RefPoint's frame.
struct Marker {
  std::string name;
  int line = 0;
  Pose pose;
};

struct Part {
  std::string name;
  int line = 0;
  Pose placement;  // in the assembly (= world) frame
  double mass = 0.0;
  Eigen::Vector3d moments = Eigen::Vector3d::Zero();  // principal moments of inertia, in mass_frame's axes
  Pose mass_frame;                                    // the principal mass marker, in the part's frame
  int mass_line = 0;
  std::vector<Marker> markers;
};

// A joint as the file writes it: its type (the section's word, e.g. RevoluteJoint), markers by path, and the
// numbers after them (offset, radiusI, pitchRadius, ...).
struct Joint {
  std::string type, name;
  int line = 0;
  std::string marker_i, marker_j;
  int line_i = 0, line_j = 0;
  std::vector<std::pair<std::string, double>> values;
  std::vector<int> value_lines;
};

struct Motion {
  std::string type, name, joint, expression;  // expression: of `time`, as the file writes it
  int line = 0, joint_line = 0, expression_line = 0;
  // A GeneralMotion: J's origin in I's axes (rIJI1..3) and J's orientation relative to I as Euler angles (angIJJ1..3)
  // about the axes RotationOrder names ("1 2 3": x, then y, then z, each turned with the ones before).
  std::string marker_i, marker_j, rotation_order;
  int line_i = 0, line_j = 0, order_line = 0;
  std::array<std::string, 6> general;
  std::array<int, 6> general_lines{};
};

// Where the scene puts a joint's or motion's forces (asmt_compare.cpp): the constraint whose reaction, or the driver
// whose effort, they are, and marker I's side, about whose origin the file states the moment.
struct ForceSite {
  std::string item, type;  // the joint's or motion's name and type (RevoluteJoint, RotationalMotion, ...) in the file
  std::string name;        // its constraint or driver in the scene
  std::string why_not;     // not empty: phiq writes no reaction for it, and why
  std::string body;        // marker I's body ("ground": the reaction is reported on J's)
  Pose marker;             // marker I in its body
  double offset = 0.0;     // the reaction's point: marker I's origin moved along its z by this
};

struct Assembly {
  std::string path, name;
  std::vector<Marker> ground;  // the assembly's own markers
  std::vector<Part> parts;
  std::vector<Joint> joints;
  std::vector<Motion> motions;
  double tstart = 0.0, tend = 0.0, hout = 0.0;
  int time_line = 0;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  std::vector<std::string> skipped;                         // "FILE:LINE: what: why", once each
  std::vector<std::pair<std::string, std::string>> bodies;  // each part's name and its body's, set by write_scene()
  std::vector<ForceSite> force_sites;                       // each joint's and motion's, set by write_scene()
};

// Reads the tree up to the TimeSeries. Throws SceneError "PATH:LINE: ..." for what cannot be read.
Assembly read_assembly(const std::string& text, const std::string& path);

// The phiq scene of an assembly; adds to a.skipped what the scene leaves out. Throws SceneError for an element that
// has no exact phiq form.
std::string write_scene(Assembly& a, const ImportOptions& options = {});

// "PATH:LINE: what" as a SceneError.
[[noreturn]] void refuse(const std::string& path, int line, const std::string& what);

}  // namespace phiq::detail::asmt
