#include "plot_mechanism.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "phiq/phiq.hpp"
#include "plot_draw.hpp"
#include "part_drawing.hpp"
#include "phiq/drawn_parts.hpp"
#include "plot_parts.hpp"

namespace phiq::tools {

namespace {

using namespace svg;
using P3 = std::array<double, 3>;

P3 at(const OutputPoint& p, const Eigen::VectorXd& q) {
  const PointMotion m = evaluate_point(p, q.data(), nullptr, nullptr);
  return {m.r[0], m.r[1], m.r[2]};
}

std::string grey(std::size_t f, std::size_t n) {
  const int g = n == 1 ? 0 : static_cast<int>(190 - 190.0 * static_cast<double>(f) / static_cast<double>(n - 1));
  char c[16];
  std::snprintf(c, sizeof c, "#%02x%02x%02x", g, g, g);
  return c;
}

// Ground under a fixed pivot at pixel (x, y): a triangle down to a base line, hatched beneath (a group with an id:
// a drawing that others use).
std::string ground_pivot(double x, double y, const std::string& id = "") {
  std::string s = "<g class=\"ground\"" + (id.empty() ? "" : " id=\"" + id + "\"") + ">\n<polygon points=\"" + px(x) +
                  "," + px(y) + " " + px(x - 8) + "," + px(y + 12) + " " + px(x + 8) + "," + px(y + 12) +
                  "\" fill=\"white\" stroke=\"black\"/>\n";
  s += "<line x1=\"" + px(x - 13) + "\" x2=\"" + px(x + 13) + "\" y1=\"" + px(y + 12) + "\" y2=\"" + px(y + 12) +
       "\" stroke=\"black\"/>\n";
  for (int k = 0; k < 6; ++k) {
    const double hx = x - 13 + 5.0 * k;
    s += "<line class=\"hatch\" x1=\"" + px(hx) + "\" x2=\"" + px(hx - 5) + "\" y1=\"" + px(y + 12) + "\" y2=\"" +
         px(y + 18) + "\" stroke=\"black\"/>\n";
  }
  return s + "</g>\n";
}

}  // namespace

std::vector<Slot> slots_of(const OutputPoint& p) {
  switch (p.kind) {
    case OutputPointKind::kPlanarPoint:
      return {p.point.x, p.point.y};
    case OutputPointKind::kPlanarBodyPoint:
      return {p.body.x, p.body.y, p.body.psi};
    default: {
      const Attachment3& a = p.spatial;
      return {a.r[0], a.r[1], a.r[2], a.p[0], a.p[1], a.p[2], a.p[3]};
    }
  }
}

std::vector<Slot> sketch_reads(const MechanismSketch& sketch) {
  std::vector<Slot> read;
  for (const SketchSegment& s : sketch.segments)
    for (const OutputPoint* p : {&s.from, &s.to})
      for (const Slot& x : slots_of(*p)) read.push_back(x);
  for (const SketchJoint& j : sketch.joints) {
    for (const Slot& x : slots_of(j.at)) read.push_back(x);
    for (const Slot& x : {j.guide.x, j.guide.y, j.guide.psi}) read.push_back(x);  // a prismatic block's angle
  }
  return read;
}

std::vector<Slot> drawing_reads(const MechanismSketch& sketch, const std::vector<Part>& parts) {
  std::vector<Slot> read = sketch_reads(sketch);
  for (const Slot& x : part_reads(parts)) read.push_back(x);
  return read;
}

std::pair<double, double> project(const P3& p, bool spatial) {
  if (!spatial) return {p[0], p[1]};
  // seen from (1, 1, 1): screen right is (y − x)/√2 and up the rest of z; x − y instead mirrors the picture
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  return {c * (p[1] - p[0]), p[2] - s * (p[0] + p[1])};
}

MechanismView mechanism_view(const MechanismFrames& m, double x0, double y0, double side) {
  const MechanismSketch& sk = *m.sketch;
  // the extent of everything drawn, on screen axes
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  auto extend = [&](const P3& p) {
    const auto [u, v] = project(p, m.spatial);
    if (!std::isfinite(u) || !std::isfinite(v)) return;
    xmin = std::min(xmin, u), xmax = std::max(xmax, u), ymin = std::min(ymin, v), ymax = std::max(ymax, v);
  };
  for (const Eigen::VectorXd& q : m.q) {
    for (const SketchSegment& s : sk.segments) extend(at(s.from, q)), extend(at(s.to, q));
    for (const SketchJoint& j : sk.joints) extend(at(j.at, q));
  }
  for (const auto& tr : m.traces)
    for (const P3& p : tr.second) extend(p);
  for (const P3& p : m.part_bounds) extend(p);
  if (!(xmax >= xmin)) xmin = -1, xmax = 1, ymin = -1, ymax = 1;  // nothing to draw
  // in space, the axes from the origin: a round length, at most 0.3 of the drawing, inside the panel with their names
  double len = 0.0;
  if (m.spatial) {
    const double most = 0.3 * std::max(xmax - xmin, ymax - ymin), mag = std::pow(10.0, std::floor(std::log10(most)));
    len = most >= 5 * mag ? 5 * mag : (most >= 2 * mag ? 2 * mag : mag);
    extend({0, 0, 0}), extend({1.3 * len, 0, 0}), extend({0, 1.3 * len, 0}), extend({0, 0, 1.3 * len});
  }
  widen(xmin, xmax), widen(ymin, ymax);
  const double span = std::max(xmax - xmin, ymax - ymin), cx = 0.5 * (xmin + xmax), cy = 0.5 * (ymin + ymax);
  // room below for the ground symbols: 10 % more span, the centre lifted
  return {{x0, y0, side, side, cx - 0.55 * span, cx + 0.55 * span, cy - 0.6 * span, cy + 0.5 * span}, len};
}

std::string mechanism_background(const MechanismFrames& m, const MechanismView& view, GroundPivots pivots) {
  const MechanismSketch& sk = *m.sketch;
  const Box& b = view.box;
  const double x0 = b.x0, y0 = b.y0, side = b.w, len = view.axis_length;
  auto screen = [&](const P3& p) {
    const auto [u, v] = project(p, m.spatial);
    return std::pair<double, double>{b.sx(u), b.sy(v)};
  };
  std::string s;
  if (m.spatial) {  // projected axes carry no scale: a frame, the three axes from the origin, and a scale bar
    s += "<rect class=\"frame\" x=\"" + px(x0) + "\" y=\"" + px(y0) + "\" width=\"" + px(side) + "\" height=\"" +
         px(side) + "\" fill=\"none\" stroke=\"#888\"/>\n";
    const auto o = screen({0, 0, 0});
    const char* names[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      P3 e{0, 0, 0};
      e[static_cast<std::size_t>(a)] = len;
      const auto p = screen(e);
      s += "<line class=\"axis3d\" data-axis=\"" + std::string(names[a]) + "\" x1=\"" + px(o.first) + "\" y1=\"" +
           px(o.second) + "\" x2=\"" + px(p.first) + "\" y2=\"" + px(p.second) +
           "\" stroke=\"#999\" stroke-dasharray=\"4,3\"/>\n<text class=\"axis-label\" x=\"" + px(p.first + 4) +
           "\" y=\"" + px(p.second - 4) + "\" fill=\"#666\">" + names[a] + " (m)</text>\n";
    }
    const double bar = b.sx(b.xmin + len) - b.sx(b.xmin);
    s += "<line class=\"scale\" x1=\"" + px(x0 + 10) + "\" x2=\"" + px(x0 + 10 + bar) + "\" y1=\"" +
         px(y0 + side + 18) + "\" y2=\"" + px(y0 + side + 18) +
         "\" stroke=\"black\" stroke-width=\"2\"/>\n<text "
         "class=\"scale-label\" x=\"" +
         px(x0 + 16 + bar) + "\" y=\"" + px(y0 + side + 22) + "\">" + label(len) + " m (axes: " + label(len) +
         " m each)</text>\n";
  } else {
    s += axes(b, "x (m)", "y (m)", 6, 6);
  }
  // ground: fixed pivots and fixed link ends, once (as uses of one drawing: a line of 10⁴ pivots stays small)
  const Eigen::VectorXd& q0 = m.q.front();
  if (pivots == GroundPivots::kUses) s += "<defs>" + ground_pivot(0, 0, "ground-pivot") + "</defs>\n";
  std::set<std::pair<long, long>> used;  // kUses: the 2-pixel cells holding a pivot already
  for (const SketchJoint& j : sk.joints)
    if (j.fixed && j.mark != JointMark::kPrismatic) {
      const auto [x, y] = screen(at(j.at, q0));
      if (pivots == GroundPivots::kUses && !used.emplace(std::lround(x / 2), std::lround(y / 2)).second) continue;
      s += pivots == GroundPivots::kUses
               ? "<use class=\"ground\" href=\"#ground-pivot\" x=\"" + px(x) + "\" y=\"" + px(y) + "\"/>\n"
               : ground_pivot(x, y);
    }
  return s;
}

std::string mechanism_panel(const MechanismFrames& m, double x0, double y0, double side) {
  const MechanismSketch& sk = *m.sketch;
  const MechanismView view = mechanism_view(m, x0, y0, side);
  const Box& b = view.box;
  auto screen = [&](const P3& p) {
    const auto [u, v] = project(p, m.spatial);
    return std::pair<double, double>{b.sx(u), b.sy(v)};
  };

  std::string s = "<g id=\"mechanism\">\n<text x=\"" + px(x0) + "\" y=\"" + px(y0 - 12) + "\">mechanism at " +
                  std::to_string(m.q.size()) + " rows (light: first, dark: last)" +
                  (m.traces.empty() ? "" : ", traced points") + (m.spatial ? ", isometric view" : "") + "</text>\n";
  s += mechanism_background(m, view);
  for (std::size_t f = 0; f < m.q.size(); ++f) {
    const Eigen::VectorXd& q = m.q[f];
    const std::string colour = grey(f, m.q.size());
    s += "<g class=\"position\" data-t=\"" + label(m.t[f]) + "\">\n";
    const double n = static_cast<double>(m.q.size());
    s += parts_svg(m.parts, q, m.t[f], m.spatial, screen, b.w / (b.xmax - b.xmin),
                   f + 1 == m.q.size() ? 1.0 : 0.25 + 0.5 * static_cast<double>(f) / std::max(1.0, n - 1));
    for (const SketchSegment& seg : sk.segments) {
      const auto a = screen(at(seg.from, q)), c = screen(at(seg.to, q));
      s += polyline("mechanism", colour, 2, {a, c});
    }
    for (const SketchJoint& j : sk.joints) {
      if (j.fixed && f + 1 != m.q.size()) continue;  // it does not move: drawn once, dark
      const auto [x, y] = screen(at(j.at, q));
      if (j.mark == JointMark::kPrismatic) {
        // the block along its guide's direction (the guide frame's angle plus the axis's), and the guide through it
        const double psi = j.guide.psi.of(q.data()), ang = psi + std::atan2(j.axis.y, j.axis.x);
        const double deg = -ang * 180 / M_PI, ux = std::cos(ang), uy = -std::sin(ang);
        s += "<line class=\"guide\" x1=\"" + px(x - 26 * ux) + "\" y1=\"" + px(y - 26 * uy) + "\" x2=\"" +
             px(x + 26 * ux) + "\" y2=\"" + px(y + 26 * uy) + "\" stroke=\"" + colour + "\" stroke-width=\"1\"/>\n";
        s += "<rect class=\"joint prismatic\" x=\"" + px(x - 9) + "\" y=\"" + px(y - 5) +
             "\" width=\"18\" height=\"10\" transform=\"rotate(" + px(deg) + " " + px(x) + " " + px(y) +
             ")\" fill=\"white\" stroke=\"" + colour + "\" stroke-width=\"1.5\"/>\n";
        if (!j.guide.psi.is_coordinate() && !j.guide.x.is_coordinate() && !j.guide.y.is_coordinate())
          for (int k = -2; k <= 2; ++k) {  // a guide on ground: hatched below it
            const double hx = x + 10 * k * ux, hy = y + 10 * k * uy;
            s += "<line class=\"hatch\" x1=\"" + px(hx + 7 * uy) + "\" y1=\"" + px(hy - 7 * ux) + "\" x2=\"" +
                 px(hx + 7 * uy - 5 * ux) + "\" y2=\"" + px(hy - 7 * ux - 5 * uy) + "\" stroke=\"" + colour + "\"/>\n";
          }
      } else if (j.mark == JointMark::kPoint) {
        s += "<circle class=\"joint point\" cx=\"" + px(x) + "\" cy=\"" + px(y) + "\" r=\"2.5\" fill=\"" + colour +
             "\"/>\n";
      } else {
        const bool ball = j.mark == JointMark::kSpherical;
        s += std::string("<circle class=\"joint ") + (ball ? "spherical" : "revolute") + "\" cx=\"" + px(x) +
             "\" cy=\"" + px(y) + "\" r=\"4\" fill=\"" + (ball ? colour : std::string("white")) + "\" stroke=\"" +
             colour + "\" stroke-width=\"1.5\"/>\n";
      }
    }
    s += "</g>\n";
  }
  for (std::size_t k = 0; k < m.traces.size(); ++k) {
    Line pts;
    for (const P3& p : m.traces[k].second)
      if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) pts.push_back(screen(p));
    s += polyline("trace", kPalette[k % 8], 1.5, pts, " data-point=\"" + escape(m.traces[k].first) + "\"");
    s += "<text class=\"legend\" x=\"" + px(x0 + 6) + "\" y=\"" + px(y0 + 16 + 14 * static_cast<double>(k)) +
         "\" fill=\"" + kPalette[k % 8] + "\">" + escape(m.traces[k].first) + "</text>\n";
  }
  return s + "</g>\n";
}

}  // namespace phiq::tools
