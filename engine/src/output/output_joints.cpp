// Joint measures and body orientations of a sweep's rows (phiq/output_joints.hpp).
#include "phiq/output_joints.hpp"

#include <algorithm>
#include <cmath>

namespace phiq {

namespace {
// The largest coordinate index an attachment reads.
Index max_slot(const Attachment3& a) {
  Index m = -1;
  for (const Slot& s : a.r)
    if (s.is_coordinate()) m = std::max(m, s.coord());
  for (const Slot& s : a.p)
    if (s.is_coordinate()) m = std::max(m, s.coord());
  return m;
}
// X, Ẋ, Ẍ of an attachment (Ẍ = the q̈-linear part + 2 R(ė) s, as evaluate_point()).
struct Motion3 {
  kin3::V3 x{}, v{}, a{};
};
Motion3 motion(const Attachment3& at, const double* q, const double* qd, const double* qdd) {
  Motion3 m;
  m.x = at.value(q);
  if (qd) m.v = at.rate(q, qd);
  if (qd && qdd) m.a = at.rate(q, qdd) + at.bias(qd);
  return m;
}
// u · w and its first two derivatives.
std::array<double, 3> product(const Motion3& u, const Motion3& w) {
  return {kin3::dot(u.x, w.x), kin3::dot(u.v, w.x) + kin3::dot(u.x, w.v),
          kin3::dot(u.a, w.x) + 2.0 * kin3::dot(u.v, w.v) + kin3::dot(u.x, w.a)};
}
}  // namespace

Index OutputJoint::max_coordinate() const {
  Index m = -1;
  for (const Attachment3& a : att) m = std::max(m, max_slot(a));
  return m;
}

OutputJoint output_joint(std::string name, JointMeasure measure, const JointSide3& a, const JointSide3& b) {
  using namespace detail3;
  OutputJoint j;
  j.name = std::move(name), j.measure = measure;
  static constexpr std::int8_t kAngle[3] = {kXa, kYa, kXb};
  static constexpr std::int8_t kDistance[3] = {kPa, kPb, kZa};
  const std::int8_t* index = measure == JointMeasure::kAngle ? kAngle : kDistance;
  std::int8_t sorted[3] = {index[0], index[1], index[2]};
  std::sort(sorted, sorted + 3);
  const std::array<Attachment3, kCount> all = joint_attachments(a, b, sorted, 3, j.name.c_str());
  // (joint_attachments returns them compacted, in the ascending order of `sorted`)
  for (int k = 0; k < 3; ++k)
    j.att[static_cast<std::size_t>(k)] =
        all[static_cast<std::size_t>(std::find(sorted, sorted + 3, index[k]) - sorted)];
  return j;
}

JointMotion evaluate_joint(const OutputJoint& j, const double* q, const double* qd, const double* qdd) {
  const Motion3 m0 = motion(j.att[0], q, qd, qdd), m1 = motion(j.att[1], q, qd, qdd), m2 = motion(j.att[2], q, qd, qdd);
  JointMotion out;
  if (j.measure == JointMeasure::kDistance) {
    // d = z_a · (P_b − P_a)
    const Motion3 h{m1.x - m0.x, m1.v - m0.v, m1.a - m0.a};
    const std::array<double, 3> d = product(m2, h);
    out.value = d[0], out.rate = qd ? d[1] : 0.0, out.acceleration = qd && qdd ? d[2] : 0.0;
    return out;
  }
  // θ = atan2(s, c), c = x_a · x_b, s = y_a · x_b: θ̇ = (c ṡ − s ċ)/ρ, θ̈ = (c s̈ − s c̈)/ρ − (c ṡ − s ċ) ρ̇/ρ²,
  // ρ = c² + s², ρ̇ = 2 (c ċ + s ṡ)
  const std::array<double, 3> c = product(m0, m2), s = product(m1, m2);
  out.value = std::atan2(s[0], c[0]);
  if (!qd) return out;
  const double rho = c[0] * c[0] + s[0] * s[0], num = c[0] * s[1] - s[0] * c[1];
  out.rate = num / rho;
  if (qdd) {
    const double rhod = 2.0 * (c[0] * c[1] + s[0] * s[1]);
    out.acceleration = (c[0] * s[2] - s[0] * c[2]) / rho - num * rhod / (rho * rho);
  }
  return out;
}

double unwrap_angle(double wrapped, double previous, double predicted_change) {
  const double expected = previous + predicted_change;
  return expected + std::remainder(wrapped - expected, 2.0 * M_PI);
}

std::vector<std::string> OrientationForm::suffixes() const {
  if (form == "matrix") return {"R11", "R12", "R13", "R21", "R22", "R23", "R31", "R32", "R33"};
  if (form == "axis_angle") return {"ux", "uy", "uz", "angle"};
  return {form + "_1", form + "_2", form + "_3"};
}

OrientationMotion evaluate_orientation(const OutputOrientation& o, const OrientationForm& form, const double* q,
                                       const double* qd, const double* qdd) {
  OrientationMotion m;
  const EulerParameters e{o.e[0].of(q), o.e[1].of(q), o.e[2].of(q), o.e[3].of(q)};
  if (form.form == "axis_angle") {
    const auto [u, angle] = axis_angle(e);
    m.values[0] = u[0], m.values[1] = u[1], m.values[2] = u[2], m.values[3] = angle;
  } else {
    const RotationMatrix r = rotation_matrix(e);
    if (form.form == "matrix") {
      std::copy(r.begin(), r.end(), m.values.begin());
    } else {
      const std::array<double, 3> a = sequence_angles(form.form, r);
      std::copy(a.begin(), a.end(), m.values.begin());
    }
  }
  // ω = 2 E(e) ė with E(e) = [−e1 e0 −e3 e2; −e2 e3 e0 −e1; −e3 −e2 e1 e0] (world frame), α = 2 E(e) ë
  auto world = [&](const double* d) {
    const double d0 = o.e[0].rate(d), d1 = o.e[1].rate(d), d2 = o.e[2].rate(d), d3 = o.e[3].rate(d);
    return std::array<double, 3>{2.0 * (-e[1] * d0 + e[0] * d1 - e[3] * d2 + e[2] * d3),
                                 2.0 * (-e[2] * d0 + e[3] * d1 + e[0] * d2 - e[1] * d3),
                                 2.0 * (-e[3] * d0 - e[2] * d1 + e[1] * d2 + e[0] * d3)};
  };
  if (qd) m.omega = world(qd);
  if (qd && qdd) m.alpha = world(qdd);
  return m;
}

}  // namespace phiq
