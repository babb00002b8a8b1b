// Scenario::channels(): the scenario's unit as a list of channels (sensor/channel.hpp).
#include <vector>

#include "gyrocal/config/scenario.hpp"

namespace gyrocal {

std::vector<SensorChannel> Scenario::channels() const {
  SensorChannel c = lone_channel(sensor());
  if (record) c.output = record->output_columns().front();
  return {c};
}

}  // namespace gyrocal
