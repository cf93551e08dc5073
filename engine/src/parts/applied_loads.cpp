// add_applied_forces() and applied_power() (phiq/applied_loads.hpp).
#include "phiq/applied_loads.hpp"

#include <algorithm>
#include <cmath>

#include "phiq/part_motion.hpp"

namespace phiq {

namespace {

using kin3::V3;

// R v: a vector of the frame's axes in the world's.
V3 turned(const RotationMatrix& r, V3 v) {
  return {r[0] * v.x + r[1] * v.y + r[2] * v.z, r[3] * v.x + r[4] * v.y + r[5] * v.z,
          r[6] * v.x + r[7] * v.y + r[8] * v.z};
}

// Q_k += (∂x/∂q_k) · F for the force F at the body point s of `frame` (at `pose`, its pose at (q, t)), and
// ∂θ/∂q_k · M for the moment M.
void add_virtual_work(const PartFrame& frame, const Pose& pose, V3 s, V3 force, V3 moment, const double* q, double t,
                      Eigen::VectorXd& Q) {
  thread_local PartJacobian j;  // its vectors' capacity kept from row to row (a sweep's efforts)
  part_jacobian(frame, q, t, j);
  if (j.coordinates.empty()) return;
  const V3 arm = turned(pose.rotation, s);  // R s, world axes
  for (std::size_t i = 0; i < j.coordinates.size(); ++i)
    Q(j.coordinates[i]) +=
        kin3::dot(j.d_origin[i] + kin3::cross(j.d_angle[i], arm), force) + kin3::dot(j.d_angle[i], moment);
}

// The velocity of a spring's end: 0 without q̇.
V3 end_velocity(const SpringEnd& e, const double* q, const double* qd, double t) {
  if (!qd) return {};
  return part_motion(e.frame, q, qd, nullptr, t).point(e.at).first;
}

// A spring's state at (q, q̇, t): its ends in the world, the unit vector from a to b, and its tension.
struct SpringState {
  Pose pa, pb;  // the ends' frames
  V3 xa, xb, unit;
  double length = 0.0, rate = 0.0, tension = 0.0;
};

SpringState spring_state(const LinearSpring& s, const double* q, const double* qd, double t) {
  SpringState st;
  st.pa = part_pose(s.a.frame, q, t), st.pb = part_pose(s.b.frame, q, t);
  st.xa = st.pa.apply(s.a.at);
  st.xb = st.pb.apply(s.b.at);
  const V3 d = st.xb - st.xa;
  st.length = kin3::norm(d);
  if (st.length == 0.0) return st;  // no direction: no force (LinearSpring)
  st.unit = (1.0 / st.length) * d;
  if (s.damping != 0.0 || s.friction != 0.0)
    st.rate = kin3::dot(st.unit, end_velocity(s.b, q, qd, t) - end_velocity(s.a, q, qd, t));
  const double stretch = st.length - s.free_length;
  st.tension = (s.law.has_value() ? s.law.evaluate(stretch).f : s.stiffness * stretch) + s.damping * st.rate +
               s.friction * friction_direction(st.rate) + s.preload;
  if (s.tension.expr) st.tension += s.tension.value(q, qd, t);
  return st;
}

// A torsional spring's angle from its free angle, its rate (0 without q̇) and its moment.
struct AngleState {
  double from_free = 0.0, rate = 0.0, moment = 0.0;  // θ − θ0, θ̇, τ
};

// θ̈ at (q, q̇, q̈): ∇θ · q̈ − γ for an expression (its γ holds q̇ᵀ H q̇ and the t terms), the joint's own otherwise.
double angle_acceleration(const TorsionalSpring& s, const double* q, const double* qd, const double* qdd, double t,
                          const std::vector<double>& gradient) {
  if (!s.angle) return evaluate_joint(*s.joint, q, qd, qdd).acceleration;
  const std::vector<Index>& c = s.angle->coordinates();
  double a = -s.angle->gamma(q, qd, t);
  for (std::size_t i = 0; i < c.size(); ++i) a += gradient[i] * qdd[c[i]];
  return a;
}

// The coordinates a torsional spring's angle reads, increasing.
const std::vector<Index>& angle_coordinates(const TorsionalSpring& s) {
  return s.angle ? s.angle->coordinates() : s.joint_coordinates;
}

// ∂θ/∂q_k for angle_coordinates(), into `gradient`: an expression's own gradient, or a joint angle's rate along
// each coordinate's unit velocity (exact: the rate is linear in q̇).
void angle_gradient(const TorsionalSpring& s, const double* q, double t, std::vector<double>& gradient) {
  if (s.angle) {
    gradient.resize(s.angle->coordinates().size());
    s.angle->gradient(q, t, gradient.data());
    return;
  }
  const std::vector<Index>& c = s.joint_coordinates;
  gradient.assign(c.size(), 0.0);
  if (c.empty()) return;
  thread_local std::vector<double> unit;  // (capacity kept from row to row; all zeros between uses)
  unit.resize(std::max(unit.size(), static_cast<std::size_t>(c.back()) + 1), 0.0);
  for (std::size_t i = 0; i < c.size(); ++i) {
    unit[static_cast<std::size_t>(c[i])] = 1.0;
    gradient[i] = evaluate_joint(*s.joint, q, unit.data(), nullptr).rate;
    unit[static_cast<std::size_t>(c[i])] = 0.0;
  }
}

// θ − θ0, and ∂θ/∂q_k into `gradient` (angle_gradient()).
double angle_from_free(const TorsionalSpring& s, const double* q, double t, std::vector<double>& gradient) {
  angle_gradient(s, q, t, gradient);
  if (s.angle) return s.angle->value(q, t) - s.free_angle;
  return std::remainder(evaluate_joint(*s.joint, q, nullptr, nullptr).value - s.free_angle, 2.0 * M_PI);
}

// θ̇ = ∂θ/∂t + ∇θ · q̇, with ∇θ in `gradient` (angle_from_free()'s).
double rate_along(const TorsionalSpring& s, const double* q, const double* qd, double t,
                  const std::vector<double>& gradient) {
  const std::vector<Index>& c = angle_coordinates(s);
  double rate = s.angle ? s.angle->partial_t(q, t) : 0.0;
  for (std::size_t i = 0; i < c.size(); ++i) rate += gradient[i] * qd[c[i]];
  return rate;
}

AngleState angle_state(const TorsionalSpring& s, const double* q, const double* qd, const double* qdd, double t,
                       std::vector<double>& gradient) {
  AngleState st;
  st.from_free = angle_from_free(s, q, t, gradient);
  if (qd) st.rate = rate_along(s, q, qd, t, gradient);
  st.moment = (s.law.has_value() ? s.law.evaluate(st.from_free).f : s.stiffness * st.from_free) + s.damping * st.rate +
              s.friction * friction_direction(st.rate);
  if (s.inertia != 0.0 && qd && qdd) st.moment += s.inertia * angle_acceleration(s, q, qd, qdd, t, gradient);
  if (s.moment.expr) st.moment += s.moment.value(q, qd, t);
  return st;
}

}  // namespace

double angle_rate(const TorsionalSpring& s, const double* q, const double* qd, double t,
                  std::vector<double>& gradient) {
  angle_gradient(s, q, t, gradient);  // (θ itself is not needed)
  return qd ? rate_along(s, q, qd, t, gradient) : 0.0;
}

const std::vector<Index>& torsional_coordinates(const TorsionalSpring& s) { return angle_coordinates(s); }

double LoadValue::value(const double* q, const double* qd, double t) const {
  const double u = expr->value(q, qd, t);
  return law.has_value() ? law.evaluate(u).f : u;  // (NaN outside its table)
}

V3 world_components(const std::array<LoadValue, 3>& components, LoadAxes axes, const Pose& pose, const double* q,
                    const double* qd, double t) {
  double v[3] = {0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < 3; ++k)
    if (components[k].expr) v[k] = components[k].value(q, qd, t);
  const V3 c{v[0], v[1], v[2]};
  return axes == LoadAxes::kPart ? turned(pose.rotation, c) : c;
}

void add_applied_forces(const AppliedLoads& loads, const double* q, const double* qd, const double* qdd, double t,
                        Eigen::VectorXd& Q) {
  for (const AppliedForce& f : loads.forces) {
    const Pose pose = part_pose(f.frame, q, t);
    add_virtual_work(f.frame, pose, f.at, world_components(f.components, f.axes, pose, q, qd, t), {}, q, t, Q);
  }
  for (const AppliedTorque& m : loads.torques) {
    const Pose pose = part_pose(m.frame, q, t);
    add_virtual_work(m.frame, pose, {}, {}, world_components(m.components, m.axes, pose, q, qd, t), q, t, Q);
  }
  for (const LinearSpring& s : loads.springs) {
    const SpringState st = spring_state(s, q, qd, t);
    // the tension pulls a toward b and b toward a
    add_virtual_work(s.a.frame, st.pa, s.a.at, st.tension * st.unit, {}, q, t, Q);
    add_virtual_work(s.b.frame, st.pb, s.b.at, -st.tension * st.unit, {}, q, t, Q);
  }
  thread_local std::vector<double> gradient;  // (capacity kept from row to row)
  for (const TorsionalSpring& s : loads.torsional_springs) {
    const AngleState st = angle_state(s, q, qd, qdd, t, gradient);
    const std::vector<Index>& c = angle_coordinates(s);
    for (std::size_t i = 0; i < c.size(); ++i) Q(c[i]) -= st.moment * gradient[i];
  }
}

double applied_power(const AppliedLoads& loads, const double* q, const double* qd, const double* qdd, double t) {
  double power = 0.0;
  for (const AppliedForce& f : loads.forces) {
    const PartMotion m = part_motion(f.frame, q, qd, nullptr, t);
    power += kin3::dot(world_components(f.components, f.axes, m.pose, q, qd, t), m.point(f.at).first);
  }
  for (const AppliedTorque& tq : loads.torques) {
    const PartMotion m = part_motion(tq.frame, q, qd, nullptr, t);
    power += kin3::dot(world_components(tq.components, tq.axes, m.pose, q, qd, t), m.omega);
  }
  for (const LinearSpring& s : loads.springs) {
    const SpringState st = spring_state(s, q, qd, t);
    if (st.length == 0.0) continue;
    // the rate of L from the ends' velocities (spring_state() computes it only for a damper)
    const double rate = kin3::dot(st.unit, end_velocity(s.b, q, qd, t) - end_velocity(s.a, q, qd, t));
    power -= st.tension * rate;
  }
  thread_local std::vector<double> gradient;
  for (const TorsionalSpring& s : loads.torsional_springs) {
    const AngleState st = angle_state(s, q, qd, qdd, t, gradient);
    power -= st.moment * st.rate;
  }
  return power;
}

}  // namespace phiq
