// What the URDF and MJCF import tests share: their data files, a scene swept as `phiq run` sweeps it (prepared,
// every row kept), a body's pose in q, the four-bar's and slider-crank's closed forms, and the four-bar written as a
// phiq scene by hand, the reference both imports are held to.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "phiq/import_model.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq::test {

inline std::string import_data(const std::string& name) { return std::string(PHIQ_SOURCE_DIR) + "/tests/data/" + name; }

struct ImportRun {
  Scene scene;
  Trace trace;
  SolveStatus status = SolveStatus::kSuccess;
  std::string message;
  const Model& model() const { return *scene.model; }
};

// The scene's text swept at a tolerance of 1e-12 (so that two writings of one mechanism agree to about 1e-13).
inline ImportRun import_sweep(const std::string& yaml, const std::string& path) {
  ImportRun r;
  r.scene = parse_scene(yaml, path);
  r.scene.sweep.newton.tolerance = r.scene.sweep.assembly.tolerance = 1e-12;
  SquareScene square;
  const SolveStatus prepared = prepare_scene(*r.scene.model, r.scene.sweep.t_begin, r.scene.sweep.assembly, &square);
  if (prepared != SolveStatus::kSuccess) {
    r.status = prepared, r.message = square.assembly.message;
    return r;
  }
  const Model& m = square.model(*r.scene.model);
  Workspace ws(m);
  ws.q = square.start;
  SweepSummary summary;
  r.status = sweep(m, r.scene.sweep, &r.trace, &summary, &ws);
  r.message = summary.message;
  return r;
}

inline Eigen::Matrix3d import_rotation(const Model& m, const Eigen::VectorXd& q, const std::string& body) {
  const Index e0 = m.coordinate_index(body + "_e0");
  return Eigen::Quaterniond(q(e0), q(e0 + 1), q(e0 + 2), q(e0 + 3)).normalized().toRotationMatrix();
}
// The world position of the point `at` of a body (in its frame).
inline Eigen::Vector3d import_point(const Model& m, const Eigen::VectorXd& q, const std::string& body,
                                    const Eigen::Vector3d& at = Eigen::Vector3d::Zero()) {
  return q.segment<3>(m.coordinate_index(body + "_x")) + import_rotation(m, q, body) * at;
}
// The turn of a body's x axis about world z.
inline double import_yaw(const Model& m, const Eigen::VectorXd& q, const std::string& body) {
  const Eigen::Matrix3d R = import_rotation(m, q, body);
  return std::atan2(R(1, 0), R(0, 0));
}

// The four-bar of tests/data/urdf/fourbar.urdf and mjcf/fourbar.xml: crank a about the origin, coupler b, rocker c
// about (d, 0), on the upper branch: the rocker's tip at the crank angle θ2.
inline Eigen::Vector3d fourbar_rocker_tip(double theta2) {
  const double a = 0.2, b = 0.5, c = 0.4, d = 0.45;
  const Eigen::Vector2d A(a * std::cos(theta2), a * std::sin(theta2)), D(d, 0);
  const Eigen::Vector2d AD = D - A;
  const double L = AD.norm(), phi = std::atan2(AD.y(), AD.x());
  const double theta3 = phi + std::acos((b * b + L * L - c * c) / (2 * b * L));
  const Eigen::Vector2d B = A + b * Eigen::Vector2d(std::cos(theta3), std::sin(theta3));
  return Eigen::Vector3d(B.x(), B.y(), 0);
}
// The slider-crank of slider_crank.urdf/.xml: crank 0.1, rod 0.35, the slider's x at the crank angle θ.
inline double slider_crank_x(double theta) {
  const double a = 0.1, b = 0.35;
  return a * std::cos(theta) + std::sqrt(b * b - a * a * std::sin(theta) * std::sin(theta));
}

// The five-bar of five_bar.urdf/.xml: cranks 0.3 about (0, 0) and (0.4, 0) at θ1, θ2, distal links 0.4 meeting at
// the end effector, on the upper branch.
inline Eigen::Vector3d five_bar_effector(double theta1, double theta2) {
  const double l1 = 0.3, l2 = 0.4;
  const Eigen::Vector2d A1 = l1 * Eigen::Vector2d(std::cos(theta1), std::sin(theta1));
  const Eigen::Vector2d A2 = Eigen::Vector2d(0.4, 0) + l1 * Eigen::Vector2d(std::cos(theta2), std::sin(theta2));
  const Eigen::Vector2d d = A2 - A1;
  const double h = std::sqrt(l2 * l2 - d.squaredNorm() / 4);
  const Eigen::Vector2d E = A1 + d / 2 + h * Eigen::Vector2d(-d.y(), d.x()) / d.norm();
  return Eigen::Vector3d(E.x(), E.y(), 0);
}

// The same four-bar written as a phiq scene, driven as the tests drive the imports (crank angle π/3 + 2πt).
inline constexpr const char* kFourbarByHand = R"(phiq: 1
dimension: 3
bodies:
  crank: {at: [0, 0, 0], orientation: {axis: [0, 0, 1], angle: 1.0471975511965976}}
  coupler: {at: [0.1, 0.17320508075688773, 0], orientation: {axis: [0, 0, 1], angle: 0.4412688833019244}}
  rocker: {at: [0.45, 0, 0], orientation: {axis: [0, 0, 1], angle: 1.3126765347553853}}
constraints:
  - {name: O, type: revolute, between: [{body: ground}, {body: crank}]}
  - {name: A, type: revolute, between: [{body: crank, at: [0.2, 0, 0]}, {body: coupler}]}
  - {name: D, type: revolute, between: [{body: ground, at: [0.45, 0, 0]}, {body: rocker}]}
  - {name: B, type: revolute, between: [{body: rocker, at: [0.4, 0, 0]}, {body: coupler, at: [0.5, 0, 0]}]}
drivers:
  - {name: motor, joint: O, law: {type: expression, f: "pi/3 + 2*pi*t"}}
time: {start: 0, end: 1, steps: 40}
)";

}  // namespace phiq::test
