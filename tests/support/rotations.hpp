#pragma once
// For tests: the elementary rotations about the frame's axes, built by Eigen's angle-axis rather than by the
// model's own chain (model/centrifuge.cpp), so that a test's expected pose comes by an independent route.
#include <Eigen/Geometry>

namespace gyrocal::testing {

/// The rotation by `a` (rad) about x, y or z, as a matrix.
inline Eigen::Matrix3d rx(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
inline Eigen::Matrix3d ry(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
inline Eigen::Matrix3d rz(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

}  // namespace gyrocal::testing
