/// @file
/// The registry of constraint kinds: the one list that the model builder, the scene reader, the mechanism sketch,
/// the Grübler count, the documentation and the tests iterate over. A new kind is one header in kinds/ (its
/// equation in a comment, residual, Jacobian entries, Φt, γ, the validation of its data, its joint count, its
/// sketch, its scene forms, its value equality and, for a joint that others refer to by name, its JointTraits), one
/// line below, and one finite-difference test; the ConstraintKind concept refuses at compile time a registered kind
/// that lacks any of these members, and tests/test_kind_registry.cpp fails for one without a finite-difference
/// check, without its scene examples in models/README.md, or with a constraint type missing from the fuzzing
/// dictionary or claimed by another kind. The joint types that joint drivers, `output.joints` and shafts accept are
/// derived from the kinds' JointTraits (joint_types(), below).
#pragma once

#include <algorithm>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <vector>

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
// What a kind's sketch() is called with: the drawing primitives. mechanism_sketch.cpp implements them for the lines
// and marks of a mechanism (it draws no kind's own geometry), drawn_parts.cpp for the derived parts (its comments
// say each primitive's shapes). A kind states its geometry once, with these.
struct SketchProbe {
  void bar(const Point2&, const Point2&, double /*length, 0: none*/ = 0.0) {}
  void arm(const Frame2&, const kin::V2&) {}
  void pivot(const Frame2&, const kin::V2&, const Frame2&, const kin::V2&) {}
  void slider(const Frame2&, const kin::V2&, const Frame2&, const kin::V2&) {}
  void bar3(const Attachment3&, const Attachment3&, double /*length, 0: none*/ = 0.0) {}
  void arm3(const Attachment3&) {}
  void joint3(const Attachment3&, const Attachment3&, JointMark) {}
  void joint_parts3(const JointSide3&, const JointSide3&, JointForm) {}
  void thread3(const JointSide3&, double /*pitch*/) {}
  void spatial_gear_pair(const JointSide3&, const JointSide3&, const JointSide3&, const JointSide3&, double, double,
                         bool /*reversed*/, double /*mesh_offset*/) {}
  void open_chain(const std::vector<LoopSpec::Link>&) {}
  void gear_pair(const Slot&, const Slot&, double, double, bool /*internal*/) {}
  void belt(const Slot&, const Slot&, double, double, bool /*crossed*/) {}
  void rack(const Slot& /*travel*/, const Slot& /*pinion*/, double /*radius*/, bool /*reversed*/) {}
  void curve(const CurveOn&) {}
  void roller(const Frame2&, const kin::V2&, double /*radius*/) {}
  void face(const Frame2&, const kin::V2&, const kin::V2& /*direction*/) {}
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
  /// The kind at place `I` (0 ≤ I < size).
  template <std::size_t I>
  using at = std::tuple_element_t<I, std::tuple<K...>>;
  /// The place of `L` in the list; `size` when it is not in it.
  template <class L>
  static constexpr std::size_t index_of() {
    constexpr bool same[] = {std::is_same_v<L, K>..., false};
    std::size_t i = 0;
    while (i < size && !same[i]) ++i;
    return i;
  }
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
             LoopSpec, EquationSpec, CouplerSpec, CoordinateDriverSpec, PointOnCurveSpec,
             FlatFollowerSpec,  // higher pairs on curves
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

/// A kind read as a named spatial joint: its sides a and b (the scene reader keeps them by name, for the joint
/// drivers, `output.joints` and the shafts that refer to the joint).
template <class K>
concept SpatialJointKind = requires(const K& k) {
  { k.a } -> std::convertible_to<JointSide3>;
  { k.b } -> std::convertible_to<JointSide3>;
};

/// @cond internal
namespace detail {
// A kind with joint traits (JointTraits) is a spatial joint written in the constraints section of dimension 3; what
// a driver drives of it, its outputs measure (the driven value can be read back), and a shaft measures its angle.
template <class K>
constexpr bool joint_traits_fit() {
  const JointTraits t = joint_traits<K>();
  if (!t.measures.any() && !t.drives.any() && !t.shaft) return true;
  if ((t.drives.angle && !t.measures.angle) || (t.drives.distance && !t.measures.distance)) return false;
  if (t.shaft && !t.measures.angle) return false;
  if constexpr (!SpatialJointKind<K>) return false;
  for (const SceneForm& f : K::kScene)
    if (std::string_view(f.section) != "constraints" || f.dimension != 3) return false;
  return true;
}
template <class... K>
constexpr bool all_joint_traits_fit(KindList<K...>*) {
  return (joint_traits_fit<K>() && ...);
}
static_assert(all_joint_traits_fit(static_cast<ConstraintKinds*>(nullptr)),
              "a kind with JointTraits must be a spatial joint (sides a and b) written only as a constraint of "
              "dimension 3, measure what it drives, and measure its angle if a shaft");
}  // namespace detail
/// @endcond

/// The scene types of the joints whose traits satisfy `select` (a predicate on JointTraits), in registry order:
/// the one list of the joint types that `output.joints`, the joint drivers and the shafts of transmissions accept.
template <class Select>
std::vector<std::string_view> joint_types(Select select) {
  std::vector<std::string_view> types;
  ConstraintKinds::for_each([&]<class K>() {
    if (select(joint_traits<K>()))
      for (const SceneForm& f : K::kScene) types.push_back(f.type);
  });
  return types;
}

/// Whether `kind` (a ConstraintInfo::kind) is a transmission (gear, rack and pinion, belt: kinds/transmissions.hpp),
/// whose one row relates its members' motions: its effort (OutputEfforts::constraints may list it as a driver), −λ of
/// that row, is what it applies to its first member, a torque on gear 1 or pulley 1 or a force along the rack's
/// travel, conjugate to the row's unit as a driver's effort is to what the driver drives.
inline bool is_transmission_kind(std::string_view kind) {
  bool found = false;
  ConstraintKinds::for_each([&]<class K>() {
    if constexpr (std::is_base_of_v<LinearTransmission<K>, K>) found = found || kind == K::kKind;
  });
  return found;
}

/// Scene types as a message lists them: "revolute, cylindrical or screw".
inline std::string type_list(const std::vector<std::string_view>& types) {
  std::string list;
  for (std::size_t k = 0; k < types.size(); ++k)
    list += (k == 0 ? "" : k + 1 == types.size() ? " or " : ", ") + std::string(types[k]);
  return list;
}

/// joint_types(select) as a message lists them (type_list()).
template <class Select>
std::string joint_type_list(Select select) {
  return type_list(joint_types(select));
}

/// The scene types of the constraints whose kinds state a ReactionSite (kinds/reaction_site.hpp) in a scene of
/// `dimension` (2 or 3), in registry order, each once: the joints `output.reactions` accepts.
inline std::vector<std::string_view> reaction_types(int dimension) {
  std::vector<std::string_view> types;
  ConstraintKinds::for_each([&]<class K>() {
    if constexpr (requires(const K& k, const double* q) { k.reaction_site(q); })
      for (const SceneForm& f : K::kScene)
        if (f.dimension == dimension && std::string_view(f.section) == "constraints" &&
            std::find(types.begin(), types.end(), f.type) == types.end())
          types.push_back(f.type);
  });
  return types;
}

}  // namespace phiq
