// Joint reactions (phiq/joint_reactions.hpp, the scene's `output: reactions`): every kind that states a
// ReactionSite passes a virtual-work check (the written wrench does on its body the work −λᵀ δΦ does, by finite
// differences); a massive four-bar's pins satisfy every link's Newton–Euler equations written here, with no moment
// at a pin; a screw jack's thread carries its nut's weight and inertia with Mz = −p Fz / 2π; a redundant door's
// hinges give the minimum-norm multipliers of a dense pseudo-inverse and are named indeterminate, with its driver's
// torque unique.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/phiq.hpp"
#include "reaction_rows.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

// A model of two moving bodies joined by one constraint of `joint` (a scene constraint line naming bodies a, b).
std::string reaction_two_bodies_text(bool spatial, const std::string& joint) {
  std::string text = "phiq: 1\nname: two\n";
  if (spatial)
    text +=
        "dimension: 3\n"
        "coordinates: {xa: 0.1, ya: 0.2, za: -0.3, a0: 0.8, a1: 0.2, a2: -0.4, a3: 0.4, "
        "xb: 0.7, yb: -0.1, zb: 0.4, b0: 0.5, b1: 0.5, b2: 0.5, b3: 0.5}\n"
        "bodies: {a: [xa, ya, za, a0, a1, a2, a3], b: [xb, yb, zb, b0, b1, b2, b3]}\n";
  else
    text +=
        "coordinates: {xa: 0.1, ya: 0.2, pa: 0.3, xb: 0.7, yb: -0.1, pb: 1.1}\n"
        "bodies: {a: [xa, ya, pa], b: [xb, yb, pb]}\n";
  return text + "constraints:\n  - " + joint + "\ntime: {start: 0, end: 1, steps: 1}\n";
}
Scene reaction_two_bodies(bool spatial, const std::string& joint) {
  return parse_scene(reaction_two_bodies_text(spatial, joint), "two.yaml");
}

kin3::V3 reaction_rotation_step(const RotationMatrix& plus, const RotationMatrix& minus, double h2) {
  // R₊ R₋ᵀ ≈ I + [2h δθ]×, its skew part 2h δθ twice over: δθ per unit step, world axes
  double m[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      m[3 * i + j] = 0.0;
      for (int k = 0; k < 3; ++k) m[3 * i + j] += plus[3 * i + k] * minus[3 * j + k];
    }
  return {(m[7] - m[5]) / (4 * h2), (m[2] - m[6]) / (4 * h2), (m[3] - m[1]) / (4 * h2)};
}

// The block holding constraint c, and its index there.
std::pair<const ConstraintBlock*, std::size_t> reaction_block_of(const Model& m, Index c) {
  for (const auto& b : m.blocks())
    for (std::size_t i = 0; i < b->size(); ++i)
      if (b->first_row(i) == m.constraints()[static_cast<std::size_t>(c)].first_row) return {b.get(), i};
  return {nullptr, 0};
}

// The virtual-work identity for the constraint of `s`: for random λ and random displacements δq of body a's
// coordinates (Euler parameters moved perpendicular to e), −λᵀ δΦ = F · δP + M_P · δθ, δP the displacement of
// the body's point at P and δθ its rotation, both from finite differences of the body's pose.
void expect_reaction_virtual_work(const Scene& s, bool spatial) {
  const Model& m = *s.model;
  const Index c = m.find_constraint("j");
  ASSERT_GE(c, 0);
  ASSERT_EQ(reaction_width(m, c), spatial ? 6 : 3);
  JointReactions jr(m, std::vector<Index>{c});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::VectorXd q = m.initial_positions();
  PartFrame frame;
  frame.kind = spatial ? PartFrameKind::kSpatialBody : PartFrameKind::kPlanarBody;
  if (spatial)
    frame.spatial = Frame3{Slot::coordinate(0), Slot::coordinate(1), Slot::coordinate(2), Slot::coordinate(3),
                           Slot::coordinate(4), Slot::coordinate(5), Slot::coordinate(6)};
  else
    frame.planar = Frame2{Slot::coordinate(0), Slot::coordinate(1), Slot::coordinate(2)};
  const int body_coordinates = spatial ? 7 : 3;
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m.num_equations());
    const ConstraintInfo& info = m.constraints()[static_cast<std::size_t>(c)];
    for (Index r = info.first_row; r < info.first_row + info.rows; ++r) lambda(r) = u(rng);
    double w[6];
    jr.evaluate(q.data(), 0.0, lambda, w);
    const kin3::V3 force = spatial ? kin3::V3{w[0], w[1], w[2]} : kin3::V3{w[0], w[1], 0.0};
    const kin3::V3 moment = spatial ? kin3::V3{w[3], w[4], w[5]} : kin3::V3{0.0, 0.0, w[2]};
    Eigen::VectorXd dq = Eigen::VectorXd::Zero(m.num_coordinates());
    for (int k = 0; k < body_coordinates; ++k) dq(k) = u(rng);
    if (spatial) {  // δe ⟂ e: a rotation, not a change of |e|
      const Eigen::Vector4d e = q.segment<4>(3), de = dq.segment<4>(3);
      dq.segment<4>(3) = de - e * e.dot(de) / e.squaredNorm();
    }
    const double h = 1e-6;
    const Eigen::VectorXd qp = q + h * dq, qm = q - h * dq;
    Eigen::VectorXd phip(m.num_equations()), phim(m.num_equations());
    m.residual(qp.data(), 0.0, phip.data());
    m.residual(qm.data(), 0.0, phim.data());
    const double work_rows = -lambda.dot(phip - phim) / (2 * h);
    const Pose pp = part_pose(frame, qp.data(), 0.0), pm = part_pose(frame, qm.data(), 0.0),
               p0 = part_pose(frame, q.data(), 0.0);
    const kin3::V3 dtheta = reaction_rotation_step(pp.rotation, pm.rotation, h);
    const kin3::V3 d_origin = (1.0 / (2 * h)) * (pp.at - pm.at);
    // The written moment is about the joint's point P (the kind's ReactionSite): about the origin it is
    // M_O = M_P + (P − O) × F. (That P is the joint's is checked below: a pin has no moment about it.)
    ReactionSite site;
    const auto [block, index] = reaction_block_of(m, c);
    ASSERT_TRUE(block->reaction_site(index, q.data(), site));
    const kin3::V3 m_origin = moment + kin3::cross(site.point - p0.at, force);
    const double best = kin3::dot(force, d_origin) + kin3::dot(m_origin, dtheta);
    EXPECT_NEAR(best, work_rows, 1e-7 * (1.0 + std::fabs(work_rows))) << info.kind << " trial " << trial;
  }
}

TEST(JointReactions, EveryPlanarKindWithASiteDoesTheWorkOfItsMultipliers) {
  for (const std::string joint :
       {"{name: j, type: revolute, between: [{body: a, at: [0.3, -0.2]}, {body: b, at: [-0.1, 0.4]}]}",
        "{name: j, type: prismatic, between: [{body: a, at: [0.3, -0.2]}, {body: b, at: [-0.1, 0.4]}], "
        "axis: [0.6, 0.8], angle: 0.2}",
        "{name: j, type: cam, cam: {body: b, circle: {centre: [0.1, 0.2], radius: 0.5}}, follower: {body: a, at: "
        "[0.3, -0.2]}, roller: 0.05}",
        "{name: j, type: point_on_curve, point: {body: a, at: [0.3, -0.2]}, curve: {body: b, circle: {centre: [0.1, "
        "0.2], radius: 0.5}}}",
        "{name: j, type: flat_cam, cam: {body: b, circle: {centre: [0.1, 0.2], radius: 0.5}}, follower: {body: a, "
        "at: [0.3, -0.2], direction: [0.6, 0.8]}}"}) {
    SCOPED_TRACE(joint);
    expect_reaction_virtual_work(reaction_two_bodies(false, joint), false);
  }
}

TEST(JointReactions, EverySpatialKindWithASiteDoesTheWorkOfItsMultipliers) {
  const std::string sides =
      "between: [{body: a, at: [0.3, -0.2, 0.1], axis: [0, 0.6, 0.8]}, {body: b, at: [-0.1, 0.4, 0.2], "
      "axis: [1, 0, 0]}]";
  for (const char* type : {"spherical", "revolute", "cylindrical", "prismatic", "universal", "planar", "rigid",
                           "point_on_line", "point_on_plane", "screw", "distance"}) {
    SCOPED_TRACE(type);
    const std::string pitch = std::string(type) == "screw"      ? ", pitch: 0.05"
                              : std::string(type) == "distance" ? ", length: 1"
                                                                : "";
    expect_reaction_virtual_work(
        reaction_two_bodies(true, std::string("{name: j, type: ") + type + ", " + sides + pitch + "}"), true);
  }
}

// The reaction of constraint "j" of `s` under random multipliers, in world axes and along the joint's own
// (OutputEfforts::reactions_in_joint_axes), at the initial positions.
std::pair<std::vector<double>, std::vector<double>> reaction_both_axes(const Scene& s, bool spatial, int trial) {
  const Model& m = *s.model;
  const Index c = m.find_constraint("j");
  OutputEfforts e;
  e.reactions.push_back({c, spatial});
  JointReactions world(m, e);
  e.reactions_in_joint_axes = true;
  JointReactions joint(m, e);
  std::mt19937 rng(11 + trial);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(m.num_equations());
  const ConstraintInfo& info = m.constraints()[static_cast<std::size_t>(c)];
  for (Index r = info.first_row; r < info.first_row + info.rows; ++r) lambda(r) = u(rng);
  const Eigen::VectorXd q = m.initial_positions();
  std::vector<double> w(spatial ? 6 : 3), j(spatial ? 6 : 3);
  world.evaluate(q.data(), 0.0, lambda, w.data());
  joint.evaluate(q.data(), 0.0, lambda, j.data());
  return {w, j};
}

// Along the joint's axes, computed here from the scene's numbers (Eigen's quaternion for side a's Euler parameters):
// the world reaction turned, and the loads a joint cannot carry zero for any multipliers — a revolute pair's moment
// about its axis, a slide's force along it — which in world axes they are not.
TEST(JointReactions, AlongTheJointsAxesTheLoadsItCannotCarryAreZero) {
  const std::string planar_at = "between: [{body: a, at: [0.3, -0.2]}, {body: b, at: [-0.1, 0.4]}]";
  const Eigen::Rotation2Dd pa(0.3);
  struct Case {
    std::string joint;
    Eigen::Matrix3d axes;           // columns x, y, z of the joint's frame, world axes
    std::vector<int> cannot_carry;  // components zero along the joint's axes
  };
  Eigen::Matrix3d pin = Eigen::Matrix3d::Identity(), slide = Eigen::Matrix3d::Identity();
  pin.topLeftCorner<2, 2>() = pa.toRotationMatrix();
  const Eigen::Vector2d e = pa * Eigen::Vector2d(0.6, 0.8);
  slide.topLeftCorner<2, 2>() << e.x(), -e.y(), e.y(), e.x();
  std::vector<Case> planar = {
      {"{name: j, type: revolute, " + planar_at + "}", pin, {2}},
      {"{name: j, type: prismatic, " + planar_at + ", axis: [0.6, 0.8], angle: 0.2}", slide, {0}},
      {"{name: j, type: flat_cam, cam: {body: b, circle: {centre: [0.1, 0.2], radius: 0.5}}, follower: {body: a, "
       "at: [0.3, -0.2], direction: [0.6, 0.8]}}",
       slide,
       {0}}};
  for (const Case& k : planar) {
    SCOPED_TRACE(k.joint);
    const Scene s = reaction_two_bodies(false, k.joint);
    for (int trial = 0; trial < 3; ++trial) {
      const auto [w, j] = reaction_both_axes(s, false, trial);
      const Eigen::Vector3d turned = k.axes.transpose() * Eigen::Vector3d(w[0], w[1], 0.0);
      EXPECT_NEAR(j[0], turned.x(), 1e-14);
      EXPECT_NEAR(j[1], turned.y(), 1e-14);
      EXPECT_EQ(j[2], w[2]);
      for (int c : k.cannot_carry) {
        EXPECT_NEAR(j[static_cast<std::size_t>(c)], 0.0, 1e-13) << "component " << c;
        if (c == 0) {
          EXPECT_GT(std::fabs(w[0]), 1e-3);  // (in world axes the slide's force has an x)
        }
      }
    }
  }
  // side a: axis (0, 0.6, 0.8), reference x (the axis is far from x), turned by a's Euler parameters
  const Eigen::Matrix3d ra = Eigen::Quaterniond(0.8, 0.2, -0.4, 0.4).normalized().toRotationMatrix();
  Eigen::Matrix3d spatial_axes;
  spatial_axes.col(2) = ra * Eigen::Vector3d(0, 0.6, 0.8), spatial_axes.col(0) = ra * Eigen::Vector3d(1, 0, 0);
  spatial_axes.col(1) = spatial_axes.col(2).cross(spatial_axes.col(0));
  const std::string sides =
      "between: [{body: a, at: [0.3, -0.2, 0.1], axis: [0, 0.6, 0.8]}, {body: b, at: [0.3, -0.2, 0.1], "
      "axis: [0, 0.6, 0.8]}]}";
  const std::string crossed =
      "between: [{body: a, at: [0.3, -0.2, 0.1], axis: [0, 0.6, 0.8]}, {body: b, at: [0.3, -0.2, 0.1], "
      "axis: [1, 0, 0]}]}";
  const std::vector<std::pair<const char*, std::vector<int>>> spatial = {
      {"revolute", {5}},
      {"cylindrical", {2, 5}},
      {"prismatic", {2}},
      {"universal", {5}},
      {"spherical", {3, 4, 5}},
      {"planar", {0, 1, 5}},
      {"rigid", {}},
      {"screw", {}},
      {"point_on_line", {2, 3, 4, 5}},  // a point sliding and turning on a's axis: pushed across it alone
      {"point_on_plane", {0, 1, 3, 4, 5}}};
  const double pitch = 0.05;  // the screw's: along its axis it carries Fz and Mz = −p Fz / 2π together
  for (const auto& [type, cannot_carry] : spatial) {
    SCOPED_TRACE(type);
    const bool screw = std::string(type) == "screw";
    // both bodies at the same pose and the sides alike (the universal's axes crossed): the joint assembled
    std::string joint =
        std::string("{name: j, type: ") + type + ", " + (std::string(type) == "universal" ? crossed : sides);
    if (screw) joint.insert(joint.size() - 1, ", pitch: " + std::to_string(pitch));
    std::string text = reaction_two_bodies_text(true, joint);
    const std::string b_pose = "xb: 0.7, yb: -0.1, zb: 0.4, b0: 0.5, b1: 0.5, b2: 0.5, b3: 0.5";
    text.replace(text.find(b_pose), b_pose.size(), "xb: 0.1, yb: 0.2, zb: -0.3, b0: 0.8, b1: 0.2, b2: -0.4, b3: 0.4");
    const Scene s = parse_scene(text, "two.yaml");
    for (int trial = 0; trial < 3; ++trial) {
      const auto [w, j] = reaction_both_axes(s, true, trial);
      const Eigen::Vector3d f = spatial_axes.transpose() * Eigen::Vector3d(w[0], w[1], w[2]);
      const Eigen::Vector3d m = spatial_axes.transpose() * Eigen::Vector3d(w[3], w[4], w[5]);
      const double scale = 1.0 + Eigen::Vector3d(w[0], w[1], w[2]).norm() + Eigen::Vector3d(w[3], w[4], w[5]).norm();
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(j[static_cast<std::size_t>(i)], f(i), 1e-12 * scale);
        EXPECT_NEAR(j[static_cast<std::size_t>(3 + i)], m(i), 1e-12 * scale);
      }
      for (int c : cannot_carry) EXPECT_NEAR(j[static_cast<std::size_t>(c)], 0.0, 1e-12 * scale) << "component " << c;
      if (screw) {  // no work in the turn δθ and travel p δθ / 2π the thread lets through, and both loads there
        EXPECT_NEAR(j[5], -pitch / (2 * M_PI) * j[2], 1e-12 * scale);
        EXPECT_GT(std::fabs(j[2]), 1e-3 * scale);
      }
      if (std::string(type) == "revolute") {  // about world z it carries a moment: the axes matter
        EXPECT_GT(std::fabs(w[5]), 1e-3 * scale);
      }
    }
  }
}

// A spatial distance between bodies is a bar with a ball at each end: whatever its multiplier, it pulls end A's body
// at A along B − A and nothing else (no moment about the ball), so along its axes (x from A toward B) it carries
// Fx alone, the bar's tension. Between natural points it is a part's own bar: no reaction.
TEST(JointReactions, ABallEndedBarPullsAlongItselfAlone) {
  const Scene s = reaction_two_bodies(true,
                                      "{name: j, type: distance, between: [{body: a, at: [0.3, -0.2, 0.1]}, "
                                      "{body: b, at: [-0.1, 0.4, 0.2]}], length: 1}");
  const Eigen::Vector3d a =
      Eigen::Vector3d(0.1, 0.2, -0.3) +
      Eigen::Quaterniond(0.8, 0.2, -0.4, 0.4).toRotationMatrix() * Eigen::Vector3d(0.3, -0.2, 0.1);
  const Eigen::Vector3d b = Eigen::Vector3d(0.7, -0.1, 0.4) +
                            Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5).toRotationMatrix() * Eigen::Vector3d(-0.1, 0.4, 0.2);
  const Eigen::Vector3d along = (b - a).normalized();
  for (int trial = 0; trial < 3; ++trial) {
    const auto [w, j] = reaction_both_axes(s, true, trial);
    const Eigen::Vector3d f(w[0], w[1], w[2]);
    EXPECT_GT(f.norm(), 1e-3);
    EXPECT_NEAR(f.cross(along).norm(), 0.0, 1e-12 * f.norm());
    for (int c = 3; c < 6; ++c) EXPECT_NEAR(w[static_cast<std::size_t>(c)], 0.0, 1e-12 * f.norm()) << c;
    EXPECT_NEAR(j[0], f.dot(along), 1e-12 * f.norm());
    for (int c = 1; c < 6; ++c) EXPECT_NEAR(j[static_cast<std::size_t>(c)], 0.0, 1e-12 * f.norm()) << c;
  }
  const Scene natural = parse_scene(
      "phiq: 1\nname: n\ndimension: 3\ncoordinates: {x: 1, y: 0.1, z: 0}\npoints: {O: [0, 0, 0], A: [x, y, z]}\n"
      "constraints:\n  - {name: bar, type: distance, points: [O, A], length: 1}\ntime: {start: 0, end: 1, steps: 1}\n",
      "n.yaml");
  EXPECT_EQ(reaction_width(*natural.model, 0), 0);
  EXPECT_THROW(JointReactions(*natural.model, std::vector<Index>{0}), Error);
}

TEST(JointReactions, KindsWithoutASiteAreRefusedByName) {
  const Scene s = parse_scene(
      "phiq: 1\nname: d\ncoordinates: {x: 1, y: 0.1}\npoints: {O: [0, 0], A: [x, y]}\n"
      "constraints:\n  - {name: bar, type: distance, points: [O, A], length: 1}\ntime: {start: 0, end: 1, steps: 1}\n",
      "d.yaml");
  EXPECT_EQ(reaction_width(*s.model, 0), 0);
  try {
    JointReactions jr(*s.model, std::vector<Index>{0});
    ADD_FAILURE() << "a distance has no reaction site";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("constraint 'bar' (distance) states no joint point"), std::string::npos)
        << e.what();
  }
}

using test::ReactionRows;
using test::sweep_reactions;

// The scene's `reaction_axes`: along a sweep of the massive four-bar, each pin's force along its body's axes is the
// world one turned by that body's angle at the row.
TEST(JointReactions, TheScenesReactionAxesTurnEachPinsForceByItsBody) {
  const std::string base = test::model_file_text("dynamics/fourbar_pin_loads.yaml", "output:");
  const Scene world = parse_scene(base + "output: {velocities: true, accelerations: true, reactions: all}\n", "k.yaml");
  const Scene joint = parse_scene(
      base + "output: {velocities: true, accelerations: true, reactions: all, reaction_axes: joint}\n", "k.yaml");
  EXPECT_FALSE(world.sweep.efforts.reactions_in_joint_axes);
  ASSERT_TRUE(joint.sweep.efforts.reactions_in_joint_axes);
  const Model* swept = nullptr;
  const ReactionRows w = sweep_reactions(world, nullptr, &swept), j = sweep_reactions(joint);
  ASSERT_EQ(w.values.size(), j.values.size());
  const Model& m = *swept;
  const std::vector<OutputReaction>& rs = world.sweep.efforts.reactions;
  ASSERT_GE(rs.size(), 4u);
  for (std::size_t row = 0; row < w.values.size(); ++row)
    for (std::size_t k = 0; k < rs.size(); ++k) {
      ReactionSite site;  // the body the pin's load is on, its angle read here
      const auto [block, index] = reaction_block_of(m, rs[k].constraint);
      ASSERT_TRUE(block->reaction_site(index, w.q[row].data(), site));
      const double psi = site.frame2.psi.of(w.q[row].data());
      const Eigen::Vector2d f(w.values[row][3 * k], w.values[row][3 * k + 1]);
      const Eigen::Vector2d turned = Eigen::Rotation2Dd(-psi) * f;
      EXPECT_NEAR(j.values[row][3 * k], turned.x(), 1e-12 * (1.0 + f.norm())) << row << " " << k;
      EXPECT_NEAR(j.values[row][3 * k + 1], turned.y(), 1e-12 * (1.0 + f.norm())) << row << " " << k;
      EXPECT_EQ(j.values[row][3 * k + 2], w.values[row][3 * k + 2]);
    }
  auto error = [&](const std::string& output) {
    try {
      (void)parse_scene(base + output, "k.yaml");
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("output: {reactions: all, reaction_axes: body}\n").find("reaction_axes: expected `world` or `joint`"),
            std::string::npos);
  EXPECT_NE(error("output: {efforts: all, reaction_axes: joint}\n")
                .find("reaction_axes: the axes of the reactions: list `reactions` too"),
            std::string::npos);
}

// Natural joints along their body's axes (reaction_axes: joint): the four-bar of
// models/dynamics/fourbar_motor_torque.yaml, its coupler massless. A massless link pinned at both ends and loaded
// nowhere else is a two-force member: at B (reported on the coupler, the first part that holds it) the force lies
// along the coupler, nothing across it, though in world axes both components are not zero. At A (reported on the
// crank) the world force turned by the crank's angle; animate --forces turns them back (AnimateHtml).
TEST(JointReactions, ANaturalJointAlongItsBodysAxesShowsAMasslessCouplerPushingAlongItself) {
  std::string base = test::model_file_text("dynamics/fourbar_motor_torque.yaml", "output:");
  const std::string massive =
      "coupler: {frame: {origin: A, x: B}, center_of_mass: [L3/2, 0], mass: 2.0, "
      "inertia: 2.0*L3*L3/12}";
  ASSERT_NE(base.find(massive), std::string::npos);
  base.replace(base.find(massive), massive.size(), "coupler: {frame: {origin: A, x: B}}");
  const std::string out = "output: {velocities: true, accelerations: true, reactions: [A, B]";
  const Scene world = parse_scene(base + out + "}\n", "k.yaml"),
              joint = parse_scene(base + out + ", reaction_axes: joint}\n", "k.yaml");
  const Model* swept = nullptr;
  const ReactionRows w = sweep_reactions(world, nullptr, &swept), j = sweep_reactions(joint);
  ASSERT_EQ(w.values.size(), 121u);
  const Model& m = *swept;
  const Index xa = m.find_coordinate("xA"), ya = m.find_coordinate("yA"), xb = m.find_coordinate("xB"),
              yb = m.find_coordinate("yB");
  double along = 0.0;
  for (std::size_t row = 0; row < w.values.size(); ++row) {
    const Eigen::VectorXd& q = w.q[row];
    const Eigen::Vector2d fa(w.values[row][0], w.values[row][1]), fb(w.values[row][3], w.values[row][4]);
    const Eigen::Vector2d crank = Eigen::Vector2d(q(xa), q(ya)).normalized();
    const Eigen::Vector2d coupler = Eigen::Vector2d(q(xb) - q(xa), q(yb) - q(ya)).normalized();
    const Eigen::Vector2d across(-coupler.y(), coupler.x());
    const double scale = 1.0 + fb.norm();
    EXPECT_NEAR(fb.dot(across), 0.0, 1e-9 * scale) << row;  // the world force itself lies along the coupler
    EXPECT_NEAR(j.values[row][3], fb.dot(coupler), 1e-12 * scale) << row;
    EXPECT_NEAR(j.values[row][4], 0.0, 1e-9 * scale) << row;
    EXPECT_NEAR(j.values[row][0], fa.dot(crank), 1e-12 * (1.0 + fa.norm())) << row;
    EXPECT_NEAR(j.values[row][1], fa.dot(Eigen::Vector2d(-crank.y(), crank.x())), 1e-12 * (1.0 + fa.norm())) << row;
    EXPECT_EQ(j.values[row][2], 0.0);
    along = std::max(along, std::min(std::fabs(fb.x()), std::fabs(fb.y())));
  }
  EXPECT_GT(along, 1.0);  // newtons in both world components somewhere: the turn is not the identity
}

// A roller follower lifted by an eccentric cam (models/cams/eccentric_roller.yaml) with a mass on the rod under
// gravity: the rod's guide carries no force along y, so the cam pushes it up by m (ÿ + g) (Newton, on the rod
// alone), along the line from the cam circle's centre to the roller's (a frictionless contact): along the cam's
// normal, with nothing along its tangent (reaction_axes: joint).
TEST(JointReactions, ACamPushesItsRollerAlongTheNormalWithTheRodsWeightAndInertia) {
  const double m = 0.7, g = 9.81, e = 0.015;
  const std::string base = test::model_file_text("cams/eccentric_roller.yaml", "output:") +
                           "parts:\n  rod: {mass: 0.7, center_of_mass: [0, 0], inertia: 1e-3}\n"
                           "  disc: {mass: 2.0, center_of_mass: [0, 0], inertia: 3e-3}\n"
                           "loads: {gravity: [0, -9.81]}\n";
  const std::string out = "output: {velocities: true, accelerations: true, reactions: [cam]";
  const Scene world = parse_scene(base + out + "}\n", "cam.yaml"),
              joint = parse_scene(base + out + ", reaction_axes: joint}\n", "cam.yaml");
  const Model* swept = nullptr;
  const ReactionRows w = sweep_reactions(world, nullptr, &swept), j = sweep_reactions(joint);
  const Index yf = swept->find_coordinate("yf"), th = swept->find_coordinate("th");
  ASSERT_GE(yf, 0);
  ASSERT_EQ(w.values.size(), 73u);
  for (std::size_t row = 0; row < w.values.size(); ++row) {
    const double fx = w.values[row][0], fy = w.values[row][1];
    EXPECT_NEAR(fy, m * (w.qdd[row](yf) + g), 1e-9) << row;
    const double t = w.q[row](th);  // the normal: from the cam circle's centre to the roller's (on x = 0)
    const double nx = 0.0 - e * std::cos(t), ny = w.q[row](yf) - e * std::sin(t);
    EXPECT_NEAR(fx * ny - fy * nx, 0.0, 1e-9 * std::hypot(fx, fy)) << row;
    EXPECT_NEAR(w.values[row][2], 0.0, 1e-12) << row;  // about the roller's centre, on the force's line
    EXPECT_NEAR(j.values[row][0], 0.0, 1e-9 * std::hypot(fx, fy)) << row;  // along the tangent
    EXPECT_NEAR(std::fabs(j.values[row][1]), std::hypot(fx, fy), 1e-12 * std::hypot(fx, fy)) << row;
  }
}

// A screw jack (models/transmissions/screw_jack.yaml) lifting its nut of mass m against gravity: the thread holds it
// up by Fz = m (z̈ + g) (Newton along the axis, the nut's centre on it: no other force, no moment about x or y), with
// Mz = −p Fz / 2π about the axis, and the driver turns it by τ = Izz θ̈ − Mz = Izz θ̈ + p m (z̈ + g) / 2π.
TEST(JointReactions, AScrewJackHoldsItsNutsWeightAndInertiaThroughTheThread) {
  const double m = 2.0, izz = 0.02, g = 9.81, p = 0.004;
  const Scene s = parse_scene(test::model_file_text("transmissions/screw_jack.yaml", "output:") +
                                  "parts:\n  nut: {mass: 2, center_of_mass: [0, 0, 0], inertia: [0.01, 0.01, 0.02]}\n"
                                  "loads: {gravity: [0, 0, -9.81]}\n"
                                  "output: {velocities: true, accelerations: true, efforts: [crank], "
                                  "reactions: [lead_screw]}\n",
                              "jack.yaml");
  const Model* swept = nullptr;
  const ReactionRows r = sweep_reactions(s, nullptr, &swept);
  const Index z = swept->find_coordinate("nut_z");
  ASSERT_GE(z, 0);
  ASSERT_EQ(r.values.size(), 91u);
  double largest_moment = 0.0;
  for (std::size_t row = 0; row < r.values.size(); ++row) {
    const std::vector<double>& v = r.values[row];  // the effort, its power, then Fx, Fy, Fz, Mx, My, Mz
    ASSERT_EQ(v.size(), 8u);
    const double fz = m * (r.qdd[row](z) + g), theta_dd = 2 * M_PI / p * r.qdd[row](z);
    for (int k : {2, 3, 5, 6}) EXPECT_NEAR(v[static_cast<std::size_t>(k)], 0.0, 1e-9) << row << " component " << k;
    EXPECT_NEAR(v[4], fz, 1e-9 * (1 + std::fabs(fz))) << row;
    EXPECT_NEAR(v[7], -p / (2 * M_PI) * fz, 1e-12) << row;
    EXPECT_NEAR(v[0], izz * theta_dd + p / (2 * M_PI) * fz, 1e-9 * (1 + std::fabs(v[0]))) << row;
    EXPECT_NEAR(v[1], v[0] * 2 * M_PI / p * r.qd[row](z), 1e-9 * (1 + std::fabs(v[1]))) << row;  // τ θ̇
    largest_moment = std::max(largest_moment, std::fabs(izz * theta_dd));
  }
  EXPECT_GT(largest_moment, 0.1);  // the nut's inertia counts (θ̈ up to 3π): 0.19 N·m, its weight 0.0125
}

// Model::constraint_block(), the table JointReactions and the minimum-norm multipliers read a constraint through,
// against a scan of the blocks, in a planar and a spatial model and in the spatial one reduced to its independent
// rows (without_rows() shares the table); reaction_width(), the kind's trait, against the site a kind states.
TEST(JointReactions, TheModelsTableFindsEveryConstraintsBlockAndItsWidthIsItsSites) {
  const Scene planar = parse_scene(test::model_file_text("clearance/fourbar_knee.yaml", "output:"), "knee.yaml");
  const Scene door = parse_scene(test::model_file_text("redundant/door_three_hinges.yaml", "output:"), "door.yaml");
  const Model reduced = door.model->without_rows({0, 1});
  int sites = 0;
  for (const Model* m : std::initializer_list<const Model*>{planar.model.get(), door.model.get(), &reduced}) {
    ASSERT_GT(m->constraints().size(), 3u);
    for (Index c = 0; c < static_cast<Index>(m->constraints().size()); ++c) {
      const auto [block, index] = m->constraint_block(c);
      const auto [scanned, scanned_index] = reaction_block_of(*m, c);
      ASSERT_NE(block, nullptr) << c;
      EXPECT_EQ(block, scanned) << m->constraints()[static_cast<std::size_t>(c)].name;
      EXPECT_EQ(index, scanned_index) << m->constraints()[static_cast<std::size_t>(c)].name;
      ReactionSite site;
      const bool has_site = block->reaction_site(index, m->initial_positions().data(), site);
      EXPECT_EQ(reaction_width(*m, c), has_site ? (site.spatial ? 6 : 3) : 0)
          << m->constraints()[static_cast<std::size_t>(c)].name;
      sites += has_site;
    }
    EXPECT_THROW((void)m->constraint_block(static_cast<Index>(m->constraints().size())), Error);
  }
  EXPECT_GE(sites, 4 + 3 + 3);  // the knee's four pins, the door's three hinges twice
}

// The knee four-bar (reference-point links, centres at the reference points) with masses under gravity.
TEST(JointReactions, FourBarPinsSatisfyEveryLinksNewtonEulerEquations) {
  std::string text = test::model_file_text("clearance/fourbar_knee.yaml", "output:");
  text.erase(text.find("parts:"));
  text +=
      "parts:\n"
      "  crank: {mass: 1.0, center_of_mass: [0, 0], inertia: 1.0*L2*L2/12}\n"
      "  coupler: {mass: 2.0, center_of_mass: [0, 0], inertia: 2.0*L3*L3/12}\n"
      "  rocker: {mass: 1.5, center_of_mass: [0, 0], inertia: 1.5*L4*L4/12}\n"
      "loads: {gravity: [0, -9.81]}\n"
      "output: {velocities: true, accelerations: true, efforts: [motor], reactions: all}\n";
  const Scene s = parse_scene(text, "knee.yaml");
  ASSERT_EQ(s.sweep.efforts.reactions.size(), 4u);
  const ReactionRows rows = sweep_reactions(s);
  double largest_force = 0.0;
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    const std::vector<double>& v = rows.values[k];
    // reactions O, A, B, C after the effort and its power, about the pin: no moment at a pin
    for (int j = 0; j < 4; ++j) {
      const double force = std::hypot(v[2 + 3 * j], v[3 + 3 * j]);
      EXPECT_NEAR(v[4 + 3 * j], 0.0, 1e-9 * (1.0 + force)) << "a pin carries no moment, row " << k;
      largest_force = std::max(largest_force, force);
    }
    test::expect_fourbar_links_balance(*s.model, rows.q[k], rows.qdd[k], v, {v[0], 0.0, 0.0}, 1e-8, k);
  }
  EXPECT_GT(largest_force, 10.0);  // the links' weights at least: the check is not of zeros
}

// A door on three collinear hinges (10 redundant rows): its hinges' share of the load is not determined; the
// written reactions are those of the minimum-norm multipliers, which a dense pseudo-inverse of Φqᵀ gives too.
TEST(JointReactions, RedundantDoorHingesAreMinimumNormAndNamedIndeterminate) {
  std::string text = test::model_file_text("redundant/door_three_hinges.yaml", "output:");
  text +=
      "parts:\n  door: {mass: 20, center_of_mass: [0.4, 0, 1], inertia: [4, 5, 1.2]}\n"
      "loads: {gravity: [0, 0, -9.81]}\n"
      "output: {velocities: true, accelerations: true, efforts: all, reactions: all}\n";
  const Scene s = parse_scene(text, "door.yaml");
  ASSERT_EQ(s.sweep.efforts.reactions.size(), 3u);
  SweepSummary sum;
  const Model* swept = nullptr;
  const ReactionRows rows = sweep_reactions(s, &sum, &swept);
  ASSERT_FALSE(swept->dropped_rows().empty());
  int named = 0;
  for (const SweepWarning& w : sum.warnings)
    if (w.kind == "indeterminate") {
      ++named;
      for (const char* h : {"'hinge1'", "'hinge2'", "'hinge3'"})
        EXPECT_NE(w.message.find(h), std::string::npos) << w.message;
    }
  EXPECT_EQ(named, 1);
  // The dense minimum-norm multipliers at a few rows, and their reactions, against the sweep's.
  const Model& full = *s.model;  // every row: the whole Φq, which the swept model was reduced from
  Workspace ws(full);
  std::vector<Index> hinges;
  for (const OutputReaction& r : s.sweep.efforts.reactions) hinges.push_back(r.constraint);
  JointReactions jr(full, hinges);
  for (std::size_t k = 0; k < rows.q.size(); k += 7) {
    Eigen::VectorXd Q = Eigen::VectorXd::Zero(full.num_coordinates());
    add_generalized_forces(*s.sweep.efforts.parts, *s.sweep.efforts.loads, rows.q[k].data(), rows.qd[k].data(),
                           rows.qdd[k].data(), 0.0, Q);
    const JacobianView J = evaluate_jacobian(full, rows.q[k], 0.0, ws);
    const Eigen::MatrixXd Jt = Eigen::MatrixXd(J).transpose();
    const Eigen::VectorXd lambda = Jt.completeOrthogonalDecomposition().solve(Q);  // least norm
    ASSERT_LT((Jt * lambda - Q).norm(), 1e-9 * (1.0 + Q.norm()));
    std::vector<double> expected(18);
    jr.evaluate(rows.q[k].data(), 0.0, lambda, expected.data());
    for (std::size_t i = 0; i < 18; ++i)
      EXPECT_NEAR(rows.values[k][2 + i], expected[i], 1e-8 * (1.0 + std::fabs(expected[i]))) << "row " << k << " " << i;
    // the driver's torque is unique: the dense multipliers give it too
    const Index open = full.find_constraint("open");
    EXPECT_NEAR(rows.values[k][0], -lambda(full.constraints()[static_cast<std::size_t>(open)].first_row),
                1e-8 * (1.0 + std::fabs(rows.values[k][0])));
  }
}

}  // namespace
}  // namespace phiq
