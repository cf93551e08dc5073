#include "plot_parts.hpp"

#include <algorithm>
#include <cmath>

#include "part_drawing.hpp"
#include "phiq/shapes.hpp"
#include "plot_draw.hpp"

namespace phiq::tools {

namespace {

using P3 = std::array<double, 3>;
using P2 = std::pair<double, double>;

P3 world(const Pose& pose, const kin3::V3& v) {
  const kin3::V3 w = pose.apply(v);
  return {w.x, w.y, w.z};
}

// The convex hull of `pts`, counter-clockwise (Andrew's monotone chain).
std::vector<P2> hull(std::vector<P2> pts) {
  std::sort(pts.begin(), pts.end());
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  std::vector<P2> h(2 * pts.size());
  std::size_t k = 0;
  auto cross = [](const P2& o, const P2& a, const P2& b) {
    return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
  };
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], pts[i - 1]) <= 0) --k;
    h[k++] = pts[i - 1];
  }
  h.resize(k - 1);
  return h;
}

std::string path_of(const std::vector<P2>& pts, bool closed) {
  std::string d;
  for (std::size_t i = 0; i < pts.size(); ++i)
    d += (i ? "L" : "M") + svg::px(pts[i].first) + " " + svg::px(pts[i].second);
  return closed ? d + "Z" : d;
}

}  // namespace

std::vector<std::array<double, 2>> shape_outline(const Shape& shape) {
  std::vector<std::array<double, 2>> out;
  const auto& r = shape.rotation;
  auto place = [&](double x, double y, double z) {
    out.push_back({shape.at.x + r[0] * x + r[1] * y + r[2] * z, shape.at.y + r[3] * x + r[4] * y + r[5] * z});
  };
  if (shape.kind == ShapeKind::kCurve) {
    for (const kin3::V3& p : shape.points) place(p.x, p.y, p.z);
  } else if (shape.kind == ShapeKind::kPolygon) {
    for (const auto& [x, y] : shape.outline) place(x, y, 0.0);
  } else {
    std::vector<P2> pts;
    for (const kin3::V3& v : shape_triangles(shape, kPartSegments).vertices) pts.emplace_back(v.x, v.y);
    for (const P2& p : hull(std::move(pts))) out.push_back({p.first, p.second});
  }
  return out;
}

namespace {

// One shape seen along z, as shape_outline() gives it.
std::string planar_shape(const Part& part, const Shape& shape, const Pose& pose, const ScreenOf& screen,
                         double pixels_per_metre) {
  const std::string colour = hex_colour(shape_colour(part, shape));
  std::vector<P2> pts;
  for (const auto& [x, y] : shape_outline(shape)) pts.push_back(screen(world(pose, {x, y, 0.0})));
  const std::string head = "<path class=\"part\" data-part=\"" + svg::escape(part.name) + "\" data-shape=\"" +
                           svg::escape(shape.name) + "\" d=\"";
  if (shape.kind == ShapeKind::kCurve)  // `radius` is half its width
    return head + path_of(pts, shape.closed) + "\" fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"" +
           svg::px(std::max(1.0, 2 * shape.radius * pixels_per_metre)) + "\" stroke-linejoin=\"round\"/>\n";
  return head + path_of(pts, true) + "\" fill=\"" + colour + "\" fill-opacity=\"0.55\" stroke=\"" + colour +
         "\" stroke-width=\"1\"/>\n";
}

// A part's facing triangles in the isometric view, with their depth along the view (far first when sorted).
struct Facet {
  double depth;
  std::string path;
};
void spatial_facets(const Part& part, const Pose& pose, const ScreenOf& screen, std::vector<Facet>& out) {
  const std::string tag = "<path data-part=\"" + svg::escape(part.name) + "\" d=\"";
  const double view[3] = {1 / std::sqrt(3.0), 1 / std::sqrt(3.0), 1 / std::sqrt(3.0)};  // towards the eye
  const double light[3] = {0.33, 0.17, 0.93};
  for (const Shape& shape : part.shapes) {
    const std::array<double, 4> c = shape_colour(part, shape);
    const TriangleMesh mesh = shape_triangles(shape, 16);
    for (const auto& tri : mesh.triangles) {
      P3 p[3];
      for (int k = 0; k < 3; ++k) p[k] = world(pose, mesh.vertices[static_cast<std::size_t>(tri[k])]);
      const double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
      const double w[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
      double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (!(len > 0) || n[0] * view[0] + n[1] * view[1] + n[2] * view[2] <= 0) continue;  // edge-on or turned away
      for (double& x : n) x /= len;
      const double shade = 0.55 + 0.45 * std::max(0.0, n[0] * light[0] + n[1] * light[1] + n[2] * light[2]);
      const std::string colour = hex_colour({shade * c[0], shade * c[1], shade * c[2], 1.0});
      double depth = 0;
      for (const P3& x : p) depth += x[0] + x[1] + x[2];
      out.push_back({depth, tag + path_of({screen(p[0]), screen(p[1]), screen(p[2])}, true) + "\" fill=\"" + colour +
                                "\" stroke=\"" + colour + "\" stroke-width=\"0.5\"/>\n"});
    }
  }
}

}  // namespace

std::string parts_svg(const std::vector<Part>& parts, const Eigen::VectorXd& q, double t, bool spatial,
                      const ScreenOf& screen, double pixels_per_metre, double opacity) {
  if (parts.empty()) return "";
  std::string s = "<g class=\"parts\"" + (opacity < 1 ? " opacity=\"" + svg::px(opacity) + "\"" : "") + ">\n";
  if (!spatial) {
    for (const Part& part : parts) {
      const Pose pose = part_pose(part.frame, q.data(), t);
      for (const Shape& shape : part.shapes) s += planar_shape(part, shape, pose, screen, pixels_per_metre);
    }
    return s + "</g>\n";
  }
  std::vector<Facet> facets;  // of every part: one order for all, as they hide each other
  for (const Part& part : parts) spatial_facets(part, part_pose(part.frame, q.data(), t), screen, facets);
  std::stable_sort(facets.begin(), facets.end(), [](const Facet& a, const Facet& b) { return a.depth < b.depth; });
  for (const Facet& f : facets) s += f.path;
  return s + "</g>\n";
}

std::vector<std::array<double, 3>> parts_extent(const std::vector<Part>& parts, const std::vector<PartBox>& boxes,
                                                const Eigen::VectorXd& q, double t) {
  std::vector<std::array<double, 3>> out;
  for (std::size_t k = 0; k < parts.size(); ++k) posed_bounds(boxes[k], part_pose(parts[k].frame, q.data(), t), out);
  return out;
}

}  // namespace phiq::tools
