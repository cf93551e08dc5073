// Internal: the MJCF reader (mjcf_reader.cpp: the compiler, defaults, assets, bodies, joints and geoms;
// mjcf_equality.cpp: the equalities that close loops and couple joints), one class over the file's elements.
#pragma once

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "import/mechanism.hpp"
#include "import/mjcf_documents.hpp"

namespace phiq::detail::mechanism {

using Attributes = std::map<std::string, std::string>;

class MjcfReader {
 public:
  MjcfReader(const std::string& text, const std::string& path) : text_(text), path_(path) {}
  Mechanism read(int* loops);

 private:
  void compiler(const tinyxml2::XMLElement* e);
  void defaults(const tinyxml2::XMLElement* e, const std::string& cls, const std::string& parent);
  void assets(const tinyxml2::XMLElement* e);
  // The attribute as the element gives it, or its class's default (the chain up to "main"); nullptr when neither.
  const std::string* attr(const tinyxml2::XMLElement* e, const char* name, const std::string& childclass) const;
  std::vector<double> numbers(const tinyxml2::XMLElement* e, const char* name, const std::string& childclass,
                              std::vector<double> fallback, std::size_t count_min, std::size_t count_max) const;
  Eigen::Matrix3d rotation(const tinyxml2::XMLElement* e, const std::string& childclass) const;
  Pose pose(const tinyxml2::XMLElement* e, const std::string& childclass) const;
  // A child element with the pose of the <frame>s it stands in (identity outside any) and its class in effect.
  struct Placed {
    const tinyxml2::XMLElement* e;
    Pose frame;
    std::string childclass;
  };
  // The children of `e`, the contents of <frame>s among them in their place.
  std::vector<Placed> placed(const tinyxml2::XMLElement* e, const std::string& childclass, const Pose& frame = {});
  void body(const tinyxml2::XMLElement* e, int parent, const std::string& childclass, const Pose& frame = {});
  // A geom (as geom()) placed by its frame, or a site recorded for the equalities that name it.
  void placed_geom_or_site(const Placed& c, int body, bool* solid_only, std::optional<double>* density);
  void geom(const tinyxml2::XMLElement* e, Body* b, const std::string& childclass, bool* solid_only,
            std::optional<double>* density);
  void equality(const tinyxml2::XMLElement* e);
  // <actuator>'s children on joints: a force range, times the gear, is the joint's effort range.
  void actuators(const tinyxml2::XMLElement* list);
  // Whether a range is in force by its `…limited` attribute: "true"; "auto" (or none) under autolimits.
  bool limited(const std::string* attribute) const {
    return attribute && *attribute != "auto" ? *attribute == "true" : autolimits_;
  }
  // A connect (spherical) or weld (rigid) equality between bodies (anchor, relpose) or sites, closing a loop.
  Joint connect_or_weld(const tinyxml2::XMLElement* e, const std::string& name);
  int body_named(const tinyxml2::XMLElement* e, const char* attribute, bool required) const;
  double angle(double v) const { return degrees_ ? v * M_PI / 180.0 : v; }
  void unmapped(const tinyxml2::XMLElement* e, const std::string& why) {
    skip_at(e, std::string("<") + e->Name() + ">", why);
  }
  void skip_at(const tinyxml2::XMLElement* e, const std::string& what, const std::string& why) {
    m_.skip(what, e->GetLineNum(), why, docs_.included_file(e));
  }
  // "FILE:LINE: what" for the element, in the file it was read from.
  [[noreturn]] void fail(const tinyxml2::XMLElement* e, const std::string& what) const {
    refuse(docs_.file_of(e), e->GetLineNum(), what);
  }

  const std::string& text_;
  const std::string& path_;
  MjcfDocuments docs_{path_};
  bool degrees_ = true;
  bool autolimits_ = true;  // <compiler autolimits>: MuJoCo's default since 2.2.2
  std::string eulerseq_ = "xyz", meshdir_;
  std::map<std::string, std::map<std::string, Attributes>> defaults_;  // class → element → attributes
  std::map<std::string, std::string> parent_class_;
  struct MeshAsset {
    std::string file;
    Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  };
  std::map<std::string, MeshAsset> meshes_;
  std::map<std::string, int> body_index_, joint_index_;
  struct Site {
    int body = 0;
    Pose at;  // in the body's frame
  };
  std::map<std::string, Site> sites_;
  std::map<int, double> joint_ref_;  // a hinge's or slide's `ref` (qpos at the model's pose), by joint index
  int loops_ = 0;
  Mechanism m_;
};

}  // namespace phiq::detail::mechanism
