#include "gltf_motion.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>

#include "glb.hpp"
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

// One node: its shape and its transform at every row.
struct Track {
  std::string name;
  int mesh = -1;
  std::vector<float> t, r, s;  // translation, rotation, scale per row (r, s empty: not animated)
};

// A shape: positions, normals and indices of triangles.
struct Shape {
  std::string name;
  int material = 0;
  std::vector<float> pos, nrm;
  std::vector<std::uint16_t> idx;
};

// A box from lo to hi, each face with its own four vertices (flat normals).
Shape box(std::string name, int material, Vec3 lo, Vec3 hi) {
  Shape b{std::move(name), material, {}, {}, {}};
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto base = static_cast<std::uint16_t>(b.pos.size() / 3);
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
      const std::uint16_t tri[6] = {0, 1, 2, 0, 2, 3}, flipped[6] = {0, 2, 1, 0, 3, 2};
      for (int k = 0; k < 6; ++k) b.idx.push_back(static_cast<std::uint16_t>(base + (side ? tri[k] : flipped[k])));
    }
  return b;
}

// A sphere of radius r about the origin (latitude-longitude grid).
Shape sphere(std::string name, int material, double r) {
  Shape s{std::move(name), material, {}, {}, {}};
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
      const auto a = static_cast<std::uint16_t>(i * (kLon + 1) + j), b = static_cast<std::uint16_t>(a + kLon + 1);
      for (std::uint16_t k : {a, b, static_cast<std::uint16_t>(a + 1), static_cast<std::uint16_t>(a + 1), b,
                              static_cast<std::uint16_t>(b + 1)})
        s.idx.push_back(k);
    }
  return s;
}

void push(std::vector<float>& v, std::initializer_list<double> x) {
  for (double d : x) v.push_back(static_cast<float>(d));
}

enum Material { kBody, kLink, kJoint, kFixedJoint };

}  // namespace

std::vector<Slot> glb_reads(const Scene& scene, const MechanismSketch& sketch) {
  std::vector<Slot> read;
  for (const Frame2& f : scene.planar_bodies) read.insert(read.end(), {f.x, f.y, f.psi});
  for (const Frame3& f : scene.spatial_bodies) read.insert(read.end(), {f.x, f.y, f.z, f.e0, f.e1, f.e2, f.e3});
  for (const SketchSegment& s : sketch.segments)
    if (s.line == SketchLine::kBar)
      for (const OutputPoint* p : {&s.from, &s.to})
        for (const Slot& x : slots_of(*p)) read.push_back(x);
  for (const SketchJoint& j : sketch.joints)
    for (const Slot& x : slots_of(j.at)) read.push_back(x);
  return read;
}

std::string motion_glb(const Scene& scene, const CsvTable& table, const std::string& result) {
  const Model& model = *scene.model;
  const bool spatial = scene.dimension == 3;
  const MechanismSketch sketch = sketch_mechanism(model);
  const std::string title = scene.name.empty() ? std::filesystem::path(scene.path).stem().string() : scene.name;

  std::vector<const SketchSegment*> links;
  for (const SketchSegment& s : sketch.segments)
    if (s.line == SketchLine::kBar) links.push_back(&s);
  const MotionColumns columns(scene, glb_reads(scene, sketch), table, result);
  const std::size_t nodes =
      scene.planar_bodies.size() + scene.spatial_bodies.size() + links.size() + sketch.joints.size();
  if (nodes == 0) throw Error(scene.path + ": nothing to animate (no moving body, link or joint)");

  // ---- the transforms of every node at every row
  const double w = 0.04 * model.length_scale();  // thickness of the shapes
  std::vector<Track> tracks;
  for (std::size_t k = 0; k < scene.planar_bodies.size() + scene.spatial_bodies.size(); ++k)
    tracks.push_back({model.body_names()[k], -1, {}, {}, {}});
  for (const SketchSegment* s : links)
    tracks.push_back({s->constraint >= 0 ? model.constraints()[static_cast<std::size_t>(s->constraint)].name : "link",
                      -1,
                      {},
                      {},
                      {}});
  for (const SketchJoint& j : sketch.joints) {
    std::string name = j.constraint >= 0 ? model.constraints()[static_cast<std::size_t>(j.constraint)].name : "joint";
    if (j.end >= 0) name += ".end" + std::to_string(j.end);
    tracks.push_back({name, -1, {}, {}, {}});
  }
  std::vector<double> length0(links.size()), theta(links.size());
  std::vector<Quat> last(links.size());
  std::vector<float> times;
  Eigen::VectorXd q = model.initial_positions();
  for (std::size_t row = 0; row < table.rows.size(); ++row) {
    columns.positions(row, q);
    const std::string at_row = columns.at_row(row);
    const auto t = static_cast<float>(table.rows[row][columns.t_column()]);
    if (!times.empty() && !(t > times.back()))
      throw Error(at_row + ": t does not increase (as 32-bit floats, which glTF keyframe times are)");
    times.push_back(t);
    std::size_t n = 0;
    for (const Frame2& f : scene.planar_bodies) {
      Track& tr = tracks[n++];
      const double psi = f.psi.of(q.data());
      push(tr.t, {f.x.of(q.data()), f.y.of(q.data()), 0.0});
      push(tr.r, {0.0, 0.0, std::sin(psi / 2), std::cos(psi / 2)});
    }
    for (const Frame3& f : scene.spatial_bodies) {
      Track& tr = tracks[n++];
      const double e[4] = {f.e0.of(q.data()), f.e1.of(q.data()), f.e2.of(q.data()), f.e3.of(q.data())};
      const double norm = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
      if (!(norm > 0.0)) throw Error(at_row + ": body '" + tr.name + "' has Euler parameters of norm 0");
      push(tr.t, {f.x.of(q.data()), f.y.of(q.data()), f.z.of(q.data())});
      push(tr.r, {e[1] / norm, e[2] / norm, e[3] / norm, e[0] / norm});
    }
    for (std::size_t k = 0; k < links.size(); ++k) {
      Track& tr = tracks[n++];
      const Vec3 a = position(links[k]->from, q.data()), b = position(links[k]->to, q.data());
      const Vec3 d{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      Quat r{0, 0, 0, 1};
      if (!spatial) {  // about z, the angle unwrapped so that keyframes interpolate the short way
        double th = std::atan2(d[1], d[0]);
        if (row > 0) th = theta[k] + std::remainder(th - theta[k], 2 * M_PI);
        theta[k] = th;
        r = {0.0, 0.0, std::sin(th / 2), std::cos(th / 2)};
      } else if (len > 0) {
        r = x_to({d[0] / len, d[1] / len, d[2] / len});
        if (row > 0 && r[0] * last[k][0] + r[1] * last[k][1] + r[2] * last[k][2] + r[3] * last[k][3] < 0)
          for (double& c : r) c = -c;  // the same rotation, on the side of the previous keyframe
      }
      last[k] = r;
      if (row == 0) length0[k] = len > 0 ? len : 1.0;
      push(tr.t, {a[0], a[1], a[2]});
      push(tr.r, {r[0], r[1], r[2], r[3]});
      push(tr.s, {len / length0[k], 1.0, 1.0});
    }
    for (const SketchJoint& j : sketch.joints) {
      const Vec3 p = position(j.at, q.data());
      push(tracks[n++].t, {p[0], p[1], p[2]});
    }
  }

  // ---- shapes: a box per body spanning its attachments, a box per link along x, one ball for the joints
  std::vector<Shape> shapes;
  std::size_t n = 0;
  auto body_box = [&](const std::string& name, const std::vector<Vec3>& local) {
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    for (const Vec3& s : local)
      for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], s[c]), hi[c] = std::max(hi[c], s[c]);
    for (int c = 0; c < 3; ++c) lo[c] -= w / 2, hi[c] += w / 2;
    tracks[n++].mesh = static_cast<int>(shapes.size());
    shapes.push_back(box(name, kBody, lo, hi));
  };
  for (const Frame2& f : scene.planar_bodies) {
    std::vector<Vec3> local;
    auto on = [&](const OutputPoint& p) {
      if (p.kind == OutputPointKind::kPlanarBodyPoint && same(p.body.x, f.x) && same(p.body.y, f.y) &&
          same(p.body.psi, f.psi))
        local.push_back({p.local_x, p.local_y, 0.0});
    };
    for (const SketchSegment& s : sketch.segments) on(s.from), on(s.to);
    for (const SketchJoint& j : sketch.joints) on(j.at);
    body_box(tracks[n].name, local);
  }
  for (const Frame3& f : scene.spatial_bodies) {
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
    for (const SketchSegment& s : sketch.segments) on(s.from), on(s.to);
    for (const SketchJoint& j : sketch.joints) on(j.at);
    body_box(tracks[n].name, local);
  }
  for (std::size_t k = 0; k < links.size(); ++k) {
    tracks[n].mesh = static_cast<int>(shapes.size());
    shapes.push_back(box(tracks[n].name, kLink, {0, -w / 2, -w / 2}, {length0[k], w / 2, w / 2}));
    const std::vector<float>& s = tracks[n].s;
    bool varies = false;
    for (std::size_t i = 0; i < s.size(); i += 3) varies = varies || s[i] != 1.0f;
    if (!varies) tracks[n].s.clear();  // a link of constant length: no scale channel
    ++n;
  }
  int balls[2] = {-1, -1};  // moving, fixed: made when first used (the validator notes unused objects)
  for (const SketchJoint& j : sketch.joints) {
    int& ball = balls[j.fixed ? 1 : 0];
    if (ball < 0) {
      ball = static_cast<int>(shapes.size());
      shapes.push_back(j.fixed ? sphere("fixed joint", kFixedJoint, 0.75 * w) : sphere("joint", kJoint, 0.75 * w));
    }
    tracks[n++].mesh = ball;
  }

  // ---- the glTF document and its buffer: geometry, indices, then the animation's keyframes
  nlohmann::json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", std::string("phiq ") + kVersion}, {"extras", {{"scene", title}}}};
  doc["accessors"] = doc["bufferViews"] = nlohmann::json::array();
  gltf::BufferBuilder buffer(doc);
  std::vector<std::array<int, 3>> prims;                     // position, normal, indices accessor of each shape
  buffer.begin_view(gltf::kArrayBuffer, 3 * sizeof(float));  // positions and normals: float VEC3 each
  for (const Shape& s : shapes)
    prims.push_back({buffer.add_floats(s.pos, 3, true), buffer.add_floats(s.nrm, 3, false), 0});
  buffer.begin_view(gltf::kElementArrayBuffer);
  for (std::size_t k = 0; k < shapes.size(); ++k) prims[k][2] = buffer.add_indices(shapes[k].idx);
  const double colours[4][3] = {{0.27, 0.45, 0.70}, {0.90, 0.50, 0.10}, {0.25, 0.25, 0.25}, {0.05, 0.05, 0.05}};
  const char* material_names[4] = {"body", "link", "joint", "fixed joint"};
  int materials[4] = {-1, -1, -1, -1};  // made when first used
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    int& m = materials[shapes[k].material];
    if (m < 0) {
      const double* c = colours[shapes[k].material];
      m = static_cast<int>(doc["materials"].size());
      doc["materials"].push_back(
          {{"name", material_names[shapes[k].material]},
           {"pbrMetallicRoughness",
            {{"baseColorFactor", {c[0], c[1], c[2], 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.6}}}});
    }
    doc["meshes"].push_back({{"name", shapes[k].name},
                             {"primitives",
                              {{{"attributes", {{"POSITION", prims[k][0]}, {"NORMAL", prims[k][1]}}},
                                {"indices", prims[k][2]},
                                {"material", m}}}}});
  }
  buffer.begin_view(0);
  const int input = buffer.add_floats(times, 1, true);
  nlohmann::json channels = nlohmann::json::array(), samplers = nlohmann::json::array();
  const bool moves = times.size() > 1;  // one row: a still pose, no animation
  for (std::size_t k = 0; k < tracks.size(); ++k) {
    const Track& tr = tracks[k];
    nlohmann::json node = {{"name", tr.name}, {"mesh", tr.mesh}};
    node["translation"] = {tr.t[0], tr.t[1], tr.t[2]};
    if (!tr.r.empty()) node["rotation"] = {tr.r[0], tr.r[1], tr.r[2], tr.r[3]};
    if (!tr.s.empty()) node["scale"] = {tr.s[0], tr.s[1], tr.s[2]};
    doc["nodes"].push_back(node);
    doc["scenes"][0]["nodes"].push_back(k);
    const bool fixed =
        k >= tracks.size() - sketch.joints.size() && sketch.joints[k - (tracks.size() - sketch.joints.size())].fixed;
    if (!moves || fixed) continue;
    auto channel = [&](const std::vector<float>& v, int components, const char* path) {
      if (v.empty()) return;
      samplers.push_back(
          {{"input", input}, {"output", buffer.add_floats(v, components, false)}, {"interpolation", "LINEAR"}});
      channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", k}, {"path", path}}}});
    };
    channel(tr.t, 3, "translation");
    channel(tr.r, 4, "rotation");
    channel(tr.s, 3, "scale");
  }
  doc["scenes"][0]["name"] = title;
  doc["scene"] = 0;
  if (!channels.empty()) doc["animations"] = {{{"name", title}, {"channels", channels}, {"samplers", samplers}}};
  const std::string bin = buffer.finish();
  if (bin.size() > (std::size_t{1} << 31))
    throw Error(result + ": the motion needs " + std::to_string(bin.size() >> 20) +
                " MiB of keyframes, more than a .glb holds (2 GiB here): write fewer rows");
  return gltf::glb_file(doc, bin);
}

}  // namespace phiq::tools
