#pragma once
// A scenario: everything a configuration file describes. Every key is optional; the defaults are the
// default scenario of docs/physics.md section 11.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gyrocal/model/centrifuge.hpp"
#include "gyrocal/model/gyro.hpp"
#include "gyrocal/plan/test_spec.hpp"
#include "gyrocal/record/record_layout.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"
#include "gyrocal/sensor/channel.hpp"
#include "gyrocal/sensor/sensor.hpp"

namespace gyrocal {

/// [unit]: the unit under test, as a calibration report states it (docs/report.md). Every key optional; an
/// empty string (or no temperature) = not stated, and the record's metadata (`# unit = ...`) may state it.
struct UnitUnderTest {
  std::string serial;                   ///< the unit's serial number
  std::string model;                    ///< its model or part number
  std::string operator_name;            ///< [unit] operator: who ran the test
  std::optional<double> temperature_c;  ///< the test's temperature, deg C
  std::string notes;                    ///< conditions, warm-up, mounting: a short paragraph

  /// True when no key is stated.
  bool empty() const {
    return serial.empty() && model.empty() && operator_name.empty() && !temperature_c && notes.empty();
  }
};

struct Scenario {
  Site site;
  CentrifugeGeometry centrifuge;
  CentrifugeErrors errors;   ///< [centrifuge.errors]
  DriftCoefficients gyro;    ///< [gyro]: the truth, for simulation
  GyroRateErrors gyro_rate;  ///< [gyro] scale factor and input-axis misalignment: the truth, for simulation
  /// [calibration] gyro_model: the gyro model identification fits unless the command line says otherwise.
  GyroModel gyro_model = GyroModel::kDrift;
  GyroNoise noise;               ///< [gyro.noise]
  TestSpec test;                 ///< [test]
  CentrifugeErrors uncertainty;  ///< [uncertainty]: standard uncertainty of each error (Monte Carlo)
  /// [uncertainty] gravity_m_s2: the standard uncertainty of the local gravity ([site] gravity_m_s2), m/s^2
  /// (Monte Carlo). The radius is measured as omega^2 R / g, so 1 ppm of g reads as 1 ppm of R (1 um at 1 m).
  double gravity_uncertainty_m_s2 = 0.0;
  /// [calibration] estimate: machine errors estimated from the data (--estimate; docs/self_calibration.md),
  /// names as model/machine_errors.hpp parses them. Empty by default.
  std::vector<std::string> estimate;
  /// [record]: how to read a rig's own record (docs/records.md); nullopt (no [record] section) means
  /// gyrocal's own format, magic line required.
  std::optional<RecordLayout> record;
  /// [reduce]: how the reducer finds dwells in a record and reduces them (tolerances, the outlier rule, the
  /// harmonic order...), and [calibration] reduction: its method. Defaults: ReduceOptions{}, whose header
  /// gives each default's reason. The command line's --reduction overrides the method.
  ReduceOptions reduce;
  /// [sensor] kind: the sensor whose output the record holds (docs/accelerometer.md). The gyro by default;
  /// an accelerometer configuration holds no [gyro] key and a gyro configuration no [accelerometer] key.
  SensorKind sensor_kind = SensorKind::kGyro;
  /// [accelerometer] and [accelerometer.noise]: the accelerometer's truth and noise, for simulation (used
  /// when sensor_kind is kAccelerometer). Defaults: docs/contract.md's.
  Accelerometer accelerometer;
  /// [history] database: the calibration history's database file (docs/history.md) that `history add` and
  /// `calibrate --history` use when the command line names none; empty = gyrocal-history.sqlite in the
  /// current folder. A relative path is taken from the configuration file's folder.
  std::string history_database;
  /// [unit]: the unit under test (serial, model, operator, temperature, notes), for the report.
  UnitUnderTest unit;

  /// The sensor this scenario describes: the gyro of [gyro], [gyro.noise] and calibration.gyro_model, or the
  /// accelerometer.
  Sensor sensor() const {
    if (sensor_kind == SensorKind::kAccelerometer) return accelerometer;
    return Gyro{gyro, gyro_rate, noise, gyro_model};
  }

  /// The centrifuge model this scenario describes.
  CentrifugeModel model() const { return CentrifugeModel(site, centrifuge, errors); }

  /// [sensor] kind = "imu" and its [[channel]] tables (docs/imu.md): a whole IMU's channels in the record's
  /// order, each a gyro or an accelerometer (its truth and noise for simulation) on its own axes in the
  /// IMU's body frame, its output column named by the channel (or its `column` key), read as a rate or an
  /// increment with the channel's output_scale. Empty for a lone sensor (sensor_kind and its sections then
  /// describe it).
  std::vector<SensorChannel> imu_channels;

  /// True when the scenario describes a whole IMU ([sensor] kind = "imu").
  bool is_imu() const { return !imu_channels.empty(); }

  /// The unit's channels, in the record's order (sensor/channel.hpp): an IMU's imu_channels; a lone sensor
  /// is one channel, named by its kind, its axes the mount's (model().mount(), which [centrifuge.errors]
  /// mount_misalignment_rad and lever_arm_m configure) and its output column the [record] section's
  /// (RecordLayout::output_columns()) or gyrocal's own (gyro_deg_h, accel_g).
  std::vector<SensorChannel> channels() const;

  /// The layout a record of this scenario is read with: `record` for a lone sensor (nullopt: gyrocal's own
  /// format, magic line required); for an IMU, `record` (or gyrocal's own column names) with one output
  /// column per channel (RecordLayout::outputs, the channels' OutputColumn).
  std::optional<RecordLayout> reading_layout() const;
};

/// The default scenario of docs/physics.md section 11.
Scenario default_scenario();

/// The default accelerometer scenario (`gyrocal init --sensor accelerometer`; docs/accelerometer.md): the
/// default scenario's machine and site with [sensor] kind = "accelerometer", the accelerometer's default
/// truth and noise (10 ug/sqrt(Hz)), and a test that identifies all eleven coefficients: rates 0 (a static
/// set of 10 s holds), 6 and 12 rad/s, beta 0, 180, 90, 270 deg, eight gamma every 45 deg, 100 revolutions.
Scenario default_accelerometer_scenario();

/// The default IMU scenario (`gyrocal init --sensor imu`; docs/imu.md, "The default IMU"): the default
/// accelerometer scenario's machine, site and test (rates 0, 6 and 12 rad/s, four beta, eight gamma) with
/// [sensor] kind = "imu" and six channels gx gy gz ax ay az, the usual triad (gx: I = +x, O = +y; gy: I = +y,
/// O = +z; gz: I = +z, O = +x; ax, ay, az alike with i and p), written as increments as high-grade units
/// write them: the gyros' in rad (output_scale 4.84813681109536e-6 rad/s per deg/h), the accelerometers' in
/// m/s (9.80665 m/s^2 per g), each with its own truth (a few deg/h of drift terms; the default
/// accelerometer's coefficients varied per axis) and noise (0.003 deg/sqrt(h); 10 ug/sqrt(Hz)), and
/// [calibration] estimate = ["radius_error", "radius_stretch"]: one mounting identifies every channel with
/// the radius error and stretch (docs/imu.md, "What one mounting identifies").
Scenario default_imu_scenario();

/// Throws Error "<command> does not serve an IMU configuration yet ([sensor] kind = "imu"); docs/imu.md,
/// "What serves an IMU", lists the commands that do." when `scenario` describes a whole IMU (is_imu());
/// nothing for a lone sensor. The one check at the entry of every command that does not serve an IMU yet
/// (docs/imu.md, "What serves an IMU", lists both kinds).
void refuse_imu(const Scenario& scenario, std::string_view command);

/// The sentence refuse_imu throws, for `command` and what it was given (`input`: "configuration", or
/// "result" for a report of an IMU's result).
std::string imu_not_served(std::string_view command, std::string_view input = "configuration");

/// What `gyrocal demo` runs: the default scenario, with a standard uncertainty of 10% of each configured
/// machine error in [uncertainty] (docs/physics.md gives none; only the Monte Carlo budget uses them).
Scenario demo_scenario();

/// What `gyrocal demo --sensor accelerometer` runs: the default accelerometer scenario on an arm 20 um longer
/// than nominal that stretches by 1e-7 m/(rad/s)^2, with the demo's [uncertainty] (10% of each machine error;
/// the radius error known to 5 um, the stretch to 20%).
Scenario demo_accelerometer_scenario();

/// What `gyrocal demo --sensor imu` runs: the default IMU scenario on the arm of
/// demo_accelerometer_scenario (20 um longer than nominal, stretching by 1e-7 m/(rad/s)^2) with the same
/// [uncertainty] (10% of each machine error; the radius error known to 5 um, the stretch to 20%).
Scenario demo_imu_scenario();

}  // namespace gyrocal
