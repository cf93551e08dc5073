#include "phiq/mechanism_sketch.hpp"

#include <set>
#include <tuple>
#include <utility>

namespace phiq {

namespace {

// A point's identity: kind, slots and local coordinates; two ends are the same point of the mechanism when they
// read the same slots the same way.
using PointKey = std::tuple<int, Index, double, Index, double, Index, double, double, double>;
double constant_part(const Slot& s) { return s.value(); }
PointKey key_of(const OutputPoint& p) {
  if (p.kind == OutputPointKind::kPlanarPoint)
    return {0, p.point.x.coord(), constant_part(p.point.x), p.point.y.coord(), constant_part(p.point.y), -1, 0.0, 0.0, 0.0};
  return {1, p.body.x.coord(), constant_part(p.body.x), p.body.y.coord(), constant_part(p.body.y), p.body.psi.coord(),
          constant_part(p.body.psi), p.local_x, p.local_y};
}

bool moves(const OutputPoint& p) { return p.max_coordinate() >= 0; }

class Sketcher {
 public:
  void line(const OutputPoint& a, const OutputPoint& b) {
    if (!moves(a) && !moves(b)) return;
    PointKey ka = key_of(a), kb = key_of(b);
    if (ka == kb) return;
    if (kb < ka) std::swap(ka, kb);
    if (seen_.emplace(ka, kb).second) out_.push_back({a, b});
  }
  void bar(const Point2& a, const Point2& b) { line(planar_point("", a), planar_point("", b)); }
  // A pair's attachment on a body: its reference point to the attachment point (nothing for a natural point or
  // ground, whose frame does not rotate, or for an attachment at the reference point itself).
  void arm(const Frame2& f, const kin::V2& s) {
    if (!f.psi.is_coordinate() || (s.x == 0.0 && s.y == 0.0)) return;
    line(planar_body_point("", f, 0.0, 0.0), planar_body_point("", f, s.x, s.y));
  }
  std::vector<SketchSegment> take() { return std::move(out_); }

 private:
  std::vector<SketchSegment> out_;
  std::set<std::pair<PointKey, PointKey>> seen_;  // segments drawn, either way round
};

template <class Spec, class F>
void each(const ConstraintBlock& b, F&& f) {
  if (auto* t = dynamic_cast<const TypedBlock<Spec>*>(&b))
    for (std::size_t i = 0; i < t->size(); ++i) f(t->spec(i));
}

}  // namespace

std::vector<SketchSegment> sketch_segments(const Model& model) {
  Sketcher sk;
  // per block (one kind each, in the order the model first used them), each constraint's own sketch()
  for (const auto& block : model.blocks())
    ConstraintKinds::for_each([&]<class K>() { each<K>(*block, [&](const K& s) { s.sketch(sk); }); });
  return sk.take();
}

}  // namespace phiq
