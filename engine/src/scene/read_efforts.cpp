// The scene's `output: efforts`, `power`, `reactions` and `losses` (models/README.md): which drivers' efforts, which
// joints' reactions and which bearings' and gears' losses a sweep writes, resolved to constraints once the model is
// built, with the parts and loads they are computed from (OutputPlan::efforts).
#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <string_view>
#include <unordered_map>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"
#include "phiq/kinds/registry.hpp"
#include "phiq/natural_joints.hpp"
#include "scene/scene_reader.hpp"
#include "solve/friction_losses.hpp"

namespace phiq::detail::scene {

// The named points, read before their table is freed (the natural joints are found with the model).
void SceneReader::keep_natural_points() {
  if (!pending_.natural_points.empty()) return;
  if (spatial_)
    for (Index k = 0; k < names_.points3.size(); ++k)
      pending_.natural_points.emplace_back(names_.points3.name(k), Attachment3::natural(names_.points3[k]));
  else
    for (Index k = 0; k < names_.points.size(); ++k)
      pending_.natural_points.emplace_back(
          names_.points.name(k),
          Attachment3::natural(Point3{names_.points[k].x, names_.points[k].y, Slot::constant(0)}));
}

void SceneReader::read_output_efforts(const Cursor& output) {
  const Cursor e = output.field("efforts");
  if (auto p = output.field("power"); p.present()) {
    pending_.efforts_power = p.boolean();
    if (pending_.efforts_power && !e.present()) p.fail("power is written with the efforts: list `efforts` too");
  }
  if (const Cursor a = output.field("reaction_axes"); a.present()) {
    if (a.text() != "world" && a.text() != "joint") a.fail("expected `world` or `joint`");
    if (!output.field("reactions").present()) a.fail("the axes of the reactions: list `reactions` too");
    pending_.reactions_in_joint_axes = a.text() == "joint";
  }
  if (const Cursor r = output.field("reactions"); r.present()) {
    pending_.reactions_field = r;
    keep_natural_points();
    if (r.is_scalar()) {
      if (r.text() != "all") r.fail("expected `all` or a list of joints");
    } else {
      std::set<std::string> seen;
      for (const Cursor& i : r.items()) {
        const std::string n = i.name();
        if (!builder_.has_constraint(n) && !(spatial_ ? names_.points3.contains(n) : names_.points.contains(n)))
          i.fail("unknown joint '" + n + "'");
        if (!seen.insert(n).second) i.fail("joint listed twice");
        pending_.reaction_items.push_back(i);
      }
    }
  }
  if (const Cursor l = output.field("losses"); l.present()) {
    pending_.losses_field = l;
    if (l.is_scalar()) {
      if (l.text() != "all") l.fail("expected `all` or a list of bearings' torsional springs and gears");
    } else {
      std::set<std::string> seen;
      for (const Cursor& i : l.items()) {
        if (!seen.insert(i.name()).second) i.fail("loss listed twice");
        pending_.loss_items.push_back(i);
      }
    }
  }
  if (!e.present()) return;
  pending_.efforts_field = e;
  if (e.is_scalar()) {
    if (e.text() != "all") e.fail("expected `all` or a list of drivers");
    return;
  }
  std::set<std::string> seen;
  for (const Cursor& i : e.items()) {
    const std::string n = i.name();
    if (!builder_.has_constraint(n)) i.fail("unknown driver '" + n + "'");
    if (!seen.insert(n).second) i.fail("driver listed twice");
    pending_.effort_items.push_back(i);
  }
}

namespace {

// Why part `name` cannot carry a load when natural points' reactions are written.
std::string why_no_body(const std::string& name) {
  return "part '" + name + "' moves with the points but is none of their bodies (give it a frame of points)";
}

// What a natural point's reaction (its bodies' balance there) cannot split among its bodies, refused by name through
// `refuse(what, why)`, which does not return: a part that is no body of points (a frame of expressions, say) but
// moves with the points, whose mass and loads push them in no body's balance, and a torsional spring whose angle
// reads the points (an expression of them), which pushes them without saying which bodies it turns; one on a
// coordinate of its own (a segment_angle's) acts through that constraint's multiplier, which its body owns.
template <class Refuse>
void refuse_unsplit_loads(const Scene& scene, const std::vector<char>& of_point, const Refuse& refuse) {
  if (scene.loads.applied)
    for (const TorsionalSpring& ts : scene.loads.applied->torsional_springs)
      for (const Index c : torsional_coordinates(ts))
        if (of_point[static_cast<std::size_t>(c)])
          refuse("torsional spring '" + ts.name + "''s moment",
                 "its angle reads the points, and does not say which bodies it turns (give the angle a coordinate, "
                 "as a segment_angle does)");
  std::set<std::string_view> moved;  // such parts, by name
  std::vector<Index> read;
  for (const Part& p : scene.parts) {
    if (p.frame.kind == PartFrameKind::kPoints) continue;  // (a body, or fixed)
    frame_coordinates(p.frame, read);
    if (std::none_of(read.begin(), read.end(), [&](Index c) { return of_point[static_cast<std::size_t>(c)]; }))
      continue;
    moved.insert(p.name);
    if (p.mass_source != MassSource::kNone && p.mass.mass > 0.0)
      refuse("the weight and inertia of part '" + p.name + "'", why_no_body(p.name));
  }
  if (moved.empty() || !scene.loads.applied) return;
  const AppliedLoads& l = *scene.loads.applied;
  auto on = [&](const std::string& part) { return moved.count(part) > 0; };
  for (const AppliedForce& f : l.forces)
    if (on(f.part)) refuse("force '" + f.name + "'", why_no_body(f.part));
  for (const AppliedTorque& f : l.torques)
    if (on(f.part)) refuse("torque '" + f.name + "'", why_no_body(f.part));
  for (const LinearSpring& s : l.springs)
    for (const SpringEnd* e : {&s.a, &s.b})
      if (on(e->part)) refuse("spring '" + s.name + "''s pull", why_no_body(e->part));
}

}  // namespace

void SceneReader::resolve_output_efforts(Scene& scene) const {
  const Model& model = *scene.model;
  OutputEfforts& out = scene.sweep.efforts;
  // the natural joints a bearing may name, whatever the output lists (driver_efforts() of the scene reads them too)
  if (pending_.natural_bearings) {
    out.natural = std::make_shared<NaturalJoints>(
        find_natural_joints(scene.parts, scene.loads, pending_.natural_points, model.num_coordinates(), spatial_));
    for (const Pending::BearingPoint& b : pending_.bearing_points)  // (else the sweep's set-up would refuse it)
      if (std::none_of(out.natural->joints.begin(), out.natural->joints.end(),
                       [&](const NaturalJoint& j) { return j.name == b.name; }))
        fail_at(file_, b.mark, b.path,
                "point '" + b.name +
                    "' is no joint: no two parts with frames of points hold it, nor one with a component fixed");
    // its load is the point's reaction, which holds what its bodies' balance cannot split
    if (!pending_.bearing_points.empty()) {
      const Pending::BearingPoint& b = pending_.bearing_points.front();
      refuse_unsplit_loads(scene, point_coordinates(*out.natural, model.num_coordinates()),
                           [&](const std::string& what, const std::string& why) {
                             fail_at(file_, b.mark, b.path,
                                     "the bearing at natural point '" + b.name + "' would hold " + what + ": " + why);
                           });
    }
  }
  if (!pending_.efforts_field && !pending_.reactions_field && !pending_.losses_field) return;
  resolve_output_reactions(scene);
  if (!out.reactions.empty() && spatial_) {  // gears on shafts: their bearings carry the teeth's push
    for (std::size_t c = 0; c < model.constraints().size(); ++c) {
      const auto [block, index] = model.constraint_block(static_cast<Index>(c));
      if (GearMesh g; block->gear_mesh(index, g)) {  // (between rotation angles: the shafts are not known)
        OutputMesh m;
        m.constraint = static_cast<Index>(c), m.mesh = g;
        m.unloaded =
            "in dimension 3 it relates angle or travel coordinates, whose shafts it does not know (a spatial_gear "
            "between the shafts' joints does)";
        out.meshes.push_back(m);
        continue;
      }
      SpatialMesh sm;
      if (!block->spatial_mesh(index, sm) || !(detail::frame_moves(sm.b1.frame) || detail::frame_moves(sm.b2.frame)))
        continue;
      OutputMesh m;
      m.constraint = static_cast<Index>(c), m.spatial = sm;
      if (sm.a1.natural || sm.b1.natural || sm.a2.natural || sm.b2.natural)
        m.unloaded = "a shaft or housing is in natural coordinates";
      out.meshes.push_back(m);
    }
  }
  if (!out.reactions.empty() && !spatial_) {  // gears and racks on bodies: their bearings carry the teeth's push
    // the planar bodies by the coordinates of their frames: (body, 0 x, 1 y, 2 ψ)
    std::unordered_map<Index, std::pair<const Frame2*, int>> frame_of;
    for (const Frame2& f : scene.planar_bodies) {
      const Slot* slots[3] = {&f.x, &f.y, &f.psi};
      for (int k = 0; k < 3; ++k)
        if (slots[k]->is_coordinate()) frame_of.emplace(slots[k]->coord(), std::pair{&f, k});
    }
    // the body whose frame's component `k` (or x or y: k < 0) is the coordinate of `s`; its component in `which`
    auto body = [&](const Slot& s, int k, int* which = nullptr) -> const Frame2* {
      const auto i = s.is_coordinate() ? frame_of.find(s.coord()) : frame_of.end();
      if (i == frame_of.end() || (k >= 0 ? i->second.second != k : i->second.second == 2)) return nullptr;
      if (which) *which = i->second.second;
      return i->second.first;
    };
    for (std::size_t c = 0; c < model.constraints().size(); ++c) {
      const auto [block, index] = model.constraint_block(static_cast<Index>(c));
      OutputMesh m;
      if (!block->gear_mesh(index, m.mesh)) continue;
      // a gear's angles are its bodies' ψ; a rack's travel is its body's x or y
      const Frame2 *first = m.mesh.rack ? body(m.mesh.first, -1, &m.rack_axis) : body(m.mesh.first, 2),
                   *second = body(m.mesh.second, 2);
      // a gear held fixed (a constant angle: the ground's or a fixed body's) beside one that turns: in an epicyclic
      // train it is coaxial with the carrier, whose reference point stands for its centre
      const bool fixed1 = !first && !m.mesh.first.is_coordinate() && second && !m.mesh.rack,
                 fixed2 = !second && !m.mesh.second.is_coordinate() && first;
      if (fixed1 || fixed2) {
        const Frame2* carrier = body(m.mesh.carrier, 2);
        if (carrier && !m.mesh.belt)
          (fixed1 ? first : second) = carrier, m.fixed = fixed1 ? 0 : 1;
        else
          m.unloaded = m.mesh.belt ? "one pulley is fixed" : "it meshes with a fixed gear and names no carrier body";
      }
      if (!m.mesh.first.is_coordinate() && !m.mesh.second.is_coordinate()) continue;  // (nothing turns)
      if (m.mesh.belt && m.unloaded.empty() && !m.mesh.strands_known())
        m.unloaded = std::isnan(m.mesh.tension) ? "it states no tension" : "its teeth state no pitch";
      if ((!first || !second) && m.unloaded.empty())
        m.unloaded = "it relates angle or travel coordinates, not bodies', so it has no centres to push";
      m.constraint = static_cast<Index>(c);
      if (first) m.first = *first;
      if (second) m.second = *second;
      out.meshes.push_back(m);
    }
  }
  if (pending_.efforts_field && pending_.effort_items.empty()) {
    out.constraints = rheonomic_constraints(model);
    if (out.constraints.empty()) pending_.efforts_field->fail("the scene has no driver: no effort to write");
  } else if (pending_.efforts_field) {
    std::unordered_map<std::string, Index> index;
    for (std::size_t k = 0; k < model.constraints().size(); ++k)
      index.emplace(model.constraints()[k].name, static_cast<Index>(k));
    for (const Cursor& i : pending_.effort_items) {
      const Index c = index.at(i.name());
      if (!has_effort(model.constraints()[static_cast<std::size_t>(c)]))
        i.fail("'" + i.name() +
               "' does not depend on time: no motor drives it, it has no effort (a driver has, and a "
               "transmission: the load it applies to its first member)");
      out.constraints.push_back(c);
    }
  }
  // the parts with mass, without their shapes (a mesh's triangles are not read by the dynamics)
  auto massive = std::make_shared<std::vector<Part>>();
  massive->reserve(scene.parts.size());
  for (const Part& p : scene.parts)
    if (p.mass_source != MassSource::kNone && p.mass.mass > 0.0) massive->push_back(without_shapes(p));
  if (massive->empty() && !(scene.loads.applied && !scene.loads.applied->empty()))
    (pending_.efforts_field     ? *pending_.efforts_field
     : pending_.reactions_field ? *pending_.reactions_field
                                : *pending_.losses_field)
        .fail(
            "no part has mass and no load is applied: every effort would be zero (give parts a mass "
            "or a density, or apply loads)");
  if (pending_.losses_field) out.losses = resolve_output_losses(scene.loads.applied.get());
  out.parts = std::move(massive);
  out.loads = std::make_shared<const Loads>(scene.loads);
  out.power = pending_.efforts_power;
  out.reactions_in_joint_axes = pending_.reactions_in_joint_axes;
}

// `output: reactions` resolved to constraints and natural points (OutputEfforts::reactions, natural).
void SceneReader::resolve_output_reactions(Scene& scene) const {
  const Model& model = *scene.model;
  OutputEfforts& out = scene.sweep.efforts;
  if (pending_.reactions_field) {
    // natural coordinates' joints: named points that parts with frames of points share (phiq/natural_joints.hpp),
    // found already where a bearing names one
    auto natural = out.natural
                       ? out.natural
                       : std::make_shared<NaturalJoints>(find_natural_joints(
                             scene.parts, scene.loads, pending_.natural_points, model.num_coordinates(), spatial_));
    std::unordered_map<std::string_view, int> joint_index;  // (a list of 10⁴ names scanned 10⁴ joints for each)
    if (!pending_.reaction_items.empty())
      for (std::size_t j = 0; j < natural->joints.size(); ++j)
        joint_index.emplace(natural->joints[j].name, static_cast<int>(j));
    auto natural_joint = [&](const std::string& name) {
      const auto it = joint_index.find(name);
      return it == joint_index.end() ? -1 : it->second;
    };
    if (pending_.reaction_items.empty()) {  // all: every joint with a reaction that no driver moves
      for (std::size_t c = 0; c < model.constraints().size(); ++c)
        if (const int w = reaction_width(model, static_cast<Index>(c));
            w > 0 && !model.constraints()[c].depends_on_time)
          out.reactions.push_back({static_cast<Index>(c), w == 6});
      for (std::size_t j = 0; j < natural->joints.size(); ++j)
        out.reactions.push_back({-1, spatial_, static_cast<int>(j)});
      if (out.reactions.empty())
        pending_.reactions_field->fail(
            "no constraint of the scene joins bodies (revolute, prismatic, spatial joints) and no named point is "
            "shared by parts with frames of points: no reaction to write");
    }
    if (!natural->joints.empty()) out.natural = natural;
    for (const Cursor& i : pending_.reaction_items) {
      if (model.find_constraint(i.name()) < 0) {  // (the builder is the model now: it is asked)
        const int j = natural_joint(i.name());
        if (j < 0)
          i.fail("point '" + i.name() +
                 "' is no joint: no two parts with frames of points hold it, nor one with a component fixed");
        out.reactions.push_back({-1, spatial_, j});
        out.natural = natural;
        continue;
      }
      const Index c = model.find_constraint(i.name());
      const int w = reaction_width(model, c);
      if (w == 0)
        i.fail("'" + i.name() + "' (" + std::string(model.constraints()[static_cast<std::size_t>(c)].kind) +
               ") is not a joint between bodies: it has no reaction (a " + type_list(reaction_types(spatial_ ? 3 : 2)) +
               " has)");
      out.reactions.push_back({c, w == 6});
    }
  }
  // A natural point's reaction balances its bodies' own loads at their points: what it cannot split is refused
  // rather than written into the reactions (refuse_unsplit_loads()).
  const auto natural_listed =
      std::find_if(out.reactions.begin(), out.reactions.end(), [](const OutputReaction& r) { return r.natural >= 0; });
  if (natural_listed == out.reactions.end()) return;
  const std::vector<char> of_point = point_coordinates(*out.natural, model.num_coordinates());
  auto refuse = [&](const std::string& what, const std::string& why) {
    pending_.reactions_field->fail("the reaction at natural point '" + out.reaction_name(model, *natural_listed) +
                                   "' would hold " + what + ": " + why);
  };
  refuse_unsplit_loads(scene, of_point, refuse);
}

std::vector<OutputLoss> SceneReader::resolve_output_losses(const AppliedLoads* loads) const {
  std::vector<OutputLoss> all;  // OutputLoss::index's order: the bearings, then the gear losses
  if (loads) {
    for (const TorsionalSpring& s : loads->torsional_springs)
      if (s.bearing) all.push_back({s.name, all.size(), true, s.bearing->slide});
    for (const GearLoss& g : loads->gear_losses) all.push_back({g.gear, all.size(), false, false});
  }
  const Cursor& field = *pending_.losses_field;
  if (all.empty())
    field.fail("the scene has no bearing (`torsional_springs[].bearing`) and no `gear_losses`: no loss to write");
  std::vector<OutputLoss> out;
  if (pending_.loss_items.empty()) out = all;
  for (const Cursor& i : pending_.loss_items) {
    const auto l = std::find_if(all.begin(), all.end(), [&](const OutputLoss& o) { return o.name == i.name(); });
    if (l == all.end())
      i.fail("unknown loss '" + i.name() + "': neither a bearing's torsional spring nor a gear with losses");
    out.push_back(*l);
  }
  return out;  // (a spring and a gear of one name cannot meet here: bearings are refused in geared models)
}

}  // namespace phiq::detail::scene
