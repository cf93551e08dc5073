// An asmt::Assembly written as a phiq scene (models/README.md): parts as bodies, markers as the sides of spatial
// joints, motions as joint drivers. Joints whose rows are direction cosines or displacements between markers that
// no spatial kind states directly are written with natural points pinned to the parts' markers (each a `spherical`
// to its body) and `dot`, `segment_angle`, `rotation_angle`, `coupler` and `equation` rows over them: the same
// equations as OndselSolver's, not an approximation of them.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>
#include <sstream>

#include "import/asmt_model.hpp"
#include "import/scene_text.hpp"
#include "phiq/expression.hpp"
#include "phiq/text.hpp"

namespace phiq::detail::asmt {

namespace {

// A marker found by its path: the body it is fixed in ("ground" for the assembly's), its pose there and in the world.
struct Where {
  std::string body;
  Pose local, world;
};

class SceneWriter {
 public:
  SceneWriter(Assembly& a, const ImportOptions& o) : a_(a), o_(o) {}
  std::string write();

 private:
  Where marker(const std::string& path, int line) const;
  std::string side(const Where& w, double z_offset = 0.0) const {
    const Eigen::Vector3d at = w.local.p + z_offset * w.local.R.col(2);
    return "{body: " + w.body + ", at: " + scene_vector(at) + ", axis: " + scene_vector(w.local.R.col(2)) +
           ", ref: " + scene_vector(w.local.R.col(0)) + "}";
  }
  std::string axis(const Where& w) const {
    return "{body: " + w.body + ", axis: " + scene_vector(w.local.R.col(2)) +
           ", ref: " + scene_vector(w.local.R.col(0)) + "}";
  }
  // A natural point at the marker's origin plus `offset` (in the marker's axes), pinned to its body; on the ground,
  // a point of constants. Returns its name; coords[i] is what an expression writes for its component i.
  std::string point(const std::string& base, const Where& w, const Eigen::Vector3d& offset,
                    std::array<std::string, 3>* coords = nullptr);
  std::string segment(const std::string& base, const Where& w, int k) {
    return "[" + point(base + "_o", w, Eigen::Vector3d::Zero()) + ", " +
           point(base + "_" + "xyz"[k], w, Eigen::Vector3d::Unit(k)) + "]";
  }
  void dot(const std::string& name, const std::string& a, const std::string& b, double value) {
    constraints_ << "  - {name: " << names_.make(name) << ", type: dot, directions: [" << a << ", " << b
                 << "], value: " << scene_number(value) << "}\n";
  }
  double value(const Joint& j, const std::string& key, double fallback, bool required = false) const;
  void joint(const Joint& j);
  void gear(const Joint& j, const std::string& name, const Where& wi, const Where& wj);
  void radial_distance(const Joint& j, const std::string& name, const Where& wi, const Where& wj);
  void travel_and_turn(const std::string& name, const Where& wi, const Where& wj, int axis_k, double per_turn);
  void motion(const Motion& m);
  void general_motion(const Motion& m);
  std::string time_grid() const;
  std::string parts_and_mass();

  Assembly& a_;
  const ImportOptions& o_;
  SceneNames names_;
  std::map<std::string, std::string> body_of_part_;
  std::map<std::string, std::pair<std::string, std::string>> joints_;  // file name → phiq name, type
  std::map<std::string, std::string> points_;                          // point base → phiq name
  std::ostringstream coordinates_, points_text_, constraints_, drivers_;
};

Where SceneWriter::marker(const std::string& path, int line) const {
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string s; std::getline(ss, s, '/');) parts.push_back(s);
  if (parts.size() < 3 || parts.size() > 4 || !parts[0].empty() || parts[1] != a_.name)
    refuse(a_.path, line, "marker '" + path + "' is not /" + a_.name + "/MARKER or /" + a_.name + "/PART/MARKER");
  const std::string& mname = parts.back();
  if (parts.size() == 3) {
    for (const Marker& m : a_.ground)
      if (m.name == mname) return Where{"ground", m.pose, m.pose};
    refuse(a_.path, line, "marker '" + path + "': the assembly has no marker '" + mname + "'");
  }
  for (const Part& p : a_.parts) {
    if (p.name != parts[2]) continue;
    for (const Marker& m : p.markers)
      if (m.name == mname)
        return Where{body_of_part_.at(p.name), m.pose,
                     Pose{p.placement.p + p.placement.R * m.pose.p, p.placement.R * m.pose.R}};
    refuse(a_.path, line, "marker '" + path + "': part '" + p.name + "' has no marker '" + mname + "'");
  }
  refuse(a_.path, line, "marker '" + path + "' is on an unknown part '" + parts[2] + "'");
}

std::string SceneWriter::point(const std::string& base, const Where& w, const Eigen::Vector3d& offset,
                               std::array<std::string, 3>* coords) {
  auto it = points_.find(base);
  const bool fresh = it == points_.end();
  const std::string name = fresh ? names_.make(base) : it->second;
  const Eigen::Vector3d world = w.world.p + w.world.R * offset;
  std::array<std::string, 3> c;
  for (int i = 0; i < 3; ++i)
    c[static_cast<std::size_t>(i)] = w.body == "ground" ? "(" + scene_number(world[i]) + ")" : name + "_" + "xyz"[i];
  if (fresh) {
    points_[base] = name;
    if (w.body == "ground") {
      points_text_ << "  " << name << ": " << scene_vector(world) << "\n";
    } else {
      for (int i = 0; i < 3; ++i)
        coordinates_ << "  " << c[static_cast<std::size_t>(i)] << ": " << scene_number(world[i]) << "\n";
      points_text_ << "  " << name << ": [" << c[0] << ", " << c[1] << ", " << c[2] << "]\n";
      constraints_ << "  - {name: " << names_.make(name + "_pin") << ", type: spherical, between: [{body: " << w.body
                   << ", at: " << scene_vector(w.local.p + w.local.R * offset) << "}, {point: " << name << "}]}\n";
    }
  }
  if (coords) *coords = c;
  return name;
}

double SceneWriter::value(const Joint& j, const std::string& key, double fallback, bool required) const {
  for (const auto& [k, v] : j.values)
    if (k == key) return v;
  if (required) refuse(a_.path, j.line, j.type + " '" + j.name + "' has no " + key + " (the file may be truncated)");
  return fallback;
}

void SceneWriter::joint(const Joint& j) {
  static const std::map<std::string, std::string> direct = {{"FixedJoint", "rigid"},
                                                            {"RevoluteJoint", "revolute"},
                                                            {"CylindricalJoint", "cylindrical"},
                                                            {"TranslationalJoint", "prismatic"},
                                                            {"SphericalJoint", "spherical"},
                                                            {"UniversalJoint", "universal"},
                                                            {"PlanarJoint", "planar"},
                                                            {"PointInPlaneJoint", "point_on_plane"},
                                                            {"PointInLineJoint", "point_on_line"}};
  static const std::map<std::string, std::set<std::string>> fields = {
      {"PlanarJoint", {"offset"}},          {"PointInPlaneJoint", {"offset"}}, {"LineInPlaneJoint", {"offset"}},
      {"AngleJoint", {"theIzJz"}},          {"SphSphJoint", {"distanceIJ"}},   {"GearJoint", {"radiusI", "radiusJ"}},
      {"RackPinionJoint", {"pitchRadius"}}, {"ScrewJoint", {"pitch"}},         {"CylSphJoint", {"distanceIJ"}},
      {"RevCylJoint", {"distanceIJ"}},      {"RevRevJoint", {"distanceIJ"}},   {"ConstantVelocityJoint", {}}};
  const bool known = direct.count(j.type) || fields.count(j.type) || j.type == "ParallelAxesJoint" ||
                     j.type == "PerpendicularJoint" || j.type == "NoRotationJoint";
  if (!known)
    refuse(a_.path, j.line,
           "joint type '" + j.type + "' ('" + j.name + "') has no phiq kind yet; the file is " +
               "refused rather than approximated");
  for (std::size_t k = 0; k < j.values.size(); ++k) {
    const auto f = fields.find(j.type);
    if (f == fields.end() || !f->second.count(j.values[k].first))
      refuse(a_.path, j.value_lines[k], j.type + " '" + j.name + "': field '" + j.values[k].first + "' is not read");
  }
  if (joints_.count(j.name)) refuse(a_.path, j.line, "a second joint named '" + j.name + "'");
  const Where wi = marker(j.marker_i, j.line_i), wj = marker(j.marker_j, j.line_j);
  const std::string name = names_.make(j.name);
  joints_[j.name] = {name, j.type};
  const double offset = value(j, "offset", 0.0);
  a_.force_sites.push_back(ForceSite{j.name, j.type, name, "", wi.body, wi.local, offset});
  if (const auto d = direct.find(j.type); d != direct.end()) {
    constraints_ << "  - {name: " << name << ", type: " << d->second << ", between: [" << side(wi, offset) << ", "
                 << side(wj) << "]}\n";
    return;
  }
  a_.force_sites.back().why_not = "phiq writes it as rows over points pinned to its markers, which have no reaction";
  const std::string I = name + "_I", J = name + "_J";
  if (j.type == "LineInPlaneJoint") {
    constraints_ << "  - {name: " << name << ", type: point_on_plane, between: [" << side(wi, offset) << ", "
                 << side(wj) << "]}\n";
    dot(name + "_zz", segment(I, wi, 2), segment(J, wj, 2), 0.0);
  } else if (j.type == "ParallelAxesJoint") {
    dot(name + "_xz", segment(I, wi, 0), segment(J, wj, 2), 0.0);
    dot(name + "_yz", segment(I, wi, 1), segment(J, wj, 2), 0.0);
  } else if (j.type == "PerpendicularJoint") {
    dot(name, segment(I, wi, 2), segment(J, wj, 2), 0.0);
  } else if (j.type == "AngleJoint") {
    dot(name, segment(I, wi, 2), segment(J, wj, 2), std::cos(value(j, "theIzJz", 0.0)));
  } else if (j.type == "NoRotationJoint") {
    dot(name + "_yx", segment(I, wi, 1), segment(J, wj, 0), 0.0);
    dot(name + "_zx", segment(I, wi, 2), segment(J, wj, 0), 0.0);
    dot(name + "_zy", segment(I, wi, 2), segment(J, wj, 1), 0.0);
  } else if (j.type == "SphSphJoint") {
    const double l = value(j, "distanceIJ", 0.0, true);
    if (!(l > 0.0))
      refuse(a_.path, j.line, "SphSphJoint '" + j.name + "': distanceIJ must be positive (0: a SphericalJoint)");
    constraints_ << "  - {name: " << name << ", type: distance, between: [" << side(wi) << ", " << side(wj)
                 << "], length: " << scene_number(l) << "}\n";
  } else if (j.type == "CylSphJoint" || j.type == "RevCylJoint" || j.type == "RevRevJoint") {
    radial_distance(j, name, wi, wj);
    if (j.type != "CylSphJoint") {  // z_J parallel to z_I
      dot(name + "_zx", segment(I, wi, 2), segment(J, wj, 0), 0.0);
      dot(name + "_zy", segment(I, wi, 2), segment(J, wj, 1), 0.0);
    }
    if (j.type == "RevRevJoint")  // and J's origin in I's x-y plane
      constraints_ << "  - {name: " << names_.make(name + "_z") << ", type: point_on_plane, between: [" << side(wi)
                   << ", " << side(wj) << "]}\n";
  } else if (j.type == "ConstantVelocityJoint") {  // the origins together, x_I·y_J + y_I·x_J = 0
    constraints_ << "  - {name: " << name << ", type: spherical, between: [" << side(wi) << ", " << side(wj) << "]}\n";
    std::array<std::string, 3> io, ix, iy, jo, jx, jy;
    point(I + "_o", wi, Eigen::Vector3d::Zero(), &io), point(I + "_x", wi, Eigen::Vector3d::UnitX(), &ix);
    point(I + "_y", wi, Eigen::Vector3d::UnitY(), &iy), point(J + "_o", wj, Eigen::Vector3d::Zero(), &jo);
    point(J + "_x", wj, Eigen::Vector3d::UnitX(), &jx), point(J + "_y", wj, Eigen::Vector3d::UnitY(), &jy);
    std::string expr;
    for (std::size_t i = 0; i < 3; ++i)
      expr += (i ? " + " : "") + std::string("(") + ix[i] + " - " + io[i] + ")*(" + jy[i] + " - " + jo[i] + ") + (" +
              iy[i] + " - " + io[i] + ")*(" + jx[i] + " - " + jo[i] + ")";
    constraints_ << "  - {name: " << names_.make(name + "_cv") << ", type: equation, unit: none, expr: \"" << expr
                 << "\"}\n";
  } else if (j.type == "GearJoint") {
    gear(j, name, wi, wj);
  } else if (j.type == "ScrewJoint") {  // 2π z − pitch θ = c: z = pitch θ / 2π + c'
    travel_and_turn(name, wi, wj, 2, -value(j, "pitch", 0.0, true) / (2 * M_PI));
  } else {  // x + pitchRadius θ = c
    travel_and_turn(name, wi, wj, 0, value(j, "pitchRadius", 0.0, true));
  }
}

// OndselSolver's gear: orbit(J about I) · rI/rJ + orbit(I about J) held at its value in the file's placement, an
// orbit being the angle of the other marker's origin in a marker's x-y plane (phiq's segment_angle, any turns).
void SceneWriter::gear(const Joint& j, const std::string& name, const Where& wi, const Where& wj) {
  const double ri = value(j, "radiusI", 0.0, true), rj = value(j, "radiusJ", 0.0, true);
  if (!(ri > 0.0) || !(rj > 0.0)) refuse(a_.path, j.line, "GearJoint '" + j.name + "': its radii must be positive");
  const std::string pi = point(name + "_I_o", wi, Eigen::Vector3d::Zero());
  const std::string pj = point(name + "_J_o", wj, Eigen::Vector3d::Zero());
  const Eigen::Vector3d d = wj.world.p - wi.world.p;
  const Eigen::Matrix3d &Ri = wi.world.R, &Rj = wj.world.R;
  const double orbit_i = std::atan2(Ri.col(1).dot(d), Ri.col(0).dot(d));
  const double orbit_j = std::atan2(Rj.col(1).dot(-d), Rj.col(0).dot(-d));
  const std::string ti = names_.make(name + "_orbit_I"), tj = names_.make(name + "_orbit_J");
  coordinates_ << "  " << ti << ": " << scene_number(orbit_i) << "\n  " << tj << ": " << scene_number(orbit_j) << "\n";
  constraints_ << "  - {name: " << names_.make(ti + "_def") << ", type: segment_angle, segment: [" << pi << ", " << pj
               << "], axis: " << axis(wi) << ", angle: " << ti << "}\n";
  constraints_ << "  - {name: " << names_.make(tj + "_def") << ", type: segment_angle, segment: [" << pj << ", " << pi
               << "], axis: " << axis(wj) << ", angle: " << tj << "}\n";
  const double ratio = ri / rj;
  constraints_ << "  - {name: " << name << ", type: coupler, coordinates: [" << tj << ", " << ti
               << "], coefficients: [1, " << scene_number(ratio)
               << "], constant: " << scene_number(orbit_j + ratio * orbit_i) << "}\n";
}

// OndselSolver's distance of J's origin from I's z axis, x² + y² = distanceIJ² in I's frame (the CylSph, RevCyl and
// RevRev joints' first row), divided by 2 distanceIJ as phiq's distance rows are.
void SceneWriter::radial_distance(const Joint& j, const std::string& name, const Where& wi, const Where& wj) {
  const double l = value(j, "distanceIJ", 0.0, true);
  if (!(l > 0.0))
    refuse(a_.path, j.line, j.type + " '" + j.name + "': distanceIJ must be positive (0: a PointInLine joint)");
  std::array<std::string, 3> o, x, y, p;
  point(name + "_I_o", wi, Eigen::Vector3d::Zero(), &o);
  point(name + "_I_x", wi, Eigen::Vector3d::UnitX(), &x);
  point(name + "_I_y", wi, Eigen::Vector3d::UnitY(), &y);
  point(name + "_J_o", wj, Eigen::Vector3d::Zero(), &p);
  std::string ex, ey;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string d = "(" + p[i] + " - " + o[i] + ")";
    ex += (i ? " + " : "") + std::string("(") + x[i] + " - " + o[i] + ")*" + d;
    ey += (i ? " + " : "") + std::string("(") + y[i] + " - " + o[i] + ")*" + d;
  }
  constraints_ << "  - {name: " << name << ", type: equation, unit: length, expr: \"((" << ex << ")^2 + (" << ey
               << ")^2 - " << scene_number(l * l) << ")/" << scene_number(2 * l) << "\"}\n";
}

// OndselSolver's rack and pinion and screw, one row each: J's travel along I's x (rack) or z (screw), plus
// `per_turn` times J's turn about I's z (phiq's rotation_angle), held at its value in the file's placement.
void SceneWriter::travel_and_turn(const std::string& name, const Where& wi, const Where& wj, int axis_k,
                                  double per_turn) {
  std::array<std::string, 3> o, x, p;
  point(name + "_I_o", wi, Eigen::Vector3d::Zero(), &o);
  point(name + "_I_" + "xyz"[axis_k], wi, Eigen::Vector3d::Unit(axis_k), &x);
  point(name + "_J_o", wj, Eigen::Vector3d::Zero(), &p);
  const Eigen::Matrix3d &Ri = wi.world.R, &Rj = wj.world.R;
  const double turn = std::atan2(Ri.col(1).dot(Rj.col(0)), Ri.col(0).dot(Rj.col(0)));
  const double travel = Ri.col(axis_k).dot(wj.world.p - wi.world.p);
  const std::string th = names_.make(name + "_turn");
  coordinates_ << "  " << th << ": " << scene_number(turn) << "\n";
  constraints_ << "  - {name: " << names_.make(th + "_def") << ", type: rotation_angle, between: [" << side(wi) << ", "
               << side(wj) << "], angle: " << th << "}\n";
  std::string expr;
  for (std::size_t i = 0; i < 3; ++i)
    expr += (i ? " + " : "") + std::string("(") + x[i] + " - " + o[i] + ")*(" + p[i] + " - " + o[i] + ")";
  expr += " + (" + scene_number(per_turn) + ")*" + th + " - (" + scene_number(travel + per_turn * turn) + ")";
  constraints_ << "  - {name: " << name << ", type: equation, unit: length, expr: \"" << expr << "\"}\n";
}

// An OndselSolver expression of `time` as phiq's expression of `t` ("180.0d" is a Smalltalk double).
std::string expression(const std::string& e, const std::string& path, int line) {
  static const std::set<std::string> functions = {"sin", "cos",  "tan",  "asin", "acos", "atan", "atan2", "exp",
                                                  "log", "sqrt", "sinh", "cosh", "tanh", "abs",  "pi"};
  std::string out;
  for (std::size_t i = 0; i < e.size();) {
    const char c = e[i];
    if (std::isdigit(static_cast<unsigned char>(c)) ||
        (c == '.' && i + 1 < e.size() && std::isdigit(static_cast<unsigned char>(e[i + 1])))) {
      std::size_t k = i;
      while (k < e.size() && (std::isdigit(static_cast<unsigned char>(e[k])) || e[k] == '.')) ++k;
      out += e.substr(i, k - i);
      if (k < e.size() && (e[k] == 'e' || e[k] == 'E' || e[k] == 'd')) {
        std::size_t x = k + 1;
        if (x < e.size() && (e[x] == '+' || e[x] == '-')) ++x;
        if (x < e.size() && std::isdigit(static_cast<unsigned char>(e[x]))) {
          out += 'e', out += e.substr(k + 1, x - k - 1), k = x;
          while (k < e.size() && std::isdigit(static_cast<unsigned char>(e[k]))) out += e[k++];
        } else if (e[k] == 'd') {
          ++k;  // the double-precision mark of a literal
        }
      }
      i = k;
    } else if (std::isalpha(static_cast<unsigned char>(c))) {
      std::size_t k = i;
      while (k < e.size() && std::isalnum(static_cast<unsigned char>(e[k]))) ++k;
      const std::string word = e.substr(i, k - i);
      if (word == "time") {
        out += "t";
      } else if (functions.count(word)) {
        out += word;
      } else {
        refuse(path, line, "the motion's expression '" + e + "' uses '" + word + "', which phiq does not know");
      }
      i = k;
    } else if (c == '*' && i + 1 < e.size() && e[i + 1] == '*') {
      out += '^', i += 2;
    } else if (std::string("+-*/^(), \t").find(c) != std::string::npos) {
      out += c == '\t' ? ' ' : c, ++i;
    } else {
      refuse(path, line,
             "the motion's expression '" + e + "' has '" + std::string(1, c) + "', which phiq does not read");
    }
  }
  try {  // refused here, at the file's line, rather than by the scene reader at a line of the converted text
    const NameResolver time_only = [](const std::string& name) -> std::optional<NameBinding> {
      if (name == "t") return NameBinding{NameBinding::Kind::kTime};
      return std::nullopt;
    };
    (void)CompiledExpression::compile(out, time_only);
  } catch (const Error& error) {
    refuse(path, line, "the motion's expression '" + e + "': " + error.what());
  }
  return out;
}

// The rotation R_a(φ) R_b(θ) R_c(ψ) of a RotationOrder "a b c" (1: x, 2: y, 3: z), its entries as texts of the
// angles' expressions.
using TextMatrix = std::array<std::array<std::string, 3>, 3>;
TextMatrix axis_rotation(int axis, const std::string& angle) {
  TextMatrix m;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c) m[r][c] = std::string(1, r == c ? '1' : '0');
  const std::size_t i = static_cast<std::size_t>(axis + 1) % 3, j = static_cast<std::size_t>(axis + 2) % 3;
  m[i][i] = m[j][j] = "cos(" + angle + ")";
  m[j][i] = "sin(" + angle + ")";
  m[i][j] = "(-sin(" + angle + "))";
  return m;
}
TextMatrix product(const TextMatrix& a, const TextMatrix& b) {
  TextMatrix m;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c) {
      std::string sum;
      for (std::size_t k = 0; k < 3; ++k) {
        if (a[r][k] == "0" || b[k][c] == "0") continue;
        const std::string term = a[r][k] == "1" ? b[k][c] : b[k][c] == "1" ? a[r][k] : a[r][k] + "*" + b[k][c];
        sum += (sum.empty() ? "" : " + ") + term;
      }
      m[r][c] = sum.empty() ? "0" : sum;
    }
  return m;
}

// OndselSolver's general motion: J's origin in I's axes is rIJI(t), J's axes in I's are the Euler rotation of
// angIJJ(t). Six `expr` drivers over natural points pinned to the markers: the three displacements, and three
// direction cosines (y_I·x_J, z_I·x_J, z_I·y_J, the rows a Fixed joint uses) against the rotation's entries.
void SceneWriter::general_motion(const Motion& m) {
  const Where wi = marker(m.marker_i, m.line_i), wj = marker(m.marker_j, m.line_j);
  const std::string name = names_.make(m.name);
  a_.force_sites.push_back(ForceSite{m.name, m.type, name,
                                     "phiq drives it by six drivers, whose efforts are not one "
                                     "force and torque",
                                     wi.body, wi.local, 0.0});
  std::array<std::array<std::string, 3>, 4> ip;  // I's origin, x, y, z tips
  std::array<std::array<std::string, 3>, 3> jp;  // J's origin, x, y tips
  point(name + "_I_o", wi, Eigen::Vector3d::Zero(), &ip[0]);
  for (int k = 0; k < 3; ++k) point(name + "_I_" + "xyz"[k], wi, Eigen::Vector3d::Unit(k), &ip[k + 1]);
  point(name + "_J_o", wj, Eigen::Vector3d::Zero(), &jp[0]);
  for (int k = 0; k < 2; ++k) point(name + "_J_" + "xyz"[k], wj, Eigen::Vector3d::Unit(k), &jp[k + 1]);
  auto dot = [](const std::array<std::string, 3>& a, const std::array<std::string, 3>& o,
                const std::array<std::string, 3>& b, const std::array<std::string, 3>& p) {
    std::string s;
    for (std::size_t i = 0; i < 3; ++i)
      s += (i ? " + " : "") + std::string("(") + a[i] + " - " + o[i] + ")*(" + b[i] + " - " + p[i] + ")";
    return s;
  };
  std::array<std::string, 6> f;
  for (std::size_t k = 0; k < 6; ++k) f[k] = expression(m.general[k], a_.path, m.general_lines[k]);
  std::istringstream order(m.rotation_order);
  TextMatrix rotation;
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c) rotation[r][c] = std::string(1, r == c ? '1' : '0');
  for (std::size_t k = 0; k < 3; ++k) {
    int axis = 0;
    if (!(order >> axis) || axis < 1 || axis > 3)
      refuse(a_.path, m.order_line, "RotationOrder '" + m.rotation_order + "' is not three axes 1, 2, 3");
    rotation = product(rotation, axis_rotation(axis - 1, f[3 + k]));
  }
  auto driver = [&](const std::string& suffix, const std::string& g, const std::string& unit, const std::string& law) {
    drivers_ << "  - {name: " << names_.make(name + suffix) << ", expr: \"" << g << "\", unit: " << unit
             << ", law: {type: expression, f: \"" << law << "\"}}\n";
  };
  for (std::size_t k = 0; k < 3; ++k)
    driver(std::string("_") + "xyz"[k], dot(ip[k + 1], ip[0], jp[0], ip[0]), "length", f[k]);
  driver("_yx", dot(ip[2], ip[0], jp[1], jp[0]), "none", rotation[1][0]);
  driver("_zx", dot(ip[3], ip[0], jp[1], jp[0]), "none", rotation[2][0]);
  driver("_zy", dot(ip[3], ip[0], jp[2], jp[0]), "none", rotation[2][1]);
}

void SceneWriter::motion(const Motion& m) {
  if (m.type == "GeneralMotion") return general_motion(m);
  const std::string prefix = "/" + a_.name + "/";
  const std::string jname = m.joint.rfind(prefix, 0) == 0 ? m.joint.substr(prefix.size()) : "";
  const auto it = joints_.find(jname);
  if (it == joints_.end())
    refuse(a_.path, m.joint_line, m.type + " '" + m.name + "': MotionJoint '" + m.joint + "' names no joint");
  const bool rotation = m.type == "RotationalMotion";
  const std::string& type = it->second.second;
  const bool ok = rotation ? (type == "RevoluteJoint" || type == "CylindricalJoint")
                           : (type == "TranslationalJoint" || type == "CylindricalJoint");
  if (!ok)
    refuse(a_.path, m.joint_line,
           m.type + " '" + m.name + "' drives " + type + " '" + jname + "': phiq drives the " +
               (rotation ? "angle of a revolute or cylindrical"
                         : "travel of a translational "
                           "or cylindrical") +
               " joint");
  const std::string name = names_.make(m.name);
  // the motion acts between its joint's markers (found before the push_back, which may move the sites)
  const auto site = std::find_if(a_.force_sites.begin(), a_.force_sites.end(),
                                 [&](const ForceSite& j) { return j.item == jname && j.type == type; });
  if (site != a_.force_sites.end()) {
    ForceSite motion{m.name, m.type, name, "", site->body, site->marker, 0.0};
    a_.force_sites.push_back(std::move(motion));
  }
  drivers_ << "  - {name: " << name << ", joint: " << it->second.first
           << ", measure: " << (rotation ? "angle" : "distance") << ", law: {type: expression, f: \""
           << expression(m.expression, a_.path, m.expression_line) << "\"}}\n";
}

std::string SceneWriter::time_grid() const {
  const double span = a_.tend - a_.tstart;
  if (!(a_.hout > 0.0) || span < 0.0)
    refuse(a_.path, a_.time_line, "SimulationParameters: hout must be positive and tend at least tstart");
  const double steps = std::round(span / a_.hout);
  if (std::abs(steps * a_.hout - span) > 1e-9 * std::max(1.0, std::abs(span)) || steps > 1e9)
    refuse(a_.path, a_.time_line,
           "SimulationParameters: hout " + scene_number(a_.hout) + " does not divide tend - tstart " +
               scene_number(span) + " into whole steps; phiq's grid is evenly spaced");
  return "time: {start: " + scene_number(a_.tstart) + ", end: " + scene_number(a_.tend) +
         ", steps: " + scene_number(steps) + "}\n";
}

// The parts' mass as phiq parts: a principal mass marker with positive mass and moments that a rigid body can have.
std::string SceneWriter::parts_and_mass() {
  std::ostringstream out;
  for (const Part& p : a_.parts) {
    const Eigen::Vector3d& m = p.moments;
    const bool rigid = p.mass > 0.0 && m.minCoeff() > 0.0 && m.x() <= m.y() + m.z() && m.y() <= m.x() + m.z() &&
                       m.z() <= m.x() + m.y();
    if (!rigid) {
      if (p.mass_line)
        a_.skipped.push_back(a_.path + ":" + std::to_string(p.mass_line) + ": Part '" + p.name +
                             "' PrincipalMassMarker: mass " + scene_number(p.mass) + " and moments " + scene_vector(m) +
                             " are no rigid body's; the part is given no mass");
      continue;
    }
    const Eigen::Matrix3d& R = p.mass_frame.R;
    Eigen::Matrix3d I = R * m.asDiagonal() * R.transpose();
    I = 0.5 * (I + I.transpose()).eval();
    out << "  " << body_of_part_.at(p.name) << ": {body: " << body_of_part_.at(p.name)
        << ", mass: " << scene_number(p.mass) << ", center_of_mass: " << scene_vector(p.mass_frame.p) << ", inertia: ["
        << scene_vector(I.row(0).transpose()) << ", " << scene_vector(I.row(1).transpose()) << ", "
        << scene_vector(I.row(2).transpose()) << "]}\n";
  }
  return out.str().empty() ? "" : "parts:\n" + out.str();
}

std::string SceneWriter::write() {
  std::ostringstream bodies;
  for (const Part& p : a_.parts) {
    if (body_of_part_.count(p.name)) refuse(a_.path, p.line, "a second part named '" + p.name + "'");
    const std::string b = names_.make(p.name, true);
    body_of_part_[p.name] = b;
    a_.bodies.emplace_back(p.name, b);
    Eigen::Quaterniond q(p.placement.R);
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    bodies << "  " << b << ": {at: " << scene_vector(p.placement.p) << ", orientation: {euler_parameters: ["
           << scene_number(q.w()) << ", " << scene_number(q.x()) << ", " << scene_number(q.y()) << ", "
           << scene_number(q.z()) << "]}}\n";
  }
  for (const Joint& j : a_.joints) joint(j);
  for (const Motion& m : a_.motions) motion(m);
  const std::string grid = time_grid(), mass = parts_and_mass();
  const auto line_of = [&](const std::string& why) { return std::atoi(why.c_str() + a_.path.size() + 1); };
  std::stable_sort(a_.skipped.begin(), a_.skipped.end(),
                   [&](const std::string& x, const std::string& y) { return line_of(x) < line_of(y); });
  const Eigen::Vector3d gravity =
      o_.gravity ? Eigen::Vector3d((*o_.gravity)[0], (*o_.gravity)[1], (*o_.gravity)[2]) : a_.gravity;
  if (!gravity.allFinite()) refuse(a_.path, 0, "--gravity: the components must be finite numbers");
  std::ostringstream s;
  s << "# Converted by phiq from " << single_line(a_.path) << " (FreeCAD Assembly / OndselSolver .asmt): lengths in\n"
    << "# the file's unit (FreeCAD writes millimetres), angles in radians, time in seconds.\n"
    << "# Gravity " << scene_vector(gravity) << " (length unit)/s²: "
    << (o_.gravity               ? "--gravity"
        : a_.gravity.isZero(0.0) ? "none (the file's ConstantGravity is zero or absent)"
                                 : "the file's ConstantGravity")
    << "\n";
  if (!a_.skipped.empty()) s << "# Not mapped:\n";
  for (const std::string& why : a_.skipped) s << "#   " << single_line(why) << "\n";
  s << "phiq: 1\nname: " << yaml_quoted(a_.name) << "\n"
    << "description: \"FreeCAD Assembly (OndselSolver .asmt); lengths in millimetres as FreeCAD writes them\"\n"
    << "dimension: 3\n";
  if (!coordinates_.str().empty()) s << "coordinates:\n" << coordinates_.str();
  if (!points_text_.str().empty()) s << "points:\n" << points_text_.str();
  s << "bodies:\n" << bodies.str();
  if (!constraints_.str().empty()) s << "constraints:\n" << constraints_.str();
  if (!drivers_.str().empty()) s << "drivers:\n" << drivers_.str();
  s << grid << mass;
  if (!gravity.isZero(0.0)) s << "loads: {gravity: " << scene_vector(gravity) << "}\n";
  bool reactions = false;
  for (const ForceSite& f : a_.force_sites)
    reactions = reactions || (f.why_not.empty() && f.type.find("Joint") != std::string::npos);
  s << import_output_section(a_.path, o_.rates, o_.forces, !drivers_.str().empty(), reactions, !mass.empty());
  return s.str();
}

}  // namespace

std::string write_scene(Assembly& a, const ImportOptions& options) { return SceneWriter(a, options).write(); }

}  // namespace phiq::detail::asmt
