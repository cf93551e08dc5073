// SDF read as a mechanism::Mechanism through Debian's libsdformat 12, which checks the file against the SDFormat
// specification, resolves every pose (`relative_to`, frames) and gives each element's line. One model (the file's, or
// the first of its world); its frame is phiq's world frame. SDF's joints form any graph, so a loop closes natively:
// each joint joins its parent and child links at the joint frame, at the links' poses in the file. A link that no
// joint joins to `world` moves freely, as in SDF. This file is the module libphiq_sdf.so, which the engine loads on
// the first SDF file it reads (sdf_module.hpp says why).
#include <console_bridge/console.h>
#include <sdf/Console.hh>
#include <sdf/Geometry.hh>
#include <sdf/Joint.hh>
#include <sdf/JointAxis.hh>
#include <sdf/Link.hh>
#include <sdf/Model.hh>
#include <sdf/ParserConfig.hh>
#include <sdf/Root.hh>
#include <sdf/Visual.hh>
#include <sdf/World.hh>
#include <sdf/parser.hh>
#include <tinyxml2.h>
#include <sdf/Box.hh>
#include <sdf/Capsule.hh>
#include <sdf/Cylinder.hh>
#include <sdf/Sphere.hh>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <new>
#include <set>
#include <sstream>

#include "import/mechanism.hpp"
#include "import/sdf_module.hpp"
#include "phiq/scene.hpp"

namespace phiq {

namespace detail::mechanism {
namespace {

// urdfdom, which libsdformat asks whether a file it cannot read as SDF is URDF, prints its refusal on standard
// error through console_bridge ("Error: Could not find the 'robot' element"): quiet while libsdformat reads, so
// that phiq's refusal is the one line. console_bridge's handler is one per process: this one lives as long as the
// process, so that a handler left set by readers on two threads never dangles.
class SdfQuietUrdfdom : public console_bridge::OutputHandler {
 public:
  void log(const std::string&, console_bridge::LogLevel, const char*, int) override {}
};

Eigen::Vector3d sdf_vector(const ignition::math::Vector3d& v) { return {v.X(), v.Y(), v.Z()}; }
Pose sdf_pose(const ignition::math::Pose3d& p) {
  const ignition::math::Quaterniond& q = p.Rot();
  return Pose{sdf_vector(p.Pos()), Eigen::Quaterniond(q.W(), q.X(), q.Y(), q.Z()).normalized().toRotationMatrix()};
}
int sdf_line(const sdf::ElementPtr& e) { return e && e->LineNumber() ? *e->LineNumber() : 0; }
// The file an element was read from when an <include> brought it in; "" for the file being read.
std::string sdf_file(const sdf::ElementPtr& e, const std::string& path) {
  const std::string f = e ? e->FilePath() : "";
  return f.empty() || f == path || f == "data-string" ? "" : f;
}

// The environment variables whose folders hold the models an <include><uri>model://NAME</uri> names, in the order
// Gazebo's find-file callback searches them (libsdformat searches SDF_PATH itself, then asks the callback).
constexpr const char* kSdfResourcePaths[] = {"SDF_PATH", "GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH"};

// The file or folder of a URI (`model://NAME/...`, the scheme dropped) in the first folder of kSdfResourcePaths that
// has it; "" (and the URI appended to `unresolved`) when none has.
std::string sdf_find_resource(const std::string& uri, std::vector<std::string>* unresolved) {
  const std::size_t scheme = uri.find("://");
  const std::string rest = scheme == std::string::npos ? uri : uri.substr(scheme + 3);
  for (const char* variable : kSdfResourcePaths) {
    const char* value = std::getenv(variable);
    std::stringstream folders(value ? value : "");
    for (std::string folder; std::getline(folders, folder, ':');) {
      std::error_code ec;
      if (!folder.empty() && std::filesystem::exists(std::filesystem::path(folder) / rest, ec))
        return (std::filesystem::path(folder) / rest).string();
    }
  }
  unresolved->push_back(uri);
  return "";
}

class SdfReader {
 public:
  SdfReader(const std::string& text, const std::string& path) : text_(text), path_(path) {}
  Mechanism read(int* loops);

 private:
  // Children of `e` written in the file and not in `mapped`, listed once per kind.
  void unmapped_children(const sdf::ElementPtr& e, const std::set<std::string>& mapped, const std::string& why) {
    for (sdf::ElementPtr c = e->GetFirstElement(); c; c = c->GetNextElement(""))
      if (c->GetExplicitlySetInFile() && !mapped.count(c->GetName()))
        m_.skip("<" + e->GetName() + "><" + c->GetName() + ">", sdf_line(c), why, sdf_file(c, path_));
  }
  void sdf_gravity(const sdf::Root& root);
  void link(const sdf::Link& l, Body* b);
  // A model's links, then its nested models' (named MODEL::LINK, as SDF scopes them), then its joints; `placed`: the
  // model's frame in the top model's, `prefix`: its scope ("" for the top model, "arm::" for a model arm in it).
  void model(const sdf::Model& model, const Pose& placed, const std::string& prefix);
  void joint(const sdf::Joint& j, const Pose& placed, const std::string& prefix);

  const std::string& text_;
  const std::string& path_;
  Mechanism m_;
  std::map<std::string, int> body_of_;  // a link's scoped name → its body
  std::size_t links_ = 0;
};

void SdfReader::link(const sdf::Link& l, Body* b) {
  const sdf::ElementPtr e = l.Element();
  if (const sdf::ElementPtr in = e->FindElement("inertial"); in && in->GetExplicitlySetInFile()) {
    const ignition::math::Inertiald& inertial = l.Inertial();
    b->has_mass = true, b->mass = inertial.MassMatrix().Mass();
    b->com = sdf_vector(inertial.Pose().Pos());
    const ignition::math::Matrix3d I = inertial.Moi();  // about the centre, in the link's axes
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) b->inertia(r, c) = I(r, c);
  }
  for (uint64_t k = 0; k < l.VisualCount(); ++k) {
    const sdf::Visual* v = l.VisualByIndex(k);
    const sdf::Geometry* g = v->Geom();
    ignition::math::Pose3d at;
    (void)v->SemanticPose().Resolve(at, l.Name());
    Shape s;
    s.at = sdf_pose(at);
    if (g->Type() == sdf::GeometryType::BOX) {
      s.type = "box", s.size = sdf_vector(g->BoxShape()->Size());
    } else if (g->Type() == sdf::GeometryType::SPHERE) {
      s.type = "sphere", s.radius = g->SphereShape()->Radius();
    } else if (g->Type() == sdf::GeometryType::CYLINDER) {
      s.type = "cylinder", s.radius = g->CylinderShape()->Radius(), s.length = g->CylinderShape()->Length();
    } else if (g->Type() == sdf::GeometryType::CAPSULE) {
      s.type = "capsule", s.radius = g->CapsuleShape()->Radius(), s.length = g->CapsuleShape()->Length();
    } else {
      m_.skip("<visual><geometry> other than box, sphere, cylinder, capsule", sdf_line(v->Element()),
              "meshes, planes and height maps of SDF are not read", sdf_file(v->Element(), path_));
      continue;
    }
    b->shapes.push_back(s);
  }
  unmapped_children(e, {"pose", "inertial", "visual"}, "not kinematics, or drawn from the visuals");
}

void SdfReader::model(const sdf::Model& model, const Pose& placed, const std::string& prefix) {
  if (model.Static()) refuse(path_, sdf_line(model.Element()), "a static model does not move");
  for (uint64_t k = 0; k < model.LinkCount(); ++k) {
    const sdf::Link* l = model.LinkByIndex(k);
    ignition::math::Pose3d pose;
    (void)l->SemanticPose().Resolve(pose, "__model__");
    Body b = Body::named(prefix + l->Name(), sdf_line(l->Element()), placed * sdf_pose(pose));
    link(*l, &b);
    body_of_[b.name] = static_cast<int>(m_.bodies.size());
    m_.bodies.push_back(b);
    ++links_;
  }
  for (uint64_t k = 0; k < model.ModelCount(); ++k) {
    const sdf::Model* nested = model.ModelByIndex(k);
    ignition::math::Pose3d pose;
    (void)nested->SemanticPose().Resolve(pose, "__model__");
    this->model(*nested, placed * sdf_pose(pose), prefix + nested->Name() + "::");
  }
  for (uint64_t k = 0; k < model.JointCount(); ++k) joint(*model.JointByIndex(k), placed, prefix);
  unmapped_children(model.Element(), {"link", "joint", "pose", "static", "model"}, "not an element phiq maps");
}

void SdfReader::joint(const sdf::Joint& j, const Pose& placed, const std::string& prefix) {
  Joint out;
  out.name = prefix + j.Name(), out.line = sdf_line(j.Element());
  auto body = [&](const std::string& name, const char* side) {
    if (name == "world") return 0;
    const auto it = body_of_.find(prefix + name);
    if (it == body_of_.end())
      refuse(path_, out.line, "joint '" + out.name + "': " + side + " '" + name + "' is not a link of the model");
    return it->second;
  };
  const int parent = body(j.ParentLinkName(), "parent"), child = body(j.ChildLinkName(), "child");
  ignition::math::Pose3d frame;
  (void)j.SemanticPose().Resolve(frame, "__model__");
  const Pose J = placed * sdf_pose(frame);
  auto axis_of = [&](unsigned index) {
    ignition::math::Vector3d xyz(0, 0, 1);
    if (const sdf::JointAxis* a = j.Axis(index)) (void)a->ResolveXyz(xyz, "__model__");
    return (placed.R * sdf_vector(xyz)).normalized();
  };
  const Pose& wp = m_.bodies[static_cast<std::size_t>(parent)].world;
  const Pose& wc = m_.bodies[static_cast<std::size_t>(child)].world;
  auto sides = [&](const Eigen::Vector3d& a1, const Eigen::Vector3d& r1, const Eigen::Vector3d& a2,
                   const Eigen::Vector3d& r2) {
    out.parent = Side{parent, wp.inverse().R * (J.p - wp.p), wp.R.transpose() * a1, wp.R.transpose() * r1};
    out.child = Side{child, wc.inverse().R * (J.p - wc.p), wc.R.transpose() * a2, wc.R.transpose() * r2};
  };
  switch (j.Type()) {
    case sdf::JointType::REVOLUTE:
    case sdf::JointType::CONTINUOUS:
    case sdf::JointType::PRISMATIC: {
      const Eigen::Vector3d a = axis_of(0), r = perpendicular(a);
      sides(a, r, a, r);
      out.kind = j.Type() == sdf::JointType::PRISMATIC ? "prismatic" : "revolute";
      if (const sdf::JointAxis* ax = j.Axis(0)) {  // its spring-damper (position 0 at the file's pose)
        out.stiffness = ax->SpringStiffness(), out.damping = ax->Damping(), out.free = ax->SpringReference();
        out.friction = ax->Friction();
        // its limits (SDF's "none", ±1e16, ±inf or −1, are left out as the scene is written)
        out.lower = ax->Lower(), out.upper = ax->Upper(), out.velocity = ax->MaxVelocity();
        out.effort_lower = -ax->Effort(), out.effort_upper = ax->Effort();
        if (!(out.stiffness >= 0.0 && out.damping >= 0.0 && out.friction >= 0.0))
          refuse(path_, out.line, "joint '" + out.name + "': a negative spring_stiffness, damping or friction");
      }
      break;
    }
    case sdf::JointType::BALL:
    case sdf::JointType::FIXED:
      sides(J.R.col(2), J.R.col(0), J.R.col(2), J.R.col(0));
      out.kind = j.Type() == sdf::JointType::BALL ? "spherical" : "rigid";
      break;
    case sdf::JointType::UNIVERSAL: {
      const Eigen::Vector3d a1 = axis_of(0), a2 = axis_of(1);
      if (std::abs(a1.dot(a2)) > 1e-9)
        refuse(path_, out.line,
               "universal joint '" + out.name + "': its axes are not perpendicular in the file's pose");
      sides(a1, perpendicular(a1), a2, perpendicular(a2));
      out.kind = "universal";
      break;
    }
    default:
      refuse(path_, out.line,
             "joint '" + out.name + "': SDF's " + j.Element()->GetAttribute("type")->GetAsString() +
                 " joint has no exact phiq form here (screw: SDF does not state thread_pitch's unit)");
  }
  m_.joints.push_back(out);
  const char* why = "limits, dynamics and sensors are not kinematics";
  unmapped_children(j.Element(), {"parent", "child", "pose", "axis", "axis2"}, why);
  const bool sprung = out.kind == "revolute" || out.kind == "prismatic";
  for (const char* axis : {"axis", "axis2"})
    if (const sdf::ElementPtr a = j.Element()->FindElement(axis)) {
      const bool read = sprung && axis[4] == 0;  // (a revolute's or prismatic's one axis)
      unmapped_children(a, {"xyz", read ? "dynamics" : "xyz", read ? "limit" : "xyz"}, why);
      if (const sdf::ElementPtr d = a->FindElement("dynamics"); d && read)
        unmapped_children(d, {"damping", "friction", "spring_stiffness", "spring_reference"}, "not modelled");
      if (const sdf::ElementPtr l = a->FindElement("limit"); l && read)
        unmapped_children(l, {"lower", "upper", "velocity", "effort"}, "not modelled");
    }
}

// The world's gravity as libsdformat reads it (SDFormat's default where the world has no <gravity>); a file that
// is a bare model, with no world, gets the default of a world that has no <gravity>.
void SdfReader::sdf_gravity(const sdf::Root& root) {
  if (root.WorldCount() > 0) {
    const sdf::World& world = *root.WorldByIndex(0);
    m_.gravity = sdf_vector(world.Gravity());
    const sdf::ElementPtr g = world.Element()->FindElement("gravity");
    m_.gravity_from = g && g->GetExplicitlySetInFile()
                          ? "the world's <gravity> at " + path_ + ":" + std::to_string(sdf_line(g))
                          : "SDFormat's default: the world has no <gravity>";
    return;
  }
  sdf::ElementPtr world(new sdf::Element);
  if (!sdf::initFile("world.sdf", world)) {
    m_.gravity_from = "the file has no <world>: the conventional value";
    return;
  }
  m_.gravity = sdf_vector(world->GetElement("gravity")->Get<ignition::math::Vector3d>());
  m_.gravity_from = "the file has no <world>: SDFormat's default of a world without <gravity>";
}

Mechanism SdfReader::read(int* loops) {
  m_.path = path_, m_.format = "SDF";
  m_.units = "lengths in metres, angles in radians, mass in kg, time in seconds.";
  {  // as the URDF and MJCF readers say it (libsdformat's own message holds the whole text, and no line)
    tinyxml2::XMLDocument xml;
    if (xml.Parse(text_.data(), text_.size()) != tinyxml2::XML_SUCCESS) refuse_xml(path_, xml);
  }
  sdf::Root root;
  {
    static std::mutex sdformat_console;  // libsdformat's console is one per process: quiet while it reads
    std::lock_guard<std::mutex> lock(sdformat_console);
    sdf::Console::Instance()->SetQuiet(true);
    sdf::ParserConfig config;
    std::vector<std::string> unresolved;
    config.SetFindCallback([&](const std::string& uri) { return sdf_find_resource(uri, &unresolved); });
    static SdfQuietUrdfdom quiet;
    console_bridge::useOutputHandler(&quiet);
    const sdf::Errors errors = root.LoadSdfString(text_, config);
    console_bridge::restorePreviousOutputHandler();
    if (!errors.empty() && !unresolved.empty()) {  // an <include> not found: its line, where its URI is written
      const std::size_t at = text_.find(unresolved.front());
      const auto before = text_.begin() + static_cast<std::ptrdiff_t>(at == std::string::npos ? 0 : at);
      refuse(path_, at == std::string::npos ? 0 : 1 + static_cast<int>(std::count(text_.begin(), before, '\n')),
             "<include> " + unresolved.front() +
                 ": found in no folder of SDF_PATH, GZ_SIM_RESOURCE_PATH or IGN_GAZEBO_RESOURCE_PATH (each a list "
                 "of folders, separated by ':', that hold the model's folder)");
    }
    if (!errors.empty())
      refuse(path_, errors.front().LineNumber().value_or(0), "libsdformat: " + errors.front().Message());
  }
  const sdf::Model* model = root.Model();
  if (!model && root.WorldCount() > 0 && root.WorldByIndex(0)->ModelCount() > 0)
    model = root.WorldByIndex(0)->ModelByIndex(0);
  if (!model) refuse(path_, 0, "the file has no model");
  if (root.WorldCount() > 0)
    for (uint64_t k = 1; k < root.WorldByIndex(0)->ModelCount(); ++k)
      m_.skip("<model> after the world's first", sdf_line(root.WorldByIndex(0)->ModelByIndex(k)->Element()),
              "phiq reads one model of a world", sdf_file(root.WorldByIndex(0)->ModelByIndex(k)->Element(), path_));
  sdf_gravity(root);
  m_.name = model->Name();
  m_.bodies.push_back(Body::named("world", sdf_line(model->Element())));
  this->model(*model, Pose{}, "");
  // Loops: the joints beyond a spanning tree of the links and the world.
  *loops = std::max(0, static_cast<int>(m_.joints.size()) - static_cast<int>(links_));
  return std::move(m_);
}

}  // namespace
}  // namespace detail::mechanism

}  // namespace phiq

extern "C" __attribute__((visibility("default"))) phiq::detail::mechanism::ReadSdf phiq_sdf_reader(
    int abi, std::size_t mechanism_bytes) {
  using namespace phiq::detail::mechanism;
  if (abi != kSdfModuleAbi || mechanism_bytes != sizeof(Mechanism)) return nullptr;
  return [](const std::string& text, const std::string& path, Mechanism& out, int& loops, std::string& error) {
    try {
      out = SdfReader(text, path).read(&loops);
      return true;
    } catch (const std::bad_alloc&) {  // the machine's refusal, not the file's: the caller's out-of-memory exit
      throw;
    } catch (const std::exception& e) {
      error = e.what();
      return false;
    }
  };
}
