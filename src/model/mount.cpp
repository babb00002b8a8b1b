#include "gyrocal/model/mount.hpp"

#include <Eigen/Geometry>

namespace gyrocal {
namespace {

Eigen::Matrix3d elementary(int axis, double q) {
  return Eigen::AngleAxisd(q, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
}

}  // namespace

SensorMount::SensorMount() : SensorMount(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()) {}

SensorMount::SensorMount(const Eigen::Vector3d& misalignment_rad, const Eigen::Vector3d& lever_arm_m)
    : misalignment_rad_(misalignment_rad),
      lever_arm_m_(lever_arm_m),
      // docs/physics.md section 3: R_mount = Rz(mis_3) Ry(mis_2) Rx(mis_1).
      rotation_(elementary(2, misalignment_rad.z()) * elementary(1, misalignment_rad.y()) *
                elementary(0, misalignment_rad.x())) {}

}  // namespace gyrocal
