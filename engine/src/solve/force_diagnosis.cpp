// nonfinite_force_source() (phiq/inverse_dynamics.hpp): which part or load made Q not finite at a row, and why.
// Called only after a row's Q was found not finite, so it evaluates each contribution alone, plainly.
#include <cmath>
#include <sstream>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/part_motion.hpp"
#include "phiq/text.hpp"
#include "solve/part_forces.hpp"

namespace phiq {

namespace {

using kin3::V3;

bool finite(V3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

bool finite(const Pose& p) {
  if (!finite(p.at)) return false;
  for (double r : p.rotation)
    if (!std::isfinite(r)) return false;
  return true;
}

std::string print(double v) {
  if (std::isnan(v)) return "NaN";
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

// A load's value: (x, y), (x, y, z) where z is not 0, or z alone for a planar torque (about z).
std::string print(V3 v) {
  if (v.x == 0.0 && v.y == 0.0) return print(v.z);
  return "(" + print(v.x) + ", " + print(v.y) + (v.z != 0.0 ? ", " + print(v.z) : std::string()) + ")";
}

V3 slots_at(const Slot* r, const double* q) { return {r[0].of(q), r[1].of(q), r[2].of(q)}; }

// Why `frame`'s pose is not finite at (q, t): a frame of points without a direction, else its values.
std::string frame_fault(const PartFrame& f, const double* q) {
  if (f.kind == PartFrameKind::kPoints) {
    const V3 o = slots_at(f.origin.r, q);
    V3 x = slots_at(f.x_toward.r, q);
    if (f.x_is_point) x = x - o;
    if (!f.spatial_frame) x.z = 0.0;
    if (kin3::dot(x, x) == 0.0)
      return f.x_is_point ? "its frame's x has no direction: x's point is on its origin" : "its frame's x is zero";
    if (f.spatial_frame) {
      V3 y = slots_at(f.y_toward.r, q);
      if (f.y_is_point) y = y - o;
      const V3 n = kin3::cross(x, y);
      if (kin3::dot(n, n) == 0.0) return "its frame's y is along its x (or zero): the frame has no plane";
    }
    return "its frame's origin or direction is not finite";
  }
  if (f.kind == PartFrameKind::kExpressions) return "its frame's expressions are not finite";
  return "its frame's coordinates are not finite";
}

std::string part_fault(const Part& p, V3 gravity, Index n, const double* q, const double* qd, const double* qdd,
                       double t) {
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(n);
  std::vector<Part> one{p};
  add_generalized_forces(one, Loads{gravity, nullptr}, q, qd, qdd, t, Q);
  if (Q.allFinite()) return {};
  const std::string who = "part '" + p.name + "': ";
  if (!finite(part_pose(p.frame, q, t))) return who + frame_fault(p.frame, q);
  const PartMotion m = part_motion(p.frame, q, qd, qdd, t);
  if (!finite(m.velocity) || !finite(m.omega) || !finite(m.acceleration) || !finite(m.alpha))
    return who + "its frame's velocity or acceleration is not finite";
  return who + "its weight and inertia forces overflow doubles (its mass, inertia or gravity too large)";
}

template <class Load>
bool load_finite(const Load& load, std::vector<Load> AppliedLoads::*list, Index n, const double* q, const double* qd,
                 const double* qdd, double t) {
  AppliedLoads one;
  (one.*list).push_back(load);
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(n);
  add_applied_forces(one, q, qd, qdd, t, Q);
  return Q.allFinite();
}

// Why a force's or torque's generalized force is not finite: its value, its part's frame, or an overflow.
template <class Load>
std::string vector_load_fault(const Load& l, const char* what, const double* q, const double* qd, double t) {
  const std::string who = what + (" '" + l.name + "' on part '" + l.part + "': ");
  const Pose pose = part_pose(l.frame, q, t);
  if (!finite(pose)) return who + frame_fault(l.frame, q);
  const V3 v = world_components(l.components, l.axes, pose, q, qd, t);
  for (const LoadValue& c : l.components) {  // a law's argument outside the table it is defined on
    if (!c.expr || !c.law.has_value()) continue;
    const double u = c.expr->value(q, qd, t);
    if (!(u >= c.law.domain_begin() && u <= c.law.domain_end()))
      return who + "its law's argument '" + c.expr->text() + "' is " + significant(u, 6) + ", outside the table's [" +
             significant(c.law.domain_begin(), 6) + ", " + significant(c.law.domain_end(), 6) + "]";
  }
  if (!finite(v)) return who + "its value is not finite: " + print(v);
  return who + "its generalized force overflows doubles";
}

}  // namespace

std::string nonfinite_force_source(const std::vector<Part>& parts, const Loads& loads, Index num_coordinates,
                                   const double* q, const double* qd, const double* qdd, double t) {
  for (const Part& p : parts)
    if (detail::has_mass(p)) {
      std::string why = part_fault(p, loads.gravity, num_coordinates, q, qd, qdd, t);
      if (!why.empty()) return why;
    }
  if (!loads.applied) return {};
  const AppliedLoads& a = *loads.applied;
  const Index n = num_coordinates;
  for (const AppliedForce& f : a.forces)
    if (!load_finite(f, &AppliedLoads::forces, n, q, qd, qdd, t)) return vector_load_fault(f, "force", q, qd, t);
  for (const AppliedTorque& f : a.torques)
    if (!load_finite(f, &AppliedLoads::torques, n, q, qd, qdd, t)) return vector_load_fault(f, "torque", q, qd, t);
  for (const LinearSpring& s : a.springs)
    if (!load_finite(s, &AppliedLoads::springs, n, q, qd, qdd, t))
      return "spring '" + s.name + "': its tension or direction is not finite (its ends' frames or an overflow)";
  for (const TorsionalSpring& s : a.torsional_springs)
    if (!load_finite(s, &AppliedLoads::torsional_springs, n, q, qd, qdd, t))
      return "torsional spring '" + s.name + "': its angle or moment is not finite";
  return {};
}

}  // namespace phiq
