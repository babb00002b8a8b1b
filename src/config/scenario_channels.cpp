// Scenario::channels(): the scenario's unit as a list of channels (sensor/channel.hpp); the refusal of an
// IMU by the commands that do not serve one yet.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/error.hpp"

namespace gyrocal {

std::vector<SensorChannel> Scenario::channels() const {
  if (is_imu()) return imu_channels;
  SensorChannel c = lone_channel(sensor());
  if (record) c.output = record->output_columns().front();
  return {c};
}

std::optional<RecordLayout> Scenario::reading_layout() const {
  if (!is_imu()) return record;
  RecordLayout layout = record.value_or(RecordLayout{});
  layout.outputs.clear();
  for (const SensorChannel& c : imu_channels) layout.outputs.push_back(c.output);
  return layout;
}

std::string imu_not_served(std::string_view command, std::string_view input) {
  return std::string(command) + " does not serve an IMU " + std::string(input) +
         " yet ([sensor] kind = \"imu\"); docs/imu.md, \"What serves an IMU\", lists the commands that do.";
}

void refuse_imu(const Scenario& scenario, std::string_view command) {
  if (scenario.is_imu()) throw Error(imu_not_served(command));
}

}  // namespace gyrocal
