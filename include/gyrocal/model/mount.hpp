#pragma once
// A sensor's mount on the position platform (docs/physics.md section 3, "The sensor's mount"): where the
// sensor's centre sits on the platform and how its axes are turned from the platform's. The chain of the
// centrifuge ends at the position platform (PlatformMotion, model/centrifuge.hpp); the mount is the last
// step, and a sensor's exact inputs are the platform's motion evaluated at its mount (inputs_at_mount).
// Today's one sensor has the one mount that `[centrifuge.errors] mount_misalignment_rad` and `lever_arm_m`
// configure (CentrifugeModel::mount()); an IMU's channels each carry their own.
#include <Eigen/Core>

namespace gyrocal {

/// A sensor's mount on the position platform: a value, constant once built (its rotation is computed with
/// it).
class SensorMount {
 public:
  /// The mount of a sensor whose axes are the position platform's and whose centre is the platform's origin.
  SensorMount();
  /// misalignment_rad: rotations about the sensor's first, second and third axes (a gyro's I, O, S; an
  /// accelerometer's i, p, o), rad; lever_arm_m: the sensor centre's offset from the position platform's
  /// origin, in position-platform axes (the sensor's first, second, third axes at beta = 0 with no
  /// misalignment), m.
  SensorMount(const Eigen::Vector3d& misalignment_rad, const Eigen::Vector3d& lever_arm_m);

  /// The misalignment about the sensor's first, second and third axes, rad.
  const Eigen::Vector3d& misalignment_rad() const { return misalignment_rad_; }
  /// The sensor centre's offset from the position platform's origin, position-platform axes, m.
  const Eigen::Vector3d& lever_arm_m() const { return lever_arm_m_; }
  /// R_mount = Rz(mis_3) Ry(mis_2) Rx(mis_1): takes a vector in the sensor's axes to the position platform's
  /// axes (its columns are the sensor's axes seen from the platform). Dimensionless.
  const Eigen::Matrix3d& rotation() const { return rotation_; }

 private:
  Eigen::Vector3d misalignment_rad_;
  Eigen::Vector3d lever_arm_m_;
  Eigen::Matrix3d rotation_;
};

}  // namespace gyrocal
