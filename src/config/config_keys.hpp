#pragma once
// The keys of a configuration (docs/contract.md, "Configuration (TOML)"), private to src/config: each list is
// used by both the reader (scenario_reader.cpp) and the writer (scenario_writer.cpp), so the two cannot
// disagree; and numbers as text, written back bit for bit (toml_numbers.cpp).
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/limits.hpp"
#include "gyrocal/core/units.hpp"
#include "gyrocal/model/machine_errors.hpp"

namespace gyrocal::config_detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------------------
// The keys. Each list is used by both the reader and the writer, so the two cannot disagree.

/// Allowed interval of a value, in the file's unit.
struct Range {
  double min = -kInf;
  double max = kInf;
  bool min_exclusive = false;
  /// Why a finite range bounds it, said in the refusal (limits.hpp gives the value's reason in full).
  const char* reason = nullptr;
};

constexpr Range kAnyValue{};
constexpr Range kPositive{0.0, kInf, true};
constexpr Range kNonNegative{0.0, kInf, false};
constexpr Range kLatitude{-90.0, 90.0, false};
/// A gyro's scale-factor error (ppm) or input-axis misalignment (arcsec): within 10 % (1e5 ppm, 5.7 deg),
/// where the first-order model of docs/physics.md section 15 still describes a gyro.
constexpr Range kRateError{-1e5, 1e5, false};
// Physically generous ranges (core/limits.hpp): beyond them the model's products leave a double's range
// ([gyro] dF = 1e308 made `plan` say "Observation 0 is not finite").
constexpr Range kGravity{0.0, limits::kGravityMS2, true, "limits::kGravityMS2, ten times the Earth's"};
constexpr Range kGravityUncertainty{0.0, limits::kGravityUncertaintyMS2, false,
                                    "limits::kGravityUncertaintyMS2, 10 % of the Earth's gravity"};
constexpr Range kEarthRate{0.0, limits::kEarthRateRadS, false, "limits::kEarthRateRadS"};
constexpr Range kRadius{0.0, limits::kRadiusM, true,
                        "limits::kRadiusM, 100 times the largest centrifuge's arm"};
/// An encoder angle the simulation writes or a layout subtracts, deg.
constexpr Range kEncoderAngle{-limits::kEncoderAngleDeg, limits::kEncoderAngleDeg, false,
                              "limits::kEncoderAngleDeg, no encoder reads beyond it"};
constexpr Range kGyroCoefficientRange{-limits::kGyroCoefficient, limits::kGyroCoefficient, false,
                                      "limits::kGyroCoefficient, beyond any gyro's range"};
constexpr Range kGyroNoiseRange{0.0, limits::kGyroNoise, false,
                                "limits::kGyroNoise, beyond any gyro's noise"};
constexpr Range kAccelerometerCoefficientRange{-limits::kAccelerometerCoefficient,
                                               limits::kAccelerometerCoefficient, false,
                                               "limits::kAccelerometerCoefficient, 10 g per g^n"};
constexpr Range kAccelerometerScaleRange{-limits::kAccelerometerScale, limits::kAccelerometerScale, false,
                                         "limits::kAccelerometerScale, output units per g"};
constexpr Range kAccelerometerAngleRange{-1e6 * limits::kMachineErrorSi, 1e6 * limits::kMachineErrorSi, false,
                                         "1 rad, limits::kMachineErrorSi"};
constexpr Range kAccelerometerNoiseRange{0.0, limits::kAccelerometerCoefficient, false,
                                         "limits::kAccelerometerCoefficient, 10 g"};

/// A number key of section struct S: the file holds member / to_si.
template <class S>
struct NumberKey {
  std::string_view key;
  double S::*member;
  double to_si;  ///< file unit -> SI
  Range range;
  std::string_view comment;
};

constexpr NumberKey<Site> kSiteKeys[] = {
    {"latitude_deg", &Site::latitude_rad, kDegToRad, kLatitude, "geodetic latitude, deg, in [-90, 90]"},
    {"gravity_m_s2", &Site::gravity_m_s2, 1.0, kGravity, "local gravity, m/s^2; specific force is in this g"},
    {"earth_rate_rad_s", &Site::earth_rate_rad_s, 1.0, kEarthRate, "Earth rate magnitude, rad/s"},
};

constexpr NumberKey<CentrifugeGeometry> kCentrifugeKeys[] = {
    {"radius_m", &CentrifugeGeometry::radius_m, 1.0, kRadius, "R0, nominal arm radius to the gyro centre, m"},
    {"rate_rad_s", &CentrifugeGeometry::rate_rad_s, 1.0, kAnyValue,
     "main-axis rate, rad/s, signed: + is counter-clockwise seen from above"},
    {"heading_deg", &CentrifugeGeometry::heading_rad, kDegToRad, kAnyValue,
     "psi0: direction of I at beta = 0, from North toward West, deg"},
    {"initial_main_angle_deg", &CentrifugeGeometry::initial_main_angle_rad, kDegToRad, kEncoderAngle,
     "theta0: main-axis angle at t = 0, deg"},
};

constexpr NumberKey<GyroNoise> kNoiseKeys[] = {
    {"angle_random_walk_deg_rt_h", &GyroNoise::angle_random_walk_deg_rt_h, 1.0, kGyroNoiseRange,
     "white rate noise, deg/sqrt(h)"},
    {"bias_instability_deg_h", &GyroNoise::bias_instability_deg_h, 1.0, kGyroNoiseRange,
     "flat Allan deviation floor, deg/h"},
    {"rate_random_walk_deg_h_rt_h", &GyroNoise::rate_random_walk_deg_h_rt_h, 1.0, kGyroNoiseRange,
     "rate random walk, deg/h/sqrt(h)"},
    {"quantization_deg_h", &GyroNoise::quantization_deg_h, 1.0, kGyroNoiseRange,
     "output quantization step, deg/h (0 = none)"},
    {"output_lag_s", &GyroNoise::output_lag_s, 1.0, kNonNegative,
     "first-order output lag time constant, s (0 = none)"},
};

/// The meaning of each drift coefficient, in Coefficient order; the unit comes from kCoefficientUnits.
constexpr std::string_view kCoefficientMeanings[kNumGyroCoefficients] = {
    "bias",           "drift per g along I", "drift per g along O", "drift per g along S", "drift per aI^2",
    "drift per aO^2", "drift per aS^2",      "drift per aI*aO",     "drift per aI*aS",     "drift per aO*aS",
};

/// A key of [centrifuge.errors] and [uncertainty] (docs/physics.md section 3), derived from the one table of
/// machine errors (model/machine_errors.hpp): its key, and for a series the key of its terms' amplitude.
/// The strings live as long as the program (Section keeps views of the keys it was asked for).
struct ErrorKey {
  const MachineErrorField* field;
  std::string key;
  std::string amplitude_key;
};

const std::vector<ErrorKey>& error_keys();

/// Which keys of the machine-error table a section holds: [centrifuge.errors] the machine's, [record] the
/// acquisition's (MachineErrorSection), [uncertainty] every one's.
enum class ErrorKeys { kMachine, kRecord, kAll };
/// Whether `keys` holds the field's key.
bool holds(ErrorKeys keys, const MachineErrorField& field);

/// A key of [reduce]: one ReduceOptions field (reduce/dwell_accumulator.hpp, where each default's full reason
/// is written), in the unit its name carries (the field's own, so no conversion), as a number, an integer or
/// a boolean (one member set). The comment gives the unit and the reason for the default, which `init` writes
/// after the key with the default's value; the range is ReduceOptions::IsValid's, whose refusal names the
/// key.
struct ReduceKey {
  std::string_view key;
  double ReduceOptions::*number = nullptr;
  int ReduceOptions::*integer = nullptr;
  bool ReduceOptions::*flag = nullptr;
  std::string_view unit;
  std::string_view reason;
};

/// The keys of [reduce], in the order `init` writes them: the fit, then finding dwells (docs/calibration.md,
/// "Cutting a record into dwells"), then the outlier rule ("Spikes"). The method itself is [calibration]
/// reduction (harmonic or window), which --reduction overrides.
constexpr ReduceKey kReduceKeys[] = {
    {"harmonic_order", nullptr, &ReduceOptions::harmonic_order, nullptr, "integer",
     "harmonic fit: orders 0..n in gamma; order 3 needs 14 samples per revolution"},
    {"linear_drift", nullptr, nullptr, &ReduceOptions::linear_drift, "true or false",
     "harmonic fit and window mean: a linear drift in time, so a slow drift of the bias does not bias the "
     "values at the dwell's mid-time"},
    {"window_deg", &ReduceOptions::window_deg, nullptr, nullptr, "deg",
     "window mean: full width of the window around each gamma"},
    {"window_s", &ReduceOptions::window_s, nullptr, nullptr, "s",
     "windows of encoder readings that recognise a steady state; physics.md section 14 asks >= 0.25 s, "
     "0.5 s measures 10 rad/s to ~4e-5 through 0.1 deg quantisation at 200 Hz"},
    {"angle_tolerance_deg", &ReduceOptions::angle_tolerance_deg, nullptr, nullptr, "deg",
     "a reading this far from its window's line leaves the steady state: ten times what 0.1 deg "
     "quantisation, 0.1 ms stamp jitter at 10 rad/s and 2e-4 rate ripple explain together"},
    {"beta_tolerance_deg", &ReduceOptions::beta_tolerance_deg, nullptr, nullptr, "deg",
     "beta (and a static hold's gamma) matches the plan, and beta (and a static hold's main and counter "
     "angles) stays put within it: four 0.1 deg quanta and a toggling count, far below any two planned "
     "positions' separation"},
    {"rate_tolerance", &ReduceOptions::rate_tolerance, nullptr, nullptr, "relative",
     "a steady rate matches a planned rate, and the counter platform minus the main rate, within it: "
     "a drive may differ from its nominal by up to 1e-3 (the measured rate is used), twice that for margin"},
    {"rate_steadiness", &ReduceOptions::rate_steadiness, nullptr, nullptr, "relative",
     "each window's rate stays this close to the dwell's: rate ripple up to 2e-4, five times"},
    {"static_rate_tolerance_rad_s", &ReduceOptions::static_rate_tolerance_rad_s, nullptr, nullptr, "rad/s",
     "below it the main axis (or a platform) counts as stopped"},
    {"wander_warning_deg", &ReduceOptions::wander_warning_deg, nullptr, nullptr, "deg RMS",
     "a dwell's main encoder off its constant-rate line by more than this, beyond its scatter, is warned "
     "about (the model's channels follow the line)"},
    {"gap_intervals", &ReduceOptions::gap_intervals, nullptr, nullptr, "planned sample intervals",
     "a longer interval between two rows is a gap; a dwell with gaps is still one dwell"},
    {"encoder_glitch_rows", nullptr, &ReduceOptions::encoder_glitch_rows, nullptr, "rows",
     "up to this many consecutive rows whose encoders leave the dwell's line and come back are dropped "
     "as a glitch; more end the dwell"},
    {"leave_guard_s", &ReduceOptions::leave_guard_s, nullptr, nullptr, "s",
     "samples this close to the end of a run that left its steady state are dropped: a platform starting "
     "to move at 20 deg/s^2 leaves beta_tolerance_deg only after 0.14 s, and the glitch rows follow"},
    {"max_stretches_per_dwell", nullptr, &ReduceOptions::max_stretches_per_dwell, nullptr, "stretches",
     "a dwell broken into more stretches (by gaps and glitches) is refused: it bounds the channels' memory"},
    {"static_batches", nullptr, &ReduceOptions::static_batches, nullptr, "batches",
     "a static hold's standard error comes from this many batch means"},
    {"model_samples_per_revolution", nullptr, &ReduceOptions::model_samples_per_revolution, nullptr,
     "samples",
     "the model's channels on every k-th sample, keeping this many per revolution; 0 = every sample, the "
     "only choice exact on any configuration (32 left 4.3e-6 deg/h/g^2 on dOS with large machine errors)"},
    {"outlier_threshold", &ReduceOptions::outlier_threshold, nullptr, nullptr, "robust standard deviations",
     "an output sample further than this from its block's median residual about the dwell's fit is an "
     "outlier, counted and left out of the fit (0 = no rejection): Gaussian noise passes 6 once in 5e8"},
    {"outlier_block_samples", nullptr, &ReduceOptions::outlier_block_samples, nullptr, "samples",
     "the outlier rule tests blocks of whole revolutions of at least this many samples, enough for the "
     "median absolute deviation to be a good scale (+-13 % at 128); the memory of one block"},
};

/// The string keys of [record] that name a column (docs/contract.md, "Records").
constexpr std::pair<std::string_view, std::string RecordLayout::*> kRecordColumnKeys[] = {
    {"time_column", &RecordLayout::time_column},
    {"main_angle_column", &RecordLayout::main_angle_column},
    {"counter_angle_column", &RecordLayout::counter_angle_column},
    {"position_angle_column", &RecordLayout::position_angle_column},
    {"output_column", &RecordLayout::output_column},
};
/// The keys of [record] that hold encoder counts per revolution.
constexpr std::pair<std::string_view, std::int64_t RecordLayout::*> kRecordCountKeys[] = {
    {"main_counts_per_revolution", &RecordLayout::main_counts_per_revolution},
    {"counter_counts_per_revolution", &RecordLayout::counter_counts_per_revolution},
    {"position_counts_per_revolution", &RecordLayout::position_counts_per_revolution},
};

/// The number keys of [record] (any finite value; RecordLayout::IsValid checks the scale's sign).
constexpr std::pair<std::string_view, double RecordLayout::*> kRecordNumberKeys[] = {
    {"output_scale_per_deg_h", &RecordLayout::output_scale_per_deg_h},
    {"output_scale_per_g", &RecordLayout::output_scale_per_g},
    {"output_offset", &RecordLayout::output_offset},
    {"main_angle_offset_deg", &RecordLayout::main_angle_offset_deg},
    {"counter_angle_offset_deg", &RecordLayout::counter_angle_offset_deg},
    {"position_angle_offset_deg", &RecordLayout::position_angle_offset_deg},
};

// ---------------------------------------------------------------------------------------------------------
// Numbers as text (toml_numbers.cpp).

/// Shortest decimal form that reads back to the same double.
std::string shortest(double v);

/// A TOML float, bit exact: the shortest form, with ".0" added where it would otherwise read as an integer.
std::string toml_number(double v);

/// True when a and b are the same double, bit for bit.
bool same_bits(double a, double b);

/// The value in the file's unit that the reader turns back into si exactly (as value * to_si); among the
/// candidates, the one with the shortest text: 127.96 deg is read as 127.96 * kDegToRad, and dividing that
/// by kDegToRad gives 127.96000000000001, a neighbour that reads back to the same radians.
double in_file_unit(double si, double to_si);

/// The values of a list of numbers as the file would write them: "[a, b]".
std::string list_text(const std::vector<double>& values);

/// The value of a [reduce] key as the file writes it.
std::string reduce_value(const ReduceKey& k, const ReduceOptions& o);

// ---------------------------------------------------------------------------------------------------------
// The one rate of a configuration (config_keys.cpp).

/// The test's first non-zero rate, which [centrifuge] rate_rad_s follows when the file gives only [test]
/// rates_rad_s; nullopt for a static test.
std::optional<double> first_spinning_rate(const std::vector<double>& rates);

}  // namespace gyrocal::config_detail
