// Joint reactions at natural coordinates' shared points (phiq/natural_joints.hpp): the natural four-bar's pins O, A,
// B, C carry the forces the reference-point four-bar's revolutes carry, under gravity, forces, a torque (part of it
// viscous, of der()), a spring to ground and one between two links (or to a part of expressions moved by t), with the
// same motor torque; each of its links satisfies its Newton–Euler equations written here with them; the bodies'
// weight and inertia read from the whole model's Q (a sweep's way) give the reactions their own Q gives, bit for bit,
// and so do the flat sites' sums on random natural chains, in both forms of Q (rigid bars' constant mass matrices or
// their frames' motion). What is refused: test_natural_reaction_refusals.cpp.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <sstream>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"
#include "phiq/natural_joints.hpp"
#include "phiq/phiq.hpp"
#include "natural_four_bar_text.hpp"
#include "solve/part_forces.hpp"
#include "test_support.hpp"

namespace phiq {
namespace {

struct NaturalRows {
  std::vector<double> t;
  std::vector<Eigen::VectorXd> q, qd, qdd;
  std::vector<std::vector<double>> values;  // efforts, powers, reactions
};

NaturalRows natural_reactions_sweep(const Scene& s) {
  NaturalRows r;
  SquareScene square;
  EXPECT_EQ(prepare_scene(*s.model, s.sweep.t_begin, s.sweep.assembly, &square), SolveStatus::kSuccess);
  EXPECT_EQ(&square.model(*s.model), s.model.get());  // no redundant row: the scene's own model
  Workspace ws(*s.model);
  ws.q = square.start;
  const std::size_t n = static_cast<std::size_t>(s.sweep.efforts.size());
  SweepSummary sum;
  EXPECT_EQ(run_sweep(
                *s.model, s.sweep, ws,
                [&](const StepView& v) {
                  r.t.push_back(v.t), r.q.push_back(v.q), r.qd.push_back(*v.qd), r.qdd.push_back(*v.qdd);
                  r.values.emplace_back(v.efforts, v.efforts + n);
                  return true;
                },
                &sum),
            SolveStatus::kSuccess)
      << sum.message;
  return r;
}

// The loads of both forms: gravity off the vertical, a force on the coupler (part axes), a torque on the rocker
// with a viscous part of its turning rate (der() of `rocker_angle`, that form's angle of the rocker), a spring from
// the rocker to a world point and a spring-damper `tie` from the coupler to the rocker (a load between two bodies,
// which the natural form's bodies must each take at their own end); `coupler_at`, `rocker_at` the parts' origins in
// the reference-point form's frames
// (the natural frames start at A and C, the reference-point bodies at the links' centres).
constexpr const char* kNaturalRockerAngle = "atan2(yB, xB - L1)";
// `tie_end`: the tie's second end, the rocker's point when empty.
std::string natural_reactions_loads(double coupler_at, double rocker_at,
                                    const std::string& rocker_angle = kNaturalRockerAngle,
                                    const std::string& crank_angle = "theta2", const std::string& tie_end = "") {
  std::ostringstream s;
  s << "loads:\n  gravity: [0.8, -9.81]\n"
    << "  forces: [{name: push, part: coupler, at: [" << coupler_at + 0.1 << ", 0.05], force: [3 + sin(t), -2], "
    << "axes: part}]\n"
    << "  torques: [{name: brake, part: rocker, torque: \"-1.5 - 0.7*der(" << rocker_angle << ")\"}]\n"
    << "  springs: [{name: s, between: [{part: rocker, at: [" << rocker_at + 0.3 << ", 0]}, {point: [1.5, 1]}], "
    << "stiffness: 40, free_length: 0.2},\n"
    << "            {name: tie, between: [{part: coupler, at: [" << coupler_at + 0.2 << ", 0.1]}, ";
  if (tie_end.empty())
    s << "{part: rocker, at: [" << rocker_at + 0.3 << ", 0]}";
  else
    s << tie_end;
  s << "], stiffness: 25, free_length: 0.3, damping: 0.4}]\n"
    << "  torsional_springs: [{name: return, coordinate: " << crank_angle
    << ", stiffness: 3, free_angle: 0.2, damping: 0.1}]\n";
  return s.str();
}

// `first`: parts listed before the links (a massless one shifts their indices among the parts with mass).
Scene natural_four_bar(const std::string& first = "", const std::string& tie_end = "") {
  std::string text = natural_reactions_scene("seed/fourbar_natural.yaml");
  text += "parts:\n" + first + natural_reactions_part("crank", 0, 0.2, "frame: {origin: O, x: A}, ") +
          natural_reactions_part("coupler", 1, 0.6, "frame: {origin: A, x: B}, ") +
          natural_reactions_part("rocker", 2, 0.5, "frame: {origin: C, x: B}, ") +
          natural_reactions_loads(0.6, 0.5, kNaturalRockerAngle, "theta2", tie_end) +
          "output: {velocities: true, accelerations: true, efforts: [motor], reactions: all}\n";
  return parse_scene(text, "fourbar_natural.yaml");
}

// The reference-point four-bar with the same parts, loads and outputs.
Scene reference_four_bar(const std::string& first = "", const std::string& tie_end = "") {
  std::string text = natural_reactions_scene("seed/fourbar_reference_point.yaml");
  text += "parts:\n" + first + natural_reactions_part("crank", 0, 0, "") + natural_reactions_part("coupler", 1, 0, "") +
          natural_reactions_part("rocker", 2, 0, "") + natural_reactions_loads(0, 0, "psi4", "psi2", tie_end) +
          "output: {velocities: true, accelerations: true, efforts: [motor], reactions: all}\n";
  return parse_scene(text, "fourbar_reference_point.yaml");
}

// The natural form's motor torque and pins' forces are the reference-point form's at every row (1e-8), and a
// point carries no moment.
void expect_four_bar_forms_agree(const Scene& natural, const Scene& reference) {
  ASSERT_EQ(natural.sweep.efforts.reactions.size(), 4u);
  ASSERT_EQ(reference.sweep.efforts.reactions.size(), 4u);
  for (std::size_t j = 0; j < 4; ++j)
    EXPECT_EQ(natural.sweep.efforts.reaction_name(*natural.model, natural.sweep.efforts.reactions[j]),
              reference.sweep.efforts.reaction_name(*reference.model, reference.sweep.efforts.reactions[j]));
  const NaturalRows a = natural_reactions_sweep(natural), b = natural_reactions_sweep(reference);
  ASSERT_EQ(a.values.size(), b.values.size());
  double largest = 0.0;
  for (std::size_t k = 0; k < a.values.size(); ++k) {
    ASSERT_EQ(a.t[k], b.t[k]);
    const std::vector<double>&u = a.values[k], &v = b.values[k];
    ASSERT_EQ(u.size(), 2u + 12u);
    EXPECT_NEAR(u[0], v[0], 1e-8 * (1 + std::fabs(v[0]))) << "motor torque, row " << k;
    for (std::size_t j = 0; j < 4; ++j) {
      for (std::size_t c = 0; c < 2; ++c) {
        const double x = u[2 + 3 * j + c], y = v[2 + 3 * j + c];
        EXPECT_NEAR(x, y, 1e-8 * (1 + std::fabs(y))) << "pin " << j << " F"
                                                     << "xy"[c] << ", row " << k;
        largest = std::max(largest, std::fabs(y));
      }
      EXPECT_EQ(u[4 + 3 * j], 0.0);                                          // a point carries no moment
      EXPECT_NEAR(v[4 + 3 * j], 0.0, 1e-9 * (1 + std::fabs(v[2 + 3 * j])));  // nor does a revolute
    }
  }
  EXPECT_GT(largest, 10.0);  // the weights at least: not a comparison of zeros
}

// A natural body keeps its part's mass, not a copy of the part: natural_body_parts() builds it, named as the body,
// with the scene part's mass properties, on its frame with the promoted points (O's and C's constants as
// coordinates n, n + 1, …), and none for a body without mass.
TEST(NaturalReactions, ABodysPartIsBuiltOnItsPromotedPoints) {
  const Scene s = natural_four_bar();
  const NaturalJoints& natural = *s.sweep.efforts.natural;
  const Index n = s.model->num_coordinates();
  std::vector<Part> built;
  int promoted = 0;
  for (const NaturalBody& b : natural.bodies) {
    natural_body_parts(b, built);
    ASSERT_EQ(built.size(), 1u) << b.name;
    const Part& p = built[0];
    const Part& scene = s.parts.at(b.part);
    EXPECT_EQ(p.name, b.name);
    EXPECT_EQ(p.mass.mass, scene.mass.mass);
    EXPECT_EQ(p.mass.inertia, scene.mass.inertia);
    EXPECT_EQ(p.mass.center.x, scene.mass.center.x);
    for (const auto& [built_point, body_point] :
         {std::pair{&p.frame.origin, &b.points.at(0)}, std::pair{&p.frame.x_toward, &b.points.at(1)}})
      for (int k = 0; k < 2; ++k) {
        EXPECT_EQ(built_point->r[k], body_point->r[k]) << b.name << k;
        ASSERT_TRUE(built_point->r[k].is_coordinate()) << b.name << k;  // (constants promoted)
        promoted += built_point->r[k].coord() >= n;
      }
    NaturalBody massless = b;
    massless.mass_source = MassSource::kNone;
    natural_body_parts(massless, built);
    EXPECT_TRUE(built.empty()) << b.name;
  }
  EXPECT_EQ(promoted, 4);  // O's and C's x and y
}

TEST(NaturalReactions, FourBarPinsAndTorqueAreTheReferencePointForms) {
  expect_four_bar_forms_agree(natural_four_bar(), reference_four_bar());
}

// The tie's far end on a part of expressions moved by t alone (a frame that reads no coordinate, so no body's): the
// coupler takes the tie's pull at its own end, its damping from the far end's velocity, as in the reference-point
// form. Before the far end was placed at slots of its own, the coupler's balance left the tie out and its pins
// carried the pull.
TEST(NaturalReactions, ASpringToAFrameOfExpressionsPullsItsNaturalBodyAtItsEnd) {
  const std::string beacon = "  beacon: {frame: {at: [\"1.2 + 0.2*sin(3*t)\", \"0.9 - 0.1*t\"], angle: \"0.5*t\"}}\n";
  const std::string end = "{part: beacon, at: [0.1, 0.05]}";
  expect_four_bar_forms_agree(natural_four_bar(beacon, end), reference_four_bar(beacon, end));
}

double natural_cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Newton–Euler for each link of the natural four-bar, its centre's acceleration and its angular acceleration from
// its two points' q̈, with the pins' forces as written (on the crank at O and A, the coupler at B, the rocker at C;
// the other link at a pin gets the opposite), the motor torque on the crank, gravity, and the applied loads.
TEST(NaturalReactions, EveryNaturalLinkBalancesUnderItsPinForces) {
  const Scene s = natural_four_bar();
  const NaturalRows rows = natural_reactions_sweep(s);
  const Model& m = *s.model;
  const Eigen::Vector2d g(0.8, -9.81);
  for (std::size_t k = 0; k < rows.q.size(); ++k) {
    // a point's position (of q), or its velocity or acceleration (of q̇, q̈: the fixed O and C's are zero)
    auto at = [&](const Eigen::VectorXd& q, const char* p) -> Eigen::Vector2d {
      if (p[0] == 'O') return {0, 0};
      if (p[0] == 'C') return &q == &rows.q[k] ? Eigen::Vector2d(1, 0) : Eigen::Vector2d(0, 0);
      const std::string n(p);
      return {q(m.coordinate_index("x" + n)), q(m.coordinate_index("y" + n))};
    };
    const std::vector<double>& v = rows.values[k];
    auto F = [&](int j) { return Eigen::Vector2d(v[2 + 3 * j], v[3 + 3 * j]); };
    const double t = rows.t[k], tau = v[0];
    struct Link {
      const char *origin, *x;
      int index;
      std::vector<std::pair<const char*, Eigen::Vector2d>> forces;  // at points
      double torque;
    };
    // the crank's return spring on its angle θ2 (a coordinate no point holds: the crank's segment angle)
    const Index th = m.coordinate_index("theta2");
    const double spring = 3 * (rows.q[k](th) - 0.2) + 0.1 * rows.qd[k](th);
    const Link links[3] = {{"O", "A", 0, {{"O", F(0)}, {"A", F(1)}}, tau - spring},
                           {"A", "B", 1, {{"A", -F(1)}, {"B", F(2)}}, 0.0},
                           {"C", "B", 2, {{"B", -F(2)}, {"C", F(3)}}, -1.5}};  // (and −0.7 ω below)
    for (const Link& l : links) {
      const Eigen::Vector2d o = at(rows.q[k], l.origin), d = at(rows.q[k], l.x) - o;
      const Eigen::Vector2d dv = at(rows.qd[k], l.x) - at(rows.qd[k], l.origin);
      const Eigen::Vector2d da = at(rows.qdd[k], l.x) - at(rows.qdd[k], l.origin);
      const Eigen::Vector2d e = d / d.norm(), ao = at(rows.qdd[k], l.origin);
      const double w = natural_cross(d, dv) / d.squaredNorm(), alpha = natural_cross(d, da) / d.squaredNorm();
      const double half = kNaturalLength[l.index] / 2, mass = kNaturalMass[l.index];
      const Eigen::Vector2d G = o + half * e,
                            aG = ao + alpha * half * Eigen::Vector2d(-e.y(), e.x()) - w * w * half * e;
      Eigen::Vector2d sum = mass * g;
      double moment = l.torque + (l.index == 2 ? -0.7 * w : 0.0);
      for (const auto& [p, f] : l.forces) sum += f, moment += natural_cross(at(rows.q[k], p) - G, f);
      if (l.index == 1) {  // the push, in the coupler's axes at (0.7, 0.05) from A
        const Eigen::Vector2d n(-e.y(), e.x()), f = (3 + std::sin(t)) * e - 2 * n;
        sum += f, moment += natural_cross(o + 0.7 * e + 0.05 * n - G, f);
      }
      if (l.index == 2) {  // the spring from (0.8, 0) of the rocker to (1.5, 1)
        const Eigen::Vector2d p = o + 0.8 * e, to = Eigen::Vector2d(1.5, 1) - p;
        const Eigen::Vector2d f = 40 * (to.norm() - 0.2) * to / to.norm();
        sum += f, moment += natural_cross(p - G, f);
      }
      if (l.index != 0) {  // the tie from (0.8, 0.1) of the coupler to (0.8, 0) of the rocker, its pull on this link
        auto place = [&](const Eigen::VectorXd& x, const char* origin, const char* tip, double along, double across) {
          const Eigen::Vector2d a = at(x, origin), b = at(x, tip), q = at(rows.q[k], tip) - at(rows.q[k], origin);
          const double len = q.norm();  // (the link's length, constant: its rates move only its direction)
          return Eigen::Vector2d(a + (along * (b - a) + across * Eigen::Vector2d(a.y() - b.y(), b.x() - a.x())) / len);
        };
        const Eigen::Vector2d pc = place(rows.q[k], "A", "B", 0.8, 0.1), pr = place(rows.q[k], "C", "B", 0.8, 0);
        const Eigen::Vector2d vc = place(rows.qd[k], "A", "B", 0.8, 0.1), vr = place(rows.qd[k], "C", "B", 0.8, 0);
        const Eigen::Vector2d u = (pr - pc) / (pr - pc).norm();
        const double tension = 25 * ((pr - pc).norm() - 0.3) + 0.4 * u.dot(vr - vc);
        const Eigen::Vector2d f = l.index == 1 ? Eigen::Vector2d(tension * u) : Eigen::Vector2d(-tension * u);
        sum += f, moment += natural_cross((l.index == 1 ? pc : pr) - G, f);
      }
      const double inertia = mass * kNaturalLength[l.index] * kNaturalLength[l.index] / 12;
      EXPECT_NEAR((sum - mass * aG).norm(), 0.0, 1e-8 * (1 + sum.norm())) << l.origin << l.x << " row " << k;
      EXPECT_NEAR(moment, inertia * alpha, 1e-8 * (1 + std::fabs(moment))) << l.origin << l.x << " row " << k;
    }
  }
}

// A sweep's reactions read each natural body's weight and inertia where the whole model's Q left them
// (detail::PlanarForce), rather than the body's own Q: the same numbers, bit for bit, at every row of the four-bar
// with gravity, a force, a torque, two springs and the fixed pins O, C (constant components, promoted). In the frames'
// motion's form Q itself is add_generalized_forces()' to the bit; a shifted cached force moves the reactions where
// it acts (the cache is read, not passed over). In the rigid bars' form (the links are held at their lengths by the
// distance constraints crank, coupler, rocker) Q differs, but only along the bars' own rows: every other multiplier
// and every reaction is the frames' motion's, and the body's own bar form (the cache marked invalid) gives the
// cache's bits.
TEST(NaturalReactions, BodyForcesFromTheModelsQAreTheBodiesOwnBitForBit) {
  const Scene s = natural_four_bar();
  const NaturalRows rows = natural_reactions_sweep(s);
  const Model& m = *s.model;
  const OutputEfforts& e = s.sweep.efforts;
  const std::vector<Part>& parts = *e.parts;
  ASSERT_EQ(e.natural->bodies.size(), 3u);
  for (const NaturalBody& b : e.natural->bodies) EXPECT_EQ(parts.at(b.part).name, b.name);
  EXPECT_EQ(e.natural->promoted.size(), 8u);  // O's and C's x and y, and the tie's far ends' copies of A's and B's
  EXPECT_EQ(e.natural->mirrors.size(), 4u);
  Workspace ws(m);
  for (const bool bars : {false, true}) {
    JointReactions reactions(m, e, bars), plain(m, e);
    const detail::PartForces forces(parts, m, bars);
    const std::size_t n = static_cast<std::size_t>(reactions.size());
    double bar_rows_moved = 0.0;  // the largest change of a bar's own multiplier (the bar form taken at all)
    for (std::size_t k = 0; k < rows.q.size(); ++k) {
      const double t = rows.t[k];
      const double *q = rows.q[k].data(), *qd = rows.qd[k].data(), *qdd = rows.qdd[k].data();
      Eigen::VectorXd Q = Eigen::VectorXd::Zero(m.num_coordinates()), own = Q, lambda, own_lambda;
      std::vector<detail::PlanarForce> planar(parts.size());
      forces.add(parts, *e.loads, q, qd, qdd, t, Q, planar.data());
      add_generalized_forces(parts, *e.loads, q, qd, qdd, t, own);
      const bool same_q = std::memcmp(Q.data(), own.data(), sizeof(double) * static_cast<std::size_t>(Q.size())) == 0;
      if (!bars) {
        ASSERT_TRUE(same_q) << k;
      }
      for (const NaturalBody& b : e.natural->bodies) ASSERT_TRUE(planar[b.part].valid) << b.name << ", row " << k;
      ws.q = rows.q[k];
      ASSERT_EQ(constraint_multipliers(m, t, ws, Q, lambda), SolveStatus::kSuccess);
      ASSERT_EQ(constraint_multipliers(m, t, ws, own, own_lambda), SolveStatus::kSuccess);
      for (std::size_t c = 0; c < m.constraints().size(); ++c) {
        const Index r = m.constraints()[c].first_row;
        const std::string& name = m.constraints()[c].name;
        if (name == "crank" || name == "coupler" || name == "rocker")
          bar_rows_moved = std::max(bar_rows_moved, std::fabs(lambda(r) - own_lambda(r)));
        else
          EXPECT_NEAR(lambda(r), own_lambda(r), 1e-10 * (1 + std::fabs(own_lambda(r)))) << name << ", row " << k;
      }
      std::vector<double> general(n), cached(n), own_bars(n), shifted(n);
      plain.evaluate(q, qd, qdd, t, own_lambda, general.data());
      reactions.evaluate(q, qd, qdd, t, lambda, cached.data(), planar.data());
      for (std::size_t j = 0; j < n; ++j) {
        EXPECT_NEAR(cached[j], general[j], 1e-10 * (1 + std::fabs(general[j]))) << j << ", row " << k;
        // the sweep's, whose λ comes from its own factors
        EXPECT_NEAR(rows.values[k][2 + j], general[j], 1e-9 * (1 + std::fabs(general[j]))) << j << ", row " << k;
      }
      if (!bars) {
        ASSERT_EQ(std::memcmp(general.data(), cached.data(), sizeof(double) * n), 0) << "row " << k;
      }
      std::vector<detail::PlanarForce> unread = planar;  // each body's own force, in the same form
      for (detail::PlanarForce& f : unread) f.valid = false;
      reactions.evaluate(q, qd, qdd, t, lambda, own_bars.data(), unread.data());
      ASSERT_EQ(std::memcmp(own_bars.data(), cached.data(), sizeof(double) * n), 0) << bars << ", row " << k;
      for (detail::PlanarForce& f : planar) f.fx += 1.0;
      reactions.evaluate(q, qd, qdd, t, lambda, shifted.data(), planar.data());
      // R = Φqᵀλ − Q_b: a newton more along x at each part's origin, O (the crank's) and C (the rocker's); A and B
      // are their bodies' x points, which fx does not reach (in either form)
      for (std::size_t j : {0u, 3u})
        EXPECT_NEAR(shifted[3 * j], cached[3 * j] - 1.0, 1e-9 * (1 + std::fabs(cached[3 * j]))) << j << ", " << k;
      for (std::size_t j : {1u, 2u}) EXPECT_EQ(shifted[3 * j], cached[3 * j]) << j << ", " << k;
    }
    if (bars)
      EXPECT_GT(bar_rows_moved, 1e-3);  // (the links' centripetal loads: the bar form changes their rows' λ)
    else
      EXPECT_EQ(bar_rows_moved, 0.0);
  }
}

// A massless part listed before the links (a housing drawn on ground) leaves them at other indices among the
// efforts' parts (those with mass): their forces are still read from the sweep's Q, as a shifted PlanarForce shows
// at O and C, and the reactions are the same, in either form of Q.
TEST(NaturalReactions, AMasslessPartBeforeTheLinksLeavesTheirForcesReadFromQ) {
  const Scene s = natural_four_bar("  housing: {body: ground, shapes: [{type: box, size: [0.1, 0.1, 0.1]}]}\n");
  const Scene plain = natural_four_bar();
  ASSERT_EQ(s.parts.size(), 4u);
  ASSERT_EQ(s.sweep.efforts.parts->size(), 3u);            // the housing has no mass
  EXPECT_EQ(s.sweep.efforts.natural->bodies[0].part, 1u);  // the crank, after the housing, among all the parts
  const NaturalRows rows = natural_reactions_sweep(s), same = natural_reactions_sweep(plain);
  ASSERT_EQ(rows.values.size(), same.values.size());
  for (std::size_t k = 0; k < rows.values.size(); ++k) EXPECT_EQ(rows.values[k], same.values[k]) << k;
  const Model& m = *s.model;
  const OutputEfforts& e = s.sweep.efforts;
  Workspace ws(m);
  for (const bool bars : {false, true}) {
    JointReactions reactions(m, e, bars);
    const detail::PartForces forces(*e.parts, m, bars);
    const std::size_t k = 5, n = static_cast<std::size_t>(reactions.size());
    const double *q = rows.q[k].data(), *qd = rows.qd[k].data(), *qdd = rows.qdd[k].data();
    Eigen::VectorXd Q = Eigen::VectorXd::Zero(m.num_coordinates()), lambda;
    std::vector<detail::PlanarForce> planar(e.parts->size());
    forces.add(*e.parts, *e.loads, q, qd, qdd, rows.t[k], Q, planar.data());
    ws.q = rows.q[k];
    ASSERT_EQ(constraint_multipliers(m, rows.t[k], ws, Q, lambda), SolveStatus::kSuccess);
    std::vector<double> cached(n), shifted(n);
    reactions.evaluate(q, qd, qdd, rows.t[k], lambda, cached.data(), planar.data());
    for (std::size_t j = 0; j < n; ++j)
      EXPECT_NEAR(cached[j], rows.values[k][2 + j], 1e-9 * (1 + std::fabs(cached[j]))) << bars << ", " << j;
    for (detail::PlanarForce& f : planar) f.fx += 1.0;
    reactions.evaluate(q, qd, qdd, rows.t[k], lambda, shifted.data(), planar.data());
    for (std::size_t j : {0u, 3u})
      EXPECT_NEAR(shifted[3 * j], cached[3 * j] - 1.0, 1e-9 * (1 + std::fabs(cached[3 * j]))) << bars;
  }
}

// An nfourbar in natural coordinates (cranks from G{i} to P{i}, couplers P{i} to P{i+1}) with random masses,
// centres, inertias, gravity and, on some cranks, a torque: each P{i} on its crank, whose force is read from Q.
Scene natural_random_nfourbar(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::ostringstream s;
  s.precision(17);
  s << "phiq: 1\nparameters: {N: " << n << ", c: 0.7071067811865476, s: 0.7071067811865475}\n"
    << "coordinates:\n  for i in 0..N:\n    x{i}: i + c\n    y{i}: s\n  theta: 0.7853981633974483\n"
    << "points:\n  O: [0, 0]\n  for i in 0..N:\n    G{i}: [i, 0]\n    P{i}: [\"x{i}\", \"y{i}\"]\n"
    << "constraints:\n  - for i in 0..N:\n      - {name: \"crank{i}\", type: distance, points: [\"G{i}\", \"P{i}\"], "
       "length: 1}\n  - for i in 0..N-1:\n      - {name: \"coupler{i}\", type: distance, points: [\"P{i}\", "
       "\"P{i+1}\"], length: 1}\n  - {name: crank0_angle, type: segment_angle, segment: [O, P0], angle: theta}\n"
    << "drivers:\n  - {name: motor, coordinate: theta, law: {type: linear, initial: 0.7853981633974483, rate: 1.3}}\n"
    << "time: {start: 0, end: 1, steps: 12}\nparts:\n";
  auto part = [&](const std::string& name, const std::string& origin, const std::string& x) {
    const double m = 0.2 + 3 * u(rng);
    s << "  " << name << ": {frame: {origin: " << origin << ", x: " << x << "}, mass: " << m << ", center_of_mass: ["
      << u(rng) << ", " << 0.2 * (u(rng) - 0.5) << "], inertia: " << m * (0.05 + u(rng)) / 12 << "}\n";
  };
  for (int i = 0; i <= n; ++i) part("crank" + std::to_string(i), "G" + std::to_string(i), "P" + std::to_string(i));
  for (int i = 0; i < n; ++i) part("coupler" + std::to_string(i), "P" + std::to_string(i), "P" + std::to_string(i + 1));
  s << "loads:\n  gravity: [" << u(rng) - 0.5 << ", " << -9.81 * u(rng) << "]\n  torques:\n";
  for (int i = 0; i <= n; i += 3) s << "    - {name: t" << i << ", part: crank" << i << ", torque: " << u(rng) << "}\n";
  s << "output: {velocities: true, accelerations: true, efforts: all, reactions: all}\n";
  return parse_scene(s.str(), "nfourbar.yaml");
}

// The flat sites (JointReactions::NaturalSite: a point on a body whose force Q computed, no load its own; moving,
// or fixed as the cranks' pivots G{i}) sum the same terms as the general path, bit for bit: random natural four-bar
// chains, every row, every joint, in both forms of Q (the frames' motion's, whose general path is the body's own Q
// from its frame; the rigid bars', whose general path is the body's own bar form). A sweep's Q, which writes only
// the planar forces the sites read (JointReactions::planar_parts_read()), gives them the same bits.
TEST(NaturalReactions, FlatSitesAreTheGeneralPathBitForBit) {
  std::mt19937 rng(49);
  for (int trial = 0; trial < 4; ++trial) {
    const Scene s = natural_random_nfourbar(rng, 3 + 2 * trial);
    const NaturalRows rows = natural_reactions_sweep(s);
    const Model& m = *s.model;
    const OutputEfforts& e = s.sweep.efforts;
    Workspace ws(m);
    for (const bool bars : {false, true}) {
      JointReactions reactions(m, e, bars);
      const detail::PartForces forces(*e.parts, m, bars);
      const std::size_t n = static_cast<std::size_t>(reactions.size());
      ASSERT_EQ(n, 3 * e.natural->joints.size());
      for (std::size_t k = 0; k < rows.q.size(); ++k) {
        const double t = rows.t[k];
        const double *q = rows.q[k].data(), *qd = rows.qd[k].data(), *qdd = rows.qdd[k].data();
        Eigen::VectorXd Q = Eigen::VectorXd::Zero(m.num_coordinates()), lambda;
        std::vector<detail::PlanarForce> planar(e.parts->size());
        forces.add(*e.parts, *e.loads, q, qd, qdd, t, Q, planar.data());
        ws.q = rows.q[k];
        ASSERT_EQ(constraint_multipliers(m, t, ws, Q, lambda), SolveStatus::kSuccess);
        std::vector<double> general(n), flat(n);
        // the general path, in the bars' form where they are (no rigid bar's simple site summing its force itself:
        // sum_bars false), against the flat sites' sums (with those bar sites: JointReactions::SimpleSite)
        std::vector<detail::PlanarForce> unread = planar;
        for (detail::PlanarForce& f : unread) f.valid = false;
        reactions.evaluate(q, qd, qdd, t, lambda, general.data(), bars ? unread.data() : nullptr, false);
        reactions.evaluate(q, qd, qdd, t, lambda, flat.data(), planar.data());
        ASSERT_EQ(std::memcmp(general.data(), flat.data(), sizeof(double) * n), 0) << trial << bars << ", row " << k;
        // a sweep's Q writes only the planar forces the sites read (the cranks': every joint is a crank's point)
        const std::vector<char> read = reactions.planar_parts_read(e.parts->size());
        for (std::size_t p = 0; p < read.size(); ++p)
          ASSERT_EQ(read[p] != 0, (*e.parts)[p].name.rfind("crank", 0) == 0) << (*e.parts)[p].name;
        const detail::PartForces sweeps(*e.parts, m, bars, read);
        Eigen::VectorXd sweeps_q = Eigen::VectorXd::Zero(m.num_coordinates());
        std::vector<detail::PlanarForce> sweeps_planar(e.parts->size());
        sweeps.add(*e.parts, *e.loads, q, qd, qdd, t, sweeps_q, sweeps_planar.data());
        ASSERT_EQ(std::memcmp(Q.data(), sweeps_q.data(), sizeof(double) * static_cast<std::size_t>(Q.size())), 0);
        for (std::size_t p = 0; p < read.size(); ++p) ASSERT_EQ(sweeps_planar[p].valid, read[p] != 0) << p;
        std::vector<double> sweeps_flat(n);
        reactions.evaluate(q, qd, qdd, t, lambda, sweeps_flat.data(), sweeps_planar.data());
        ASSERT_EQ(std::memcmp(sweeps_flat.data(), flat.data(), sizeof(double) * n), 0) << trial << bars << ", " << k;
        // either form, the frames' motion's reactions and motor torque (bars off the centre line: c_y ≠ 0)
        Eigen::VectorXd own = Eigen::VectorXd::Zero(m.num_coordinates()), own_lambda;
        add_generalized_forces(*e.parts, *e.loads, q, qd, qdd, t, own);
        ASSERT_EQ(constraint_multipliers(m, t, ws, own, own_lambda), SolveStatus::kSuccess);
        std::vector<double> frames(n);
        JointReactions(m, e).evaluate(q, qd, qdd, t, own_lambda, frames.data());
        const Index motor = m.constraints()[static_cast<std::size_t>(m.find_constraint("motor"))].first_row;
        EXPECT_NEAR(lambda(motor), own_lambda(motor), 1e-10 * (1 + std::fabs(own_lambda(motor)))) << trial << bars;
        for (std::size_t j = 0; j < n; ++j) {
          EXPECT_NEAR(flat[j], frames[j], 1e-9 * (1 + std::fabs(frames[j]))) << trial << bars << ", " << j;
          EXPECT_NEAR(flat[j], rows.values[k][2 + j], 1e-9 * (1 + std::fabs(flat[j]))) << trial << bars << ", " << j;
        }
        for (detail::PlanarForce& f : planar) f.along_x += 1.0;  // read, not passed over: P{i} is its crank's x point
        reactions.evaluate(q, qd, qdd, t, lambda, flat.data(), planar.data());
        for (std::size_t j = 0; j < e.natural->joints.size(); ++j) {
          const char first = e.natural->joints[j].name[0];
          if (first != 'P' && first != 'G') continue;  // (O, crank 0's angle's)
          // G{i}, its crank's fixed origin, takes −along_x in the frames' form (R = −Σ g over the crank's moving
          // point − Q_b: its Q at G is fx − along_x); a bar's x share is its x point's alone, and a rigid bar's
          // simple site, P{i} on a crank without a torque (a load of its own makes the site general), sums it from
          // q̈ itself (the bits above), reading no PlanarForce
          const std::string crank = "crank" + e.natural->joints[j].name.substr(1);
          const auto& torques = e.loads->applied->torques;
          const bool summed_here = bars && std::none_of(torques.begin(), torques.end(),
                                                        [&](const AppliedTorque& a) { return a.part == crank; });
          const double moved = first == 'P' ? (summed_here ? 0.0 : -1.0) : bars ? 0.0 : 1.0;
          EXPECT_NEAR(flat[3 * j], general[3 * j] + moved, 1e-9 * (1 + std::fabs(general[3 * j])));
        }
      }
    }
  }
}

// A sweep's Q takes the rigid bars' constant mass matrix assembled once (detail::PartForces): at every row of random
// natural four-bar chains (bars off the centre line, gravity off the vertical, torques on some cranks), it is the sum
// of each bar's own form (add_massive_part() on massive_part() with the bar's length) to rounding, with q̈ and
// without it (the weights alone), and the planar forces it leaves for the sites are each bar's own, bit for bit.
TEST(NaturalReactions, RigidBarsQIsEachBarsOwnFormAssembled) {
  std::mt19937 rng(4949);
  for (int trial = 0; trial < 3; ++trial) {
    const Scene s = natural_random_nfourbar(rng, 2 + 3 * trial);
    const NaturalRows rows = natural_reactions_sweep(s);
    const Model& m = *s.model;
    const OutputEfforts& e = s.sweep.efforts;
    const std::vector<Part>& parts = *e.parts;
    const detail::PartForces forces(parts, m, true);
    const detail::BarLengths bars(m);
    for (std::size_t k = 0; k < rows.q.size(); ++k) {
      const double t = rows.t[k];
      const double *q = rows.q[k].data(), *qd = rows.qd[k].data();
      for (const double* qdd : {rows.qdd[k].data(), static_cast<const double*>(nullptr)}) {
        Eigen::VectorXd Q = Eigen::VectorXd::Zero(m.num_coordinates()), each = Q;
        std::vector<detail::PlanarForce> planar(parts.size()), own(parts.size());
        forces.add(parts, *e.loads, q, qd, qdd, t, Q, planar.data());
        int taken = 0;
        for (std::size_t i = 0; i < parts.size(); ++i) {
          const double length = bars.of(parts[i].frame);
          taken += length > 0.0;
          detail::add_massive_part(parts[i], detail::massive_part(parts[i], i, length), e.loads->gravity, q, qd, qdd, t,
                                   each, own.data() + i);
        }
        add_applied_forces(*e.loads->applied, q, qd, qdd, t, each);
        ASSERT_EQ(taken, static_cast<int>(parts.size()));  // every link is a bar
        const double scale = each.cwiseAbs().maxCoeff();
        ASSERT_GT(scale, 0.1);  // (not all zero)
        for (Index c = 0; c < Q.size(); ++c)
          EXPECT_NEAR(Q(c), each(c), 1e-13 * scale) << trial << ", " << k << ", " << c;
        for (std::size_t i = 0; i < parts.size(); ++i) {
          ASSERT_TRUE(planar[i].valid && own[i].valid) << i;
          for (double detail::PlanarForce::*f : detail::kPlanarFields) ASSERT_EQ(planar[i].*f, own[i].*f) << i;
        }
      }
    }
  }
}

// for_each_planar_term() lists add_planar_force()'s terms in its order: summed per coordinate from +0, the same
// Q bit for bit, on frames whose slots repeat coordinates and mix in constants.
TEST(NaturalReactions, PlanarTermsSumAsAddPlanarForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::uniform_int_distribution<int> pick(0, 4);
  for (int trial = 0; trial < 200; ++trial) {
    detail::PlanarFrame frame;
    for (Slot& slot : frame.slots) slot = pick(rng) == 4 ? Slot::constant(u(rng)) : Slot::coordinate(pick(rng));
    frame.body = trial % 3 == 0, frame.x_is_point = trial % 2 == 0;
    frame.bar = !frame.body && frame.x_is_point && trial % 4 == 2;  // (a rigid bar's: no share taken off the origin)
    detail::PlanarForce f;
    f.fx = u(rng), f.fy = u(rng), f.fz = u(rng), f.turn = u(rng), f.along_x = u(rng), f.along_y = u(rng);
    Eigen::VectorXd Q = Eigen::VectorXd::Zero(5), terms = Q;
    detail::add_planar_force(frame, f, Q);
    detail::for_each_planar_term(frame, [&](const Slot& slot, int field, bool negated) {
      const double v = f.*detail::kPlanarFields[field];
      if (slot.is_coordinate()) terms(slot.coord()) += negated ? -v : v;
    });
    ASSERT_EQ(std::memcmp(Q.data(), terms.data(), sizeof(double) * 5), 0) << trial;
  }
}

// A second part on the crank's two points (a drawn shape, or a weight from A to O) makes the crank's length row the
// joints' rather than the crank's (two bodies hold the same coordinates): its reactions would not take back a bar's
// Q, so no bar takes that form, and the sweep's reactions are the frames' motion's, as they are without it.
TEST(NaturalReactions, ASecondPartOnABarsPointsKeepsItsReactionsTheFramesMotions) {
  const std::string shape = "  shape: {frame: {origin: O, x: A}, shapes: [{type: box, size: [0.1, 0.1, 0.1]}]}\n";
  const std::string weight =
      "  weight: {frame: {origin: A, x: O}, mass: 0.7, center_of_mass: [0.1, 0.02], inertia: 0.01}\n";
  for (const std::string& second : {std::string(), shape, weight}) {
    std::string text = natural_reactions_scene("seed/fourbar_natural.yaml");
    text += "parts:\n" + natural_reactions_part("crank", 0, 0.2, "frame: {origin: O, x: A}, ") + second +
            natural_reactions_part("coupler", 1, 0.6, "frame: {origin: A, x: B}, ") +
            natural_reactions_part("rocker", 2, 0.5, "frame: {origin: C, x: B}, ") + natural_reactions_loads(0.6, 0.5) +
            "output: {velocities: true, accelerations: true, efforts: [motor], reactions: all}\n";
    const Scene s = parse_scene(text, "fourbar_natural.yaml");
    const Model& m = *s.model;
    const OutputEfforts& e = s.sweep.efforts;
    EXPECT_EQ(JointReactions(m, e, true).rigid_bars(), second.empty()) << second;
    const NaturalRows rows = natural_reactions_sweep(s);
    JointReactions frames(m, e);
    Workspace ws(m);
    for (std::size_t k = 0; k < rows.q.size(); ++k) {
      const double *q = rows.q[k].data(), *qd = rows.qd[k].data(), *qdd = rows.qdd[k].data(), t = rows.t[k];
      Eigen::VectorXd Q = Eigen::VectorXd::Zero(m.num_coordinates()), lambda;
      add_generalized_forces(*e.parts, *e.loads, q, qd, qdd, t, Q);
      ws.q = rows.q[k];
      ASSERT_EQ(constraint_multipliers(m, t, ws, Q, lambda), SolveStatus::kSuccess);
      std::vector<double> r(static_cast<std::size_t>(frames.size()));
      frames.evaluate(q, qd, qdd, t, lambda, r.data());
      for (std::size_t j = 0; j < r.size(); ++j)
        EXPECT_NEAR(rows.values[k][2 + j], r[j], 1e-9 * (1 + std::fabs(r[j]))) << second << j << ", row " << k;
    }
  }
}

}  // namespace
}  // namespace phiq
