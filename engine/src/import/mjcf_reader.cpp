// MJCF (MuJoCo's XML) read as a mechanism::Mechanism through tinyxml2, which gives the line of every element.
// MuJoCo's semantics kept: a body's pose relative to its parent (pos, and quat, axisangle, euler with the compiler's
// eulerseq, xyaxes or zaxis; angles in degrees unless `<compiler angle="radian">`); joints in the body's frame at the
// model's pose, several in one body applied in order (phiq gives each after the first a massless body of its own);
// a body without a joint welded to its parent; default classes (`class`, `childclass`) for joints, geoms and
// inertials; geoms as parts' shapes (sizes are half-sizes in MJCF); `frame`s placing what they hold; `include`d files
// (mjcf_documents.hpp); equality constraints `connect`, `weld` (between bodies or sites) and `joint` as joints and
// couplers.
#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "base/quaternion_between.hpp"
#include "import/mjcf_reader.hpp"
#include "import/mjcf_option.hpp"
#include "phiq/scene.hpp"

namespace phiq {

namespace detail::mechanism {

void MjcfReader::compiler(const tinyxml2::XMLElement* e) {
  for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
    const std::string name = a->Name(), value = a->Value();
    if (name == "angle") {
      if (value != "degree" && value != "radian") fail(e, "<compiler angle=\"" + value + "\">: degree or radian");
      degrees_ = value == "degree";
    } else if (name == "eulerseq") {
      if (value.size() != 3 || value.find_first_not_of("xyzXYZ") != std::string::npos)
        fail(e, "<compiler eulerseq=\"" + value + "\">: three of x, y, z, X, Y, Z");
      eulerseq_ = value;
    } else if (name == "meshdir") {
      meshdir_ = value;
    } else if (name == "autolimits") {  // whether a range alone (limited="auto") limits its joint
      autolimits_ = value != "false";
    } else {
      skip_at(e, "<compiler " + name + ">", "a setting of MuJoCo's compiler phiq does not need");
    }
  }
}

void MjcfReader::defaults(const tinyxml2::XMLElement* e, const std::string& cls, const std::string& parent) {
  parent_class_[cls] = parent;
  for (const tinyxml2::XMLElement* c : docs_.children(e)) {
    const std::string tag = c->Name();
    if (tag == "default") {
      const char* name = c->Attribute("class");
      if (!name) fail(c, "a nested <default> without a class");
      defaults(c, name, cls);
    } else if (tag == "joint" || tag == "geom" || tag == "mesh") {
      Attributes& a = defaults_[cls][tag];
      for (const tinyxml2::XMLAttribute* x = c->FirstAttribute(); x; x = x->Next()) a[x->Name()] = x->Value();
    } else {
      unmapped(c, "defaults of elements phiq does not read");
    }
  }
}

void MjcfReader::assets(const tinyxml2::XMLElement* e) {
  for (const tinyxml2::XMLElement* c : docs_.children(e)) {
    if (std::string(c->Name()) != "mesh") {
      unmapped(c, "textures, materials and height fields: phiq's parts take rgba colours only");
      continue;
    }
    MeshAsset mesh;
    const char* file = c->Attribute("file");
    if (!file) fail(c, "<mesh> without a file (meshes given by vertices are not read)");
    mesh.file = meshdir_.empty() ? std::string(file) : (std::filesystem::path(meshdir_) / file).string();
    const std::vector<double> s = numbers(c, "scale", "", {1, 1, 1}, 3, 3);
    mesh.scale = Eigen::Vector3d(s[0], s[1], s[2]);
    std::string name = c->Attribute("name") ? c->Attribute("name") : std::filesystem::path(file).stem().string();
    meshes_[name] = mesh;
  }
}

const std::string* MjcfReader::attr(const tinyxml2::XMLElement* e, const char* name,
                                    const std::string& childclass) const {
  if (const tinyxml2::XMLAttribute* a = e->FindAttribute(name)) {
    static thread_local std::string value;  // (read at once by the caller)
    value = a->Value();
    return &value;
  }
  std::string cls = e->Attribute("class") ? e->Attribute("class") : childclass.empty() ? "main" : childclass;
  for (int depth = 0; depth < 64 && !cls.empty(); ++depth) {
    const auto c = defaults_.find(cls);
    if (c != defaults_.end())
      if (const auto t = c->second.find(e->Name()); t != c->second.end())
        if (const auto v = t->second.find(name); v != t->second.end()) return &v->second;
    const auto p = parent_class_.find(cls);
    if (p == parent_class_.end()) {
      if (cls != "main" && !defaults_.count(cls)) fail(e, "class '" + cls + "' is not a <default> class of the file");
      break;
    }
    cls = p->second;
  }
  return nullptr;
}

std::vector<double> MjcfReader::numbers(const tinyxml2::XMLElement* e, const char* name, const std::string& childclass,
                                        std::vector<double> fallback, std::size_t count_min,
                                        std::size_t count_max) const {
  const std::string* text = attr(e, name, childclass);
  if (!text) return fallback;
  std::istringstream in(*text);
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  if (!(in.eof()) || v.size() < count_min || v.size() > count_max || v.empty())
    fail(e, std::string("<") + e->Name() + " " + name + "=\"" + *text + "\">: " +
                (count_min == count_max ? std::to_string(count_min)
                                        : std::to_string(count_min) + " to " + std::to_string(count_max)) +
                " numbers");
  return v;
}

Eigen::Matrix3d MjcfReader::rotation(const tinyxml2::XMLElement* e, const std::string& cc) const {
  if (e->Attribute("quat")) {
    const std::vector<double> q = numbers(e, "quat", cc, {}, 4, 4);
    const Eigen::Quaterniond r(q[0], q[1], q[2], q[3]);
    if (!(r.norm() > 0)) fail(e, "a zero quat");
    return r.normalized().toRotationMatrix();
  }
  if (e->Attribute("axisangle")) {
    const std::vector<double> a = numbers(e, "axisangle", cc, {}, 4, 4);
    return axis_angle(Eigen::Vector3d(a[0], a[1], a[2]), angle(a[3]));
  }
  if (e->Attribute("euler")) {
    const std::vector<double> a = numbers(e, "euler", cc, {}, 3, 3);
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    for (std::size_t k = 0; k < 3; ++k) {
      const char c = eulerseq_[k];
      const Eigen::Matrix3d step = axis_angle(Eigen::Vector3d::Unit(std::tolower(c) - 'x'), angle(a[k]));
      R = std::islower(c) ? (R * step).eval() : (step * R).eval();  // lower case: about the moving axes
    }
    return R;
  }
  if (e->Attribute("xyaxes")) {
    const std::vector<double> a = numbers(e, "xyaxes", cc, {}, 6, 6);
    const Eigen::Vector3d x = Eigen::Vector3d(a[0], a[1], a[2]).normalized();
    const Eigen::Vector3d y =
        (Eigen::Vector3d(a[3], a[4], a[5]) - x.dot(Eigen::Vector3d(a[3], a[4], a[5])) * x).normalized();
    Eigen::Matrix3d R;
    R << x, y, x.cross(y);
    return R;
  }
  if (e->Attribute("zaxis")) {
    const std::vector<double> a = numbers(e, "zaxis", cc, {}, 3, 3);
    return detail::quaternion_between(Eigen::Vector3d::UnitZ(), Eigen::Vector3d(a[0], a[1], a[2])).toRotationMatrix();
  }
  return Eigen::Matrix3d::Identity();
}

Pose MjcfReader::pose(const tinyxml2::XMLElement* e, const std::string& cc) const {
  const std::vector<double> p = numbers(e, "pos", cc, {0, 0, 0}, 3, 3);
  return Pose{Eigen::Vector3d(p[0], p[1], p[2]), rotation(e, cc)};
}

void MjcfReader::geom(const tinyxml2::XMLElement* e, Body* b, const std::string& cc, bool* solid_only,
                      std::optional<double>* density) {
  const std::string* t = attr(e, "type", cc);
  const std::string type = t ? *t : "sphere";
  const std::vector<double> size = numbers(e, "size", cc, {0, 0, 0}, 1, 3);
  auto at = [&](std::size_t k) { return k < size.size() ? size[k] : 0.0; };
  Shape s;
  s.at = pose(e, cc);
  if (const std::string* rgba = attr(e, "rgba", cc)) {
    const std::vector<double> c = numbers(e, "rgba", cc, {}, 4, 4);
    s.rgba = Eigen::Vector4d(c[0], c[1], c[2], c[3]);
    (void)rgba;
  }
  if (attr(e, "mass", cc)) *solid_only = false;
  const std::vector<double> d = numbers(e, "density", cc, {1000}, 1, 1);
  if (!density->has_value())
    *density = d[0];
  else if (**density != d[0])
    *solid_only = false;
  if (e->Attribute("fromto") && (type == "capsule" || type == "cylinder")) {
    const std::vector<double> f = numbers(e, "fromto", cc, {}, 6, 6);
    const Eigen::Vector3d a(f[0], f[1], f[2]), c(f[3], f[4], f[5]);
    s.at = Pose{0.5 * (a + c), detail::quaternion_between(Eigen::Vector3d::UnitZ(), c - a).toRotationMatrix()};
    s.type = type, s.radius = at(0), s.length = (c - a).norm();
  } else if (e->Attribute("fromto")) {
    unmapped(e, "a " + type + " given by fromto is not read");
    *solid_only = false;
    return;
  } else if (type == "sphere") {
    s.type = "sphere", s.radius = at(0);
  } else if (type == "box") {
    s.type = "box", s.size = 2.0 * Eigen::Vector3d(at(0), at(1), at(2));
  } else if (type == "capsule" || type == "cylinder") {
    s.type = type, s.radius = at(0), s.length = 2.0 * at(1);
  } else if (type == "plane" && at(0) > 0 && at(1) > 0) {
    s.type = "plane", s.size = Eigen::Vector3d(2 * at(0), 2 * at(1), 0);
  } else if (type == "mesh") {
    const std::string* name = attr(e, "mesh", cc);
    if (!name || !meshes_.count(*name))
      fail(e, "geom of type mesh names no <mesh> asset" + (name ? " '" + *name + "'" : std::string()));
    const MeshAsset& mesh = meshes_.at(*name);
    *solid_only = false;
    std::string ext = std::filesystem::path(mesh.file).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    const std::filesystem::path folder = std::filesystem::path(path_).parent_path();
    if (ext != ".stl" && ext != ".obj") {
      skip_at(e, "<geom type=\"mesh\"> not STL or OBJ", "phiq's parts read STL and OBJ meshes");
      return;
    }
    if (mesh.scale.x() != mesh.scale.y() || mesh.scale.x() != mesh.scale.z()) {
      skip_at(e, "<geom type=\"mesh\"> scaled unevenly", "phiq scales a mesh by one factor");
      return;
    }
    if (!std::filesystem::exists(std::filesystem::path(mesh.file).is_absolute() ? std::filesystem::path(mesh.file)
                                                                                : folder / mesh.file)) {
      skip_at(e, "<geom type=\"mesh\"> file not found", "'" + mesh.file + "' is not beside the file");
      return;
    }
    // MuJoCo moves a mesh to its centre of mass and principal axes; phiq draws it in the file's own frame.
    skip_at(e, "<geom type=\"mesh\"> placement",
            "drawn in the mesh file's frame, not recentred at its centre of mass as MuJoCo does");
    s.type = "mesh", s.file = mesh.file, s.scale = mesh.scale.x();
  } else {
    unmapped(e, "a geom of type " + type + " has no phiq shape");
    *solid_only = false;
    return;
  }
  b->shapes.push_back(s);
}

int MjcfReader::body_named(const tinyxml2::XMLElement* e, const char* attribute, bool required) const {
  const char* name = e->Attribute(attribute);
  if (!name) {
    if (required) fail(e, std::string("<") + e->Name() + "> without " + attribute);
    return 0;
  }
  if (std::string(name) == "world") return 0;
  const auto it = body_index_.find(name);
  if (it == body_index_.end()) fail(e, std::string(attribute) + " '" + name + "' is not a body of the file");
  return it->second;
}

std::vector<MjcfReader::Placed> MjcfReader::placed(const tinyxml2::XMLElement* e, const std::string& childclass,
                                                   const Pose& frame) {
  std::vector<Placed> out;
  for (const tinyxml2::XMLElement* c : docs_.children(e)) {
    if (std::string(c->Name()) != "frame") {
      out.push_back(Placed{c, frame, childclass});
      continue;
    }
    const std::string cc = c->Attribute("childclass") ? c->Attribute("childclass") : childclass;
    for (Placed& inner : placed(c, cc, frame * pose(c, childclass))) out.push_back(std::move(inner));
  }
  return out;
}

void MjcfReader::placed_geom_or_site(const Placed& c, int body, bool* solid_only, std::optional<double>* density) {
  Body& b = m_.bodies[static_cast<std::size_t>(body)];
  if (std::string(c.e->Name()) == "geom") {
    const std::size_t before = b.shapes.size();
    geom(c.e, &b, c.childclass, solid_only, density);
    if (b.shapes.size() > before) b.shapes.back().at = c.frame * b.shapes.back().at;
    return;
  }
  if (const char* name = c.e->Attribute("name"))  // (a site: listed as not mapped all the same)
    if (!sites_.emplace(name, Site{body, c.frame * pose(c.e, c.childclass)}).second)
      fail(c.e, std::string("a second site named '") + name + "'");
  unmapped(c.e, "no kinematics: phiq outputs points instead");
}

void MjcfReader::body(const tinyxml2::XMLElement* e, int parent, const std::string& childclass, const Pose& frame) {
  const std::string cc = e->Attribute("childclass") ? e->Attribute("childclass") : childclass;
  Body b;
  b.name = e->Attribute("name") ? e->Attribute("name") : "body_" + std::to_string(m_.bodies.size());
  b.line = e->GetLineNum(), b.file = docs_.included_file(e);
  b.world = m_.bodies[static_cast<std::size_t>(parent)].world * frame * pose(e, cc);
  const int index = static_cast<int>(m_.bodies.size());
  if (e->Attribute("name") && !body_index_.emplace(b.name, index).second)
    fail(e, "a second body named '" + b.name + "'");
  std::vector<Placed> joints, children, geoms_and_sites;  // each with the pose of the <frame>s it is in
  bool solid_only = true, inertial = false;
  std::optional<double> density;
  for (const Placed& p : placed(e, cc)) {
    const tinyxml2::XMLElement* c = p.e;
    const std::string tag = c->Name();
    if (tag == "joint" || tag == "freejoint") {
      joints.push_back(p);
    } else if (tag == "body") {
      children.push_back(p);
    } else if (tag == "geom" || tag == "site") {
      geoms_and_sites.push_back(p);  // (once the body is in m_.bodies)
    } else if (tag == "inertial") {
      const Pose at = p.frame * pose(c, p.childclass);
      const std::vector<double> mass = numbers(c, "mass", p.childclass, {}, 1, 1);
      Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
      if (c->Attribute("fullinertia")) {
        const std::vector<double> f = numbers(c, "fullinertia", p.childclass, {}, 6, 6);
        I << f[0], f[3], f[4], f[3], f[1], f[5], f[4], f[5], f[2];
      } else {
        const std::vector<double> d = numbers(c, "diaginertia", p.childclass, {}, 3, 3);
        I.diagonal() << d[0], d[1], d[2];
      }
      if (mass.empty() || I.isZero(0.0)) fail(c, "<inertial> needs mass and diaginertia or fullinertia");
      b.has_mass = true, b.mass = mass[0], b.com = at.p, b.inertia = at.R * I * at.R.transpose();
      inertial = true;
    } else if (tag == "replicate" || tag == "composite" || tag == "flexcomp") {
      fail(c, "<" + tag + ">: not read by phiq (expand it into bodies first)");
    } else {
      unmapped(c, tag == "camera" || tag == "light" ? "no kinematics: phiq outputs points instead"
                                                    : "not an element phiq maps");
    }
  }
  m_.bodies.push_back(b);
  for (const Placed& p : geoms_and_sites) placed_geom_or_site(p, index, &solid_only, &density);
  Body& placed_body = m_.bodies[static_cast<std::size_t>(index)];
  if (!inertial && solid_only && density && !placed_body.shapes.empty()) placed_body.density = density;
  if (!inertial && !solid_only) skip_at(e, "mass from geoms", "given per geom or by meshes: the body gets no mass");
  // Its joints, in order; each after the first moves a massless body of its own, at the body's pose.
  int from = parent;
  if (joints.empty()) {
    Joint w;
    w.name = b.name + "_weld", w.line = b.line, w.file = b.file, w.kind = "rigid";
    const Pose rel = m_.bodies[static_cast<std::size_t>(from)].world.inverse() * b.world;
    w.parent = Side{from, rel.p, rel.R.col(2), rel.R.col(0)};
    w.child = Side{index, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
    m_.joints.push_back(w);
  }
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const tinyxml2::XMLElement* j = joints[k].e;
    const Pose& frame = joints[k].frame;            // its pos and axis are in the frame's axes
    const std::string& jcc = joints[k].childclass;  // a <frame childclass> applies within it
    int to = index;
    if (k + 1 < joints.size()) {
      Body step = Body::named(b.name + "_joint" + std::to_string(k + 1), j->GetLineNum(), b.world);
      step.file = b.file;
      to = static_cast<int>(m_.bodies.size());
      m_.bodies.push_back(step);
    }
    const std::string* t = attr(j, "type", jcc);
    const std::string type = std::string(j->Name()) == "freejoint" ? "free" : t ? *t : "hinge";
    Joint out;
    out.line = j->GetLineNum(), out.file = b.file;
    out.name = j->Attribute("name") ? j->Attribute("name") : b.name + "_joint_" + std::to_string(k);
    static const std::map<std::string, std::string> kinds = {
        {"hinge", "revolute"}, {"slide", "prismatic"}, {"ball", "spherical"}, {"free", ""}};
    const auto kind = kinds.find(type);
    if (kind == kinds.end())
      fail(j, "joint '" + out.name + "' has type '" + type + "': MJCF's are hinge, slide, ball, free");
    out.kind = kind->second;
    const std::vector<double> p = numbers(j, "pos", jcc, {0, 0, 0}, 3, 3);
    const std::vector<double> a = numbers(j, "axis", jcc, {0, 0, 1}, 3, 3);
    const Eigen::Vector3d at = frame.p + frame.R * Eigen::Vector3d(p[0], p[1], p[2]);
    const Eigen::Vector3d axis = frame.R * Eigen::Vector3d(a[0], a[1], a[2]);
    if (!(axis.norm() > 0)) fail(j, "joint '" + out.name + "': a zero axis");
    const Pose rel = m_.bodies[static_cast<std::size_t>(from)].world.inverse() * b.world;
    const Eigen::Vector3d ref = perpendicular(axis);
    out.parent = Side{from, rel.p + rel.R * at, rel.R * axis.normalized(), rel.R * ref};
    out.child = Side{to, at, axis.normalized(), ref};
    if (type == "ball")
      out.parent.axis = rel.R.col(2), out.parent.ref = rel.R.col(0), out.child.axis = Eigen::Vector3d::UnitZ(),
      out.child.ref = Eigen::Vector3d::UnitX();
    if (const std::vector<double> r = numbers(j, "ref", jcc, {0}, 1, 1); r[0] != 0.0)
      joint_ref_[static_cast<int>(m_.joints.size())] = type == "hinge" ? angle(r[0]) : r[0];
    // a hinge's or slide's spring, damper, frictionloss, armature and range (limited="true", or "auto", the default,
    // with the compiler's autolimits), all of q − ref, q = ref at the file's pose: a torsional spring and a limit
    const bool sprung = type == "hinge" || type == "slide";
    const auto value = [&](const char* name) { return sprung ? numbers(j, name, jcc, {0}, 1, 1)[0] : 0.0; };
    double* const loads[] = {&out.stiffness, &out.damping, &out.friction, &out.armature};
    const char* const fields[] = {"stiffness", "damping", "frictionloss", "armature", "springref", "range", "limited"};
    for (std::size_t k = 0; k < 4; ++k)
      if (!((*loads[k] = value(fields[k])) >= 0.0)) fail(j, "joint '" + out.name + "': a negative " + fields[k]);
    const double unit = type == "hinge" ? angle(1.0) : 1.0, q0 = value("ref");
    out.free = unit * (value("springref") - q0);
    const std::vector<double> range = sprung ? numbers(j, "range", jcc, {0, 0}, 2, 2) : std::vector<double>{0, 0};
    if (limited(attr(j, "limited", jcc))) out.lower = unit * (range[0] - q0), out.upper = unit * (range[1] - q0);
    const std::vector<double> force = sprung ? numbers(j, "actuatorfrcrange", jcc, {0, 0}, 2, 2) : range;
    if (sprung && limited(attr(j, "actuatorfrclimited", jcc))) out.effort_lower = force[0], out.effort_upper = force[1];
    for (std::size_t k = 0; !sprung && k < 7u; ++k)
      if (attr(j, fields[k], jcc)) skip_at(j, std::string("<joint ") + fields[k] + ">", "not modelled");
    if (!joint_index_.emplace(out.name, static_cast<int>(m_.joints.size())).second)
      fail(j, "a second joint named '" + out.name + "'");
    m_.joints.push_back(out);
    from = to;
  }
  for (const Placed& c : children) body(c.e, index, c.childclass, c.frame);
}

void MjcfReader::actuators(const tinyxml2::XMLElement* list) {
  std::map<int, std::pair<double, double>> sum;  // the joints' actuators' ranges, summed as MuJoCo sums their forces
  for (const tinyxml2::XMLElement* a = list->FirstChildElement(); a; a = a->NextSiblingElement()) {
    const char* name = a->Attribute("joint");
    const std::vector<double> range = numbers(a, "forcerange", "", {0, 0}, 2, 2);
    if (!name || !limited(attr(a, "forcelimited", "")) || !(range[0] < range[1])) continue;
    const auto it = joint_index_.find(name);
    if (it == joint_index_.end()) fail(a, "<" + std::string(a->Name()) + "> on joint '" + name + "', not in the file");
    const double gear = numbers(a, "gear", "", {1, 0, 0, 0, 0, 0}, 1, 6)[0];  // joint effort = gear · force
    auto& [lo, hi] = sum[it->second];
    lo += std::min(gear * range[0], gear * range[1]), hi += std::max(gear * range[0], gear * range[1]);
  }
  for (const auto& [joint, range] : sum) {  // (a joint's own actuatorfrcrange bounds them all: it stands)
    Joint& j = m_.joints[static_cast<std::size_t>(joint)];
    if (!(j.effort_lower < j.effort_upper)) j.effort_lower = range.first, j.effort_upper = range.second;
  }
}

Mechanism MjcfReader::read(int* loops) {
  m_.path = path_, m_.format = "MJCF";
  m_.units = "lengths in metres, angles in radians (the file's degrees converted), mass in kg, time in seconds.";
  const tinyxml2::XMLElement* root = docs_.parse(text_);
  if (!root || std::string(root->Name()) != "mujoco")
    refuse(path_, root ? root->GetLineNum() : 1, "an MJCF file's root element is <mujoco>");
  m_.name = root->Attribute("model") ? root->Attribute("model") : "";
  m_.bodies.push_back(Body::named("world", root->GetLineNum()));
  m_.gravity_from = "MuJoCo's default (the file has no <option gravity>)";
  // Settings first: compiler, defaults and assets apply to the bodies wherever they stand.
  for (const tinyxml2::XMLElement* e : docs_.children(root)) {
    const std::string tag = e->Name();
    if (tag == "compiler") compiler(e);
    if (tag == "option" && read_mjcf_option(e, docs_, m_))
      unmapped(e, "simulation settings other than gravity (timestep, integrator, ...): phiq sweeps kinematics");
  }
  for (const tinyxml2::XMLElement* e : docs_.children(root, "default")) defaults(e, "main", "");
  for (const tinyxml2::XMLElement* e : docs_.children(root, "asset")) assets(e);
  static const std::map<std::string, std::string> why = {
      {"size", "memory sizes of MuJoCo"},
      {"visual", "MuJoCo's rendering"},
      {"statistic", "MuJoCo's rendering"},
      {"contact", "contacts are not constraints in phiq (phiq clearance measures distances)"},
      {"tendon", "tendons are not read"},
      {"actuator", "actuators are forces, not drivers: drive joints with --drive (a joint's forcerange is read)"},
      {"sensor", "sensors: phiq outputs points, joints and orientations instead"},
      {"keyframe", "phiq starts from the model's pose"},
      {"custom", "user data"},
      {"extension", "plugins"},
  };
  for (const tinyxml2::XMLElement* e : docs_.children(root)) {
    const std::string tag = e->Name();
    if (tag == "worldbody") {
      bool solid = true;
      std::optional<double> density;
      for (const Placed& p : placed(e, "")) {
        const std::string t = p.e->Name();
        if (t == "body")
          body(p.e, 0, p.childclass, p.frame);
        else if (t == "geom" || t == "site")
          placed_geom_or_site(p, 0, &solid, &density);
        else if (t == "replicate")
          fail(p.e, "<" + t + ">: not read by phiq (expand it into bodies first)");
        else
          unmapped(p.e, "no kinematics: phiq outputs points instead");
      }
    } else if (tag == "equality") {
      continue;  // after every body is read
    } else if (tag != "compiler" && tag != "option" && tag != "default" && tag != "asset") {
      const auto it = why.find(tag);
      unmapped(e, it != why.end() ? it->second : "not an MJCF element phiq reads");
    }
  }
  for (const tinyxml2::XMLElement* e : docs_.children(root, "equality")) equality(e);
  for (const tinyxml2::XMLElement* e : docs_.children(root, "actuator")) actuators(e);
  *loops = loops_;
  return std::move(m_);
}

}  // namespace detail::mechanism

ModelImport import_mjcf(const std::string& text, const std::string& path, const ImportOptions& options) {
  int loops = 0;
  detail::mechanism::Mechanism m = detail::mechanism::MjcfReader(text, path).read(&loops);
  return detail::mechanism::mechanism_import(m, loops, options);
}

}  // namespace phiq
