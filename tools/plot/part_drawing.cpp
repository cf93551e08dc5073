#include "part_drawing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "phiq/shapes.hpp"

namespace phiq::tools {

namespace {

void add_frame(std::vector<Slot>& read, const Attachment3& a) {
  read.insert(read.end(), {a.r[0], a.r[1], a.r[2], a.p[0], a.p[1], a.p[2], a.p[3]});
}

}  // namespace

std::vector<Slot> part_reads(const std::vector<Part>& parts) {
  std::vector<Slot> read;
  for (const Part& part : parts) {
    const PartFrame& f = part.frame;
    switch (f.kind) {
      case PartFrameKind::kPlanarBody:
        read.insert(read.end(), {f.planar.x, f.planar.y, f.planar.psi});
        break;
      case PartFrameKind::kSpatialBody:
        read.insert(read.end(),
                    {f.spatial.x, f.spatial.y, f.spatial.z, f.spatial.e0, f.spatial.e1, f.spatial.e2, f.spatial.e3});
        break;
      case PartFrameKind::kPoints:
        add_frame(read, f.origin), add_frame(read, f.x_toward), add_frame(read, f.y_toward);
        break;
      case PartFrameKind::kExpressions: {
        std::vector<const CompiledExpression*> all;
        for (const auto& e : f.at) all.push_back(e.get());
        all.push_back(f.angle.get());
        for (const CompiledExpression* e : all)
          if (e)
            for (Index j : e->coordinates()) read.push_back(Slot::coordinate(j));
        break;
      }
    }
  }
  return read;
}

LitMesh lit_mesh(const TriangleMesh& mesh) {
  using V = kin3::V3;
  const std::size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  std::vector<V> face(nt);  // area-weighted normals: (b − a) × (c − a)
  std::vector<std::vector<std::size_t>> around(nv);
  for (std::size_t f = 0; f < nt; ++f) {
    const auto& t = mesh.triangles[f];
    const V &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const V u{b.x - a.x, b.y - a.y, b.z - a.z}, w{c.x - a.x, c.y - a.y, c.z - a.z};
    face[f] = {u.y * w.z - u.z * w.y, u.z * w.x - u.x * w.z, u.x * w.y - u.y * w.x};
    for (int k = 0; k < 3; ++k) around[static_cast<std::size_t>(t[k])].push_back(f);
  }
  auto unit = [](const V& v) {
    const double n = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return n > 0 ? V{v.x / n, v.y / n, v.z / n} : V{0, 0, 0};
  };
  const double crease = std::cos(40.0 * M_PI / 180.0);
  LitMesh out;
  // per vertex, its faces in clusters: a face joins the first cluster whose first face is within the crease angle
  std::vector<std::vector<std::pair<std::size_t, std::uint32_t>>> corner_vertex(nv);  // (face, output vertex)
  for (std::size_t v = 0; v < nv; ++v) {
    std::vector<std::pair<V, V>> clusters;  // (first face's unit normal, sum of normals)
    std::vector<std::size_t> cluster_of;
    for (std::size_t f : around[v]) {
      const V n = unit(face[f]);
      std::size_t c = 0;
      while (c < clusters.size() &&
             n.x * clusters[c].first.x + n.y * clusters[c].first.y + n.z * clusters[c].first.z < crease)
        ++c;
      if (c == clusters.size()) clusters.push_back({n, {0, 0, 0}});
      V& s = clusters[c].second;
      s = {s.x + face[f].x, s.y + face[f].y, s.z + face[f].z};
      cluster_of.push_back(c);
    }
    const auto first = static_cast<std::uint32_t>(out.pos.size() / 3);
    for (const auto& [seed, sum] : clusters) {
      V n = unit(sum);
      if (n.x == 0 && n.y == 0 && n.z == 0) n = seed;
      const V& p = mesh.vertices[v];
      out.pos.insert(out.pos.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
      out.nrm.insert(out.nrm.end(), {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)});
    }
    for (std::size_t k = 0; k < around[v].size(); ++k)
      corner_vertex[v].emplace_back(around[v][k], first + static_cast<std::uint32_t>(cluster_of[k]));
  }
  for (std::size_t f = 0; f < nt; ++f)
    for (int k = 0; k < 3; ++k) {
      const auto& list = corner_vertex[static_cast<std::size_t>(mesh.triangles[f][k])];
      const auto it = std::find_if(list.begin(), list.end(), [&](const auto& e) { return e.first == f; });
      out.idx.push_back(it->second);
    }
  return out;
}

std::array<double, 4> shape_colour(const Part& part, const Shape& shape) {
  if (shape.colour) return *shape.colour;
  if (part.colour) return *part.colour;
  return part.derived ? std::array<double, 4>{0.72, 0.72, 0.72, 1.0} : std::array<double, 4>{0.27, 0.45, 0.70, 1.0};
}

std::string hex_colour(const std::array<double, 4>& c) {
  char s[8];
  auto byte = [](double v) { return static_cast<int>(std::lround(255.0 * std::clamp(v, 0.0, 1.0))); };
  std::snprintf(s, sizeof s, "#%02x%02x%02x", byte(c[0]), byte(c[1]), byte(c[2]));
  return s;
}

std::array<double, 4> quaternion(const RotationMatrix& r) {
  // r row-major: r[3 i + j] = R_ij
  const double tr = r[0] + r[4] + r[8];
  std::array<double, 4> q;  // x, y, z, w
  if (tr >= r[0] && tr >= r[4] && tr >= r[8]) {
    const double s = 2.0 * std::sqrt(1.0 + tr);
    q = {(r[7] - r[5]) / s, (r[2] - r[6]) / s, (r[3] - r[1]) / s, 0.25 * s};
  } else if (r[0] >= r[4] && r[0] >= r[8]) {
    const double s = 2.0 * std::sqrt(1.0 + r[0] - r[4] - r[8]);
    q = {0.25 * s, (r[1] + r[3]) / s, (r[2] + r[6]) / s, (r[7] - r[5]) / s};
  } else if (r[4] >= r[8]) {
    const double s = 2.0 * std::sqrt(1.0 + r[4] - r[0] - r[8]);
    q = {(r[1] + r[3]) / s, 0.25 * s, (r[5] + r[7]) / s, (r[2] - r[6]) / s};
  } else {
    const double s = 2.0 * std::sqrt(1.0 + r[8] - r[0] - r[4]);
    q = {(r[2] + r[6]) / s, (r[5] + r[7]) / s, 0.25 * s, (r[3] - r[1]) / s};
  }
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double sign = q[3] < 0 ? -1.0 : 1.0;
  for (double& c : q) c *= sign / n;
  return q;
}

PartBox part_box(const Part& part) {
  PartBox box{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, 0.0};
  for (const Shape& s : part.shapes)
    for (const kin3::V3& v : shape_triangles(s, 8).vertices) {
      box.lo = {std::min(box.lo.x, v.x), std::min(box.lo.y, v.y), std::min(box.lo.z, v.z)};
      box.hi = {std::max(box.hi.x, v.x), std::max(box.hi.y, v.y), std::max(box.hi.z, v.z)};
      box.reach = std::max(box.reach, std::hypot(v.x, v.y, v.z));
    }
  if (box.lo.x > box.hi.x) box = {};
  return box;
}

void posed_bounds(const PartBox& box, const Pose& pose, std::vector<std::array<double, 3>>& out) {
  std::array<double, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (int k = 0; k < 8; ++k) {
    const kin3::V3 x =
        pose.apply({k & 1 ? box.hi.x : box.lo.x, k & 2 ? box.hi.y : box.lo.y, k & 4 ? box.hi.z : box.lo.z});
    const double c[3] = {x.x, x.y, x.z};
    for (std::size_t a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
  }
  const double at[3] = {pose.at.x, pose.at.y, pose.at.z};
  for (std::size_t a = 0; a < 3; ++a)
    lo[a] = std::max(lo[a], at[a] - box.reach), hi[a] = std::min(hi[a], at[a] + box.reach);
  out.push_back(lo), out.push_back(hi);
}

}  // namespace phiq::tools
