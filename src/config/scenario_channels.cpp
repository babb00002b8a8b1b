// Scenario::channels(): the scenario's unit as a list of channels (sensor/channel.hpp).
#include <optional>
#include <vector>

#include "gyrocal/config/scenario.hpp"

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

}  // namespace gyrocal
