// URDF read as a mechanism::Mechanism. urdfdom (Debian's liburdfdom) reads the tree: links, inertials, geometry,
// joints, mimics. tinyxml2 reads the file first, for what urdfdom does not give: the line of every element (so each
// message names FILE:LINE), the loop-closing joints (named `closing_*`), which it takes out because urdfdom refuses a
// graph that is not a tree, and the elements phiq does not map, listed once per kind.
//
// URDF's joint: the child link's frame is the parent's frame moved by `origin`, then by the joint's motion about or
// along `axis` (in the child's frame). So the parent's side is `origin` with its axis turned by origin's rotation,
// the child's side its own origin and `axis`; a `ref` perpendicular to the axis, the same direction on both sides at
// the model's pose, makes phiq's joint angle the URDF joint's position (0 in the file's pose).
#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <new>
#include <set>
#include <sstream>

#include "import/mechanism.hpp"
#include "phiq/scene.hpp"

namespace phiq {

namespace detail::mechanism {
namespace {

// urdfdom's messages (console_bridge) collected rather than printed, so that its refusal is phiq's one line.
class UrdfMessages : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors.push_back(text);
  }
  std::vector<std::string> errors;  // in order: the first says what, a later one may name the element
};

Eigen::Vector3d urdf_vector(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }
// urdfdom keeps colours as floats: the double of the float's shortest decimal (0.6f → 0.6, not 0.6000000238418579).
double urdf_colour(float c) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, c).ptr;
  return std::strtod(std::string(text, end).c_str(), nullptr);
}
Pose urdf_pose(const urdf::Pose& p) {
  return Pose{
      urdf_vector(p.position),
      Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).normalized().toRotationMatrix()};
}

// "x y z" of an attribute (absent: `fallback`); refused, naming the line, when it is not three numbers.
Eigen::Vector3d urdf_triple(const tinyxml2::XMLElement* e, const char* attribute, const Eigen::Vector3d& fallback,
                            const std::string& path) {
  const char* text = e ? e->Attribute(attribute) : nullptr;
  if (!text) return fallback;
  std::istringstream in(text);
  Eigen::Vector3d v;
  if (!(in >> v.x() >> v.y() >> v.z()) || !(in >> std::ws).eof())
    refuse(path, e->GetLineNum(),
           std::string("<") + e->Name() + " " + attribute + "=\"" + text + "\">: not three numbers");
  return v;
}

// URDF's rpy: R = Rz(yaw) Ry(pitch) Rx(roll).
Pose urdf_origin(const tinyxml2::XMLElement* parent, const std::string& path) {
  const tinyxml2::XMLElement* o = parent->FirstChildElement("origin");
  const Eigen::Vector3d xyz = urdf_triple(o, "xyz", Eigen::Vector3d::Zero(), path);
  const Eigen::Vector3d rpy = urdf_triple(o, "rpy", Eigen::Vector3d::Zero(), path);
  return Pose{
      xyz, (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
               .toRotationMatrix()};
}

struct UrdfJointXml {
  std::string name, type, parent, child;
  int line = 0, parent_line = 0, child_line = 0;
  const tinyxml2::XMLElement* element = nullptr;
};

const std::set<std::string> kUrdfJointTypes = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"};

class UrdfReader {
 public:
  UrdfReader(const std::string& text, const std::string& path, bool need_geometry)
      : text_(text), path_(path), need_geometry_(need_geometry) {}
  Mechanism read(int* loops);

 private:
  void scan();
  void check_tree() const;
  urdf::ModelInterfaceSharedPtr parse_urdfdom(const char* text) const;
  void map_joint(Joint* out, const std::string& type, const Pose& origin, const Eigen::Vector3d& axis_in, int parent,
                 int child, int line);
  std::optional<Shape> shape(const tinyxml2::XMLElement* geometry_owner, const urdf::Geometry* g,
                             const std::string& what);
  void unmapped(const tinyxml2::XMLElement* element);
  void dynamics(const tinyxml2::XMLElement* element, Joint& joint);

  const std::string& text_;
  const std::string& path_;
  bool need_geometry_ = false;  // a mesh that cannot be found is an error, not a shape left out
  tinyxml2::XMLDocument doc_;
  std::map<std::string, const tinyxml2::XMLElement*> links_;
  std::vector<UrdfJointXml> joints_, closing_;
  std::set<std::string> joint_names_;
  std::map<std::string, int> body_of_link_;
  Mechanism m_;
};

void UrdfReader::scan() {
  if (doc_.Parse(text_.data(), text_.size()) != tinyxml2::XML_SUCCESS) refuse_xml(path_, doc_);
  const tinyxml2::XMLElement* robot = doc_.RootElement();
  if (!robot || std::string(robot->Name()) != "robot")
    refuse(path_, robot ? robot->GetLineNum() : 1, "a URDF file's root element is <robot>");
  m_.name = robot->Attribute("name") ? robot->Attribute("name") : "";
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    const char* name = e->Attribute("name");
    if (tag == "link") {
      if (!name) refuse(path_, e->GetLineNum(), "<link> without a name");
      if (!links_.emplace(name, e).second)
        refuse(path_, e->GetLineNum(), std::string("a second link named '") + name + "'");
    } else if (tag == "joint") {
      UrdfJointXml j;
      j.element = e, j.line = e->GetLineNum();
      if (!name) refuse(path_, j.line, "<joint> without a name");
      j.name = name;
      j.type = e->Attribute("type") ? e->Attribute("type") : "";
      if (!kUrdfJointTypes.count(j.type))
        refuse(path_, j.line,
               "joint '" + j.name + "' has type '" + j.type +
                   "': URDF's are revolute, continuous, prismatic, fixed, floating, planar");
      for (auto [tag2, field, line] :
           {std::tuple{"parent", &j.parent, &j.parent_line}, std::tuple{"child", &j.child, &j.child_line}}) {
        const tinyxml2::XMLElement* x = e->FirstChildElement(tag2);
        if (!x || !x->Attribute("link"))
          refuse(path_, j.line, "joint '" + j.name + "' has no <" + tag2 + " link=\"...\">");
        *field = x->Attribute("link"), *line = x->GetLineNum();
      }
      if (!joint_names_.insert(j.name).second) refuse(path_, j.line, "a second joint named '" + j.name + "'");
      (j.name.rfind("closing_", 0) == 0 ? closing_ : joints_).push_back(j);
    } else if (tag != "material") {
      unmapped(e);
    }
  }
  for (const auto* list : {&joints_, &closing_})
    for (const UrdfJointXml& j : *list) {
      if (!links_.count(j.parent))
        refuse(path_, j.parent_line, "joint '" + j.name + "': parent link '" + j.parent + "' is not in the file");
      if (!links_.count(j.child))
        refuse(path_, j.child_line, "joint '" + j.name + "': child link '" + j.child + "' is not in the file");
    }
}

// A tree: each link one parent, no cycle. urdfdom refuses both too, without the line or the joints; here they are
// named, with the convention that closes a loop.
void UrdfReader::check_tree() const {
  std::map<std::string, const UrdfJointXml*> parent_joint;
  for (const UrdfJointXml& j : joints_) {
    if (const auto it = parent_joint.find(j.child); it != parent_joint.end())
      refuse(path_, j.line,
             "joint '" + j.name + "': link '" + j.child + "' already has a parent (joint '" + it->second->name +
                 "', line " + std::to_string(it->second->line) +
                 "); a joint that closes a loop is named closing_* (models/README.md)");
    parent_joint[j.child] = &j;
  }
  // Each joint leads up to its parent link's joint. A cycle is found by walking up from each joint once, marking
  // each joint (by its index in joints_) unseen 0, on this walk 1, done 2, on a cycle 3: linear in the joints, for a
  // serial chain of 10^5 links too. The first joint of the file on a cycle names it, with the cycle's from there.
  std::vector<char> state(joints_.size(), 0);
  auto at = [&](const UrdfJointXml* j) -> char& { return state[static_cast<std::size_t>(j - joints_.data())]; };
  const auto up = [&](const UrdfJointXml* j) -> const UrdfJointXml* {
    const auto it = parent_joint.find(j->parent);
    return it == parent_joint.end() ? nullptr : it->second;
  };
  for (const UrdfJointXml& start : joints_) {
    std::vector<const UrdfJointXml*> walk;
    const UrdfJointXml* j = &start;
    while (j && at(j) == 0) at(j) = 1, walk.push_back(j), j = up(j);
    const bool cycle = j && at(j) == 1;  // the walk came back onto itself: from j on, it is a cycle
    for (const UrdfJointXml* w : walk) at(w) = 2;
    if (cycle)
      for (auto it = std::find(walk.begin(), walk.end(), j); it != walk.end(); ++it) at(*it) = 3;
  }
  for (const UrdfJointXml& j : joints_) {
    if (at(&j) != 3) continue;
    std::string chain = j.name;
    for (const UrdfJointXml* k = up(&j); k != &j; k = up(k)) chain += ", " + k->name;
    refuse(path_, j.line,
           "joints " + chain + " form a cycle; a joint that closes a loop is named closing_* (models/README.md)");
  }
}

// <dynamics damping friction>: a revolute's or prismatic's viscous damping and Coulomb friction load it (a
// torsional spring of no stiffness in the scene).
void UrdfReader::dynamics(const tinyxml2::XMLElement* e, Joint& j) {
  for (const auto& [field, value] : {std::pair{"damping", &j.damping}, std::pair{"friction", &j.friction}})
    if (e->QueryDoubleAttribute(field, value) == tinyxml2::XML_WRONG_ATTRIBUTE_TYPE || !(*value >= 0.0) ||
        !std::isfinite(*value))
      refuse(path_, e->GetLineNum(), "joint '" + j.name + "': <dynamics " + field + "> is not a number ≥ 0");
}

void UrdfReader::unmapped(const tinyxml2::XMLElement* e) {
  static const std::map<std::string, std::string> why = {
      {"limit", "a closing joint's limits are not read"},
      {"dynamics", "a closing, fixed, floating or planar joint's damping and friction are not read"},
      {"safety_controller", "a controller's setting, not kinematics"},
      {"calibration", "a sensor's reference, not kinematics"},
      {"transmission", "actuators and gear trains to motors are not read (use a mimic joint for a coupling)"},
      {"gazebo", "simulator settings"},
  };
  const auto it = why.find(e->Name());
  m_.skip(std::string("<") + e->Name() + ">", e->GetLineNum(),
          it != why.end() ? it->second : "not a URDF element phiq reads");
}

// The file of `uri` (package://PACKAGE/REST): REST in the folder PACKAGE found on ROS_PACKAGE_PATH (each entry the
// package or a folder holding it), else in a folder above the URDF named PACKAGE, or holding one; relative to the
// URDF's folder when found above it (the way a path beside it is written), absolute from ROS_PACKAGE_PATH.
std::optional<std::string> package_file(const std::string& uri, const std::string& urdf_path) {
  namespace fs = std::filesystem;
  const std::string rest = uri.substr(10);
  const std::size_t slash = rest.find('/');
  if (slash == 0 || slash == std::string::npos) return std::nullopt;
  const std::string package = rest.substr(0, slash), inside = rest.substr(slash + 1);
  auto in = [&](const fs::path& folder) -> std::optional<fs::path> {
    if (fs::is_regular_file(folder / package / inside)) return folder / package / inside;
    if (folder.filename() == package && fs::is_regular_file(folder / inside)) return folder / inside;
    return std::nullopt;
  };
  if (const char* env = std::getenv("ROS_PACKAGE_PATH")) {
    std::string list = env;
    for (std::size_t at = 0; at <= list.size();) {
      std::size_t end = list.find(':', at);
      if (end == std::string::npos) end = list.size();
      const fs::path entry = fs::path(list.substr(at, end - at)).lexically_normal();
      at = end + 1;
      if (entry.empty()) continue;
      if (const auto p = in(entry.has_filename() ? entry : entry.parent_path()))
        return fs::absolute(*p).lexically_normal().string();
    }
  }
  const fs::path folder = fs::absolute(fs::path(urdf_path)).parent_path();
  for (fs::path above = folder; !above.empty(); above = above.parent_path()) {
    if (const auto p = in(above)) return p->lexically_relative(folder).string();
    if (above == above.root_path()) break;
  }
  return std::nullopt;
}

std::optional<Shape> UrdfReader::shape(const tinyxml2::XMLElement* owner, const urdf::Geometry* g,
                                       const std::string& what) {
  Shape s;
  s.at = urdf_origin(owner, path_);
  if (!g) return std::nullopt;
  switch (g->type) {
    case urdf::Geometry::SPHERE:
      s.type = "sphere", s.radius = static_cast<const urdf::Sphere*>(g)->radius;
      break;
    case urdf::Geometry::BOX:
      s.type = "box", s.size = urdf_vector(static_cast<const urdf::Box*>(g)->dim);
      break;
    case urdf::Geometry::CYLINDER:
      s.type = "cylinder", s.radius = static_cast<const urdf::Cylinder*>(g)->radius;
      s.length = static_cast<const urdf::Cylinder*>(g)->length;
      break;
    case urdf::Geometry::MESH: {
      const auto* mesh = static_cast<const urdf::Mesh*>(g);
      std::string file = mesh->filename;
      if (file.rfind("file://", 0) == 0) file = file.substr(7);
      const int line = owner->GetLineNum();
      if (file.rfind("package://", 0) == 0) {
        const std::optional<std::string> found = package_file(file, path_);
        if (!found && need_geometry_)
          refuse(path_, line,
                 what + " mesh '" + file + "': its package is neither on ROS_PACKAGE_PATH nor a folder " +
                     "above the file");
        if (!found) {
          m_.skip(what + " mesh of a package not found", line,
                  "its package is neither on ROS_PACKAGE_PATH nor a folder above the file (the link is drawn without)");
          return std::nullopt;
        }
        file = *found;
      }
      if (file.find("://") != std::string::npos) {
        m_.skip(what + " mesh of a URI", line, "phiq reads mesh files by path or package:// only");
        return std::nullopt;
      }
      std::string ext = std::filesystem::path(file).extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
      const Eigen::Vector3d scale = urdf_vector(mesh->scale);
      if (ext != ".stl" && ext != ".obj") {
        m_.skip(what + " mesh not STL or OBJ", line, "phiq's parts read STL and OBJ meshes");
        return std::nullopt;
      }
      if (std::abs(scale.x() - scale.y()) > 0 || std::abs(scale.x() - scale.z()) > 0) {
        m_.skip(what + " mesh scaled unevenly", line, "phiq scales a mesh by one factor");
        return std::nullopt;
      }
      const std::filesystem::path folder = std::filesystem::path(path_).parent_path();
      if (!std::filesystem::exists(std::filesystem::path(file).is_absolute() ? std::filesystem::path(file)
                                                                             : folder / file)) {
        m_.skip(what + " mesh file not found", line, "'" + file + "' is not beside the file");
        return std::nullopt;
      }
      s.type = "mesh", s.file = file, s.scale = scale.x();
      break;
    }
    default:
      return std::nullopt;
  }
  return s;
}

void UrdfReader::map_joint(Joint* out, const std::string& type, const Pose& origin, const Eigen::Vector3d& axis_in,
                           int parent, int child, int line) {
  Eigen::Vector3d axis = type == "fixed" || type == "floating" ? Eigen::Vector3d::UnitX() : axis_in;
  if (!(axis.norm() > 0.0)) refuse(path_, line, "joint '" + out->name + "': a zero axis");
  axis.normalize();
  const Eigen::Vector3d ref = perpendicular(axis);
  out->line = line;
  out->parent = Side{parent, origin.p, origin.R * axis, origin.R * ref};
  out->child = Side{child, Eigen::Vector3d::Zero(), axis, ref};
  if (type == "revolute" || type == "continuous") out->kind = "revolute";
  if (type == "prismatic") out->kind = "prismatic";
  if (type == "planar") out->kind = "planar";
  if (type == "floating") out->kind = "";
  if (type == "fixed") {
    out->kind = "rigid";
    out->parent = Side{parent, origin.p, origin.R.col(2), origin.R.col(0)};
    out->child = Side{child, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  }
}

// The tree (without its closing joints) as urdfdom reads it; refused, at the element its messages name, when it
// logs an error or throws.
urdf::ModelInterfaceSharedPtr UrdfReader::parse_urdfdom(const char* text) const {
  urdf::ModelInterfaceSharedPtr model;
  static std::mutex urdfdom_console;  // console_bridge's handler is one per process
  std::lock_guard<std::mutex> lock(urdfdom_console);
  UrdfMessages messages;
  console_bridge::useOutputHandler(&messages);
  try {
    model = urdf::parseURDF(text);
  } catch (const std::bad_alloc&) {  // the machine's refusal, not the model's: phiq's out-of-memory exit
    console_bridge::restorePreviousOutputHandler();
    throw;
  } catch (const std::exception& e) {
    model = nullptr;
    messages.errors.push_back(e.what());
  }
  console_bridge::restorePreviousOutputHandler();
  // An error urdfdom logged is a part of the model it dropped, even when it returns one (a mass of "abc": the
  // link without its inertial or visuals, which this reader then indexed: "internal error: vector::_M_range_check")
  if (!model || !messages.errors.empty()) {  // the first message says what; it or a later one names the element
    int line = 0;
    for (const std::string& why : messages.errors) {
      const std::size_t open = why.find('['), close = why.find(']', open + 1);
      if (line != 0 || open == std::string::npos || close == std::string::npos) continue;
      const std::string name = why.substr(open + 1, close - open - 1);
      for (const UrdfJointXml& j : joints_)
        if (j.name == name) line = j.line;
      if (const auto l = links_.find(name); line == 0 && l != links_.end()) line = l->second->GetLineNum();
    }
    refuse(path_, line,
           "urdfdom refused the model: " + (messages.errors.empty() ? "no reason given" : messages.errors.front()));
  }
  return model;
}

Mechanism UrdfReader::read(int* loops) {
  m_.path = path_, m_.format = "URDF";
  m_.units = "lengths in metres, angles in radians, mass in kg, time in seconds.";
  m_.gravity_from = "URDF states no gravity: the conventional value";
  scan();
  check_tree();
  // urdfdom reads the tree without the closing joints.
  tinyxml2::XMLElement* robot = doc_.RootElement();
  for (const UrdfJointXml& j : closing_) robot->DeleteChild(const_cast<tinyxml2::XMLElement*>(j.element));
  for (UrdfJointXml& j : closing_) j.element = nullptr;
  tinyxml2::XMLDocument full;  // the closing joints' elements, read again from the text for their fields
  full.Parse(text_.data(), text_.size());
  tinyxml2::XMLPrinter printer;
  doc_.Print(&printer);
  const urdf::ModelInterfaceSharedPtr model = parse_urdfdom(printer.CStr());
  // Bodies: the root link is the ground; the others in the tree's order, placed by their joints' origins.
  const urdf::LinkConstSharedPtr root = model->getRoot();
  m_.bodies.push_back(Body::named(root->name, links_.at(root->name)->GetLineNum()));
  body_of_link_[root->name] = 0;
  // Depth first, a link's children in the file's order; by an explicit stack, as a serial chain of 10^5 links
  // is as deep as it is long and would overflow the call stack.
  std::vector<std::pair<urdf::LinkConstSharedPtr, std::size_t>> path{{root, 0}};
  while (!path.empty()) {
    auto& [link, next] = path.back();
    if (next == link->child_joints.size()) {
      path.pop_back();
      continue;
    }
    const urdf::JointSharedPtr& j = link->child_joints[next++];
    Body b = Body::named(j->child_link_name, links_.at(j->child_link_name)->GetLineNum());
    b.world = m_.bodies[static_cast<std::size_t>(body_of_link_.at(link->name))].world *
              urdf_pose(j->parent_to_joint_origin_transform);
    body_of_link_[j->child_link_name] = static_cast<int>(m_.bodies.size());
    m_.bodies.push_back(b);
    path.emplace_back(model->getLink(j->child_link_name), 0);
  }
  for (const auto& [name, element] : links_)
    if (!body_of_link_.count(name))
      refuse(path_, element->GetLineNum(), "link '" + name + "' is joined to no other (only one root is allowed)");
  // Each link's inertial and shapes.
  for (Body& b : m_.bodies) {
    const urdf::LinkConstSharedPtr link = model->getLink(b.name);
    const tinyxml2::XMLElement* xml = links_.at(b.name);
    if (link->inertial && link->inertial->mass > 0.0) {
      const urdf::Inertial& in = *link->inertial;
      const Pose c = urdf_pose(in.origin);
      Eigen::Matrix3d I;
      I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      b.has_mass = &b != &m_.bodies.front();
      b.mass = in.mass, b.com = c.p, b.inertia = c.R * I * c.R.transpose();
      if (!b.has_mass)
        m_.skip("<inertial> of the root link", xml->FirstChildElement("inertial")->GetLineNum(),
                "the root link is the ground; its mass moves nothing");
    }
    const bool has_visual = !link->visual_array.empty();
    std::size_t k = 0;
    for (const tinyxml2::XMLElement* e = xml->FirstChildElement("visual"); e;
         e = e->NextSiblingElement("visual"), ++k) {
      const urdf::VisualSharedPtr& v = link->visual_array.at(k);
      std::optional<Shape> s = shape(e, v->geometry.get(), "<visual>");
      if (s && v->material)
        s->rgba = Eigen::Vector4d(urdf_colour(v->material->color.r), urdf_colour(v->material->color.g),
                                  urdf_colour(v->material->color.b), urdf_colour(v->material->color.a));
      if (s) b.shapes.push_back(*s);
    }
    k = 0;
    for (const tinyxml2::XMLElement* e = xml->FirstChildElement("collision"); e;
         e = e->NextSiblingElement("collision"), ++k) {
      if (has_visual) {
        m_.skip("<collision>", e->GetLineNum(), "a link's visual shapes stand for it; collision shapes only without");
        continue;
      }
      std::optional<Shape> s = shape(e, link->collision_array.at(k)->geometry.get(), "<collision>");
      if (s) b.shapes.push_back(*s);
    }
    for (const tinyxml2::XMLElement* e = xml->FirstChildElement(); e; e = e->NextSiblingElement()) {
      const std::string tag = e->Name();
      if (tag != "inertial" && tag != "visual" && tag != "collision") unmapped(e);
    }
  }
  // Joints: the tree's in the file's order, then the closing ones.
  std::map<std::string, int> joint_index;
  for (const UrdfJointXml& x : joints_) {
    const urdf::JointConstSharedPtr j = model->getJoint(x.name);
    Joint out;
    out.name = x.name;
    map_joint(&out, x.type, urdf_pose(j->parent_to_joint_origin_transform), urdf_vector(j->axis),
              body_of_link_.at(x.parent), body_of_link_.at(x.child), x.line);
    for (const tinyxml2::XMLElement* e = x.element->FirstChildElement(); e; e = e->NextSiblingElement()) {
      const std::string tag = e->Name();
      if (tag == "dynamics" && (out.kind == "revolute" || out.kind == "prismatic")) {
        dynamics(e, out);
        continue;
      }
      if (tag == "limit" && j->limits && (out.kind == "revolute" || out.kind == "prismatic")) {
        // (urdfdom's: lower and upper a continuous joint has not; velocity and effort ≥ 0 by the format)
        if (x.type != "continuous") out.lower = j->limits->lower, out.upper = j->limits->upper;
        out.velocity = j->limits->velocity, out.effort_lower = -j->limits->effort, out.effort_upper = j->limits->effort;
        continue;
      }
      if (tag != "origin" && tag != "axis" && tag != "parent" && tag != "child" && tag != "mimic") unmapped(e);
    }
    joint_index[x.name] = static_cast<int>(m_.joints.size());
    m_.joints.push_back(out);
  }
  // The closing joints, read from the text as written (their elements were taken out of doc_).
  const tinyxml2::XMLElement* full_robot = full.RootElement();
  for (const UrdfJointXml& x : closing_) {
    const tinyxml2::XMLElement* e = full_robot->FirstChildElement("joint");
    while (e && !(e->GetLineNum() == x.line && e->Attribute("name") && x.name == e->Attribute("name")))
      e = e->NextSiblingElement("joint");
    if (x.type == "floating") refuse(path_, x.line, "closing joint '" + x.name + "' is floating: it closes nothing");
    if (e->FirstChildElement("mimic"))
      refuse(path_, x.line, "closing joint '" + x.name + "': a mimic on a closing joint is not read");
    Joint out;
    out.name = x.name, out.closing = true;
    map_joint(&out, x.type, urdf_origin(e, path_),
              urdf_triple(e->FirstChildElement("axis"), "xyz", Eigen::Vector3d::UnitX(), path_),
              body_of_link_.at(x.parent), body_of_link_.at(x.child), x.line);
    joint_index[x.name] = static_cast<int>(m_.joints.size());
    m_.joints.push_back(out);
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
      const std::string tag = c->Name();
      if (tag != "origin" && tag != "axis" && tag != "parent" && tag != "child") unmapped(c);
    }
  }
  *loops = static_cast<int>(closing_.size());
  // Mimic joints: joint = multiplier · mimicked + offset.
  for (const UrdfJointXml& x : joints_) {
    const urdf::JointConstSharedPtr j = model->getJoint(x.name);
    if (!j->mimic) continue;
    const tinyxml2::XMLElement* e = x.element->FirstChildElement("mimic");
    const int line = e ? e->GetLineNum() : x.line;
    const auto other = joint_index.find(j->mimic->joint_name);
    if (other == joint_index.end())
      refuse(path_, line,
             "joint '" + x.name + "' mimics '" + j->mimic->joint_name + "', which is not a joint of the file");
    m_.couplers.push_back(Coupler{x.name + "_mimic", line, joint_index.at(x.name), other->second, j->mimic->multiplier,
                                  j->mimic->offset, ""});  // file: the URDF itself
  }
  return std::move(m_);
}

}  // namespace
}  // namespace detail::mechanism

ModelImport import_urdf(const std::string& text, const std::string& path, const ImportOptions& options) {
  int loops = 0;
  detail::mechanism::Mechanism m = detail::mechanism::UrdfReader(text, path, options.need_geometry).read(&loops);
  return detail::mechanism::mechanism_import(m, loops, options);
}

}  // namespace phiq
