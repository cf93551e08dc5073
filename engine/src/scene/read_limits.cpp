// The scene's `limits` (SceneReader::read_limits, resolve_limit_efforts): ranges the sweep checks a measure against
// (OutputLimit, phiq/output_plan.hpp) — an expression of the coordinates and t, a spatial joint's angle or
// distance, a point's coordinate, or a driver's effort — each a value's range and, but for an effort, a rate's.
#include <algorithm>
#include <set>

#include "phiq/expression.hpp"
#include "scene/scene_reader.hpp"

namespace phiq::detail::scene {

void SceneReader::read_limits(const Cursor& c, OutputPlan& plan) {
  std::set<std::string> names;
  for (const Cursor& item : c.items()) {
    item.expect_map({"name", "of", "joint", "point", "axis", "effort", "range", "rate"});
    const auto of = item.field("of"), joint = item.field("joint"), effort = item.field("effort");
    const auto point = item.field("point");
    if (of.present() + joint.present() + point.present() + effort.present() != 1)
      item.fail("a limit bounds one of `of: EXPRESSION`, `joint: NAME`, `point: P` (with `axis`) or `effort: DRIVER`");
    if (item.field("axis").present() != point.present()) item.fail("`axis: x, y or z` goes with `point`, and only");
    OutputLimit l;
    std::string subject;
    if (of.present()) {
      l.of = compile(of, true);
      subject = l.of->text();
      l.what = "'" + subject + "'";
    } else if (joint.present()) {
      subject = joint.name();
      if (!spatial_) joint.fail("a joint's limit is a spatial joint's; in the plane write `of:` its angle coordinate");
      const auto it = names_.joints3.find(subject);
      if (it == names_.joints3.end())
        joint.fail("unknown joint '" + subject + "' (a named spatial joint of 'constraints')");
      const JointTraits::Coordinates m = it->second.traits.measures;
      if (!m.angle && !m.distance)
        joint.fail("joint '" + subject + "' is a " + it->second.type + ": it measures nothing");
      if (m.angle && m.distance) joint.fail("joint '" + subject + "' has an angle and a distance: limit them by `of:`");
      try {
        l.joint =
            output_joint(subject, m.angle ? JointMeasure::kAngle : JointMeasure::kDistance, it->second.a, it->second.b);
      } catch (const Error& e) {
        joint.fail(e.what());
      }
      l.what = std::string(m.angle ? "the angle" : "the distance") + " of joint '" + subject + "'";
    } else if (point.present()) {
      l.point = output_point(point);
      const std::string axis = item.field("axis").text();
      l.axis = axis == "x" ? 0 : axis == "y" ? 1 : axis == "z" ? 2 : -1;
      if (l.axis < 0 || l.axis >= l.point->dimension())
        item.field("axis").fail(std::string("must be x, y") + (spatial_ ? " or z" : "") + ", not '" + axis + "'");
      subject = l.point->name + "." + axis;
      l.what = "the " + axis + " of point '" + l.point->name + "'";
    } else {
      subject = effort.name();
      l.what = "the effort of driver '" + subject + "'";
      pending_.limit_efforts.emplace_back(plan.limits.size(), effort);
      if (item.field("rate").present()) item.field("rate").fail("an effort's limit is its `range`: it has no rate");
    }
    if (auto n = item.field("name"); n.present()) l.name = n.text();
    if (l.name.empty()) l.name = subject;
    if (!names.insert(l.name).second) item.fail("a second limit named '" + l.name + "'");
    const auto range = item.field("range"), rate = item.field("rate");
    if (!range.present() && !rate.present()) item.fail("a limit has a `range: [lo, hi]`, a `rate: [lo, hi]` or both");
    for (const Cursor* r : {&range, &rate}) {
      if (!r->present()) continue;
      if (!r->is_sequence() || r->size() != 2) r->fail("must be [lo, hi]");
      OutputLimit bound = l;
      bound.lo = number(r->at(0)), bound.hi = number(r->at(1));
      if (!(bound.lo < bound.hi)) r->fail("must be [lo, hi] with lo < hi");
      bound.rate = r == &rate;
      if (bound.rate) {
        if (!plan.solves_velocities() && !pending_.efforts_field)
          r->fail("a rate's limit needs velocities (output: velocities: true)");
        bound.what = "the rate of " + bound.what;
      }
      plan.limits.push_back(std::move(bound));
    }
  }
}

void SceneReader::resolve_limit_efforts(Scene& scene) const {
  OutputPlan& plan = scene.sweep;
  for (const auto& [first, cursor] : pending_.limit_efforts) {
    const std::string name = cursor.name();
    const Index c = scene.model->find_constraint(name);
    if (c < 0) cursor.fail("unknown driver '" + name + "'");
    const auto it = std::find(plan.efforts.constraints.begin(), plan.efforts.constraints.end(), c);
    if (it == plan.efforts.constraints.end())
      cursor.fail("driver '" + name + "''s effort is not computed: list it in `output: efforts`");
    plan.limits[first].effort = static_cast<Index>(it - plan.efforts.constraints.begin());
  }
}

}  // namespace phiq::detail::scene
