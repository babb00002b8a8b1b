#include "gyrocal/identify/scenario_options.hpp"

#include "gyrocal/core/error.hpp"
#include "gyrocal/identify/unknowns.hpp"
#include "gyrocal/model/machine_errors.hpp"

namespace gyrocal {

CalibrationOptions calibration_options(const Scenario& scenario, const CalibrationChoices& choices) {
  CalibrationOptions options;
  options.sensor = scenario.sensor_kind;
  if (scenario.record) options.output_unit = scenario.record->column_unit();
  options.method = parse_method(choices.method);
  options.compensation = parse_compensation(choices.compensation);
  options.estimate = choices.estimate
                         ? parse_machine_error_names(*choices.estimate, choices.estimate_source)
                         : parse_machine_error_names(scenario.estimate, "[calibration] estimate");
  options.gyro_model =
      choices.gyro_model.empty() ? scenario.gyro_model : parse_gyro_model(choices.gyro_model);
  // [reduce] and [calibration] reduction (docs/contract.md), the method overridden by the choice.
  options.reduce = scenario.reduce;
  if (choices.reduction == "harmonic") {
    options.reduce.method = ReduceOptions::Method::kHarmonicFit;
  } else if (choices.reduction == "window") {
    options.reduce.method = ReduceOptions::Method::kWindowMean;
  } else if (!choices.reduction.empty()) {
    throw Error("unknown reduction '" + choices.reduction + "': use harmonic or window.");
  }
  return options;
}

}  // namespace gyrocal
