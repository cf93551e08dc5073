// A mechanism::Mechanism written as a phiq scene (models/README.md): bodies as maps with Euler parameters at the
// model's pose, joints as spatial joints whose sides state `ref` on both ends (a joint angle is then 0 at the model's
// pose, as the file's joint coordinates are), couplers over `rotation_angle` coordinates, drivers and the time grid
// from ImportOptions, inertials and geometry as parts.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "import/mechanism.hpp"
#include "import/scene_text.hpp"
#include "phiq/expression.hpp"
#include "phiq/scene.hpp"
#include "phiq/text.hpp"

namespace phiq::detail::mechanism {

namespace {

std::string orientation(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return "{euler_parameters: [" + scene_number(q.w()) + ", " + scene_number(q.x()) + ", " + scene_number(q.y()) + ", " +
         scene_number(q.z()) + "]}";
}

// A body whose mass phiq accepts: positive mass, symmetric positive definite inertia whose principal moments each
// are at most the sum of the others.
bool rigid_mass(const Body& b) {
  if (!(b.mass > 0.0)) return false;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (b.inertia + b.inertia.transpose()));
  const Eigen::Vector3d m = eig.eigenvalues();
  return m.minCoeff() > 0.0 && m(2) <= (m(0) + m(1)) * (1 + 1e-12);
}

class MechanismWriter {
 public:
  MechanismWriter(Mechanism& m, const ImportOptions& o) : m_(m), o_(o) {}
  std::string write();

 private:
  std::string side(const Side& s) const {
    return "{body: " + body_[static_cast<std::size_t>(s.body)] + ", at: " + scene_vector(s.at) +
           ", axis: " + scene_vector(s.axis.normalized()) + ", ref: " + scene_vector(s.ref.normalized()) + "}";
  }
  std::string joint_coordinate(int j, const Coupler& c);
  std::string travel(const Joint& joint);
  std::string joint_springs();
  std::string joint_limits();
  std::array<std::string, 3> rotated(int b, const Eigen::Vector3d& v) const;
  void coupler(const Coupler& c);
  void drivers();
  std::string parts();

  Mechanism& m_;
  const ImportOptions& o_;
  SceneNames names_;
  std::vector<std::string> body_, joint_;
  std::map<int, std::string> joint_coordinate_;
  std::map<int, std::string> driver_of_;  // a driven joint's driver
  std::ostringstream coordinates_, constraints_, drivers_;
  bool massive_ = false;  // a part has mass (parts())
};

// The coordinate that holds joint j's angle (a `rotation_angle` of a revolute joint) or travel (a prismatic joint's
// z₁ · (P₂ − P₁), an `equation` over the bodies' coordinates), made once.
std::string MechanismWriter::joint_coordinate(int j, const Coupler& c) {
  if (const auto it = joint_coordinate_.find(j); it != joint_coordinate_.end()) return it->second;
  const Joint& joint = m_.joints[static_cast<std::size_t>(j)];
  const std::string& jname = joint_[static_cast<std::size_t>(j)];
  if (joint.kind == "revolute") {
    const std::string name = names_.make(jname + "_angle");
    coordinates_ << "  " << name << ": 0\n";
    constraints_ << "  - {name: " << names_.make(name + "_def") << ", type: rotation_angle, joint: " << jname
                 << ", angle: " << name << "}\n";
    return joint_coordinate_[j] = name;
  }
  if (joint.kind != "prismatic")
    refuse(m_.file_of(c.file), c.line,
           "'" + c.name + "' couples " + (joint.kind.empty() ? "a free" : joint.kind) + " joint '" + joint.name +
               "': phiq couples revolute angles and prismatic travels");
  const std::string name = names_.make(jname + "_travel");
  coordinates_ << "  " << name << ": 0\n";
  constraints_ << "  - {name: " << names_.make(name + "_def") << ", type: equation, unit: length, expr: \"" << name
               << " - (" << travel(joint) << ")\"}\n";
  return joint_coordinate_[j] = name;
}

// A prismatic joint's travel over the bodies' coordinates: (R₁ a) · (r₂ + R₂ b − r₁) − a · p, a the axis and p the
// point of side 1, b the point of side 2 (0 at the file's pose).
std::string MechanismWriter::travel(const Joint& joint) {
  const Eigen::Vector3d a = joint.parent.axis.normalized();
  const std::array<std::string, 3> u = rotated(joint.parent.body, a);
  const std::array<std::string, 3> rb = rotated(joint.child.body, joint.child.at);
  std::string expr;
  for (std::size_t i = 0; i < 3; ++i) {
    std::string w = "(" + rb[i];
    if (joint.child.body > 0) w += " + " + body_[static_cast<std::size_t>(joint.child.body)] + "_" + "xyz"[i];
    if (joint.parent.body > 0) w += " - " + body_[static_cast<std::size_t>(joint.parent.body)] + "_" + "xyz"[i];
    expr += (i ? " + " : "") + std::string("(") + u[i] + ")*" + w + ")";
  }
  return expr + " - (" + scene_number(a.dot(joint.parent.at)) + ")";
}

// The joints' springs, dampers, frictions and rotors as torsional springs: on a revolute's angle, its coordinate
// (a rotation_angle, through any number of turns, as the file's simulator counts them), or on a prismatic's travel.
std::string MechanismWriter::joint_springs() {
  std::ostringstream s;
  for (std::size_t j = 0; j < m_.joints.size(); ++j) {
    const Joint& joint = m_.joints[j];
    if (joint.stiffness == 0.0 && joint.damping == 0.0 && joint.friction == 0.0 && joint.armature == 0.0) continue;
    const bool turns = joint.kind == "revolute";
    s << "    - {name: " << names_.make(joint_[j] + "_spring")
      << (turns ? ", coordinate: " + joint_coordinate(static_cast<int>(j), Coupler{})
                : ", angle: \"" + travel(joint) + "\"")
      << ", stiffness: " << scene_number(joint.stiffness) << ", free_angle: " << scene_number(joint.free)
      << ", damping: " << scene_number(joint.damping);
    if (joint.friction != 0.0) s << ", friction: " << scene_number(joint.friction);
    if (joint.armature != 0.0) s << ", inertia: " << scene_number(joint.armature);
    s << "}\n";
  }
  return s.str();
}

// The joints' ranges, their rates' (with velocities solved) and their drivers' efforts' (with efforts), as limits.
std::string MechanismWriter::joint_limits() {
  // (a format's "none" may be an infinity or a huge value: a bound is finite, and below 1e15)
  const auto bound = [](double v) { return std::isfinite(v) && std::fabs(v) < 1e15; };
  std::ostringstream s;
  for (std::size_t j = 0; j < m_.joints.size(); ++j) {
    const Joint& joint = m_.joints[j];
    const bool range = bound(joint.lower) && bound(joint.upper) && joint.lower < joint.upper;
    const bool speed = bound(joint.velocity) && joint.velocity > 0.0, rate = speed && o_.rates;
    if (speed && !o_.rates)
      m_.skip("a joint's velocity limit", joint.line, "checked with --rates (velocities solved)", joint.file);
    if (range || rate) {
      s << "  - {joint: " << joint_[j];
      if (range) s << ", range: [" << scene_number(joint.lower) << ", " << scene_number(joint.upper) << "]";
      if (rate) s << ", rate: [" << scene_number(-joint.velocity) << ", " << scene_number(joint.velocity) << "]";
      s << "}\n";
    }
    const auto driver = driver_of_.find(static_cast<int>(j));
    if (bound(joint.effort_lower) && bound(joint.effort_upper) && joint.effort_lower < joint.effort_upper &&
        o_.forces && driver != driver_of_.end())
      s << "  - {name: " << joint_[j] << "_effort, effort: " << driver->second << ", range: ["
        << scene_number(joint.effort_lower) << ", " << scene_number(joint.effort_upper) << "]}\n";
  }
  return s.str();
}

// The world components of R v, R the rotation of body `b` (its Euler parameters; constants for the ground).
std::array<std::string, 3> MechanismWriter::rotated(int b, const Eigen::Vector3d& v) const {
  if (b == 0)
    return {"(" + scene_number(v.x()) + ")", "(" + scene_number(v.y()) + ")", "(" + scene_number(v.z()) + ")"};
  const std::string& n = body_[static_cast<std::size_t>(b)];
  const std::string e0 = n + "_e0", e1 = n + "_e1", e2 = n + "_e2", e3 = n + "_e3";
  const std::string R[3][3] = {
      {"(1 - 2*(" + e2 + "^2 + " + e3 + "^2))", "2*(" + e1 + "*" + e2 + " - " + e0 + "*" + e3 + ")",
       "2*(" + e1 + "*" + e3 + " + " + e0 + "*" + e2 + ")"},
      {"2*(" + e1 + "*" + e2 + " + " + e0 + "*" + e3 + ")", "(1 - 2*(" + e1 + "^2 + " + e3 + "^2))",
       "2*(" + e2 + "*" + e3 + " - " + e0 + "*" + e1 + ")"},
      {"2*(" + e1 + "*" + e3 + " - " + e0 + "*" + e2 + ")", "2*(" + e2 + "*" + e3 + " + " + e0 + "*" + e1 + ")",
       "(1 - 2*(" + e1 + "^2 + " + e2 + "^2))"}};
  std::array<std::string, 3> out;
  for (std::size_t r = 0; r < 3; ++r) {
    std::string sum;
    for (std::size_t k = 0; k < 3; ++k)
      if (v[static_cast<Eigen::Index>(k)] != 0.0)
        sum += (sum.empty() ? "" : " + ") + R[r][k] + "*(" + scene_number(v[static_cast<Eigen::Index>(k)]) + ")";
    out[r] = sum.empty() ? "0" : "(" + sum + ")";
  }
  return out;
}

void MechanismWriter::coupler(const Coupler& c) {
  const std::string q = joint_coordinate(c.joint, c);
  const std::string name = names_.make(c.name);
  if (c.other < 0) {
    constraints_ << "  - {name: " << name << ", type: equation, unit: angle, expr: \"" << q << " - ("
                 << scene_number(c.offset) << ")\"}\n";
    return;
  }
  if (c.multiplier == 0.0)
    refuse(m_.file_of(c.file), c.line,
           "'" + c.name + "': a multiplier of 0 holds the joint still: phiq's coupler needs one ≠ 0");
  const std::string r = joint_coordinate(c.other, c);
  constraints_ << "  - {name: " << name << ", type: coupler, coordinates: [" << q << ", " << r
               << "], coefficients: [1, " << scene_number(-c.multiplier) << "], constant: " << scene_number(c.offset)
               << "}\n";
}

void MechanismWriter::drivers() {
  const NameResolver time_only = [](const std::string& name) -> std::optional<NameBinding> {
    if (name == "t") return NameBinding{NameBinding::Kind::kTime};
    return std::nullopt;
  };
  // The grid as the scene reader would refuse it, but named as the caller gave it (not at a line of the text
  // written here, which no user has seen)
  if (!std::isfinite(o_.t_start) || !std::isfinite(o_.t_end))
    refuse(m_.path, 0, "--time " + shortest(o_.t_start) + " " + shortest(o_.t_end) + ": START and END must be finite");
  if (o_.steps < 0) refuse(m_.path, 0, "--time: STEPS must be 0 or more, not " + std::to_string(o_.steps));
  if (o_.steps > 0 && o_.t_start == o_.t_end)
    refuse(m_.path, 0,
           "--time: START and END are both " + shortest(o_.t_start) + ": " + std::to_string(o_.steps) +
               " steps need END ≠ START");
  std::set<std::string> driven;
  for (const auto& [joint, law] : o_.drives) {
    if (!driven.insert(joint).second)
      refuse(m_.path, 0, "--drive " + joint + ": the joint is driven twice (one --drive per joint)");
    int found = -1;
    for (std::size_t k = 0; k < m_.joints.size(); ++k)
      if (m_.joints[k].name == joint) found = static_cast<int>(k);
    if (found < 0) refuse(m_.path, 0, "--drive " + joint + ": the model has no joint '" + joint + "'");
    const Joint& j = m_.joints[static_cast<std::size_t>(found)];
    if (j.kind != "revolute" && j.kind != "prismatic")
      refuse(m_.file_of(j.file), j.line,
             "--drive " + joint + ": a " + (j.kind.empty() ? "free" : j.kind) +
                 " joint; phiq drives a revolute joint's angle or a prismatic joint's travel");
    try {
      (void)CompiledExpression::compile(law, time_only);
    } catch (const Error& e) {
      refuse(m_.path, 0, "--drive " + joint + "=" + law + ": " + e.what());
    }
    driver_of_[found] = names_.make("drive_" + joint_[static_cast<std::size_t>(found)]);
    drivers_ << "  - {name: " << driver_of_[found] << ", joint: " << joint_[static_cast<std::size_t>(found)]
             << ", measure: " << (j.kind == "revolute" ? "angle" : "distance")
             << ", law: {type: expression, f: " << yaml_quoted(law) << "}}\n";
  }
}

std::string MechanismWriter::parts() {
  std::ostringstream out;
  for (std::size_t k = 0; k < m_.bodies.size(); ++k) {
    const Body& b = m_.bodies[k];
    std::ostringstream fields;
    if (b.has_mass && rigid_mass(b)) {
      massive_ = true;
      const Eigen::Matrix3d I = 0.5 * (b.inertia + b.inertia.transpose());
      fields << ", mass: " << scene_number(b.mass) << ", center_of_mass: " << scene_vector(b.com) << ", inertia: ["
             << scene_vector(I.row(0).transpose()) << ", " << scene_vector(I.row(1).transpose()) << ", "
             << scene_vector(I.row(2).transpose()) << "]";
    } else if (b.has_mass && b.mass > 0.0) {
      m_.skip("inertial of '" + b.name + "'", b.line, "a mass or inertia no rigid body has; the body is given no mass");
    } else if (b.density && !b.shapes.empty() && k > 0) {
      massive_ = true;
      fields << ", density: " << scene_number(*b.density);
    }
    if (!b.shapes.empty()) {
      fields << ", shapes: [";
      for (std::size_t s = 0; s < b.shapes.size(); ++s) {
        const Shape& sh = b.shapes[s];
        fields << (s ? ", " : "") << "{type: " << sh.type;
        if (sh.type == "box") fields << ", size: " << scene_vector(sh.size);
        if (sh.type == "plane")
          fields << ", size: [" << scene_number(sh.size.x()) << ", " << scene_number(sh.size.y()) << "]";
        if (sh.type == "sphere" || sh.type == "cylinder" || sh.type == "capsule")
          fields << ", radius: " << scene_number(sh.radius);
        if (sh.type == "cylinder" || sh.type == "capsule") fields << ", length: " << scene_number(sh.length);
        if (sh.type == "mesh") fields << ", file: " << yaml_quoted(sh.file) << ", scale: " << scene_number(sh.scale);
        if (!sh.at.p.isZero(0.0)) fields << ", at: " << scene_vector(sh.at.p);
        if (!sh.at.R.isIdentity(0.0)) fields << ", orientation: " << orientation(sh.at.R);
        if (sh.rgba)
          fields << ", colour: [" << scene_number((*sh.rgba)(0)) << ", " << scene_number((*sh.rgba)(1)) << ", "
                 << scene_number((*sh.rgba)(2)) << ", " << scene_number((*sh.rgba)(3)) << "]";
        fields << "}";
      }
      fields << "]";
    }
    if (fields.str().empty()) continue;
    out << "  " << names_.make("part_" + body_[k]) << ": {body: " << body_[k] << fields.str() << "}\n";
  }
  return out.str().empty() ? "" : "parts:\n" + out.str();
}

std::string MechanismWriter::write() {
  if (m_.bodies.size() < 2)
    refuse(m_.path, 0, "the model has no moving " + std::string(m_.format == "URDF" ? "link" : "body"));
  std::ostringstream bodies;
  body_.push_back("ground");
  for (std::size_t k = 1; k < m_.bodies.size(); ++k) {
    const Body& b = m_.bodies[k];
    body_.push_back(names_.make(b.name, true));
    bodies << "  " << body_.back() << ": {at: " << scene_vector(b.world.p)
           << ", orientation: " << orientation(b.world.R) << "}\n";
  }
  for (const Joint& j : m_.joints) {
    joint_.push_back(names_.make(j.name));
    if (j.kind.empty()) continue;  // a free body
    constraints_ << "  - {name: " << joint_.back() << ", type: " << j.kind << ", between: [" << side(j.parent) << ", "
                 << side(j.child) << "]}\n";
  }
  for (const Coupler& c : m_.couplers) coupler(c);
  drivers();
  const std::string mass = parts();
  const std::string springs = joint_springs();  // (before the coordinates are written: a revolute's adds one)
  const std::string limits = joint_limits();    // (before the unmapped are listed: it may add one)
  for (const auto& [what, u] : m_.unmapped)
    m_.skipped.push_back(m_.file_of(u.file) + ":" + std::to_string(u.line) + ": " + what +
                         (u.count > 1 ? " (" + std::to_string(u.count) + " in all)" : "") + ": " + u.why);
  // the main file's lines first, in order, then each included file's (MJCF <include>)
  const auto where = [&](const std::string& why) {
    const bool main = why.compare(0, m_.path.size() + 1, m_.path + ":") == 0;
    const std::size_t colon = main ? m_.path.size() : why.rfind(':', why.find(": ") - 1);
    return std::make_pair(main ? std::string() : why.substr(0, colon), std::atoi(why.c_str() + colon + 1));
  };
  std::stable_sort(m_.skipped.begin(), m_.skipped.end(),
                   [&](const std::string& x, const std::string& y) { return where(x) < where(y); });
  const std::pair<Eigen::Vector3d, std::string> gravity = gravity_used(m_, o_);
  std::ostringstream s;
  s << "# Converted by phiq from " << single_line(m_.path) << " (" << m_.format << "): " << m_.units << "\n"
    << "# Gravity " << single_line(gravity.second) << "\n";
  if (!m_.skipped.empty()) s << "# Not mapped:\n";
  for (const std::string& why : m_.skipped) s << "#   " << single_line(why) << "\n";
  s << "phiq: 1\nname: " << yaml_quoted(m_.name)
    << "\ndescription: " << yaml_quoted(m_.format + " model, imported by phiq") << "\ndimension: 3\n";
  if (!coordinates_.str().empty()) s << "coordinates:\n" << coordinates_.str();
  s << "bodies:\n" << bodies.str();
  if (!constraints_.str().empty()) s << "constraints:\n" << constraints_.str();
  if (!drivers_.str().empty()) s << "drivers:\n" << drivers_.str();
  s << "time: {start: " << scene_number(o_.t_start) << ", end: " << scene_number(o_.t_end) << ", steps: " << o_.steps
    << "}\n";
  s << mass;
  if (!springs.empty())
    s << "loads:\n"
      << (gravity.first.isZero(0.0) ? "" : "  gravity: " + scene_vector(gravity.first) + "\n")
      << "  torsional_springs:\n"
      << springs;
  else if (!gravity.first.isZero(0.0))
    s << "loads: {gravity: " << scene_vector(gravity.first) << "}\n";
  const bool joints = std::any_of(m_.joints.begin(), m_.joints.end(), [](const Joint& j) { return !j.kind.empty(); });
  s << import_output_section(m_.path, o_.rates, o_.forces, !drivers_.str().empty(), joints, massive_);
  if (!limits.empty()) s << "limits:\n" << limits;
  return s.str();
}

}  // namespace

std::pair<Eigen::Vector3d, std::string> gravity_used(const Mechanism& m, const ImportOptions& options) {
  Eigen::Vector3d g = m.gravity;
  std::string from = m.gravity_from;
  if (options.gravity) {
    g = Eigen::Vector3d((*options.gravity)[0], (*options.gravity)[1], (*options.gravity)[2]);
    from = "--gravity";
    if (!g.allFinite()) refuse(m.path, 0, "--gravity: the components must be finite numbers (m/s²)");
  }
  return {g, scene_vector(g) + " m/s²: " + (g.isZero(0.0) ? "none, " : "") + from};
}

std::string write_mechanism_scene(Mechanism& m, const ImportOptions& options) {
  return MechanismWriter(m, options).write();
}

ModelImport mechanism_import(Mechanism& m, int loops, const ImportOptions& options) {
  ModelImport out;
  out.bodies = static_cast<int>(m.bodies.size()) - 1;
  out.joints = static_cast<int>(m.joints.size());
  out.loops = loops;
  out.couplers = static_cast<int>(m.couplers.size());
  out.yaml = write_mechanism_scene(m, options);
  out.gravity = gravity_used(m, options).second;
  out.skipped = std::move(m.skipped);
  return out;
}

}  // namespace phiq::detail::mechanism
