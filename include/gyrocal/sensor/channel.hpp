#pragma once
// A channel (docs/architecture.md, "Glossary"): one sensor's output in a record. Its name, its sensor (the
// model with its truth and noise), its axes on the unit's mount and the record's column that holds it. A
// lone gyro or accelerometer is one channel (Scenario::channels()); an IMU's channels share one mount and
// one record, each on its own axes (docs/contract.md, "IMUs").
//
// The unit's mount on the position platform (SensorMount: misalignment, lever arm) is the model's,
// CentrifugeModel::mount(): one for every channel, configured and estimated with the machine's errors. The
// machine's motion is computed once per instant for the position platform (platform_motion,
// model/centrifuge.hpp), evaluated at the mount, then turned into each channel's axes (channel_inputs).
#include <string>

#include <Eigen/Core>

#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/record/record_layout.hpp"
#include "gyrocal/sensor/sensor.hpp"

namespace gyrocal {

/// One channel of a unit under test.
struct SensorChannel {
  /// Its name in results: the lone sensor's kind ("gyro", "accelerometer"), an IMU's channel name ("gx").
  std::string name;
  /// Its sensor: model, truth (for simulation) and noise.
  Sensor sensor;
  /// The sensor's first, second and third axes (a gyro's I, O, S; an accelerometer's i, p, o) as columns,
  /// in the unit's body axes, which lie on the mount's axes: a proper rotation, dimensionless. The identity
  /// for a lone sensor, whose axes are the mount's.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  /// The record's column that holds its output, and how it converts into the sensor's unit.
  OutputColumn output;
};

/// A lone sensor's channel: named by its kind ("gyro", "accelerometer"), on its mount's axes, its output
/// column the sensor's in gyrocal's own record (gyro_deg_h in deg/h, accel_g in g).
SensorChannel lone_channel(const Sensor& sensor);

/// The exact inputs of `channel`'s sensor, in its own axes, on a position platform moving as `motion`:
/// inputs_at_mount at the model's mount, then turned from the mount's axes into the sensor's by axesᵀ.
/// Inertial rate in rad/s, specific force in the site's g. For a channel whose axes are the identity this is
/// inputs_at_mount itself, bit for bit (so exact_inputs, or sensed_inputs for sensed_platform_motion).
SensorInputs channel_inputs(const CentrifugeModel& model, const PlatformFrameMotion& motion,
                            const SensorChannel& channel);

}  // namespace gyrocal
