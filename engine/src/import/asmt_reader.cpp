// Reading an `.asmt` file (FreeCAD Assembly / OndselSolver) into asmt::Assembly. The format is a tree written with
// one tab per level: a line holds a section's name or, one level deeper, its values (numbers separated by tabs).
// OndselSolver's reader (its ASMT*.cpp files) defines it; what this reader does not map is listed in
// Assembly::skipped, once, and what it cannot represent refuses the file naming its line.
#include <cmath>
#include <cstdlib>

#include "import/asmt_model.hpp"
#include "phiq/scene.hpp"

namespace phiq::detail::asmt {

void refuse(const std::string& path, int line, const std::string& what) {
  throw SceneError(path + ":" + std::to_string(line) + ": " + what);
}

namespace {

struct Node {
  std::string text;
  int line = 0;
  std::vector<Node> children;
};

// The lines before `TimeSeries` as a tree of tab-indented nodes under a root (the root's children are the
// depth-0 lines: the header and `Assembly`).
Node parse_tree(const std::string& text, const std::string& path) {
  Node root;
  std::vector<Node*> open{&root};  // open[d] receives the lines of depth d
  std::size_t at = 0;
  for (int line = 1; at < text.size(); ++line) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    std::string s = text.substr(at, end - at);
    at = end + 1;
    while (!s.empty() && (s.back() == '\r' || s.back() == ' ' || s.back() == '\t')) s.pop_back();
    std::size_t depth = 0;
    while (depth < s.size() && s[depth] == '\t') ++depth;
    if (depth == s.size()) continue;  // a blank line
    if (depth == 0 && s == "TimeSeries") break;
    if (depth + 1 > open.size())
      refuse(path, line, "indented " + std::to_string(depth) + " tabs, more than one past the line before");
    open.resize(depth + 1);
    open[depth]->children.push_back(Node{s.substr(depth), line, {}});
    open.push_back(&open[depth]->children.back());
  }
  return root;
}

// What reading one file needs beside the tree: its path for messages and the list of what is skipped.
class Reader {
 public:
  Reader(const std::string& path, int last_line) : path_(path), last_line_(last_line) {}
  Assembly read(const Node& root);

 private:
  const Node* find(const Node& n, const std::string& key) const {
    for (const Node& c : n.children)
      if (c.text == key) return &c;
    return nullptr;
  }
  const Node& need(const Node& n, const std::string& key, const std::string& what) const {
    if (const Node* c = find(n, key)) return *c;
    refuse(path_, n.line,
           what + " has no " + key + " (the file ends at line " + std::to_string(last_line_) + ": truncated?)");
  }
  // The one line under a field (its value).
  const Node& value(const Node& field) const {
    if (field.children.empty()) refuse(path_, field.line, field.text + " has no value (the file may be truncated)");
    return field.children.front();
  }
  std::vector<double> numbers(const Node& line_node, std::size_t count) const {
    std::vector<double> out;
    const char* s = line_node.text.c_str();
    while (*s) {
      while (*s == ' ' || *s == '\t') ++s;
      if (!*s) break;
      char* end = nullptr;
      const double v = std::strtod(s, &end);
      if (end == s || (*end && *end != ' ' && *end != '\t') || !std::isfinite(v))
        refuse(path_, line_node.line, "'" + line_node.text + "' is not a list of finite numbers");
      out.push_back(v), s = end;
    }
    if (out.size() != count)
      refuse(path_, line_node.line,
             "expected " + std::to_string(count) + " numbers, found " + std::to_string(out.size()) +
                 " (the file may be truncated)");
    return out;
  }
  double number(const Node& field) const { return numbers(value(field), 1)[0]; }
  Eigen::Vector3d vec3(const Node& field) const {
    const std::vector<double> v = numbers(value(field), 3);
    return {v[0], v[1], v[2]};
  }
  Eigen::Matrix3d rotation(const Node& field) const {
    if (field.children.size() != 3)
      refuse(path_, field.line, "RotationMatrix needs 3 rows (the file may be truncated)");
    Eigen::Matrix3d R;
    for (int i = 0; i < 3; ++i) {
      const std::vector<double> row = numbers(field.children[static_cast<std::size_t>(i)], 3);
      R.row(i) << row[0], row[1], row[2];
    }
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-9 || R.determinant() < 0)
      refuse(path_, field.line, "RotationMatrix is not a rotation (orthonormal within 1e-9, determinant +1)");
    return R;
  }
  Pose pose(const Node& n, const std::string& what) const {
    return Pose{vec3(need(n, "Position3D", what)), rotation(need(n, "RotationMatrix", what))};
  }
  std::string name_of(const Node& n, const std::string& what) const { return value(need(n, "Name", what)).text; }
  void skip(int line, const std::string& what) { skipped_.push_back(path_ + ":" + std::to_string(line) + ": " + what); }
  void skip_if_nonzero(const Node& n, const std::string& key, const std::string& what) {
    if (const Node* f = find(n, key); f && !vec3(*f).isZero(0.0)) skip(f->line, what);
  }
  std::vector<Marker> markers(const Node* refs, const std::string& what) const;
  Part part(const Node& n);
  Joint joint(const Node& n) const;
  Motion motion(const Node& n) const;
  Motion general_motion(const Node& n, Motion m) const;
  void simulation(const Node& n, Assembly& a);
  void assembly_field(const Node& f, Assembly& a);

  const std::string& path_;
  int last_line_;
  std::vector<std::string> skipped_;
};

std::vector<Marker> Reader::markers(const Node* refs, const std::string& what) const {
  std::vector<Marker> out;
  if (!refs) return out;
  for (const Node& ref : refs->children) {
    if (ref.text != "RefPoint") refuse(path_, ref.line, "expected RefPoint in RefPoints, found '" + ref.text + "'");
    const Pose r = pose(ref, "RefPoint of " + what);
    const Node* ms = find(ref, "Markers");
    if (!ms) continue;
    for (const Node& m : ms->children) {
      if (m.text != "Marker") refuse(path_, m.line, "expected Marker in Markers, found '" + m.text + "'");
      const Pose local = pose(m, "Marker");
      out.push_back(Marker{name_of(m, "Marker"), m.line, Pose{r.p + r.R * local.p, r.R * local.R}});
    }
  }
  return out;
}

Part Reader::part(const Node& n) {
  Part p;
  p.line = n.line, p.name = name_of(n, "Part");
  p.placement = pose(n, "Part '" + p.name + "'");
  p.markers = markers(find(n, "RefPoints"), "Part '" + p.name + "'");
  skip_if_nonzero(n, "Velocity3D", "Part '" + p.name + "' Velocity3D: an initial velocity is no input of a sweep");
  skip_if_nonzero(n, "Omega3D", "Part '" + p.name + "' Omega3D: an initial velocity is no input of a sweep");
  if (const Node* f = find(n, "FeatureOrder"); f && !f->children.empty())
    skip(f->line, "Part '" + p.name + "' FeatureOrder: its geometry (sketches, extrusions) is not read as shapes");
  for (const char* k : {"RefCurves", "RefSurfaces"})
    if (const Node* f = find(n, k); f && !f->children.empty())
      skip(f->line, "Part '" + p.name + "' " + k + ": no joint of phiq's attaches to curves or surfaces");
  if (const Node* m = find(n, "PrincipalMassMarker")) {
    p.mass_line = m->line;
    p.mass_frame = pose(*m, "PrincipalMassMarker");
    p.mass = number(need(*m, "Mass", "PrincipalMassMarker"));
    p.moments = vec3(need(*m, "MomentOfInertias", "PrincipalMassMarker"));
  }
  return p;
}

Joint Reader::joint(const Node& n) const {
  Joint j;
  j.type = n.text, j.line = n.line, j.name = name_of(n, n.text);
  const Node& mi = need(n, "MarkerI", j.type + " '" + j.name + "'");
  const Node& mj = need(n, "MarkerJ", j.type + " '" + j.name + "'");
  j.marker_i = value(mi).text, j.line_i = value(mi).line;
  j.marker_j = value(mj).text, j.line_j = value(mj).line;
  for (const Node& f : n.children) {
    if (f.text == "Name" || f.text == "MarkerI" || f.text == "MarkerJ") continue;
    j.values.emplace_back(f.text, number(f));
    j.value_lines.push_back(f.line);
  }
  return j;
}

Motion Reader::motion(const Node& n) const {
  Motion m;
  m.type = n.text, m.line = n.line, m.name = name_of(n, n.text);
  const std::string what = m.type + " '" + m.name + "'";
  if (m.type == "GeneralMotion") return general_motion(n, m);
  if (m.type != "RotationalMotion" && m.type != "TranslationalMotion")
    refuse(path_, n.line, what + ": not a motion phiq reads (rotational, translational, general)");
  const Node* joint = find(n, "MotionJoint");
  if (!joint)
    refuse(path_, n.line, what + ": a motion between markers (no MotionJoint) is not read; drive a joint instead");
  m.joint = value(*joint).text, m.joint_line = joint->line;
  for (const Node& f : n.children) {
    if (f.text == "Name" || f.text == "MotionJoint") continue;
    const bool rot = f.text == "RotationZ" || f.text == "rotationZ";
    const bool tra = f.text == "TranslationZ" || f.text == "translationZ";
    if ((rot && m.type == "RotationalMotion") || (tra && m.type == "TranslationalMotion")) {
      m.expression = value(f).text, m.expression_line = value(f).line;
    } else {
      refuse(path_, f.line, what + ": field '" + f.text + "' is not read (no phiq driver expresses it)");
    }
  }
  if (m.expression.empty())
    refuse(path_, n.line,
           what + " has no " + (m.type == "RotationalMotion" ? "RotationZ" : "TranslationZ") +
               " (the file may be truncated)");
  return m;
}

Motion Reader::general_motion(const Node& n, Motion m) const {
  const std::string what = m.type + " '" + m.name + "'";
  const Node& mi = need(n, "MarkerI", what);
  const Node& mj = need(n, "MarkerJ", what);
  m.marker_i = value(mi).text, m.line_i = value(mi).line;
  m.marker_j = value(mj).text, m.line_j = value(mj).line;
  static const char* keys[6] = {"rIJI1", "rIJI2", "rIJI3", "angIJJ1", "angIJJ2", "angIJJ3"};
  for (std::size_t k = 0; k < 6; ++k) {
    const Node& v = value(need(n, keys[k], what));
    m.general[k] = v.text, m.general_lines[k] = v.line;
  }
  const Node& order = value(need(n, "RotationOrder", what));
  m.rotation_order = order.text, m.order_line = order.line;
  for (const Node& f : n.children) {
    bool known = f.text == "Name" || f.text == "MarkerI" || f.text == "MarkerJ" || f.text == "RotationOrder";
    for (const char* k : keys) known = known || f.text == k;
    if (!known) refuse(path_, f.line, what + ": field '" + f.text + "' is not read");
  }
  return m;
}

void Reader::simulation(const Node& n, Assembly& a) {
  a.time_line = n.line;
  a.tstart = number(need(n, "tstart", "SimulationParameters"));
  a.tend = number(need(n, "tend", "SimulationParameters"));
  a.hout = number(need(n, "hout", "SimulationParameters"));
  for (const Node& f : n.children)
    if (f.text != "tstart" && f.text != "tend" && f.text != "hout")
      skip(f.line, "SimulationParameters " + f.text + ": an integrator setting (phiq's solver has its own tolerance)");
}

void Reader::assembly_field(const Node& f, Assembly& a) {
  const std::string& k = f.text;
  if (k == "Notes" || k == "Name" || k == "Position3D" || k == "RotationMatrix" || k == "Parts") return;
  if (k == "RefPoints") {
    a.ground = markers(&f, "Assembly");
    return;
  }
  if (k == "Velocity3D" || k == "Omega3D") {
    if (!vec3(f).isZero(0.0)) skip(f.line, "Assembly " + k + ": the ground frame does not move in phiq");
    return;
  }
  if (k == "ConstantGravity") {
    a.gravity = vec3(f);
    return;
  }
  if (k == "SimulationParameters") return simulation(f, a);
  if (k == "AnimationParameters") return skip(f.line, "AnimationParameters: display settings of FreeCAD's player");
  if (k == "ConstraintSets") {
    for (const Node& set : f.children) {
      if (set.text == "Joints") {
        for (const Node& j : set.children) a.joints.push_back(joint(j));
      } else if (set.text == "Motions") {
        for (const Node& m : set.children) a.motions.push_back(motion(m));
      } else if (!set.children.empty()) {
        refuse(path_, set.line, "ConstraintSets " + set.text + ": not read (phiq has no form for it)");
      }
    }
    return;
  }
  if (f.children.empty()) return;  // RefCurves, RefSurfaces, KinematicIJs, ForceTorques: empty
  if (k == "ForceTorques") return skip(f.line, "ForceTorques: applied loads are not read (a kinematic sweep)");
  skip(f.line, "Assembly " + k + ": not read by phiq");
}

Assembly Reader::read(const Node& root) {
  const Node* asm_node = nullptr;
  for (const Node& c : root.children)
    if (c.text == "Assembly") asm_node = &c;
  if (!asm_node)
    refuse(path_, root.children.empty() ? 1 : root.children.front().line, "no Assembly: not an .asmt file");
  const Node& n = *asm_node;
  Assembly a;
  a.path = path_;
  a.name = name_of(n, "Assembly");
  const Pose frame = pose(n, "Assembly");
  if (!frame.p.isZero(0.0) || !frame.R.isIdentity(0.0))
    refuse(path_, need(n, "Position3D", "Assembly").line,
           "the Assembly's own placement is not the identity; phiq's ground is the world frame");
  for (const Node& f : n.children) assembly_field(f, a);
  for (const Node& p : need(n, "Parts", "Assembly").children) {
    if (p.text != "Part") refuse(path_, p.line, "expected Part in Parts, found '" + p.text + "'");
    a.parts.push_back(part(p));
  }
  need(n, "SimulationParameters", "Assembly");
  a.skipped = std::move(skipped_);
  return a;
}

}  // namespace

Assembly read_assembly(const std::string& text, const std::string& path) {
  int lines = 0;
  for (char c : text) lines += c == '\n';
  const Node root = parse_tree(text, path);
  return Reader(path, lines).read(root);
}

}  // namespace phiq::detail::asmt
