// Eigen's Quaternion::FromTwoVectors, compiled in one place (base/orientation.cpp): its branch for opposite vectors
// instantiates a JacobiSVD, whose compilation in mjcf_reader.cpp's unity group was a third of that group's CPU
// (e7b8739, 2026-12-03: 38.6 s → 26.6 s in GCC Release, 55.6 s → 36.2 s under clang ASan + UBSan once called here).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace phiq::detail {

// Eigen::Quaterniond::FromTwoVectors(from, to): the least rotation taking from's direction to to's.
Eigen::Quaterniond quaternion_between(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

}  // namespace phiq::detail
