// same_inertia() and same_loads() (parts/same_forces.hpp): datum by datum, with the equality the frames, the
// attachments and the compiled expressions state of themselves.
#include "parts/same_forces.hpp"

#include "phiq/applied_loads.hpp"

namespace phiq::detail {

namespace {

// Two expressions that are both absent or both present and the same function.
bool same_expression(const std::shared_ptr<const CompiledExpression>& a,
                     const std::shared_ptr<const CompiledExpression>& b) {
  return a == b || (a && b && *a == *b);
}

bool same_value(const LoadValue& a, const LoadValue& b) { return same_expression(a.expr, b.expr) && a.law == b.law; }

bool same_values(const std::array<LoadValue, 3>& a, const std::array<LoadValue, 3>& b) {
  return same_value(a[0], b[0]) && same_value(a[1], b[1]) && same_value(a[2], b[2]);
}

bool same_mass(const MassProperties& a, const MassProperties& b) {
  return a.mass == b.mass && a.center == b.center && a.inertia == b.inertia;
}

bool same_end(const SpringEnd& a, const SpringEnd& b) { return same_frame(a.frame, b.frame) && a.at == b.at; }

bool same_applied(const AppliedLoads& a, const AppliedLoads& b) {
  if (a.forces.size() != b.forces.size() || a.torques.size() != b.torques.size() ||
      a.springs.size() != b.springs.size() || a.torsional_springs.size() != b.torsional_springs.size() ||
      a.gear_losses != b.gear_losses)
    return false;
  for (std::size_t i = 0; i < a.forces.size(); ++i) {
    const AppliedForce &x = a.forces[i], &y = b.forces[i];
    if (!same_frame(x.frame, y.frame) || !(x.at == y.at) || x.axes != y.axes ||
        !same_values(x.components, y.components))
      return false;
  }
  for (std::size_t i = 0; i < a.torques.size(); ++i) {
    const AppliedTorque &x = a.torques[i], &y = b.torques[i];
    if (!same_frame(x.frame, y.frame) || x.axes != y.axes || !same_values(x.components, y.components)) return false;
  }
  for (std::size_t i = 0; i < a.springs.size(); ++i) {
    const LinearSpring &x = a.springs[i], &y = b.springs[i];
    if (!same_end(x.a, y.a) || !same_end(x.b, y.b) || x.stiffness != y.stiffness || x.free_length != y.free_length ||
        x.damping != y.damping || x.preload != y.preload || x.friction != y.friction || !(x.law == y.law) ||
        !same_value(x.tension, y.tension))
      return false;
  }
  for (std::size_t i = 0; i < a.torsional_springs.size(); ++i) {
    const TorsionalSpring &x = a.torsional_springs[i], &y = b.torsional_springs[i];
    if (!same_expression(x.angle, y.angle) || x.joint.has_value() != y.joint.has_value() ||
        (x.joint && (x.joint->measure != y.joint->measure || !(x.joint->att == y.joint->att))) ||
        x.joint_coordinates != y.joint_coordinates || x.stiffness != y.stiffness || x.free_angle != y.free_angle ||
        x.damping != y.damping || x.friction != y.friction || x.inertia != y.inertia || !(x.law == y.law) ||
        !same_value(x.moment, y.moment) || x.bearing != y.bearing)
      return false;
  }
  return true;
}

}  // namespace

bool same_frame(const PartFrame& a, const PartFrame& b) {
  if (a.kind != b.kind || a.spatial_frame != b.spatial_frame || !(a.planar == b.planar) || !(a.spatial == b.spatial) ||
      !(a.origin == b.origin) || !(a.x_toward == b.x_toward) || !(a.y_toward == b.y_toward) ||
      a.x_is_point != b.x_is_point || a.y_is_point != b.y_is_point || !(a.axis == b.axis) ||
      !same_expression(a.angle, b.angle) || a.at.size() != b.at.size())
    return false;
  for (std::size_t i = 0; i < a.at.size(); ++i)
    if (!same_expression(a.at[i], b.at[i])) return false;
  return true;
}

bool same_inertia(const std::vector<Part>& a, const std::vector<Part>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].mass_source != b[i].mass_source || !same_mass(a[i].mass, b[i].mass) || !same_frame(a[i].frame, b[i].frame))
      return false;
  return true;
}

bool same_loads(const Loads& a, const Loads& b) {
  if (!(a.gravity == b.gravity)) return false;
  const bool none_a = !a.applied || a.applied->empty(), none_b = !b.applied || b.applied->empty();
  if (none_a || none_b) return none_a && none_b;
  return a.applied == b.applied || same_applied(*a.applied, *b.applied);
}

}  // namespace phiq::detail
