#include "gltf_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include "glb.hpp"
#include "gltf_nodes.hpp"
#include "html_clearance.hpp"
#include "part_drawing.hpp"
#include "phiq/drawn_parts.hpp"
#include "motion_columns.hpp"
#include "phiq/mechanism_sketch.hpp"
#include "phiq/phiq.hpp"
#include "phiq/version.hpp"

namespace phiq::tools {

namespace {

using Quat = std::array<double, 4>;  // glTF order: x, y, z, w
using Vec3 = std::array<double, 3>;

bool same(const Slot& a, const Slot& b) { return std::memcmp(&a, &b, sizeof(Slot)) == 0; }

Vec3 position(const OutputPoint& p, const double* q) {
  const PointMotion m = evaluate_point(p, q, nullptr, nullptr);
  return {m.r[0], m.r[1], m.r[2]};
}

// The rotation taking the x axis to the unit vector d along the shortest arc (about z for d in the plane).
Quat x_to(const Vec3& d) {
  const double w = 1.0 + d[0];
  if (w < 1e-12) return {0.0, 0.0, 1.0, 0.0};  // d = −x: half a turn about z
  const double n = std::sqrt(w * w + d[1] * d[1] + d[2] * d[2]);
  return {0.0, -d[2] / n, d[1] / n, w / n};
}

using gltf::Track;

enum Material { kBody, kLink, kJoint, kFixedJoint, kWitness };

// A shape of the sketch: a mesh of one primitive in one of its five materials.
gltf::Mesh sketch_mesh(std::string name, Material material) {
  static const char* const names[5] = {"body", "link", "joint", "fixed joint", "clearance witness"};
  static const std::array<double, 4> colours[5] = {{0.27, 0.45, 0.70, 1.0},
                                                   {0.90, 0.50, 0.10, 1.0},
                                                   {0.25, 0.25, 0.25, 1.0},
                                                   {0.05, 0.05, 0.05, 1.0},
                                                   {0.85, 0.10, 0.10, 1.0}};
  return {name, {{"", names[material], colours[material], {}, {}, {}}}};
}

// A box from lo to hi, each face with its own four vertices (flat normals).
gltf::Mesh box(std::string name, Material material, Vec3 lo, Vec3 hi) {
  gltf::Mesh mesh = sketch_mesh(std::move(name), material);
  gltf::Primitive& b = mesh.primitives[0];
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto base = static_cast<std::uint32_t>(b.pos.size() / 3);
      for (int k = 0; k < 4; ++k) {
        Vec3 p;
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = (k == 1 || k == 2) ? hi[u] : lo[u];
        p[v] = (k >= 2) ? hi[v] : lo[v];
        for (int c = 0; c < 3; ++c) {
          b.pos.push_back(static_cast<float>(p[c]));
          b.nrm.push_back(c == axis ? (side ? 1.0f : -1.0f) : 0.0f);
        }
      }
      // counter-clockwise seen from outside: (u, v) is right-handed with the axis, so flip on the low side
      const std::uint32_t tri[6] = {0, 1, 2, 0, 2, 3}, flipped[6] = {0, 2, 1, 0, 3, 2};
      for (int k = 0; k < 6; ++k) b.idx.push_back(base + (side ? tri[k] : flipped[k]));
    }
  return mesh;
}

// A sphere of radius r about the origin (latitude-longitude grid).
gltf::Mesh sphere(std::string name, Material material, double r) {
  gltf::Mesh mesh = sketch_mesh(std::move(name), material);
  gltf::Primitive& s = mesh.primitives[0];
  constexpr int kLat = 8, kLon = 12;
  for (int i = 0; i <= kLat; ++i)
    for (int j = 0; j <= kLon; ++j) {
      const double th = M_PI * i / kLat, ph = 2 * M_PI * j / kLon;
      const double n[3] = {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
      for (int c = 0; c < 3; ++c)
        s.nrm.push_back(static_cast<float>(n[c])), s.pos.push_back(static_cast<float>(r * n[c]));
    }
  for (int i = 0; i < kLat; ++i)
    for (int j = 0; j < kLon; ++j) {
      const auto a = static_cast<std::uint32_t>(i * (kLon + 1) + j), b = a + kLon + 1;
      for (std::uint32_t k : {a, b, a + 1, a + 1, b, b + 1}) s.idx.push_back(k);
    }
  return mesh;
}

void push(std::vector<float>& v, std::initializer_list<double> x) {
  for (double d : x) v.push_back(static_cast<float>(d));
}

// The sketch's nodes: a box per moving body without a part (spanning its attachments), and, in a scene without
// parts, a box per link along x (scaled where its length changes) and a ball per joint.
class SketchTracks {
 public:
  SketchTracks(const Scene& scene, const MechanismSketch& sketch, const std::vector<Part>& parts, gltf::Nodes& nodes)
      : scene_(scene), sketch_(sketch), nodes_(nodes), first_(nodes.tracks.size()) {
    const Model& model = *scene.model;
    auto has_part = [&](auto same_frame) { return std::any_of(parts.begin(), parts.end(), same_frame); };
    for (std::size_t k = 0; k < scene.planar_bodies.size(); ++k)
      if (!has_part([&](const Part& p) {
            return p.frame.kind == PartFrameKind::kPlanarBody && p.frame.planar == scene.planar_bodies[k];
          }))
        planar_.push_back(k);
    for (std::size_t k = 0; k < scene.spatial_bodies.size(); ++k)
      if (!has_part([&](const Part& p) {
            return p.frame.kind == PartFrameKind::kSpatialBody && p.frame.spatial == scene.spatial_bodies[k];
          }))
        spatial_.push_back(k);
    for (std::size_t k : planar_) nodes.tracks.push_back({model.body_names()[k], -1, {}, {}, {}});
    for (std::size_t k : spatial_)
      nodes.tracks.push_back({model.body_names()[scene.planar_bodies.size() + k], -1, {}, {}, {}});
    if (!parts.empty()) return;
    for (const SketchSegment& s : sketch.segments)
      if (s.line == SketchLine::kBar) links_.push_back(&s);
    for (const SketchSegment* s : links_)
      nodes.tracks.push_back(
          {s->constraint >= 0 ? model.constraints()[static_cast<std::size_t>(s->constraint)].name : "link",
           -1,
           {},
           {},
           {}});
    for (const SketchJoint& j : sketch.joints) {
      std::string name = j.constraint >= 0 ? model.constraints()[static_cast<std::size_t>(j.constraint)].name : "joint";
      if (j.end >= 0) name += ".end" + std::to_string(j.end);
      nodes.tracks.push_back({name, -1, {}, {}, {}, j.fixed});
      joints_.push_back(&j);
    }
    length0_.resize(links_.size()), theta_.resize(links_.size()), last_.resize(links_.size());
  }
  std::size_t size() const { return planar_.size() + spatial_.size() + links_.size() + joints_.size(); }

  // Every node's keyframe at q (`at_row` names the row in messages).
  void row(const double* q, bool first, const std::string& at_row) {
    std::size_t n = first_;
    for (std::size_t k : planar_) {
      const Frame2& f = scene_.planar_bodies[k];
      Track& tr = nodes_.tracks[n++];
      const double psi = f.psi.of(q);
      push(tr.t, {f.x.of(q), f.y.of(q), 0.0});
      push(tr.r, {0.0, 0.0, std::sin(psi / 2), std::cos(psi / 2)});
    }
    for (std::size_t k : spatial_) {
      const Frame3& f = scene_.spatial_bodies[k];
      Track& tr = nodes_.tracks[n++];
      const double e[4] = {f.e0.of(q), f.e1.of(q), f.e2.of(q), f.e3.of(q)};
      const double norm = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
      if (!(norm > 0.0)) throw Error(at_row + ": body '" + tr.name + "' has Euler parameters of norm 0");
      push(tr.t, {f.x.of(q), f.y.of(q), f.z.of(q)});
      push(tr.r, {e[1] / norm, e[2] / norm, e[3] / norm, e[0] / norm});
    }
    for (std::size_t k = 0; k < links_.size(); ++k) link_row(nodes_.tracks[n++], k, q, first);
    for (const SketchJoint* j : joints_) {
      const Vec3 p = position(j->at, q);
      push(nodes_.tracks[n++].t, {p[0], p[1], p[2]});
    }
  }

  // The shapes, sized from the sketch: `w` the thickness.
  void finish(double w) {
    std::size_t n = first_;
    for (std::size_t k : planar_) body_box(n++, body_points(scene_.planar_bodies[k]), w);
    for (std::size_t k : spatial_) body_box(n++, body_points(scene_.spatial_bodies[k]), w);
    for (std::size_t k = 0; k < links_.size(); ++k) {
      Track& tr = nodes_.tracks[n++];
      tr.mesh = static_cast<int>(nodes_.meshes.size());
      nodes_.meshes.push_back(box(tr.name, kLink, {0, -w / 2, -w / 2}, {length0_[k], w / 2, w / 2}));
      bool varies = false;
      for (std::size_t i = 0; i < tr.s.size(); i += 3) varies = varies || tr.s[i] != 1.0f;
      if (!varies) tr.s.clear();  // a link of constant length: no scale channel
    }
    int balls[2] = {-1, -1};  // moving, fixed: made when first used (the validator notes unused objects)
    for (const SketchJoint* j : joints_) {
      int& ball = balls[j->fixed ? 1 : 0];
      if (ball < 0) {
        ball = static_cast<int>(nodes_.meshes.size());
        nodes_.meshes.push_back(j->fixed ? sphere("fixed joint", kFixedJoint, 0.75 * w)
                                         : sphere("joint", kJoint, 0.75 * w));
      }
      nodes_.tracks[n++].mesh = ball;
    }
  }

 private:
  void link_row(Track& tr, std::size_t k, const double* q, bool first) {
    const Vec3 a = position(links_[k]->from, q), b = position(links_[k]->to, q);
    const Vec3 d{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    Quat r{0, 0, 0, 1};
    if (scene_.dimension != 3) {  // about z, the angle unwrapped so that keyframes interpolate the short way
      double th = std::atan2(d[1], d[0]);
      if (!first) th = theta_[k] + std::remainder(th - theta_[k], 2 * M_PI);
      theta_[k] = th;
      r = {0.0, 0.0, std::sin(th / 2), std::cos(th / 2)};
    } else if (len > 0) {
      r = x_to({d[0] / len, d[1] / len, d[2] / len});
      if (!first && r[0] * last_[k][0] + r[1] * last_[k][1] + r[2] * last_[k][2] + r[3] * last_[k][3] < 0)
        for (double& c : r) c = -c;  // the same rotation, on the side of the previous keyframe
    }
    last_[k] = r;
    if (first) length0_[k] = len > 0 ? len : 1.0;
    push(tr.t, {a[0], a[1], a[2]});
    push(tr.r, {r[0], r[1], r[2], r[3]});
    push(tr.s, {len / length0_[k], 1.0, 1.0});
  }
  // The points of the sketch on a body, in its frame.
  std::vector<Vec3> body_points(const Frame2& f) const {
    std::vector<Vec3> local;
    auto on = [&](const OutputPoint& p) {
      if (p.kind == OutputPointKind::kPlanarBodyPoint && same(p.body.x, f.x) && same(p.body.y, f.y) &&
          same(p.body.psi, f.psi))
        local.push_back({p.local_x, p.local_y, 0.0});
    };
    for (const SketchSegment& s : sketch_.segments) on(s.from), on(s.to);
    for (const SketchJoint& j : sketch_.joints) on(j.at);
    return local;
  }
  std::vector<Vec3> body_points(const Frame3& f) const {
    std::vector<Vec3> local;
    const Slot frame[7] = {f.x, f.y, f.z, f.e0, f.e1, f.e2, f.e3};
    auto on = [&](const OutputPoint& p) {
      if (p.kind != OutputPointKind::kSpatialBodyPoint) return;
      const Attachment3& a = p.spatial;
      const Slot mine[7] = {a.r[0], a.r[1], a.r[2], a.p[0], a.p[1], a.p[2], a.p[3]};
      for (int c = 0; c < 7; ++c)
        if (!same(mine[c], frame[c])) return;
      local.push_back({a.s.x, a.s.y, a.s.z});
    };
    for (const SketchSegment& s : sketch_.segments) on(s.from), on(s.to);
    for (const SketchJoint& j : sketch_.joints) on(j.at);
    return local;
  }
  void body_box(std::size_t n, const std::vector<Vec3>& local, double w) {
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    for (const Vec3& s : local)
      for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], s[c]), hi[c] = std::max(hi[c], s[c]);
    for (int c = 0; c < 3; ++c) lo[c] -= w / 2, hi[c] += w / 2;
    nodes_.tracks[n].mesh = static_cast<int>(nodes_.meshes.size());
    nodes_.meshes.push_back(box(nodes_.tracks[n].name, kBody, lo, hi));
  }

  const Scene& scene_;
  const MechanismSketch& sketch_;
  gltf::Nodes& nodes_;
  std::size_t first_;
  std::vector<std::size_t> planar_, spatial_;  // the bodies drawn as boxes
  std::vector<const SketchSegment*> links_;
  std::vector<const SketchJoint*> joints_;
  std::vector<double> length0_, theta_;
  std::vector<Quat> last_;
};

// The clearance's witness points (motion_glb() in gltf_motion.hpp says what they show): two tracks per pair.
class WitnessTracks {
 public:
  WitnessTracks(const Scene& scene, const ClearanceReport* report, gltf::Nodes& nodes)
      : scene_(scene), report_(report), nodes_(nodes), first_(nodes.tracks.size()) {
    if (!report) return;
    for (const PairClearance& p : report->pairs) {
      const std::string a = scene.parts[static_cast<std::size_t>(p.a)].name;
      const std::string b = scene.parts[static_cast<std::size_t>(p.b)].name;
      const std::string near = viewer_near_rows(*report, p);
      nlohmann::json interference = nlohmann::json::array();
      for (const InterferenceInterval& i : p.interference) interference.push_back({i.entry, i.exit});
      for (int side = 0; side < 2; ++side) {
        const std::string& part = side ? b : a;
        witnesses_.push_back({side ? p.b : p.a, side ? p.worst.local_b : p.worst.local_a, near});
        gltf::Track tr{"clearance " + a + " / " + b + ": witness on " + part, -1, {}, {}, {}};
        tr.extras["clearance"] = {{"pair", {a, b}},
                                  {"part", part},
                                  {"worst_t", p.worst.t},
                                  {"distance", p.worst.at.distance},
                                  {"threshold", report->threshold},
                                  {"near", near},
                                  {"interference", interference}};
        nodes.tracks.push_back(std::move(tr));
      }
    }
  }

  // Every ball's keyframe at (q, t).
  void row(const double* q, double t) {
    if (witnesses_.empty()) return;
    const std::vector<double>& times = report_->times;
    auto above = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
    std::size_t r = above == 0 ? 0 : above - 1;  // the report's row nearest t
    if (r + 1 < times.size() && times[r + 1] - t < t - times[r]) ++r;
    for (std::size_t k = 0; k < witnesses_.size(); ++k) {
      const Witness& w = witnesses_[k];
      const kin3::V3 x = part_pose(scene_.parts[static_cast<std::size_t>(w.part)].frame, q, t).apply(w.local);
      gltf::Track& tr = nodes_.tracks[first_ + k];
      const double scale = r < w.near.size() && w.near[r] == '1' ? 2.0 : 1.0;
      push(tr.t, {x.x, x.y, x.z});
      push(tr.s, {scale, scale, scale});
    }
  }

  // The balls' mesh (one, of radius r), made when there is a ball; no scale channel where none grows.
  void finish(double r) {
    if (witnesses_.empty()) return;
    const int mesh = static_cast<int>(nodes_.meshes.size());
    nodes_.meshes.push_back(sphere("clearance witness", kWitness, r));
    for (std::size_t k = 0; k < witnesses_.size(); ++k) {
      gltf::Track& tr = nodes_.tracks[first_ + k];
      tr.mesh = mesh;
      if (std::all_of(tr.s.begin(), tr.s.end(), [](float v) { return v == 1.0f; })) tr.s.clear();
    }
  }

 private:
  struct Witness {
    Index part;
    kin3::V3 local;    // in the part's frame
    std::string near;  // viewer_near_rows()
  };
  const Scene& scene_;
  const ClearanceReport* report_;
  gltf::Nodes& nodes_;
  std::size_t first_;
  std::vector<Witness> witnesses_;
};

}  // namespace

std::vector<Slot> glb_reads(const Scene& scene, const MechanismSketch& sketch, const std::vector<Part>& parts) {
  std::vector<Slot> read;
  for (const Frame2& f : scene.planar_bodies) read.insert(read.end(), {f.x, f.y, f.psi});
  for (const Frame3& f : scene.spatial_bodies) read.insert(read.end(), {f.x, f.y, f.z, f.e0, f.e1, f.e2, f.e3});
  for (const SketchSegment& s : sketch.segments)
    if (s.line == SketchLine::kBar)
      for (const OutputPoint* p : {&s.from, &s.to})
        for (const Slot& x : slots_of(*p)) read.push_back(x);
  for (const SketchJoint& j : sketch.joints)
    for (const Slot& x : slots_of(j.at)) read.push_back(x);
  for (const Slot& x : part_reads(parts)) read.push_back(x);
  return read;
}

std::string motion_glb(const Scene& scene, const CsvTable& table, const std::string& result,
                       const ClearanceReport* clearance) {
  const Model& model = *scene.model;
  const MechanismSketch sketch = sketch_mechanism(model);
  const std::vector<Part> parts = drawn_parts(scene);
  const std::string title = scene.name.empty() ? std::filesystem::path(scene.path).stem().string() : scene.name;
  const MotionColumns columns(scene, glb_reads(scene, sketch, parts), table, result);
  gltf::Nodes nodes;
  SketchTracks drawn(scene, sketch, parts, nodes);
  gltf::PartTracks part_tracks(parts, nodes);
  WitnessTracks witnesses(scene, clearance, nodes);
  if (nodes.tracks.empty()) throw Error(scene.path + ": nothing to animate (no moving body, part, link or joint)");

  std::vector<float> times;
  Eigen::VectorXd q = model.initial_positions();
  for (std::size_t row = 0; row < table.rows.size(); ++row) {
    columns.positions(row, q);
    const std::string at_row = columns.at_row(row);
    const double t = table.rows[row][columns.t_column()];
    if (!times.empty() && !(static_cast<float>(t) > times.back()))
      throw Error(at_row + ": t does not increase (as 32-bit floats, which glTF keyframe times are)");
    times.push_back(static_cast<float>(t));
    drawn.row(q.data(), row == 0, at_row);
    part_tracks.row(q.data(), t);
    witnesses.row(q.data(), t);
  }
  drawn.finish(0.04 * model.length_scale());
  part_tracks.finish();
  witnesses.finish(0.02 * model.length_scale());
  return gltf::write_glb(title, std::string("phiq ") + kVersion, nodes, times, scene.dimension == 3, result);
}

}  // namespace phiq::tools
