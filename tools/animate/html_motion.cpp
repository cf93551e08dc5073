#include "html_motion.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "motion_columns.hpp"
#include "phiq/phiq.hpp"
#include "part_drawing.hpp"
#include "phiq/drawn_parts.hpp"
#include "plot_draw.hpp"
#include "plot_parts.hpp"

namespace phiq::tools {

namespace {

// Rows shown at most, whatever the budget: an hour at a frame per second more than any screen needs.
constexpr std::size_t kMostFrames = 3600;
// Samples of each traced point's path (its trail): a smooth curve at any zoom of a page.
constexpr std::size_t kTraceSamples = 4000;

// The bytes that tell two sketch points apart: the kind, the slots it reads and where it sits on its body. Two
// lines meeting at a joint name the same point, stored once.
std::string identity(const OutputPoint& p) {
  std::string k(1, static_cast<char>(p.kind));
  auto add = [&](const void* x, std::size_t n) { k.append(static_cast<const char*>(x), n); };
  for (const Slot& s : slots_of(p)) add(&s, sizeof(Slot));
  if (p.kind == OutputPointKind::kPlanarBodyPoint) add(&p.local_x, sizeof(double)), add(&p.local_y, sizeof(double));
  if (p.kind != OutputPointKind::kPlanarPoint && p.kind != OutputPointKind::kPlanarBodyPoint)
    add(&p.spatial.s, sizeof(p.spatial.s));
  return k;
}

// `most` rows of `n` evenly spread, the first and the last included.
std::vector<std::size_t> spread(std::size_t n, std::size_t most) {
  std::vector<std::size_t> rows;
  if (n <= most) {
    for (std::size_t r = 0; r < n; ++r) rows.push_back(r);
    return rows;
  }
  for (std::size_t k = 0; k < most; ++k) {
    const auto r = static_cast<std::size_t>(
        std::llround(static_cast<double>(k) * static_cast<double>(n - 1) / static_cast<double>(most - 1)));
    if (rows.empty() || rows.back() != r) rows.push_back(r);
  }
  return rows;
}

std::string base64(const std::string& bytes) {
  static const char* const a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k) v = (v << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? a[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

// Values as little-endian 16-bit integers: (x − lo) over [lo, hi] onto −32767 … 32767 (viewer.js: decode()).
class Quantizer {
 public:
  Quantizer(double lo, double hi) : lo_(lo), step_(hi > lo ? (hi - lo) / 65534.0 : 0.0) {}
  void put(double x, std::string& out) const {
    const double c = step_ > 0 ? std::round((x - lo_) / step_) - 32767.0 : -32767.0;
    const auto v = static_cast<std::uint16_t>(static_cast<std::int16_t>(std::clamp(c, -32767.0, 32767.0)));
    out += static_cast<char>(v & 0xff), out += static_cast<char>(v >> 8);
  }

 private:
  double lo_, step_;
};

// The letter of a joint's mark in the viewer's data: r(evolute), p(rismatic), s(pherical), o (a link's end).
char mark_letter(JointMark m) {
  switch (m) {
    case JointMark::kRevolute:
      return 'r';
    case JointMark::kPrismatic:
      return 'p';
    case JointMark::kSpherical:
      return 's';
    default:
      return 'o';
  }
}

// The paths of the points the scene traces, at `rows`, from their columns. Throws phiq::Error for a column missing
// or a value that is not a finite number.
std::vector<std::pair<std::string, std::vector<std::array<double, 3>>>> traced_paths(
    const Scene& scene, const CsvTable& table, const MotionColumns& columns, const std::string& result,
    const std::vector<std::size_t>& trace_rows) {
  std::map<std::string, std::size_t> col;
  for (std::size_t c = 0; c < table.columns.size(); ++c) col[table.columns[c]] = c;
  std::vector<std::pair<std::string, std::vector<std::array<double, 3>>>> out;
  for (const OutputPoint& p : scene.sweep.points) {
    std::vector<std::size_t> c;
    for (const char* axis : {"x", "y", "z"}) {
      if (axis[0] == 'z' && p.dimension() != 3) break;
      const auto it = col.find(p.name + "." + axis);
      if (it == col.end())
        throw Error(result + ": no column '" + p.name + "." + axis + "', a point that " + scene.path +
                    " traces: not a result of this scene");
      c.push_back(it->second);
    }
    std::vector<std::array<double, 3>> path;
    for (std::size_t r : trace_rows) {
      std::array<double, 3> x{0, 0, 0};
      for (std::size_t k = 0; k < c.size(); ++k) {
        x[k] = table.rows[r][c[k]];
        if (!std::isfinite(x[k]))
          throw Error(columns.at_row(r) + ", column '" + table.columns[c[k]] + "': not a finite number");
      }
      path.push_back(x);
    }
    out.emplace_back(p.name, std::move(path));
  }
  return out;
}

// Bytes of base64 a frame takes: the points' positions (and velocities), the parts' poses (7 int16 each).
std::size_t frame_bytes(std::size_t points, int dim, bool velocities, std::size_t parts) {
  return (points * static_cast<std::size_t>(dim) * 2 * (velocities ? 2 : 1) * 4 + parts * 7 * 2 * 4 + 2) / 3;
}

// The parts in the viewer's data (viewer.js documents the fields): each part's name, its shapes' names and geometry
// (the same shapes once whatever their names: 10⁴ alike links share one), its poses at the kept rows quantized as the
// points' are; and points bounding the parts at those rows, for the planar view's box.
nlohmann::json parts_data(const std::vector<Part>& parts, bool spatial, const MechanismFrames& frames,
                          std::vector<std::array<double, 3>>& bounds) {
  nlohmann::json names = nlohmann::json::array(), geometry_of = nlohmann::json::array();
  nlohmann::json shape_names = nlohmann::json::array();
  nlohmann::json geometries = nlohmann::json::array();
  std::map<std::string, int> known;
  std::string fixed;
  std::vector<PartBox> boxes;
  for (const Part& part : parts) {
    nlohmann::json g = nlohmann::json::array();
    for (const Shape& shape : part.shapes) {
      nlohmann::json one = {{"colour", hex_colour(shape_colour(part, shape))}};
      if (spatial) {
        const LitMesh lit = lit_mesh(shape_triangles(shape, kPartSegments));
        one["p"] = base64(std::string(reinterpret_cast<const char*>(lit.pos.data()), lit.pos.size() * sizeof(float)));
        one["i"] =
            base64(std::string(reinterpret_cast<const char*>(lit.idx.data()), lit.idx.size() * sizeof(std::uint32_t)));
      } else {
        nlohmann::json xy = nlohmann::json::array();
        for (const auto& [x, y] : shape_outline(shape)) xy.push_back(x), xy.push_back(y);
        one["outline"] = xy;
        if (shape.kind == ShapeKind::kCurve) one["width"] = 2 * shape.radius, one["closed"] = shape.closed;
      }
      g.push_back(one);
    }
    const auto [it, fresh] = known.emplace(g.dump(), static_cast<int>(geometries.size()));
    if (fresh) geometries.push_back(g);
    names.push_back(part.name), geometry_of.push_back(it->second);
    nlohmann::json mine = nlohmann::json::array();
    for (const Shape& shape : part.shapes) mine.push_back(shape.name);
    shape_names.push_back(mine);
    fixed += part.fixed ? '1' : '0';
    boxes.push_back(part_box(part));
  }
  // the poses: origin and quaternion (x, y, z, w; on the side of the previous frame's) of every part at every frame
  std::vector<std::array<double, 7>> poses;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t f = 0; f < frames.q.size(); ++f)
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const Pose p = part_pose(parts[k].frame, frames.q[f].data(), frames.t[f]);
      std::array<double, 4> r = quaternion(p.rotation);
      if (f > 0) {
        const auto& b = poses[poses.size() - parts.size()];
        if (r[0] * b[3] + r[1] * b[4] + r[2] * b[5] + r[3] * b[6] < 0)
          for (double& c : r) c = -c;
      }
      const double at[3] = {p.at.x, p.at.y, p.at.z};
      for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], at[c]), hi[c] = std::max(hi[c], at[c]);
      posed_bounds(boxes[k], p, bounds);
      poses.push_back({at[0], at[1], at[2], r[0], r[1], r[2], r[3]});
    }
  std::string bytes;
  const Quantizer axes[3] = {{lo[0], hi[0]}, {lo[1], hi[1]}, {lo[2], hi[2]}}, unit(-1.0, 1.0);
  for (const auto& p : poses)
    for (int c = 0; c < 7; ++c) (c < 3 ? axes[c] : unit).put(p[static_cast<std::size_t>(c)], bytes);
  nlohmann::json out = {{"names", names},           {"shapes", shape_names}, {"geometry", geometry_of},
                        {"geometries", geometries}, {"fixed", fixed},        {"poses", base64(bytes)}};
  out["lo"] = parts.empty() ? nlohmann::json::array() : nlohmann::json({lo[0], lo[1], lo[2]});
  out["hi"] = parts.empty() ? nlohmann::json::array() : nlohmann::json({hi[0], hi[1], hi[2]});
  return out;
}

}  // namespace

ViewerMotion viewer_motion(const Scene& scene, const MechanismSketch& sketch, const CsvTable& table,
                           const std::string& result, std::size_t budget) {
  const Model& model = *scene.model;
  const int dim = scene.dimension == 3 ? 3 : 2;
  ViewerMotion out;
  nlohmann::json& data = out.data;

  // ---- the distinct points of the sketch, and the lines and joints between them
  std::vector<const OutputPoint*> points;
  std::map<std::string, int> index;
  auto point = [&](const OutputPoint& p) {
    const auto [it, fresh] = index.emplace(identity(p), static_cast<int>(points.size()));
    if (fresh) points.push_back(&p);
    return it->second;
  };
  nlohmann::json links = nlohmann::json::array(), arms = nlohmann::json::array();
  for (const SketchSegment& s : sketch.segments) {
    nlohmann::json& to = s.line == SketchLine::kBar ? links : arms;
    to.push_back(point(s.from)), to.push_back(point(s.to));
  }
  // a joint away from every line (a pivot on ground, a cam's roller, a slider's block) is a point of its own, moved
  // with the others: without it a mechanism drawn by its joints alone would have nothing to animate
  for (const SketchJoint& j : sketch.joints) point(j.at);
  const std::vector<Part> parts = drawn_parts(scene);  // (once: a 10⁴-loop chain has 3·10⁴)
  const MotionColumns columns(scene, drawing_reads(sketch, parts), table, result);

  // ---- every row checked (a value that is not a number, t going back); the rows kept within the budget
  Eigen::VectorXd q = model.initial_positions(), qd = Eigen::VectorXd::Zero(model.num_coordinates());
  const std::size_t n_rows = table.rows.size(), t_col = columns.t_column();
  for (std::size_t r = 0; r < n_rows; ++r) {
    columns.positions(r, q);
    if (columns.has_velocities()) columns.velocities(r, qd);
    if (r > 0 && table.rows[r][t_col] < table.rows[r - 1][t_col])
      throw Error(columns.at_row(r) + ": t decreases (" + svg::label(table.rows[r][t_col]) + " after " +
                  svg::label(table.rows[r - 1][t_col]) + ")");
  }
  const bool velocities = columns.has_velocities() && !points.empty();
  const std::size_t per_frame = frame_bytes(points.size(), dim, velocities, parts.size());
  const std::size_t most = std::clamp<std::size_t>(per_frame ? budget / per_frame : kMostFrames, 2, kMostFrames);
  out.rows = spread(n_rows, most);

  // ---- the traced points: their columns, sampled
  const std::vector<std::size_t> trace_rows = spread(n_rows, kTraceSamples);
  out.frames.traces = traced_paths(scene, table, columns, result, trace_rows);
  if (points.empty() && out.frames.traces.empty() && parts.empty())
    throw Error(scene.path +
                ": nothing to animate (its constraints draw no line or joint: loops, drivers and "
                "equations draw none; output.points traces no point)");

  // ---- positions (and velocities) at the kept rows, and their extent
  std::vector<std::vector<PointMotion>> motion;
  out.frames.model = &model, out.frames.sketch = &sketch, out.frames.spatial = dim == 3;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, vmax = 0.0;
  auto extend = [&](const std::array<double, 3>& x) {
    for (int c = 0; c < 3; ++c)
      lo[c] = std::min(lo[c], x[static_cast<std::size_t>(c)]), hi[c] = std::max(hi[c], x[static_cast<std::size_t>(c)]);
  };
  for (std::size_t r : out.rows) {
    columns.positions(r, q);
    if (velocities) columns.velocities(r, qd);
    std::vector<PointMotion> m;
    for (const OutputPoint* p : points) {
      m.push_back(evaluate_point(*p, q.data(), velocities ? qd.data() : nullptr, nullptr));
      extend(m.back().r);
      vmax = std::max(vmax, std::hypot(m.back().v[0], m.back().v[1], m.back().v[2]));
    }
    motion.push_back(std::move(m));
    out.frames.q.push_back(q);
    out.frames.t.push_back(table.rows[r][t_col]);
  }
  for (const auto& tr : out.frames.traces)
    for (const auto& x : tr.second) extend(x);
  data["parts"] = parts_data(parts, dim == 3, out.frames, out.frames.part_bounds);
  for (const auto& x : out.frames.part_bounds) extend(x);

  // ---- the JSON: frames and velocities quantized, traces likewise, joints with their marks
  data["dimension"] = dim;
  data["rows"] = n_rows;
  data["kept"] = out.rows;
  data["t"] = out.frames.t;
  data["lo"] = nlohmann::json::array(), data["hi"] = nlohmann::json::array();
  for (int c = 0; c < dim; ++c) data["lo"].push_back(lo[c]), data["hi"].push_back(hi[c]);
  data["points"] = points.size();
  std::string moving;  // a character per point: compact for 10⁴ points
  for (const OutputPoint* p : points) {
    bool moves = false;
    for (const Slot& s : slots_of(*p)) moves = moves || s.is_coordinate();
    moving += moves ? '1' : '0';
  }
  data["moving"] = moving;
  data["links"] = links, data["arms"] = arms;
  std::string bytes, vbytes;
  std::vector<Quantizer> axis;
  for (int c = 0; c < dim; ++c) axis.emplace_back(lo[c], hi[c]);
  const Quantizer rate(-vmax, vmax);
  for (const auto& m : motion)
    for (const PointMotion& p : m)
      for (int c = 0; c < dim; ++c) {
        axis[static_cast<std::size_t>(c)].put(p.r[static_cast<std::size_t>(c)], bytes);
        if (velocities) rate.put(p.v[static_cast<std::size_t>(c)], vbytes);
      }
  data["frames"] = base64(bytes);
  data["velocities"] = velocities ? nlohmann::json(base64(vbytes)) : nlohmann::json();
  data["vmax"] = vmax;
  // joints as parallel columns (a 10⁴-loop chain has 3·10⁴ of them): point, mark, fixed; prismatic pairs apart
  nlohmann::json joint_points = nlohmann::json::array(), prismatic = nlohmann::json::array();
  std::string marks, fixed;
  for (std::size_t k = 0; k < sketch.joints.size(); ++k) {
    const SketchJoint& j = sketch.joints[k];
    joint_points.push_back(point(j.at));
    marks += mark_letter(j.mark), fixed += j.fixed ? '1' : '0';
    if (j.mark == JointMark::kPrismatic && dim == 2) {
      // the block along its guide: the guide frame's angle plus the axis's, at every kept row when it turns
      nlohmann::json o = {{"joint", k}};
      const double axis_angle = std::atan2(j.axis.y, j.axis.x);
      if (j.guide.psi.is_coordinate()) {
        nlohmann::json a = nlohmann::json::array();
        for (const Eigen::VectorXd& qk : out.frames.q) a.push_back(j.guide.psi.of(qk.data()) + axis_angle);
        o["angles"] = a;
      } else {
        o["angle"] = j.guide.psi.of(q.data()) + axis_angle;
      }
      o["ground_guide"] = !j.guide.psi.is_coordinate() && !j.guide.x.is_coordinate() && !j.guide.y.is_coordinate();
      prismatic.push_back(o);
    }
  }
  data["joints"] = {{"p", joint_points}, {"marks", marks}, {"fixed", fixed}};
  data["prismatic"] = prismatic;
  nlohmann::json traces = nlohmann::json::array();
  std::vector<double> trace_t;
  for (std::size_t r : trace_rows) trace_t.push_back(table.rows[r][t_col]);
  for (std::size_t k = 0; k < out.frames.traces.size(); ++k) {
    std::string b;
    for (const auto& x : out.frames.traces[k].second)
      for (int c = 0; c < dim; ++c) axis[static_cast<std::size_t>(c)].put(x[static_cast<std::size_t>(c)], b);
    traces.push_back({{"name", out.frames.traces[k].first}, {"colour", svg::kPalette[k % 8]}, {"data", base64(b)}});
  }
  data["trace_t"] = traces.empty() ? nlohmann::json::array() : nlohmann::json(trace_t);
  data["traces"] = traces;
  return out;
}

}  // namespace phiq::tools
