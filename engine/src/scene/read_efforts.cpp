// The scene's `output: efforts`, `power` and `reactions` (models/README.md): which drivers' efforts and which joints'
// reactions a sweep writes, resolved to constraints once the model is built, with the parts and loads they are
// computed from (OutputPlan::efforts).
#include <memory>
#include <set>

#include "phiq/applied_loads.hpp"
#include "phiq/inverse_dynamics.hpp"
#include "phiq/joint_reactions.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

void SceneReader::read_output_efforts(const Cursor& output) {
  const Cursor e = output.field("efforts");
  if (auto p = output.field("power"); p.present()) {
    pending_.efforts_power = p.boolean();
    if (pending_.efforts_power && !e.present()) p.fail("power is written with the efforts: list `efforts` too");
  }
  if (const Cursor r = output.field("reactions"); r.present()) {
    pending_.reactions_field = r;
    if (r.is_scalar()) {
      if (r.text() != "all") r.fail("expected `all` or a list of joints");
    } else {
      std::set<std::string> seen;
      for (const Cursor& i : r.items()) {
        const std::string n = i.name();
        if (!builder_.has_constraint(n)) i.fail("unknown joint '" + n + "'");
        if (!seen.insert(n).second) i.fail("joint listed twice");
        pending_.reaction_items.push_back(i);
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

void SceneReader::resolve_output_efforts(Scene& scene) const {
  if (!pending_.efforts_field && !pending_.reactions_field) return;
  const Model& model = *scene.model;
  OutputEfforts& out = scene.sweep.efforts;
  if (pending_.reactions_field) {
    if (pending_.reaction_items.empty()) {  // all: every joint with a reaction that no driver moves
      for (std::size_t c = 0; c < model.constraints().size(); ++c)
        if (const int w = reaction_width(model, static_cast<Index>(c));
            w > 0 && !model.constraints()[c].depends_on_time)
          out.reactions.push_back({static_cast<Index>(c), w == 6});
      if (out.reactions.empty())
        pending_.reactions_field->fail(
            "no constraint of the scene joins bodies (revolute, prismatic, spatial joints): no "
            "reaction to write");
    }
    for (const Cursor& i : pending_.reaction_items) {
      const Index c = model.find_constraint(i.name());
      const int w = reaction_width(model, c);
      if (w == 0)
        i.fail("'" + i.name() + "' (" + std::string(model.constraints()[static_cast<std::size_t>(c)].kind) +
               ") is not a joint between bodies: it has no reaction (revolute, prismatic and spatial joints have)");
      out.reactions.push_back({c, w == 6});
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
      if (!model.constraints()[static_cast<std::size_t>(c)].depends_on_time)
        i.fail("'" + i.name() + "' does not depend on time: no motor drives it, it has no effort");
      out.constraints.push_back(c);
    }
  }
  // the parts with mass, without their shapes (a mesh's triangles are not read by the dynamics)
  auto massive = std::make_shared<std::vector<Part>>();
  for (const Part& p : scene.parts)
    if (p.mass_source != MassSource::kNone && p.mass.mass > 0.0) {
      massive->push_back(p);
      massive->back().shapes.clear();
    }
  if (massive->empty() && !(scene.loads.applied && !scene.loads.applied->empty()))
    (pending_.efforts_field ? *pending_.efforts_field : *pending_.reactions_field)
        .fail(
            "no part has mass and no load is applied: every effort would be zero (give parts a mass "
            "or a density, or apply loads)");
  out.parts = std::move(massive);
  out.loads = std::make_shared<const Loads>(scene.loads);
  out.power = pending_.efforts_power;
}

}  // namespace phiq::detail::scene
