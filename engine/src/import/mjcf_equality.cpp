// MJCF's equalities (MjcfReader::equality, connect_or_weld; mjcf_reader.hpp): `connect` and `weld` between bodies
// or sites as the joints that close loops, `joint` (a linear polycoef) as a coupler.
#include <cmath>
#include <string>

#include "base/quaternion_between.hpp"
#include "import/mjcf_reader.hpp"

namespace phiq::detail::mechanism {

Joint MjcfReader::connect_or_weld(const tinyxml2::XMLElement* e, const std::string& name) {
  const std::string tag = e->Name();
  Joint j;
  j.name = name, j.line = e->GetLineNum(), j.file = docs_.included_file(e), j.closing = true;
  j.kind = tag == "connect" ? "spherical" : "rigid";
  if (e->Attribute("site1") || e->Attribute("site2")) {  // the sites' origins (connect) or frames (weld) coincide
    for (const char* other : {"body1", "body2", "anchor", "relpose"})
      if (e->Attribute(other)) fail(e, "<" + tag + "> names sites and " + other + ": MuJoCo takes one or the other");
    Side sides[2];
    for (int k = 0; k < 2; ++k) {
      const std::string attribute = "site" + std::to_string(k + 1);
      const char* site = e->Attribute(attribute.c_str());
      if (!site) fail(e, "<" + tag + "> without " + attribute);
      const auto it = sites_.find(site);
      if (it == sites_.end()) fail(e, attribute + " '" + site + "' is not a site of the file");
      const Pose& at = it->second.at;
      sides[k] = Side{it->second.body, at.p, at.R.col(2), at.R.col(0)};
    }
    j.parent = sides[0], j.child = sides[1];
    return j;
  }
  const int b1 = body_named(e, "body1", true), b2 = body_named(e, "body2", false);
  const std::vector<double> a = numbers(e, "anchor", "", {0, 0, 0}, 3, 3);
  const Eigen::Vector3d anchor(a[0], a[1], a[2]);
  const Pose& w1 = m_.bodies[static_cast<std::size_t>(b1)].world;
  const Pose& w2 = m_.bodies[static_cast<std::size_t>(b2)].world;
  if (tag == "connect") {  // anchor in body1's frame
    j.parent = Side{b1, anchor};
    j.child = Side{b2, w2.inverse().R * (w1.p + w1.R * anchor - w2.p)};
    return j;
  }
  // anchor in body2's frame; body2's pose in body1's: relpose, or (its quaternion all zeros) the model's pose
  const std::vector<double> rel = numbers(e, "relpose", "", {0, 1, 0, 0, 0, 0, 0}, 7, 7);
  Pose in1 = w1.inverse() * w2;
  if (rel[3] != 0 || rel[4] != 0 || rel[5] != 0 || rel[6] != 0)
    in1 = Pose{Eigen::Vector3d(rel[0], rel[1], rel[2]),
               Eigen::Quaterniond(rel[3], rel[4], rel[5], rel[6]).normalized().toRotationMatrix()};
  in1 = in1 * Pose{anchor, Eigen::Matrix3d::Identity()};
  j.parent = Side{b1, in1.p, in1.R.col(2), in1.R.col(0)};
  j.child = Side{b2, anchor};
  return j;
}

void MjcfReader::equality(const tinyxml2::XMLElement* list) {
  for (const tinyxml2::XMLElement* e : docs_.children(list)) {
    const std::string tag = e->Name();
    const std::string name =
        e->Attribute("name") ? e->Attribute("name") : tag + "_line" + std::to_string(e->GetLineNum());
    if (e->Attribute("active") && std::string(e->Attribute("active")) == "false") {
      unmapped(e, "inactive (active=\"false\")");
      continue;
    }
    if (e->Attribute("solref") || e->Attribute("solimp"))
      skip_at(e, "<" + tag + " solref/solimp>", "phiq's constraints are exact, not soft");
    if (tag == "connect" || tag == "weld") {
      m_.joints.push_back(connect_or_weld(e, name));
      ++loops_;
    } else if (tag == "joint") {
      const char* j1 = e->Attribute("joint1");
      const char* j2 = e->Attribute("joint2");
      if (!j1 || !joint_index_.count(j1))
        fail(e, std::string("<joint> equality: joint1 '") + (j1 ? j1 : "") + "' is not a joint of the file");
      if (j2 && !joint_index_.count(j2))
        fail(e, std::string("<joint> equality: joint2 '") + j2 + "' is not a joint of the file");
      const std::vector<double> c = numbers(e, "polycoef", "", {0, 1, 0, 0, 0}, 1, 5);
      for (std::size_t k = 2; k < c.size(); ++k)
        if (c[k] != 0.0 && j2)
          fail(e, "<joint> equality '" + name + "': polycoef of degree " + std::to_string(k) +
                      "; phiq couples joints linearly (a coupler)");
      // MuJoCo's q1 = c0 + c1 q2 on joint positions; phiq's angles are those minus each joint's ref.
      const int a = joint_index_.at(j1), b = j2 ? joint_index_.at(j2) : -1;
      const double ra = joint_ref_.count(a) ? joint_ref_.at(a) : 0.0,
                   rb = b >= 0 && joint_ref_.count(b) ? joint_ref_.at(b) : 0.0;
      const double c1 = c.size() > 1 ? c[1] : 0.0;
      m_.couplers.push_back(
          Coupler{name, e->GetLineNum(), a, b, c1, c[0] + (b >= 0 ? c1 * rb : 0.0) - ra, docs_.included_file(e)});
    } else {
      fail(e, "<" + tag + "> equality: not read by phiq (only connect, weld and joint)");
    }
  }
}

}  // namespace phiq::detail::mechanism
