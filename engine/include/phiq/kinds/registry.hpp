/// @file
/// The registry of constraint kinds: the one list that the model builder, the scene reader, the mechanism sketch,
/// the Grübler count, the documentation and the tests iterate over. A new kind is one header in kinds/ (its
/// equation in a comment, residual, Jacobian entries, Φt, γ, the validation of its data, its joint count, its
/// sketch, its scene forms and its value equality), one line below, and one finite-difference test; the
/// ConstraintKind concept refuses at compile time a registered kind that lacks any of these members, and tests/test_kind_registry.cpp fails for
/// one without a finite-difference check, without its scene examples in models/README.md, or with a constraint type
/// missing from the fuzzing dictionary or claimed by another kind.
#pragma once

#include <string_view>

#include "phiq/kinds/constant_angle.hpp"
#include "phiq/kinds/coordinate_driver.hpp"
#include "phiq/kinds/coupler.hpp"
#include "phiq/kinds/distance.hpp"
#include "phiq/kinds/dot.hpp"
#include "phiq/kinds/equation.hpp"
#include "phiq/kinds/euler_parameters.hpp"
#include "phiq/kinds/joint_drivers.hpp"
#include "phiq/kinds/loop.hpp"
#include "phiq/kinds/pin.hpp"
#include "phiq/kinds/point_on_line.hpp"
#include "phiq/kinds/polar.hpp"
#include "phiq/kinds/prismatic.hpp"
#include "phiq/kinds/segment_angle.hpp"
#include "phiq/kinds/spatial_distance.hpp"
#include "phiq/kinds/spatial_joints.hpp"
#include "phiq/kinds/unit_vector.hpp"
// higher pairs on curves
#include "phiq/kinds/flat_follower.hpp"
#include "phiq/kinds/point_on_curve.hpp"
// transmissions, the screw joint and spatial mixed coordinates
#include "phiq/kinds/screw.hpp"
#include "phiq/kinds/spatial_gear.hpp"
#include "phiq/kinds/spatial_mixed.hpp"
#include "phiq/kinds/transmissions.hpp"

namespace phiq {

/// @cond internal
namespace detail {
// What a kind's sketch() is called with: the drawing primitives (mechanism_sketch.cpp implements them).
struct SketchProbe {
  void bar(const Point2&, const Point2&) {}
  void arm(const Frame2&, const kin::V2&) {}
  void pivot(const Frame2&, const kin::V2&, const Frame2&, const kin::V2&) {}
  void slider(const Frame2&, const kin::V2&, const Frame2&, const kin::V2&) {}
  void bar3(const Attachment3&, const Attachment3&) {}
  void arm3(const Attachment3&) {}
  void joint3(const Attachment3&, const Attachment3&, JointMark) {}
};
// What a kind's jacobian() is called with: (local row, slot, value).
struct SinkProbe {
  void operator()(int, const Slot&, double) {}
};
}  // namespace detail
/// @endcond

/// The members every constraint kind supplies (documented on DistanceSpec).
template <class K>
concept ConstraintKind = requires(K k, const K ck, const double* q, double* out, detail::SinkProbe& sink,
                                  detail::SketchProbe& sketch, const std::vector<Unit>& units) {
  { K::kRows } -> std::convertible_to<int>;
  { K::kKind } -> std::convertible_to<const char*>;
  { ck.depends_on_time() } -> std::same_as<bool>;
  { ck.row_unit(0, units) } -> std::same_as<Unit>;
  { ck.characteristic_length() } -> std::convertible_to<double>;
  ck.residual(q, 0.0, out);
  ck.jacobian(q, 0.0, sink);
  ck.phi_t(q, 0.0, out);
  ck.gamma(q, q, 0.0, out);
  { ck.joint_count() } -> std::same_as<JointCount>;
  { ck == ck } -> std::same_as<bool>;
  k.prepare(q);
  ck.sketch(sketch);
  { K::kScene[0] } -> std::convertible_to<SceneForm>;
};

/// A list of kinds, iterated at compile time.
template <class... K>
struct KindList {
  static constexpr std::size_t size = sizeof...(K);  ///< how many kinds
  /// Calls `f.template operator()<K>()` for every kind, in order.
  template <class F>
  static void for_each(F&& f) {
    (f.template operator()<K>(), ...);
  }
};

/// Every constraint kind of phiq, planar first. Scene types are read in this order (kinds whose scene forms share
/// a type, as `revolute` in the plane and in space, are told apart by the scene's dimension).
using ConstraintKinds =
    KindList<DistanceSpec, PinSpec, PointOnLineSpec, ConstantAngleSpec, SegmentAngleSpec, PolarSpec, PrismaticSpec,
             LoopSpec, EquationSpec, CouplerSpec, CoordinateDriverSpec,
             PointOnCurveSpec, FlatFollowerSpec,  // higher pairs on curves
             EulerParametersSpec, UnitVectorSpec, SpatialDistanceSpec, DotSpec, SphericalSpec, SpatialRevoluteSpec,
             SpatialPrismaticSpec, CylindricalSpec, UniversalSpec, PlanarSpec, RigidSpec, SpatialPointOnLineSpec,
             PointOnPlaneSpec, JointDistanceDriverSpec, JointAngleDriverSpec,
             // transmissions, the screw joint and spatial mixed coordinates
             GearSpec, RackPinionSpec, BeltSpec, ScrewSpec, SpatialGearSpec, SpatialPolarSpec, SpatialAngleSpec>;

/// @cond internal
namespace detail {
template <class... K>
constexpr bool all_kinds(KindList<K...>*) {
  return (ConstraintKind<K> && ...);
}
static_assert(all_kinds(static_cast<ConstraintKinds*>(nullptr)),
              "a registered constraint kind lacks a member of the ConstraintKind concept (see DistanceSpec)");
}  // namespace detail
/// @endcond

}  // namespace phiq
