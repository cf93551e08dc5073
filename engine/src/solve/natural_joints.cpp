// find_natural_joints() (phiq/natural_joints.hpp): the bodies of natural coordinates, the points they share, and
// their parts and loads with each constant point component made a coordinate of its own.
#include "phiq/natural_joints.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <string_view>
#include <type_traits>
#include <unordered_map>

#include "solve/natural_frame_points.hpp"

namespace phiq {

using detail::frame_points;

namespace {

// A point's slots as a key: per component whether it is a coordinate, and its index or value.
std::array<double, 6> point_key(const Attachment3& a) {
  std::array<double, 6> k{};
  for (int i = 0; i < 3; ++i)
    k[2 * i] = a.r[i].is_coordinate() ? 1.0 : 0.0,
          k[2 * i + 1] = a.r[i].is_coordinate() ? static_cast<double>(a.r[i].coord()) : a.r[i].value();
  return k;
}

// A point_key()'s hash: its bits, mixed.
struct PointKeyHash {
  std::size_t operator()(const std::array<double, 6>& k) const {
    std::size_t h = 0;
    for (double v : k) h = h * 1000003u ^ std::hash<double>{}(v);
    return h;
  }
};

}  // namespace

NaturalJoints find_natural_joints(const std::vector<Part>& parts, const Loads& loads,
                                  const std::vector<std::pair<std::string, Attachment3>>& points, Index coordinates,
                                  bool spatial) {
  NaturalJoints out;
  out.spatial = spatial;
  const int dimension = spatial ? 3 : 2;
  out.bodies.reserve(parts.size());
  // the applied loads by the part they act on, found once: a scene with a load on each of 10⁴ parts compared every
  // part with every load (10⁸ names)
  struct OwnLoads {
    std::vector<const AppliedForce*> forces;
    std::vector<const AppliedTorque*> torques;
    std::vector<const LinearSpring*> springs;
  };
  std::unordered_map<std::string_view, OwnLoads> loads_of;
  if (loads.applied) {
    for (const AppliedForce& f : loads.applied->forces) loads_of[f.part].forces.push_back(&f);
    for (const AppliedTorque& f : loads.applied->torques) loads_of[f.part].torques.push_back(&f);
    for (const LinearSpring& s : loads.applied->springs) {
      loads_of[s.a.part].springs.push_back(&s);
      if (s.b.part != s.a.part) loads_of[s.b.part].springs.push_back(&s);
    }
  }
  // A spring's far end on another moving body: its frame's coordinates moved to promoted slots that copy them
  // (NaturalJoints::mirrors, one per coordinate), or, on a frame of expressions (which reads q through its own
  // compiled expressions), the end's world point at slots of its own (NaturalJoints::far_points); those slots go to
  // `slots`.
  std::unordered_map<Index, std::size_t> mirror_of;
  auto mirrored = [&](SpringEnd end, std::vector<Index>& slots) -> SpringEnd {
    auto move = [&](Slot& s) {
      if (!s.is_coordinate() || s.coord() >= coordinates) return;
      const auto [it, fresh] = mirror_of.try_emplace(s.coord(), out.promoted.size());
      if (fresh) out.mirrors.push_back({out.promoted.size(), s.coord()}), out.promoted.push_back(0.0);
      s = Slot::coordinate(coordinates + static_cast<Index>(it->second));
      slots.push_back(s.coord());
    };
    PartFrame& f = end.frame;
    switch (f.kind) {
      case PartFrameKind::kPlanarBody:
        for (Slot* s : {&f.planar.x, &f.planar.y, &f.planar.psi}) move(*s);
        return end;
      case PartFrameKind::kSpatialBody:
        for (Slot* s :
             {&f.spatial.x, &f.spatial.y, &f.spatial.z, &f.spatial.e0, &f.spatial.e1, &f.spatial.e2, &f.spatial.e3})
          move(*s);
        return end;
      case PartFrameKind::kPoints:
        for (Attachment3* a : {&f.origin, &f.x_toward, &f.y_toward})
          for (Slot& s : a->r) move(s);
        return end;
      case PartFrameKind::kExpressions: {
        const std::size_t first = out.promoted.size();
        out.far_points.push_back({first, f, end.at});
        out.promoted.resize(first + static_cast<std::size_t>(dimension), 0.0);
        Slot at[3];
        for (int k = 0; k < 3; ++k) {
          at[k] = k < dimension ? Slot::coordinate(coordinates + static_cast<Index>(first) + k) : Slot::constant(0.0);
          if (k < dimension) slots.push_back(at[k].coord());
        }
        f = PartFrame{};  // a frame at the point, unturned: the end at its origin
        if (spatial)
          f.kind = PartFrameKind::kSpatialBody,
          f.spatial = {
              at[0], at[1], at[2], Slot::constant(1.0), Slot::constant(0.0), Slot::constant(0.0), Slot::constant(0.0)};
        else
          f.kind = PartFrameKind::kPlanarBody, f.planar = {at[0], at[1], Slot::constant(0.0)};
        end.at = {0.0, 0.0, 0.0};
        return end;
      }
    }
    return end;
  };
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const Part& p = parts[i];
    if (p.frame.kind != PartFrameKind::kPoints || max_coordinate(p.frame) < 0) continue;  // (a frame that moves)
    NaturalBody b;
    b.name = p.name, b.part = i;
    b.points.reserve(3);
    b.frame = p.frame;
    PartFrame promoted = p.frame;
    // each constant component of a point a coordinate of its own, past the model's (its value in `promoted`)
    for (Attachment3* a : frame_points(promoted)) {
      for (int k = 0; k < dimension; ++k)
        if (!a->r[k].is_coordinate()) {
          const double v = a->r[k].value();
          a->r[k] = Slot::coordinate(coordinates + static_cast<Index>(out.promoted.size()));
          out.promoted.push_back(v);
        }
      b.points.push_back(*a);
    }
    b.mass = p.mass, b.mass_source = p.mass_source;  // (natural_body_has_mass(): a mass > 0)
    b.loads.gravity = loads.gravity;
    if (const auto it = loads_of.find(p.name); it != loads_of.end()) {
      auto own = std::make_shared<AppliedLoads>();
      for (const AppliedForce* f : it->second.forces) own->forces.push_back(*f), own->forces.back().frame = promoted;
      for (const AppliedTorque* f : it->second.torques)
        own->torques.push_back(*f), own->torques.back().frame = promoted;
      for (const LinearSpring* sp : it->second.springs) {
        const LinearSpring& s = *sp;
        const bool a = s.a.part == p.name, c = s.b.part == p.name;
        const bool other_fixed = (a && (c || s.b.part == "ground")) || (c && s.a.part == "ground");
        own->springs.push_back(s);
        if (a) own->springs.back().a.frame = promoted;
        if (c) own->springs.back().b.frame = promoted;
        if (!other_fixed) {  // a spring to another body: its end there, mirrored
          SpringEnd& far = a ? own->springs.back().b : own->springs.back().a;
          far = mirrored(far, b.load_slots);
        }
      }
      if (!own->empty()) b.loads.applied = std::move(own);
    }
    out.bodies.push_back(std::move(b));
  }
  // a frame's point → its bodies, in order
  std::unordered_map<std::array<double, 6>, std::vector<std::size_t>, PointKeyHash> held_by(2 * out.bodies.size());
  for (std::size_t b = 0; b < out.bodies.size(); ++b) {
    for (const Attachment3* a : frame_points(out.bodies[b].frame)) {
      std::vector<std::size_t>& bodies = held_by[point_key(*a)];
      if (bodies.empty() || bodies.back() != b) bodies.push_back(b);
    }
  }
  out.joints.reserve(points.size());  // (at most; capacity that is not written is not mapped in)
  for (const auto& [name, point] : points) {
    const auto it = held_by.find(point_key(point));
    if (it == held_by.end()) continue;
    NaturalJoint j;
    j.name = name, j.point = point, j.bodies = it->second;
    bool held = false;  // by ground, in a component
    for (int k = 0; k < dimension; ++k) held = held || !point.r[k].is_coordinate();
    if (j.bodies.size() >= 2 || (j.bodies.size() == 1 && held)) out.joints.push_back(std::move(j));
  }
  return out;
}

std::vector<char> point_coordinates(const NaturalJoints& joints, Index coordinates) {
  std::vector<char> out(static_cast<std::size_t>(coordinates), 0);
  for (const NaturalBody& b : joints.bodies)
    for (const Attachment3& p : b.points)
      for (const Slot& r : p.r)
        if (r.is_coordinate() && r.coord() < coordinates) out[static_cast<std::size_t>(r.coord())] = 1;
  return out;
}

void natural_body_parts(const NaturalBody& b, std::vector<Part>& out) {
  if (!natural_body_has_mass(b)) {
    out.clear();
    return;
  }
  out.resize(1);
  Part& p = out[0];
  p.name = b.name, p.frame = b.frame, p.mass = b.mass, p.mass_source = b.mass_source;
  std::size_t k = 0;
  for (Attachment3* a : frame_points(p.frame)) *a = b.points.at(k++);
}

}  // namespace phiq
