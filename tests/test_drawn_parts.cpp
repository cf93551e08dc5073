// Derived parts (phiq/drawn_parts.hpp): every joint of the scenes in models/ puts a shape on a body it joins; the
// derived links meet at the joints the mechanism's sketch draws, in every coordinate family, as the bodies move;
// a gear's pitch circle, a belt's path, a cam's profile and a screw's thread have the geometry of their constraint;
// and the scene's stated parts are kept, their bodies given no derived part.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>

#include "phiq/drawn_parts.hpp"
#include "phiq/mechanism_sketch.hpp"
#include "phiq/phiq.hpp"
#include "test_support.hpp"

namespace phiq::drawn_parts_test {

using kin3::V3;

bool starts_with(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }
const Shape* shape_named(const std::vector<Part>& parts, const std::string& part, const std::string& shape) {
  for (const Part& p : parts)
    if (p.name == part)
      for (const Shape& s : p.shapes)
        if (s.name == shape) return &s;
  return nullptr;
}
V3 world(const PointMotion& m) { return {m.r[0], m.r[1], m.r.size() > 2 ? m.r[2] : 0.0}; }
// The two ends of a capsule's axis in its part's frame.
std::pair<V3, V3> capsule_ends(const Shape& s) {
  const V3 z{s.rotation[2], s.rotation[5], s.rotation[8]};
  return {s.at - (0.5 * s.length) * z, s.at + (0.5 * s.length) * z};
}

// Every constraint of a joint kind (JointCount::Role::kJoint, from the registry) in every scene of models/ that
// reads a body's coordinate puts at least one shape, named after it, on a part whose frame reads a coordinate it
// reads (its body), or on ground.
TEST(DrawnParts, EveryJointOfTheModelsPutsAShapeOnItsBody) {
  std::map<std::string, int> joints_of_kind;
  int scenes = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(PHIQ_MODELS_DIR)) {
    const std::string path = entry.path().string();
    if (entry.path().extension() != ".yaml" || path.find("/reference/") != std::string::npos) continue;
    Scene scene;
    try {
      scene = load_scene(path);
    } catch (const SceneError&) {
      continue;  // the hostile and fault scenes
    }
    ++scenes;
    std::set<Index> body_coordinates;
    for (const Frame2& f : scene.planar_bodies)
      for (const Slot* s : {&f.x, &f.y, &f.psi})
        if (s->is_coordinate()) body_coordinates.insert(s->coord());
    for (const Frame3& f : scene.spatial_bodies)
      for (const Slot* s : {&f.x, &f.y, &f.z, &f.e0, &f.e1, &f.e2, &f.e3})
        if (s->is_coordinate()) body_coordinates.insert(s->coord());
    const std::vector<Part> parts = drawn_parts(scene);
    for (const Part& p : parts)  // every derived shape has sizes and an outline that draw
      for (const Shape& s : p.shapes) EXPECT_NO_THROW(shape_triangles(s, 8)) << path << ": " << s.name;
    const Model& m = *scene.model;
    for (const auto& block : m.blocks())
      ConstraintKinds::for_each([&]<class K>() {
        auto* typed = dynamic_cast<const TypedBlock<K>*>(block.get());
        if (!typed) return;
        for (std::size_t i = 0; i < typed->size(); ++i) {
          const K& spec = typed->spec(i);
          if (spec.joint_count().role != JointCount::Role::kJoint) continue;
          std::set<Index> reads;
          spec.for_each_slot([&](const Slot& s, Unit) {
            if (s.is_coordinate()) reads.insert(s.coord());
          });
          bool on_body = false;
          for (Index c : reads) on_body = on_body || body_coordinates.count(c) > 0;
          if (!on_body) continue;  // between angle coordinates of no body: nothing to carry a shape
          const std::string name =
              m.constraints()[static_cast<std::size_t>(m.constraint_of_row(typed->first_row(i)))].name;
          bool found = false, stated = false;
          for (const Part& p : parts) {
            bool its_body = p.fixed;
            for (Index c : frame_coordinates(p.frame)) its_body = its_body || reads.count(c) > 0;
            for (const Shape& s : p.shapes) found = found || (p.derived && its_body && starts_with(s.name, name + "."));
            stated = stated || (!p.derived && !p.fixed && its_body);
          }
          if (!found && stated)
            continue;  // the scene's own parts draw this joint's bodies (models/spatial/cardan.yaml)
          EXPECT_TRUE(found) << path << ": " << K::kKind << " '" << name << "' has no derived shape on its body";
          ++joints_of_kind[K::kKind];
        }
      });
  }
  EXPECT_GT(scenes, 30);
  // the joint kinds of the registry that the models hold: the planar pairs, the curve pairs, the transmissions and
  // the spatial joints, screw and gears among them
  std::string seen;
  for (const auto& [kind, count] : joints_of_kind) seen += kind + " ";
  EXPECT_GE(joints_of_kind.size(), 11u) << seen;
}

// Each derived link on a body or between points runs between the two ends of a line of the mechanism's sketch
// (sketch_mechanism: a body's arm, a natural link), evaluated with evaluate_point at several rows of the sweep; a
// vertex of its triangles is its part's pose applied to it.
void expect_links_on_the_sketch(const std::string& model) {
  const Scene scene = load_scene(test::model_path(model));
  test::Trace tr;
  ASSERT_EQ(test::sweep(*scene.model, scene.sweep, &tr), SolveStatus::kSuccess) << model;
  const std::vector<Part> parts = drawn_parts(scene);
  const MechanismSketch sketch = sketch_mechanism(*scene.model);
  int links = 0;
  double ends = 0.0, vertices = 0.0, lengths = 0.0;
  for (std::size_t k : {std::size_t{0}, tr.t.size() / 3, 2 * tr.t.size() / 3, tr.t.size() - 1}) {
    const double* q = tr.q[k].data();
    for (const Part& p : parts) {
      const Pose pose = part_pose(p.frame, q, tr.t[k]);
      for (const Shape& s : p.shapes) {
        if (s.kind != ShapeKind::kCapsule) continue;
        const auto [a, b] = capsule_ends(s);
        const V3 wa = pose.apply(a), wb = pose.apply(b);
        double best = 1e300, best_residual = 0.0;
        for (const SketchSegment& seg : sketch.segments) {
          const V3 f = world(evaluate_point(seg.from, q, nullptr, nullptr));
          const V3 t = world(evaluate_point(seg.to, q, nullptr, nullptr));
          // a natural link's far end is its length along the line: off B by the distance's residual |AB| − L
          const double residual = std::fabs(kin3::norm(t - f) - s.length);
          const double gap = std::min(std::max(kin3::norm(wa - f), kin3::norm(wb - t) - residual),
                                      std::max(kin3::norm(wa - t), kin3::norm(wb - f) - residual));
          if (gap < best) best = gap, best_residual = residual;
        }
        ends = std::max(ends, best);
        lengths = std::max(lengths, best_residual);
        ++links;
        const TriangleMesh mesh = shape_triangles(s, 8);
        const V3 v = mesh.vertices[mesh.vertices.size() / 2];
        V3 expected = v;  // the vertex by the part frame's own coordinates
        if (p.frame.kind == PartFrameKind::kPlanarBody)
          expected = world(evaluate_point(planar_body_point("", p.frame.planar, v.x, v.y), q, nullptr, nullptr)) +
                     V3{0, 0, v.z};
        else if (p.frame.kind == PartFrameKind::kSpatialBody) {  // r + R(e/|e|) v
          const Frame3& f = p.frame.spatial;
          double e[4] = {f.e0.of(q), f.e1.of(q), f.e2.of(q), f.e3.of(q)};
          const double n = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
          for (double& x : e) x /= n;
          expected = V3{f.x.of(q), f.y.of(q), f.z.of(q)} + kin3::rotate(e, v);
        } else {
          expected = pose.at + v.x * V3{pose.rotation[0], pose.rotation[3], pose.rotation[6]} +
                     v.y * V3{pose.rotation[1], pose.rotation[4], pose.rotation[7]} +
                     v.z * V3{pose.rotation[2], pose.rotation[5], pose.rotation[8]};
        }
        vertices = std::max(vertices, kin3::norm(pose.apply(v) - expected));
      }
    }
  }
  EXPECT_GE(links, 4 * 2) << model;  // two links (or more) at each of four rows
  EXPECT_LT(ends, 1e-12) << model;
  EXPECT_LT(lengths, 1e-9) << model;  // a natural link's length is its constraint's, met to the solver's tolerance
  EXPECT_LT(vertices, 1e-12) << model;
}

TEST(DrawnParts, LinksMeetAtTheJointsInEveryCoordinateFamily) {
  for (const char* model : {"seed/fourbar_natural.yaml", "seed/fourbar_reference_point.yaml", "seed/fourbar_mixed.yaml",
                            "spatial/rssr.yaml", "spatial/rssr_natural.yaml"})
    expect_links_on_the_sketch(model);
}

// Relative coordinates: the loop's links end where the next begins, start at the origin, close on (L1, 0) to the
// loop's residual, and meet the joints of the reference-point four-bar (the same motion) at every row.
TEST(DrawnParts, LoopLinksFollowTheRelativeCoordinates) {
  const Scene rel = load_scene(test::model_path("seed/fourbar_relative.yaml"));
  const Scene ref = load_scene(test::model_path("seed/fourbar_reference_point.yaml"));
  test::Trace tr_rel, tr_ref;
  ASSERT_EQ(test::sweep(*rel.model, rel.sweep, &tr_rel), SolveStatus::kSuccess);
  ASSERT_EQ(test::sweep(*ref.model, ref.sweep, &tr_ref), SolveStatus::kSuccess);
  const std::vector<Part> parts = drawn_parts(rel);
  ASSERT_EQ(parts.size(), 3u);
  double chain = 0.0, across = 0.0;
  for (std::size_t k = 0; k < tr_rel.t.size(); k += 30) {
    std::vector<V3> joints{{0, 0, 0}};
    for (const Part& p : parts) {
      ASSERT_EQ(p.shapes.size(), 1u);
      const auto [a, b] = capsule_ends(p.shapes[0]);
      const Pose pose = part_pose(p.frame, tr_rel.q[k].data(), tr_rel.t[k]);
      chain = std::max(chain, kin3::norm(pose.apply(a) - joints.back()));
      joints.push_back(pose.apply(b));
    }
    chain = std::max(chain, kin3::norm(joints.back() - V3{1.0, 0, 0}) - 1e-9);  // the closure, to the tolerance
    // O, A, B, C of the reference-point four-bar: the crank's ends, then the rocker's (its axis runs C → B)
    const double* q = tr_ref.q[k].data();
    const Frame2 &crank = ref.planar_bodies[0], &rocker = ref.planar_bodies[2];
    const V3 points[4] = {world(evaluate_point(planar_body_point("", crank, -0.2, 0), q, nullptr, nullptr)),
                          world(evaluate_point(planar_body_point("", crank, 0.2, 0), q, nullptr, nullptr)),
                          world(evaluate_point(planar_body_point("", rocker, 0.5, 0), q, nullptr, nullptr)),
                          world(evaluate_point(planar_body_point("", rocker, -0.5, 0), q, nullptr, nullptr))};
    for (int j = 0; j < 4; ++j) across = std::max(across, kin3::norm(joints[j] - points[j]));
  }
  EXPECT_LT(chain, 1e-12);
  EXPECT_LT(across, 1e-9);  // two solutions of one mechanism, each to the solver's tolerance
}

// A gear's pitch circle has the pitch radius of its constraint: gear_train's module 5 mm times half the teeth, the
// planetary's ring (internal) as a ring of 60 teeth of 4 mm; the rack's pinion the rack_pinion's radius; a bevel
// pair's circles in the ratio of their teeth, both on the cone distance from the apex.
TEST(DrawnParts, PitchCirclesHaveTheRadiiOfTheirGears) {
  const std::vector<Part> train = drawn_parts(load_scene(test::model_path("transmissions/gear_train.yaml")));
  const std::pair<const char*, double> wheels[] = {{"input", 12}, {"countershaft", 36}};
  for (const auto& [body, teeth] : wheels) {
    const Shape* s = shape_named(train, body, "first_stage.pitch_circle");
    ASSERT_TRUE(s) << body;
    EXPECT_NEAR(s->radius, 0.005 * teeth / 2, 1e-15) << body;
  }
  EXPECT_NEAR(shape_named(train, "countershaft", "second_stage.pitch_circle")->radius, 0.005 * 15 / 2, 1e-15);
  EXPECT_NEAR(shape_named(train, "output", "second_stage.pitch_circle")->radius, 0.005 * 45 / 2, 1e-15);

  const std::vector<Part> planetary = drawn_parts(load_scene(test::model_path("transmissions/planetary.yaml")));
  const Shape* ring = shape_named(planetary, "ring", "planet_ring.pitch_circle");
  ASSERT_TRUE(ring);
  ASSERT_EQ(ring->kind, ShapeKind::kCurve);
  for (const V3& p : ring->points) EXPECT_NEAR(kin3::norm(p), 0.004 * 60 / 2, 1e-15);
  EXPECT_NEAR(shape_named(planetary, "planet", "planet_ring.pitch_circle")->radius, 0.004 * 18 / 2, 1e-15);

  const std::vector<Part> rack = drawn_parts(load_scene(test::model_path("transmissions/rack_pinion.yaml")));
  EXPECT_EQ(shape_named(rack, "pinion", "mesh.pitch_circle")->radius, 0.04);
  const Shape* bar = shape_named(rack, "rack", "mesh.rack");
  ASSERT_TRUE(bar);  // its top face is the pitch line, tangent to the pinion's circle (about (0, 0.04)) at y = 0
  EXPECT_NEAR(bar->at.y + bar->size.y / 2 + 0.0 /* rack body at y = 0 */, 0.0, 1e-15);

  const Scene bevel = load_scene(test::model_path("transmissions/bevel_gears.yaml"));
  const std::vector<Part> gears = drawn_parts(bevel);
  const Shape* g1 = shape_named(gears, "input_shaft", "bevel.pitch_circle");
  const Shape* g2 = shape_named(gears, "output_shaft", "bevel.pitch_circle");
  ASSERT_TRUE(g1 && g2);
  EXPECT_NEAR(g1->radius / g2->radius, 15.0 / 30.0, 1e-14);
  const double cone = bevel.model->length_scale() / 4;  // both circles lie on the sphere of the cone distance
  EXPECT_NEAR(std::hypot(g1->radius, kin3::norm(g1->at)), cone, 1e-14);
  EXPECT_NEAR(std::hypot(g2->radius, kin3::norm(g2->at)), cone, 1e-14);
}

// A belt's path, open and crossed, is as long as the closed forms for its two pulleys (to the sampling of its arcs at
// 1°: a chord falls short of its arc by θ²/24), runs around the pulleys, and its pulleys have the belt's radii.
TEST(DrawnParts, BeltPathsHaveTheClosedFormLength) {
  const std::string text = R"(phiq: 1
coordinates: {x1: 0, y1: 0, p1: 0, x2: 0.5, y2: 0.1, p2: 0, x3: -0.3, y3: 0.4, p3: 0}
bodies: {a: [x1, y1, p1], b: [x2, y2, p2], c: [x3, y3, p3]}
constraints:
  - {name: pa, type: revolute, between: [{body: ground}, {body: a}]}
  - {name: pb, type: revolute, between: [{body: ground, at: [0.5, 0.1]}, {body: b}]}
  - {name: pc, type: revolute, between: [{body: ground, at: [-0.3, 0.4]}, {body: c}]}
  - {name: open, type: belt, between: [a, b], radii: [0.08, 0.05]}
  - {name: crossed, type: belt, between: [a, c], radii: [0.08, 0.12], crossed: true}
drivers:
  - {name: motor, coordinate: p1, law: {type: linear, initial: 0, rate: 1}}
time: {start: 0, end: 1, steps: 4}
)";
  const Scene scene = parse_scene(text, "belts.yaml");
  const std::vector<Part> parts = drawn_parts(scene);
  const double d1 = std::hypot(0.5, 0.1), d2 = 0.5, pi = std::numbers::pi;
  const double open = 2 * std::sqrt(d1 * d1 - 0.03 * 0.03) + pi * 0.13 + 2 * 0.03 * std::asin(0.03 / d1);
  const double crossed = 2 * std::sqrt(d2 * d2 - 0.2 * 0.2) + 0.2 * (pi + 2 * std::asin(0.2 / d2));
  const std::pair<const char*, double> belts[] = {{"open", open}, {"crossed", crossed}};
  for (const auto& [name, exact] : belts) {
    const Shape* path = shape_named(parts, name, std::string(name) + ".path");
    ASSERT_TRUE(path && path->closed) << name;
    double length = 0.0;
    for (std::size_t k = 0; k < path->points.size(); ++k)
      length += kin3::norm(path->points[(k + 1) % path->points.size()] - path->points[k]);
    const double step = pi / 180;
    EXPECT_LT(length, exact) << name;
    EXPECT_GT(length, exact * (1 - step * step / 24)) << name;
  }
  // the path's frame: origin at pulley a's centre, x toward b's; its first point on pulley a's circle
  for (const Part& p : parts)
    if (p.name == "open") {
      const Pose pose = part_pose(p.frame, scene.model->initial_positions().data(), 0.0);
      EXPECT_NEAR(kin3::norm(pose.apply(p.shapes[0].points[0])), 0.08, 1e-15);
      EXPECT_NEAR(pose.rotation[3], 0.1 / d1, 1e-15);
    }
  EXPECT_EQ(shape_named(parts, "b", "open.pulley")->radius, 0.05);
  EXPECT_EQ(shape_named(parts, "c", "crossed.pulley")->radius, 0.12);
}

// A cam's profile and a slot's curve are samples of the kind's curve, on the body that carries it; the roller has
// the follower's radius; a screw's thread advances by its lead each turn, along its axis.
TEST(DrawnParts, CamProfilesSlotsAndThreadsFollowTheirKinds) {
  const std::pair<const char*, const char*> curves[] = {{"cams/eccentric_roller.yaml", "cam.profile"},
                                                        {"slots/curved_slot_crank.yaml", "slot.slot"}};
  for (const auto& [model, name] : curves) {
    const Scene scene = load_scene(test::model_path(model));
    const auto* block = [&]() -> const TypedBlock<PointOnCurveSpec>* {
      for (const auto& b : scene.model->blocks())
        if (auto* t = dynamic_cast<const TypedBlock<PointOnCurveSpec>*>(b.get())) return t;
      return nullptr;
    }();
    ASSERT_TRUE(block) << model;
    const Curve& curve = *block->spec(0).on.curve;
    const std::vector<Part> parts = drawn_parts(scene);
    const Shape* s = shape_named(parts, model[0] == 'c' ? "disc" : "ground", name);
    ASSERT_TRUE(s) << model;
    std::vector<V3> points = s->points;
    for (const auto& o : s->outline) points.push_back({o[0], o[1], 0});
    ASSERT_GE(points.size(), 128u) << model;
    double off = 0.0;
    for (const V3& p : points) {
      kin::V2 c[4];
      curve.evaluate(curve.nearest({p.x, p.y}), c);
      off = std::max(off, std::hypot(c[0].x - p.x, c[0].y - p.y));
    }
    EXPECT_LT(off, 1e-12) << model;
    if (model[0] == 'c') {
      EXPECT_EQ(shape_named(parts, "rod", "cam.roller")->radius, 0.01);
    }
  }
  const std::vector<Part> jack = drawn_parts(load_scene(test::model_path("transmissions/screw_jack.yaml")));
  const Shape* thread = shape_named(jack, "nut", "lead_screw.thread");
  ASSERT_TRUE(thread);
  double lead = 0.0, across = 0.0;
  for (std::size_t k = 0; k + 24 < thread->points.size(); ++k) {  // 24 points a turn
    const V3 step = thread->points[k + 24] - thread->points[k];
    lead = std::max(lead, std::fabs(step.z - 0.004));
    across = std::max(across, std::hypot(step.x, step.y));
  }
  EXPECT_LT(lead, 1e-15);
  EXPECT_LT(across, 1e-15);
}

// Stated parts come first, as the scene has them; their bodies (and a natural link's points) get no derived part,
// the others do.
TEST(DrawnParts, StatedPartsAreKeptAndTheirBodiesGetNoDerivedPart) {
  const Scene body = parse_scene(test::model_file_text("seed/fourbar_reference_point.yaml") +
                                     "\nparts:\n  coupler: {shapes: [{type: box, size: [1.2, 0.1, 0.05]}]}\n",
                                 "stated.yaml");
  const std::vector<Part> parts = drawn_parts(body);
  ASSERT_EQ(parts.size(), 4u);  // the stated coupler, the derived crank and rocker, ground's pins
  EXPECT_FALSE(parts[0].derived);
  EXPECT_EQ(parts[0].name, "coupler");
  ASSERT_EQ(parts[0].shapes.size(), 1u);
  EXPECT_EQ(parts[0].shapes[0].size.x, 1.2);
  EXPECT_EQ(parts[1].name, "crank");
  EXPECT_EQ(parts[2].name, "rocker");
  EXPECT_EQ(parts[3].name, "ground");
  EXPECT_TRUE(parts[3].fixed);
  for (std::size_t k = 1; k < parts.size(); ++k) EXPECT_TRUE(parts[k].derived);

  const Scene natural =
      parse_scene(test::model_file_text("seed/fourbar_natural.yaml") + "\nparts:\n  bar: {frame: {origin: B, x: A}}\n",
                  "stated.yaml");
  const std::vector<Part> links = drawn_parts(natural);
  std::vector<std::string> names;
  for (const Part& p : links) names.push_back(p.name);
  EXPECT_EQ(names, (std::vector<std::string>{"bar", "crank", "rocker"}));  // no derived coupler A–B
}

}  // namespace phiq::drawn_parts_test
