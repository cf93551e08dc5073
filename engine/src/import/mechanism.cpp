// The small geometry and error helpers of the robot-description readers (import/mechanism.hpp). Compiled into the
// engine and into the SDF module (sdf_module.hpp), which shares them without linking the engine.
#include <tinyxml2.h>

#include <Eigen/Geometry>

#include "import/mechanism.hpp"
#include "phiq/scene.hpp"

namespace phiq::detail::mechanism {

void refuse(const std::string& path, int line, const std::string& what) {
  throw SceneError(path + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + what);
}

void refuse_xml(const std::string& path, const tinyxml2::XMLDocument& doc) {
  if (doc.ErrorID() == tinyxml2::XML_ELEMENT_DEPTH_EXCEEDED)  // e.g. an MJCF chain of ~100 nested bodies
    refuse(path, doc.ErrorLineNum(),
           "elements nested more than " + std::to_string(TINYXML2_MAX_ELEMENT_DEPTH) +
               " deep, the most the XML reader (tinyxml2) reads; the file is not read");
  refuse(path, doc.ErrorLineNum(), std::string("malformed XML (the file may be truncated): ") + doc.ErrorName());
}

Eigen::Vector3d perpendicular(const Eigen::Vector3d& axis) {
  const Eigen::Vector3d z = axis.normalized();
  Eigen::Index k = 0;
  z.cwiseAbs().minCoeff(&k);
  return z.cross(Eigen::Vector3d::Unit(k)).cross(z).normalized();
}

Eigen::Matrix3d axis_angle(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

}  // namespace phiq::detail::mechanism
