#pragma once
// The options of one calibration, built once from a scenario and a caller's choices (issue 20, item 9):
// `gyrocal calibrate`, `gyrocal plan` and the Python module's calibrate all build them here, so that a
// configuration's [calibration] gyro_model, estimate and reduction and its [reduce] apply alike everywhere
// (docs/interface.md, docs/python.md).
#include <optional>
#include <string>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/identify/calibration.hpp"

namespace gyrocal {

/// What a command (or a Python call) chooses for one calibration. Each choice left empty (or nullopt) takes
/// the scenario's: [calibration] estimate, gyro_model and reduction. Texts as on the command line.
struct CalibrationChoices {
  std::string method = "least-squares";  ///< "least-squares" or "closed-form"
  std::string compensation = "full";     ///< "none", "seed" or "full"
  /// Machine errors estimated with the coefficients (NAME, NAME_I/_O/_S, NAME:N; docs/self_calibration.md);
  /// nullopt: [calibration] estimate. An empty list estimates none.
  std::optional<std::vector<std::string>> estimate;
  /// What the estimate override is called in a refusal of one of its names ("--estimate", "estimate").
  std::string estimate_source = "--estimate";
  std::string gyro_model;  ///< "drift" or "drift+rate"; empty: [calibration] gyro_model
  std::string reduction;   ///< "harmonic" or "window"; empty: [calibration] reduction
};

/// The calibration options of `scenario` with `choices` applied: method, compensation, estimate, gyro model,
/// and the scenario's [reduce] with the reduction's method. Every other option keeps its default. Throws
/// Error naming the choice at fault (an unknown method, compensation, gyro model, reduction or machine
/// error name; a name of [calibration] estimate is named as "[calibration] estimate").
CalibrationOptions calibration_options(const Scenario& scenario, const CalibrationChoices& choices);

}  // namespace gyrocal
