// drawn_parts() (phiq/drawn_parts.hpp): the scene's parts, then those derived from its constraints. Each kind's
// sketch() says what it draws with the primitives of kinds/registry.hpp; PartSketcher turns them into shapes on the
// parts of the bodies (or ground) that carry them, or into parts of their own (natural links, chains, belts).
#include "phiq/drawn_parts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <unordered_map>
#include <utility>

#include "derived_geometry.hpp"
#include "phiq/kinds/registry.hpp"

namespace phiq {

// (a named namespace: the engine's unity build joins this file's helpers with other files' anonymous ones)
namespace drawn {

using derived::about_z;
using kin3::V3;

// Where shapes given in some frame go: the part that carries them and that frame's pose in the part's frame (the
// identity for a body's own part, the constant frame's placement for ground).
struct Target {
  Part* part = nullptr;
  Pose to_part;
};

Attachment3 planar_attachment(const Slot& x, const Slot& y) {
  Attachment3 a;
  a.r[0] = x, a.r[1] = y;
  return a;
}
bool reads_coordinates(const Attachment3& a) {
  for (const Slot& s : a.r)
    if (s.is_coordinate()) return true;
  for (const Slot& s : a.p)
    if (s.is_coordinate()) return true;
  return false;
}
V3 unit(V3 v) { return (1.0 / kin3::norm(v)) * v; }
std::string number(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "(%.17g)", v);
  return text;
}
std::string slot_text(const Slot& s) { return s.is_coordinate() ? "q" + std::to_string(s.coord()) : number(s.value()); }

class PartSketcher {
 public:
  Index constraint = -1;  // the constraint being sketched

  explicit PartSketcher(const Scene& scene)
      : scene_(scene),
        model_(*scene.model),
        q0_(scene.model->initial_positions().data()),
        w_(scene.model->length_scale() / 50.0) {
    ground_.name = ground_.body = "ground";
    ground_.derived = ground_.fixed = true;
    for (std::size_t i = 0; i < scene.planar_bodies.size(); ++i) {
      PartFrame f;
      f.kind = PartFrameKind::kPlanarBody, f.planar = scene.planar_bodies[i];
      planar_.push_back(body_part(i, f));
      const Frame2& b = scene.planar_bodies[i];
      for (const Slot* s : {&b.x, &b.y, &b.psi})
        if (s->is_coordinate()) planar_of_[s->coord()] = i;
    }
    for (std::size_t i = 0; i < scene.spatial_bodies.size(); ++i) {
      PartFrame f;
      f.kind = PartFrameKind::kSpatialBody, f.spatial = scene.spatial_bodies[i];
      spatial_.push_back(body_part(i, f));
      const Frame3& b = scene.spatial_bodies[i];
      for (const Slot* s : {&b.x, &b.y, &b.z, &b.e0, &b.e1, &b.e2, &b.e3})
        if (s->is_coordinate()) spatial_of_[s->coord()] = i;
    }
  }

  // --- planar pairs and natural links
  void bar(const Point2& a, const Point2& b, double length = 0.0) {
    link(planar_attachment(a.x, a.y), planar_attachment(b.x, b.y), length, false);
  }
  void arm(const Frame2& f, const kin::V2& s) {
    if (!f.psi.is_coordinate() || (s.x == 0.0 && s.y == 0.0)) return;
    if (auto c = derived::capsule({}, {s.x, s.y, 0}, w_)) put(target(f), *c, "link");
  }
  void pivot(const Frame2& a, const kin::V2& sa, const Frame2& b, const kin::V2& sb) {
    put(target(a), derived::cylinder({sa.x, sa.y, 0}, {0, 0, 1}, 1.5 * w_, 2 * w_), "pin");
    put(target(b), derived::cylinder({sb.x, sb.y, 0}, {0, 0, 1}, 1.5 * w_, 2 * w_), "pin");
  }
  // b's block at sb, turned with the guide; a's guide through the block's place at the initial placement.
  void slider(const Frame2& a, const kin::V2& axis, const Frame2& b, const kin::V2& sb) {
    const double guide = std::atan2(axis.y, axis.x), psi_a = a.psi.of(q0_), psi_b = b.psi.of(q0_);
    put(target(b), derived::box({sb.x, sb.y, 0}, about_z(psi_a + guide - psi_b), {4 * w_, 3 * w_, 3 * w_}), "block");
    const V3 block = pose_of(b).apply({sb.x, sb.y, 0});
    const V3 on_a = derived::to_local(pose_of(a), block);
    put(target(a), derived::box(on_a, about_z(guide), {model_.length_scale(), w_, w_}), "guide");
  }

  // --- spatial joints and links
  void bar3(const Attachment3& a, const Attachment3& b, double length = 0.0) { link(a, b, length, true); }
  void arm3(const Attachment3& a) {
    if (!reads_coordinates(a) || kin3::is_zero(a.s)) return;
    if (auto c = derived::capsule({}, a.s, w_)) put(target(frame_of(a)), *c, "link");
  }
  void joint3(const Attachment3&, const Attachment3&, JointMark) {}
  void joint_parts3(const JointSide3& a, const JointSide3& b, JointForm form) {
    const Target ta = a.natural ? Target{} : target(a.frame), tb = b.natural ? Target{} : target(b.frame);
    const V3 ua = unit(a.axis), ub = unit(b.axis);
    switch (form) {
      case JointForm::kBall:
        if (moves(a.frame)) put(ta, derived::sphere(a.at, 1.5 * w_), "ball");
        if (moves(b.frame)) put(tb, derived::sphere(b.at, 1.5 * w_), "ball");
        return;
      case JointForm::kHinge:
        put(tb, derived::cylinder(b.at, ub, 1.2 * w_, 8 * w_), "shaft");
        for (double side : {-3.0, 3.0})
          put(ta, derived::box(a.at + (side * w_) * ua, derived::z_along(ua), {4 * w_, 4 * w_, w_}), "fork");
        return;
      case JointForm::kShaft:
        put(tb, derived::cylinder(b.at, ub, w_, 12 * w_), "shaft");
        put(ta, derived::cylinder(a.at, ua, 2 * w_, 4 * w_), "sleeve");
        return;
      case JointForm::kCross:
        put(ta, derived::cylinder(a.at, ua, 0.8 * w_, 6 * w_), "cross");
        put(tb, derived::cylinder(b.at, ub, 0.8 * w_, 6 * w_), "cross");
        return;
      case JointForm::kSlider: {
        put(tb, derived::box(b.at, derived::z_along(ub), {3 * w_, 3 * w_, 4 * w_}), "block");
        if (b.natural || a.natural) return;
        const V3 on_a = derived::to_local(pose_of(a.frame), pose_of(b.frame).apply(b.at));  // the block's place
        put(ta, derived::box(on_a, derived::z_along(ua), {w_, w_, 2 * scale()}), "guide");
        return;
      }
    }
  }
  // The thread: a helix of lead `pitch` about side b's axis, some turns about its point.
  void thread3(const JointSide3& b, double pitch) {
    if (b.natural) return;
    const V3 axis = unit(b.axis);
    const RotationMatrix r = derived::z_along(axis);
    const int turns = std::clamp(static_cast<int>(std::ceil(12 * w_ / std::fabs(pitch))), 2, 64);
    put(target(b.frame),
        derived::polyline(derived::helix(b.at, axis, {r[0], r[3], r[6]}, 1.6 * w_, pitch, turns, 24), false, w_ / 4),
        "thread");
  }
  void spatial_gear_pair(const JointSide3& a1, const JointSide3& b1, const JointSide3& a2, const JointSide3& b2,
                         double z1, double z2, bool reversed, double mesh_offset);
  void parallel_gear_pair(const JointSide3& b1, const JointSide3& b2, V3 centre1, V3 axis, V3 on2, double z1, double z2,
                          bool internal);

  // --- the kinds' own geometry in the plane
  void open_chain(const std::vector<LoopSpec::Link>& links);
  void gear_pair(const Slot& first, const Slot& second, double r1, double r2, bool internal);
  void belt(const Slot& first, const Slot& second, double r1, double r2, bool crossed);
  void rack(const Slot& travel, const Slot& pinion, double radius, bool reversed);
  void curve(const CurveOn& on) {
    const Target t = target(on.frame);
    if (!on.curve || !t.part) return;
    std::vector<V3> points = derived::curve_samples(*on.curve, 128);
    if (!on.curve->closed()) return put(t, derived::polyline(std::move(points), false, w_ / 2), "slot");
    Shape profile;  // a closed curve is a cam's profile: its outline extruded
    profile.kind = ShapeKind::kPolygon, profile.length = 2 * w_;
    for (const V3& p : points) profile.outline.push_back({p.x, p.y});
    put(t, profile, "profile");
  }
  void roller(const Frame2& a, const kin::V2& sa, double radius) {
    put(target(a), derived::cylinder({sa.x, sa.y, 0}, {0, 0, 1}, radius, 2 * w_), "roller");
  }
  void face(const Frame2& a, const kin::V2& sa, const kin::V2& direction) {
    const RotationMatrix r = about_z(std::atan2(direction.y, direction.x));
    put(target(a), derived::box({sa.x, sa.y, 0}, r, {0.5 * scale(), w_ / 2, 2 * w_}), "face");
  }

  std::vector<Part> take();

 private:
  Part body_part(std::size_t i, const PartFrame& f) const {
    Part p;
    p.name = p.body = i < model_.body_names().size() ? model_.body_names()[i] : "body" + std::to_string(i);
    p.frame = f, p.derived = true;
    return p;
  }
  double scale() const { return model_.length_scale(); }
  std::string name() const {
    return constraint >= 0 ? model_.constraints()[static_cast<std::size_t>(constraint)].name : "constraint";
  }
  void put(const Target& t, Shape s, const char* what) {
    if (!t.part) return;
    s.at = t.to_part.apply(s.at);
    s.rotation = derived::compose(t.to_part.rotation, s.rotation);
    s.name = name() + "." + what;
    t.part->shapes.push_back(std::move(s));
  }
  static bool moves(const Frame3& f) { return !f.is_fixed(); }
  static Frame3 frame_of(const Attachment3& a) {
    return Frame3{a.r[0], a.r[1], a.r[2], a.p[0], a.p[1], a.p[2], a.p[3]};
  }
  Pose pose_of(const Frame2& f) const {
    PartFrame pf;
    pf.kind = PartFrameKind::kPlanarBody, pf.planar = f;
    return part_pose(pf, q0_, 0.0);
  }
  Pose pose_of(const Frame3& f) const {
    PartFrame pf;
    pf.kind = PartFrameKind::kSpatialBody, pf.spatial = f;
    return part_pose(pf, q0_, 0.0);
  }
  // A planar body's part, ground's (with the constant frame's pose), or none (a natural point's frame).
  Target target(const Frame2& f) {
    if (!f.x.is_coordinate() && !f.y.is_coordinate() && !f.psi.is_coordinate()) return {&ground_, pose_of(f)};
    const auto i = f.psi.is_coordinate() ? planar_of_.find(f.psi.coord()) : planar_of_.end();
    if (i == planar_of_.end() || !(scene_.planar_bodies[i->second] == f)) return {};
    return {&planar_[i->second], Pose{}};
  }
  Target target(const Frame3& f) {
    if (f.is_fixed()) return {&ground_, pose_of(f)};
    for (const Slot* s : {&f.x, &f.y, &f.z, &f.e0, &f.e1, &f.e2, &f.e3}) {
      const auto i = s->is_coordinate() ? spatial_of_.find(s->coord()) : spatial_of_.end();
      if (i != spatial_of_.end() && scene_.spatial_bodies[i->second] == f) return {&spatial_[i->second], Pose{}};
    }
    return {};
  }
  // The planar body whose angle is `angle` (none for an angle coordinate of no body).
  const Frame2* body_turning(const Slot& angle) const {
    const auto i = angle.is_coordinate() ? planar_of_.find(angle.coord()) : planar_of_.end();
    if (i == planar_of_.end() || !(scene_.planar_bodies[i->second].psi == angle)) return nullptr;
    return &scene_.planar_bodies[i->second];
  }
  void link(const Attachment3& a, const Attachment3& b, double length, bool spatial);
  void add_link(Part p, bool measured);

  const Scene& scene_;
  const Model& model_;
  const double* q0_;  // the initial placement: where sizes that depend on a position are measured
  double w_;          // a link's radius: length_scale() / 50
  std::vector<Part> planar_, spatial_, links_;
  std::vector<bool> link_measured_;  // links_[k] took its length from the placement (a later stated one replaces it)
  // the first of links_ from each origin toward each point (attachment_key of both): a bar named again is found
  // in one look-up, not a scan of every link (a 10⁵-loop chain has 2·10⁵)
  std::unordered_map<std::string, std::size_t> link_at_;
  Part ground_;
  std::unordered_map<Index, std::size_t> planar_of_, spatial_of_;  // a body's coordinate → the body
};

// The bytes of a link's two ends, origin first (a signed zero of a local vector counted as +0, as == counts it).
std::string attachment_key(const Attachment3& origin, const Attachment3& toward) {
  static_assert(sizeof(Attachment3) == 7 * sizeof(Slot) + sizeof(kin3::V3), "no padding in a key's bytes");
  std::string key;
  for (Attachment3 a : {origin, toward}) {
    a.s = {a.s.x + 0.0, a.s.y + 0.0, a.s.z + 0.0};
    key.append(reinterpret_cast<const char*>(&a), sizeof a);
  }
  return key;
}

void PartSketcher::add_link(Part p, bool measured) {
  link_at_.emplace(attachment_key(p.frame.origin, p.frame.x_toward), links_.size());
  links_.push_back(std::move(p));
  link_measured_.push_back(measured);
}

// A link between two points (natural, or attached to bodies): a part whose frame has its origin at a and x toward b,
// and a capsule along x of the link's length (else their distance at the placement); between fixed points, on
// ground. A link already drawn between the same two points is not drawn again.
void PartSketcher::link(const Attachment3& a, const Attachment3& b, double length, bool spatial) {
  const V3 pa = a.value(q0_), pb = b.value(q0_);
  if (!reads_coordinates(a) && !reads_coordinates(b)) {
    if (auto c = derived::capsule(pa, pb, w_)) put({&ground_, Pose{}}, *c, "link");
    return;
  }
  const double measured = kin3::norm(pb - pa), l = length > 0.0 ? length : measured;
  const auto ab = link_at_.find(attachment_key(a, b)), ba = link_at_.find(attachment_key(b, a));
  if (ab != link_at_.end() || ba != link_at_.end()) {
    const std::size_t k =
        std::min(ab != link_at_.end() ? ab->second : links_.size(), ba != link_at_.end() ? ba->second : links_.size());
    if (link_measured_[k] && length > 0.0) links_[k].shapes[0].length = l, link_measured_[k] = false;
    return;
  }
  if (!(l > 0.0)) return;
  Part p;
  p.name = p.body = name();
  p.derived = true;
  p.frame.kind = PartFrameKind::kPoints, p.frame.origin = a, p.frame.x_toward = b, p.frame.spatial_frame = spatial;
  if (spatial) {  // y toward the world axis least along the link at the placement
    const V3 d = pb - pa;
    const V3 y = std::fabs(d.x) <= std::fabs(d.y) && std::fabs(d.x) <= std::fabs(d.z) ? V3{1, 0, 0}
                 : std::fabs(d.y) <= std::fabs(d.z)                                   ? V3{0, 1, 0}
                                                                                      : V3{0, 0, 1};
    p.frame.y_toward.r[0] = Slot::constant(y.x), p.frame.y_toward.r[1] = Slot::constant(y.y);
    p.frame.y_toward.r[2] = Slot::constant(y.z), p.frame.y_is_point = false;
  }
  add_link(std::move(p), !(length > 0.0));
  put({&links_.back(), Pose{}}, *derived::capsule({}, {l, 0, 0}, w_), "link");
}

// The links of a loop in relative coordinates, each a part of expressions: its start Σ_{j<k} ℓ_j (cos θ_j, sin θ_j)
// and its angle θ_k; a capsule of its length, or, for a length that is a coordinate (a slider's travel), a block
// at its end.
void PartSketcher::open_chain(const std::vector<LoopSpec::Link>& links) {
  const Index n = model_.num_coordinates();
  const NameResolver coordinates = [n](const std::string& s) -> std::optional<NameBinding> {
    if (s.size() < 2 || s[0] != 'q' || s.find_first_not_of("0123456789", 1) != std::string::npos) return std::nullopt;
    const Index i = std::stoll(s.substr(1));
    if (i >= n) return std::nullopt;
    return NameBinding{NameBinding::Kind::kCoordinate, i, 0.0};
  };
  std::string x = "0", y = "0";
  for (std::size_t k = 0; k < links.size(); ++k) {
    std::string angle = number(links[k].offset);
    for (const LoopSpec::Term& t : links[k].terms) angle += " + " + number(t.sign) + "*" + slot_text(t.angle);
    const std::string length = slot_text(links[k].length);
    const std::string end_x = x + " + " + length + "*cos(" + angle + ")",
                      end_y = y + " + " + length + "*sin(" + angle + ")";
    const bool slides = links[k].length.is_coordinate();
    Part p;
    p.name = p.body = name() + "[" + std::to_string(k) + "]";
    p.derived = true;
    p.frame.kind = PartFrameKind::kExpressions;
    p.frame.at = {CompiledExpression::compile(slides ? end_x : x, coordinates, false),
                  CompiledExpression::compile(slides ? end_y : y, coordinates, false)};
    p.frame.angle = CompiledExpression::compile(angle, coordinates, false);
    add_link(std::move(p), false);
    if (slides)
      put({&links_.back(), Pose{}}, derived::box({}, about_z(0), {4 * w_, 3 * w_, 3 * w_}), "block");
    else if (auto c = derived::capsule({}, {links[k].length.value(), 0, 0}, w_))
      put({&links_.back(), Pose{}}, *c, "link");
    x = end_x, y = end_y;
  }
}

// The pitch circles of a spatial gear pair: the pitch cones' apex where the housings' axes (sides a) cross at the
// placement (the middle of their common perpendicular), the shaft angle Σ between them, the cone angles
// tan δ1 = sin Σ / (z2/z1 + cos Σ), δ2 = Σ − δ1, and a cone distance R of length_scale()/4: gear i a disc of radius
// R sin δ_i (so r1 : r2 = z1 : z2) about its shaft's axis, R cos δ_i from the apex along z_a, on the shaft (side b).
// Parallel shafts: radii in the ratio that fill the distance a between the axes (a z_i/(z1 + z2), or a z_i/|z2 − z1|
// for an internal pair, whose ring is a ring), in the mid-plane mesh_offset along axis 1 from its joint's point.
void PartSketcher::spatial_gear_pair(const JointSide3& a1, const JointSide3& b1, const JointSide3& a2,
                                     const JointSide3& b2, double z1, double z2, bool reversed, double mesh_offset) {
  if (a1.natural || a2.natural || b1.natural || b2.natural) return;
  const Pose h1 = pose_of(a1.frame), h2 = pose_of(a2.frame);
  const V3 p1 = h1.apply(a1.at), p2 = h2.apply(a2.at);
  const V3 u1 = unit(derived::turn(h1, a1.axis)), u2 = unit(derived::turn(h2, a2.axis));
  const double c = kin3::dot(u1, u2), s = kin3::norm(kin3::cross(u1, u2));
  if (!(s > 1e-9))
    return parallel_gear_pair(b1, b2, p1 + mesh_offset * u1, u1, p2, z1, z2, parallel_pair_internal(c, reversed));
  // the common perpendicular: p1 + t1 u1 and p2 + t2 u2 nearest each other
  const V3 d = p2 - p1;
  const double t1 = (kin3::dot(d, u1) - c * kin3::dot(d, u2)) / (s * s);
  const double t2 = (c * kin3::dot(d, u1) - kin3::dot(d, u2)) / (s * s);
  const V3 apex = 0.5 * ((p1 + t1 * u1) + (p2 + t2 * u2));
  const double sigma = std::atan2(s, c), delta1 = std::atan2(s, z2 / z1 + c), cone = scale() / 4;
  const double delta[2] = {delta1, sigma - delta1};
  const JointSide3* shaft[2] = {&b1, &b2};
  const V3 axis[2] = {u1, u2};
  for (int i = 0; i < 2; ++i) {
    const V3 centre = apex + (cone * std::cos(delta[i])) * axis[i];
    const V3 local = derived::to_local(pose_of(shaft[i]->frame), centre);
    put(target(shaft[i]->frame), derived::cylinder(local, shaft[i]->axis, cone * std::sin(delta[i]), w_),
        "pitch_circle");
  }
}

// The pitch circles of spatial_gear_pair()'s gears on parallel shafts: `centre1` on axis 1 (unit `axis`) in their
// mid-plane, `on2` a point of axis 2.
void PartSketcher::parallel_gear_pair(const JointSide3& b1, const JointSide3& b2, V3 centre1, V3 axis, V3 on2,
                                      double z1, double z2, bool internal) {
  const ParallelPitch pitch = parallel_pitch(centre1, axis, on2, internal, z2 / z1);
  if (!(pitch.r1 > 0.0)) return;
  const V3 centre[2] = {centre1, centre1 + pitch.a * pitch.rho};
  const double radius[2] = {pitch.r1, pitch.r2};
  const JointSide3* shaft[2] = {&b1, &b2};
  for (int i = 0; i < 2; ++i) {
    const Pose pose = pose_of(shaft[i]->frame);
    const V3 local = derived::to_local(pose, centre[i]), local_axis = derived::to_local(pose, pose.at + axis);
    if (!(internal && radius[i] > radius[1 - i])) {
      put(target(shaft[i]->frame), derived::cylinder(local, local_axis, radius[i], w_), "pitch_circle");
      continue;
    }
    const RotationMatrix r = derived::z_along(unit(local_axis));  // a ring gear: a ring
    put(target(shaft[i]->frame),
        derived::polyline(derived::helix(local, unit(local_axis), {r[0], r[3], r[6]}, radius[i], 0.0, 1, 360), true,
                          w_ / 2),
        "pitch_circle");
  }
}

// The pitch circles of a gear pair turning about its bodies' reference points: radii in the pair's ratio that fill
// the distance d between the centres at the placement (r_i d/(r1 + r2) external, r_i d/(r2 − r1) internal), so that
// tooth counts and pitch radii draw alike; a disc, or a ring for an internal pair's ring gear. Nothing for a gear
// that is no body's angle, or centres that coincide.
void PartSketcher::gear_pair(const Slot& first, const Slot& second, double r1, double r2, bool internal) {
  const Frame2 *g1 = body_turning(first), *g2 = body_turning(second);
  if (!g1 || !g2) return;
  const double d = kin3::norm(pose_of(*g1).at - pose_of(*g2).at), sum = internal ? r2 - r1 : r1 + r2;
  if (!(d > 0.0) || !(sum > 0.0)) return;
  const double p1 = d * r1 / sum, p2 = d * r2 / sum;
  put(target(*g1), derived::cylinder({}, {0, 0, 1}, p1, w_), "pitch_circle");
  if (!internal) return put(target(*g2), derived::cylinder({}, {0, 0, 1}, p2, w_), "pitch_circle");
  std::vector<V3> ring;
  for (int k = 0; k < 360; ++k)
    ring.push_back({p2 * std::cos(k * std::numbers::pi / 180), p2 * std::sin(k * std::numbers::pi / 180), 0.0});
  put(target(*g2), derived::polyline(std::move(ring), true, w_ / 2), "pitch_circle");
}

// A belt's pulleys about their bodies' reference points, of the belt's radii when they fit between the centres
// (r1 + r2 < d at the placement), else (tooth counts) scaled to r1 + r2 = d/2; and its path, a part whose frame has
// its origin at pulley 1's centre and x toward pulley 2's.
void PartSketcher::belt(const Slot& first, const Slot& second, double r1, double r2, bool crossed) {
  const Frame2 *g1 = body_turning(first), *g2 = body_turning(second);
  if (!g1 || !g2) return;
  const double d = kin3::norm(pose_of(*g1).at - pose_of(*g2).at);
  if (!(d > 0.0)) return;
  const double k = r1 + r2 < d ? 1.0 : 0.5 * d / (r1 + r2);
  r1 *= k, r2 *= k;
  put(target(*g1), derived::cylinder({}, {0, 0, 1}, r1, w_), "pulley");
  put(target(*g2), derived::cylinder({}, {0, 0, 1}, r2, w_), "pulley");
  Part p;
  p.name = p.body = name();
  p.derived = true;
  p.frame.kind = PartFrameKind::kPoints;
  p.frame.origin = planar_attachment(g1->x, g1->y), p.frame.x_toward = planar_attachment(g2->x, g2->y);
  p.fixed = max_coordinate(p.frame) < 0;
  add_link(std::move(p), false);
  put({&links_.back(), Pose{}},
      derived::polyline(derived::belt_path(d, r1, r2, crossed, std::numbers::pi / 180), true, w_ / 2), "path");
}

// The pinion's pitch circle on its body; the rack on the body whose x (or y) is the travel, along it, its pitch line
// tangent to the pitch circle at the placement (below it, or above for `reversed`).
void PartSketcher::rack(const Slot& travel, const Slot& pinion, double radius, bool reversed) {
  const Frame2* p = body_turning(pinion);
  if (!p) return;
  put(target(*p), derived::cylinder({}, {0, 0, 1}, radius, w_), "pitch_circle");
  const auto i = travel.is_coordinate() ? planar_of_.find(travel.coord()) : planar_of_.end();
  if (i == planar_of_.end()) return;
  const Frame2& r = scene_.planar_bodies[i->second];
  if (!(r.x == travel) && !(r.y == travel)) return;
  const V3 along = r.x == travel ? V3{1, 0, 0} : V3{0, 1, 0}, normal{-along.y, along.x, 0};
  const double side = reversed ? 1.0 : -1.0;
  const V3 centre = pose_of(*p).at + (side * (radius + w_ / 2)) * normal;
  const Pose rack_pose = pose_of(r);
  const double angle = std::atan2(along.y, along.x) - r.psi.of(q0_);
  put(target(r),
      derived::box(derived::to_local(rack_pose, centre), about_z(angle),
                   {std::max(4 * std::numbers::pi * radius, scale()), w_, 2 * w_}),
      "rack");
}

// The parts, bodies' first (those with shapes, and none for a body with a stated part), then the links, then ground.
std::vector<Part> PartSketcher::take() {
  auto stated = [&](const PartFrame& f) {
    for (const Part& s : scene_.parts) {
      const PartFrame& g = s.frame;
      if (g.kind != f.kind) continue;
      if (f.kind == PartFrameKind::kPlanarBody && g.planar == f.planar) return true;
      if (f.kind == PartFrameKind::kSpatialBody && g.spatial == f.spatial) return true;
      if (f.kind == PartFrameKind::kPoints && g.x_is_point &&
          ((g.origin == f.origin && g.x_toward == f.x_toward) || (g.origin == f.x_toward && g.x_toward == f.origin)))
        return true;
    }
    return false;
  };
  bool ground_stated = false;
  for (const Part& s : scene_.parts)
    ground_stated = ground_stated || (s.fixed && s.frame.kind != PartFrameKind::kPoints);
  std::vector<Part> out = scene_.parts;
  for (std::vector<Part>* list : {&planar_, &spatial_, &links_})
    for (Part& p : *list)
      if (!p.shapes.empty() && !stated(p.frame)) out.push_back(std::move(p));
  if (!ground_.shapes.empty() && !ground_stated) out.push_back(std::move(ground_));
  return out;
}

template <class Spec, class F>
void each_spec(const ConstraintBlock& b, F&& f) {
  if (auto* t = dynamic_cast<const TypedBlock<Spec>*>(&b))
    for (std::size_t i = 0; i < t->size(); ++i) f(t->spec(i), t->first_row(i));
}

}  // namespace drawn

std::vector<Part> drawn_parts(const Scene& scene) {
  if (!scene.model) return scene.parts;
  drawn::PartSketcher sk(scene);
  for (const auto& block : scene.model->blocks())
    ConstraintKinds::for_each([&]<class K>() {
      drawn::each_spec<K>(*block, [&](const K& s, Index row) {
        sk.constraint = K::kRows > 0 ? scene.model->constraint_of_row(row) : -1;
        s.sketch(sk);
      });
    });
  return sk.take();
}

}  // namespace phiq
