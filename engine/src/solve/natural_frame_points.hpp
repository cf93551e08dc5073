// Internal: a natural body's frame's points, where they act and where its joints are (find_natural_joints(), and
// the bodies the losses read along a design parameter: solve/friction_losses_along.cpp).
#pragma once

#include <type_traits>

#include "phiq/parts.hpp"

namespace phiq::detail {

// The frame's points: the origin, and x and y toward when they are points (a vector has no place to act), in
// NaturalBody::points' order. In place, not a vector: set-up asks for them several times per body, 10⁵ allocations
// at nfourbar 10⁴.
template <class Point>
struct FramePoints {
  Point* at[3];
  int count = 0;
  Point* const* begin() const { return at; }
  Point* const* end() const { return at + count; }
  std::size_t size() const { return static_cast<std::size_t>(count); }
  Point* operator[](std::size_t k) const { return at[k]; }
};
template <class Frame>  // PartFrame or const PartFrame
auto frame_points(Frame& f) {
  FramePoints<std::remove_reference_t<decltype((f.origin))>> out;  // (const with a const frame)
  out.at[out.count++] = &f.origin;
  if (f.x_is_point) out.at[out.count++] = &f.x_toward;
  if (f.spatial_frame && f.y_is_point) out.at[out.count++] = &f.y_toward;
  return out;
}

}  // namespace phiq::detail
