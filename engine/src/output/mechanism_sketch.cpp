#include "phiq/mechanism_sketch.hpp"

#include <array>
#include <cstdint>
#include <cstring>
#include <set>
#include <utility>

namespace phiq {

namespace {

// A point's identity: kind, the raw bits of its slots (a coordinate index or a constant) and its local
// coordinates; two ends are the same point of the mechanism when they read the same slots the same way.
using PointKey = std::array<std::uint64_t, 12>;
std::uint64_t bits(const Slot& s) {
  std::uint64_t b;
  std::memcpy(&b, &s, sizeof b);
  return b;
}
std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}
PointKey key_of(const OutputPoint& p) {
  switch (p.kind) {
    case OutputPointKind::kPlanarPoint:
      return {0, bits(p.point.x), bits(p.point.y)};
    case OutputPointKind::kPlanarBodyPoint:
      return {1, bits(p.body.x), bits(p.body.y), bits(p.body.psi), bits(p.local_x), bits(p.local_y)};
    default: {
      const Attachment3& a = p.spatial;
      return {
          2,           bits(a.r[0]), bits(a.r[1]), bits(a.r[2]), bits(a.p[0]), bits(a.p[1]), bits(a.p[2]), bits(a.p[3]),
          bits(a.s.x), bits(a.s.y),  bits(a.s.z)};
    }
  }
}

bool moves(const OutputPoint& p) { return p.max_coordinate() >= 0; }

OutputPoint attached(const Attachment3& a) {
  OutputPoint o;
  o.kind = OutputPointKind::kSpatialBodyPoint;
  o.spatial = a;
  return o;
}
bool rotates(const Attachment3& a) {
  for (const Slot& s : a.p)
    if (s.is_coordinate()) return true;
  return false;
}

class Sketcher {
 public:
  Index constraint = -1;  // the constraint being sketched

  void line(const OutputPoint& a, const OutputPoint& b, SketchLine kind) {
    if (!moves(a) && !moves(b)) return;
    PointKey ka = key_of(a), kb = key_of(b);
    if (ka == kb) return;
    if (kb < ka) std::swap(ka, kb);
    if (seen_.emplace(ka, kb).second) out_.segments.push_back({a, b, kind, constraint});
  }
  void mark(const OutputPoint& at, JointMark m, int end = -1, kin::V2 axis = {1, 0}, Frame2 guide = {}) {
    if (!marked_.insert(key_of(at)).second) return;
    out_.joints.push_back({at, m, axis, guide, !moves(at), end, constraint});
  }
  // A link between natural points, and its ends (its length is the derived parts').
  void bar(const Point2& a, const Point2& b, double /*length*/ = 0.0) {
    const OutputPoint pa = planar_point("", a), pb = planar_point("", b);
    line(pa, pb, SketchLine::kBar);
    mark(pa, JointMark::kPoint, 0), mark(pb, JointMark::kPoint, 1);
  }
  // A pair's attachment on a body: its reference point to the attachment point (nothing for a natural point or
  // ground, whose frame does not rotate, or for an attachment at the reference point itself).
  void arm(const Frame2& f, const kin::V2& s) {
    if (!f.psi.is_coordinate() || (s.x == 0.0 && s.y == 0.0)) return;
    line(planar_body_point("", f, 0.0, 0.0), planar_body_point("", f, s.x, s.y), SketchLine::kArm);
  }
  // A revolute pair joining the point sa of frame a and sb of frame b: marked on the side that does not move, if
  // one does not (a ground pivot, drawn still and hatched), else on a.
  void pivot(const Frame2& a, const kin::V2& sa, const Frame2& b, const kin::V2& sb) {
    const OutputPoint pa = planar_body_point("", a, sa.x, sa.y), pb = planar_body_point("", b, sb.x, sb.y);
    mark(moves(pa) && !moves(pb) ? pb : pa, JointMark::kRevolute);
  }
  // A prismatic pair: the block at the point sb of body b, on the guide through sa along `axis` of frame a.
  void slider(const Frame2& a, const kin::V2& axis, const Frame2& b, const kin::V2& sb) {
    mark(planar_body_point("", b, sb.x, sb.y), JointMark::kPrismatic, -1, axis, a);
  }
  // A spatial link between two attachments, and its ends.
  void bar3(const Attachment3& a, const Attachment3& b, double /*length*/ = 0.0) {
    line(attached(a), attached(b), SketchLine::kBar);
    mark(attached(a), JointMark::kPoint, 0), mark(attached(b), JointMark::kPoint, 1);
  }
  // A body's arm in space: the attachment's frame origin to its point (nothing for a frame that does not rotate).
  void arm3(const Attachment3& a) {
    if (!rotates(a) || kin3::is_zero(a.s)) return;
    Attachment3 origin = a;
    origin.s = {};
    line(attached(origin), attached(a), SketchLine::kArm);
  }
  // A spatial joint joining two attachments: marked as pivot() marks.
  void joint3(const Attachment3& a, const Attachment3& b, JointMark m) {
    mark(moves(attached(a)) && !moves(attached(b)) ? attached(b) : attached(a), m);
  }

  // The kinds' own geometry is the derived parts' (drawn_parts.cpp): the sketch's lines and marks have none.
  void joint_parts3(const JointSide3&, const JointSide3&, JointForm) {}
  void thread3(const JointSide3&, double) {}
  void spatial_gear_pair(const JointSide3&, const JointSide3&, const JointSide3&, const JointSide3&, double, double,
                         bool, double) {}
  void open_chain(const std::vector<LoopSpec::Link>&) {}
  void gear_pair(const Slot&, const Slot&, double, double, bool) {}
  void belt(const Slot&, const Slot&, double, double, bool) {}
  void rack(const Slot&, const Slot&, double, bool) {}
  void curve(const CurveOn&) {}
  void roller(const Frame2&, const kin::V2&, double) {}
  void face(const Frame2&, const kin::V2&, const kin::V2&) {}

  MechanismSketch take() { return std::move(out_); }

 private:
  MechanismSketch out_;
  std::set<std::pair<PointKey, PointKey>> seen_;  // segments drawn, either way round
  std::set<PointKey> marked_;                     // joints marked
};

template <class Spec, class F>
void each(const ConstraintBlock& b, F&& f) {
  if (auto* t = dynamic_cast<const TypedBlock<Spec>*>(&b))
    for (std::size_t i = 0; i < t->size(); ++i) f(t->spec(i), t->first_row(i));
}

}  // namespace

MechanismSketch sketch_mechanism(const Model& model) {
  Sketcher sk;
  // per block (one kind each, in the order the model first used them), each constraint's own sketch()
  for (const auto& block : model.blocks())
    ConstraintKinds::for_each([&]<class K>() {
      each<K>(*block, [&](const K& s, Index row) {
        sk.constraint = K::kRows > 0 ? model.constraint_of_row(row) : -1;
        s.sketch(sk);
      });
    });
  return sk.take();
}

std::vector<SketchSegment> sketch_segments(const Model& model) { return sketch_mechanism(model).segments; }

}  // namespace phiq
