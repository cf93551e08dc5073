// Set-up of the spatial joints: from the sides as given (a body with a local point, axis and reference direction;
// ground; a natural point and vector) to the attachments their rows read.
#include "phiq/constraint_kinds_3d.hpp"

namespace phiq::detail3 {

namespace {

bool finite(kin3::V3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The joint frame (x, y, z) of a body side in the body's frame: z the unit axis, x the unit part of the reference
// direction perpendicular to z, y = z × x.
struct LocalFrame {
  kin3::V3 x, y, z;
};

LocalFrame local_frame(const JointSide3& s, const std::string& who) {
  if (!finite(s.axis)) throw Error(who + ": axis is not finite");
  const double n = kin3::norm(s.axis);
  if (!(n > 0.0)) throw Error(who + ": axis must not be zero");
  LocalFrame f;
  f.z = (1.0 / n) * s.axis;
  const kin3::V3 ref = reference_direction(s);
  if (!finite(ref)) throw Error(who + ": ref is not finite");
  const kin3::V3 perp = ref - kin3::dot(ref, f.z) * f.z;
  const double m = kin3::norm(perp), r = kin3::norm(ref);
  if (!(r > 0.0) || !(m > 1e-6 * r)) throw Error(who + ": ref must not be zero or along the axis");
  f.x = (1.0 / m) * perp;
  f.y = kin3::cross(f.z, f.x);
  return f;
}

}  // namespace

kin3::V3 reference_direction(const JointSide3& s) {
  if (s.ref) return *s.ref;
  const double n = kin3::norm(s.axis);
  // x, unless the axis is within 25° of it; then y (|z_x| ≥ cos 25°, so y's part perpendicular to z is ≥ sin 25°)
  return n > 0.0 && std::fabs(s.axis.x / n) >= std::cos(25.0 * M_PI / 180.0) ? kin3::V3{0, 1, 0} : kin3::V3{1, 0, 0};
}

void joint_axes(const JointSide3& s, const double* q, kin3::V3 axes[3]) {
  if (s.natural) return;
  const LocalFrame f = local_frame(s, "joint_axes");
  const double e[4] = {s.frame.e0.of(q), s.frame.e1.of(q), s.frame.e2.of(q), s.frame.e3.of(q)};
  // R(p) with p·p within the solver's tolerance of 1 scales every vector by p·p: normalised, still orthogonal
  for (int k = 0; k < 3; ++k) {
    const kin3::V3 w = kin3::rotate(e, k == 0 ? f.x : (k == 1 ? f.y : f.z));
    axes[k] = (1.0 / kin3::norm(w)) * w;
  }
}

ReactionSite joint_reaction_site(const JointSide3& a, const JointSide3& b, const double* q) {
  const Frame3& f = a.frame;
  const kin3::V3 r{f.x.of(q), f.y.of(q), f.z.of(q)};
  const double e[4] = {f.e0.of(q), f.e1.of(q), f.e2.of(q), f.e3.of(q)};
  const kin3::V3 s = kin3::rotate(e, a.at);
  ReactionSite site;
  site.point = {r.x + s.x, r.y + s.y, r.z + s.z};
  site.spatial = true;
  const bool on_a = detail::frame_moves(a.frame);
  site.frame3 = on_a ? a.frame : b.frame;
  joint_axes(on_a ? a : b, q, site.axes);
  return site;
}

std::array<Attachment3, kCount> joint_attachments(const JointSide3& a, const JointSide3& b, const std::int8_t* index,
                                                  int count, const char* kind) {
  bool used[kCount] = {};
  for (int i = 0; i < count; ++i) used[index[i]] = true;
  std::array<Attachment3, kCount> att{};
  const JointSide3* sides[2] = {&a, &b};
  for (int k = 0; k < 2; ++k) {
    const JointSide3& s = *sides[k];
    const std::string who = std::string(kind) + ": side " + (k == 0 ? "a" : "b");
    const int P = k == 0 ? kPa : kPb, X = k == 0 ? kXa : kXb, Y = k == 0 ? kYa : kYb, Z = k == 0 ? kZa : kZb;
    if (!finite(s.at)) throw Error(who + ": point is not finite");
    att[P] = Attachment3::body_point(s.frame, s.at);
    const bool frame_needed = used[X] || used[Y], axis_needed = used[Z];
    if (s.natural) {
      if (frame_needed)
        throw Error(who + ": needs a body or ground (a natural point and vector define no perpendicular directions)");
      if (axis_needed) {
        if (!s.vector) throw Error(who + ": needs an axis (a natural vector, or a body)");
        att[Z] = Attachment3::natural(*s.vector);
      }
      continue;
    }
    if (!frame_needed && !axis_needed) continue;
    const LocalFrame f = local_frame(s, who);
    att[X] = Attachment3::body_vector(s.frame, f.x);
    att[Y] = Attachment3::body_vector(s.frame, f.y);
    att[Z] = Attachment3::body_vector(s.frame, f.z);
  }
  // the named ones, in order, folded where they are constants
  std::array<Attachment3, kCount> out{};
  for (int i = 0; i < count; ++i) {
    out[static_cast<std::size_t>(i)] = att[static_cast<std::size_t>(index[i])];
    out[static_cast<std::size_t>(i)].fold_constant();
  }
  return out;
}

}  // namespace phiq::detail3
