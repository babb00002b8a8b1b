#pragma once
// A whole IMU's calibration (docs/imu.md): every channel's coefficients and the machine errors they share,
// identified jointly from one record. Each channel is reduced on its own (its outlier rule, its noise level),
// its model terms are its sensor's design rows on its own axes reduced by the same operator, and one weighted
// least squares holds every channel's products beside the shared machine errors (the radius error, the
// stretch, ...): the x and z accelerometers fix the radius, and through it the y accelerometer's scale, which
// on its own is confounded with it (docs/imu.md, "What one mounting identifies"). Each channel is judged by
// its own misfit.
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gyrocal/identify/calibration.hpp"
#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/plan/test_spec.hpp"
#include "gyrocal/record/record.hpp"
#include "gyrocal/reduce/reducer.hpp"
#include "gyrocal/sensor/channel.hpp"

namespace gyrocal {

/// One channel's part of an IMU's calibration.
struct ImuChannelResult {
  std::string name;  ///< the channel's name ("gx")
  SensorKind sensor = SensorKind::kGyro;
  /// Its coefficients, named and unitted as the lone sensor's (an accelerometer's K1 in the channel's
  /// output units per g: its output_scale times the fitted ratio), std from the joint solve.
  std::vector<CoefficientEstimate> coefficients;
  /// Where its plan leaves coefficients unidentifiable: the combinations of them the data identify (docs/
  /// imu.md, "When a plan leaves a coefficient unidentifiable"), each with its weights on the coefficients
  /// (NamedEstimate::coefficients, the pivot's 1) in its pivot coefficient's unit.
  std::vector<NamedEstimate> combinations;
  std::vector<double> products;            ///< the fitted products, in the sensor's design-row order
  std::vector<ReducedPosition> positions;  ///< its reduced positions (each with its channel's number)
  std::vector<double> residuals;           ///< per position: reduced output - fitted model, output unit
  MisfitTest misfit;                       ///< its own misfit test (chi2 of its whitened residuals)
  std::size_t outliers = 0;                ///< its samples rejected as outliers
  std::vector<std::string> warnings;       ///< warnings of this channel's reduction and fit
};

/// The angle between two channels' fitted input axes (docs/imu.md, "The triad's geometry"): each axis is the
/// channel's nominal input axis tilted by its fitted tilts (an accelerometer's delta_p and delta_o, a
/// drift+rate gyro's input-axis misalignment about O and S), in the IMU's body axes, which the mount defines.
struct InputAxisAngle {
  std::string first, second;    ///< the channels' names
  double angle_deg = 0.0;       ///< the angle between the fitted input axes, deg
  double nominal_deg = 0.0;     ///< between the configured input axes (90 for a triad), deg
  double deviation_urad = 0.0;  ///< angle - nominal, urad (the unit's non-orthogonality)
  double std_urad = 0.0;        ///< its standard uncertainty, urad (the tilts' joint covariance)
};

/// An IMU's calibration: every channel's result and the shared machine errors.
struct ImuCalibrationResult {
  std::vector<ImuChannelResult> channels;            ///< in the configuration's order
  std::vector<MachineErrorEstimate> machine_errors;  ///< the shared errors estimated (--estimate)
  DataQuality data_quality;  ///< of the record (rows, gaps); outliers summed over the channels
  std::vector<std::string> warnings;
  double g_level = 0.0;  ///< Ar of the first spinning rate, g
  int rank = 0;          ///< of the joint design
  int unknowns = 0;      ///< every channel's products and the estimated errors
  double condition_number = 0.0;
  int iterations = 0;  ///< Gauss-Newton iterations (0 without --estimate)
  /// The angles between the input axes of every two channels of one sensor kind whose tilts are fitted (the
  /// accelerometers; the gyros with gyro_model = "drift+rate").
  std::vector<InputAxisAngle> input_axis_angles;
  /// The joint covariance of every unknown (the channels' products in order, then the errors), the sandwich
  /// of the channels' own levels, in the unknowns' units; and their names ("gx.dF", ..., "radius_error").
  Eigen::MatrixXd covariance;
  std::vector<std::string> names;
  /// A channel's result by name; nullptr when there is none.
  const ImuChannelResult* channel(std::string_view name) const;
};

/// The joint identification of an IMU from its channels' reductions (one per channel, in `channels`' order,
/// from one pass over the record: reduce_record_channels), on `model` (the machine with its configured
/// errors). Every gyro channel fits options.gyro_model (the channels' own model is the one their
/// configuration was loaded with). The options' method must be least squares with full compensation; their
/// `estimate` are the shared machine errors, estimated by Gauss-Newton on the exact model as a lone sensor's
/// self-calibration (docs/self_calibration.md). Throws gyrocal::Error, naming the channel, for a channel
/// whose residuals are many times its noise (a dead, clipped or sign-flipped channel) and for the mount's
/// misalignment among the errors estimated (each channel's tilts are measured against the mount:
/// docs/imu.md). `ranges`, when given (one per channel, over the record's samples), let a channel's flat top
/// (saturated or clipped) be refused by its name before anything is fitted.
ImuCalibrationResult identify_imu(const std::vector<Reduction>& reductions,
                                  const std::vector<SensorChannel>& channels, const CentrifugeModel& model,
                                  const CalibrationOptions& options,
                                  std::span<const OutputRange> ranges = {});

/// Reads and reduces every channel of a record in one pass (`reader` through a layout with one output column
/// per channel, Scenario::reading_layout()), then identify_imu.
ImuCalibrationResult calibrate_imu_record(RecordReader& reader, const std::vector<SensorChannel>& channels,
                                          const CentrifugeModel& model, const TestSpec& plan,
                                          const CalibrationOptions& options);

}  // namespace gyrocal
