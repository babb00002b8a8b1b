#include "gyrocal/sensor/channel.hpp"

#include <string>
#include <string_view>
#include <variant>

namespace gyrocal {

SensorChannel lone_channel(const Sensor& sensor) {
  SensorChannel c;
  const SensorKind kind = kind_of(sensor);
  c.name = std::string(to_string(kind));
  c.sensor = sensor;
  c.output.column =
      std::string(std::visit([](const auto& s) -> std::string_view { return s.native_column; }, sensor));
  c.output.quantity =
      kind == SensorKind::kAccelerometer ? OutputQuantity::kSpecificForce : OutputQuantity::kRate;
  return c;
}

SensorInputs channel_inputs(const CentrifugeModel& model, const PlatformFrameMotion& motion,
                            const SensorChannel& channel) {
  const SensorInputs at_mount = inputs_at_mount(model, motion, model.mount());
  if (channel.axes == Eigen::Matrix3d::Identity()) return at_mount;
  return {channel.axes.transpose() * at_mount.rate_rad_s,
          channel.axes.transpose() * at_mount.specific_force_g};
}

}  // namespace gyrocal
