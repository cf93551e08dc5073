// frame_rates() (parts/frame_rates.hpp): the copies' constants slot by slot, a frame of expressions' expressions
// by their copies (expression_rate.hpp differences their jets).
#include "parts/frame_rates.hpp"

#include <algorithm>

namespace phiq::detail {

namespace {

// The slots a frame's jets read (frame_jets()), in an order that is the same for two frames of one kind.
std::size_t frame_slots(const PartFrame& f, std::array<const Slot*, 9>& out) {
  switch (f.kind) {
    case PartFrameKind::kPlanarBody:
      out = {&f.planar.x, &f.planar.y, &f.planar.psi};
      return 3;
    case PartFrameKind::kSpatialBody: {
      const Frame3& b = f.spatial;
      out = {&b.x, &b.y, &b.z, &b.e0, &b.e1, &b.e2, &b.e3};
      return 7;
    }
    case PartFrameKind::kPoints:
      out = {&f.origin.r[0],   &f.origin.r[1],   &f.origin.r[2],   &f.x_toward.r[0], &f.x_toward.r[1],
             &f.x_toward.r[2], &f.y_toward.r[0], &f.y_toward.r[1], &f.y_toward.r[2]};
      return 9;
    case PartFrameKind::kExpressions:
      break;
  }
  return 0;
}

// A frame of expressions along p: false where a copy has other components, another angle's presence, or an
// expression that reads other coordinates.
bool expression_frame_rates(const PartFrame& own, const std::array<const PartFrame*, 4>& copies, double h,
                            FrameRates& out) {
  out.step = h;
  const std::size_t n = std::min<std::size_t>(own.at.size(), 3);
  auto expression = [n](const PartFrame& f, std::size_t i) { return i < n ? f.at[i].get() : f.angle.get(); };
  std::array<kin3::V3, 4> axes;
  for (std::size_t k = 0; k < 4; ++k) {
    const PartFrame& c = copies[k] ? *copies[k] : own;
    if (c.kind != own.kind || c.at.size() != own.at.size() || !c.angle != !own.angle) return false;
    axes[k] = c.axis;
  }
  out.axis = vector_rate(axes, h);
  for (std::size_t i = 0; i <= n; ++i) {
    const CompiledExpression* e = expression(own, i);
    out.expressions[i] = e, out.moves[i] = false;
    if (!e) continue;
    for (std::size_t k = 0; k < 4; ++k) {
      const CompiledExpression* c = expression(copies[k] ? *copies[k] : own, i);
      if (c->coordinates() != e->coordinates()) return false;
      out.copies[i][k] = c, out.moves[i] = out.moves[i] || c != e;
    }
  }
  return true;
}

}  // namespace

bool frame_rates(const PartFrame& own, const std::array<const PartFrame*, 4>& copies, double h, FrameRates& out) {
  if (own.kind == PartFrameKind::kExpressions) return expression_frame_rates(own, copies, h, out);
  out.count = frame_slots(own, out.slots);
  std::array<std::array<const Slot*, 9>, 4> along;
  for (std::size_t k = 0; k < 4; ++k) {
    const PartFrame& c = copies[k] ? *copies[k] : own;
    if (c.kind != own.kind || c.spatial_frame != own.spatial_frame || c.x_is_point != own.x_is_point ||
        c.y_is_point != own.y_is_point)
      return false;
    frame_slots(c, along[k]);
    for (std::size_t i = 0; i < out.count; ++i)
      if (along[k][i]->coord() != out.slots[i]->coord()) return false;
  }
  for (std::size_t i = 0; i < out.count; ++i) {
    const double x[4] = {along[0][i]->value(), along[1][i]->value(), along[2][i]->value(), along[3][i]->value()};
    out.rate[i] = out.slots[i]->is_coordinate() ? 0.0 : copies_rate(x, h);
  }
  return true;
}

}  // namespace phiq::detail
