#pragma once
// The limits of every input, in one table (docs/limits.md gives each one's reason and the refusal that names
// it). Each input gyrocal reads is bounded here, so that no input, however written, runs without bound in
// time or memory. Other headers refer to these values; none restates a number.
#include <cstddef>
#include <cstdint>

namespace gyrocal::limits {

// ---- Configuration (TOML) ----

/// The largest configuration text, bytes: 16 MiB. A complete commented configuration is ~20 kB.
inline constexpr std::size_t kConfigurationBytes = std::size_t{16} << 20;
/// The most dotted parts in one key or table header (`a.b.c` has 3). gyrocal's deepest key has 4
/// (centrifuge.errors.counter_wobble_x[0].harmonic written as a dotted key); the TOML library parses a dotted
/// key by recursion, so the text is checked against this before the library sees it.
inline constexpr std::size_t kConfigurationKeyParts = 32;

// ---- The test plan ----

/// The most distinct values in one of [test] rates_rad_s, beta_deg, gamma_deg: a value a degree apart.
inline constexpr std::size_t kPlanValuesPerList = 360;
/// The most positions of a test (rates x beta x gamma, the static set included): plan's work grows with the
/// square of the positions; 1024 positions of 200 revolutions at 10 rad/s are a 36-hour test.
inline constexpr std::size_t kPositions = 1024;
/// The most revolutions of one dwell.
inline constexpr std::int64_t kRevolutions = 100000000;
/// The most samples a test may hold (its dwells, holds and settle intervals): 1e10 rows are ~0.4 TB.
inline constexpr double kTestSamples = 1e10;

// ---- Machine errors ----

/// The highest harmonic of the main or counter axis in a runout or wobble series, or in --estimate's `:n`.
/// A geometric error of a bearing or a spindle lives in its first few harmonics; beyond the 64th it is
/// vibration, which a dwell's fit averages away. The channels' Fourier route resolves up to this harmonic.
inline constexpr int kHarmonic = 64;
/// The most terms in one harmonic series of the configuration.
inline constexpr std::size_t kHarmonicTerms = 64;
/// The most machine errors named by --estimate (each a column of the design).
inline constexpr std::size_t kEstimatedErrors = 64;

// ---- Records ----

/// The longest line of a record, bytes (bounds memory on input that is not a record).
inline constexpr std::size_t kRecordLineBytes = std::size_t{1} << 16;
/// The most metadata lines (`# key = value`, held in memory) before a record's header. gyrocal writes ~40; a
/// logger's preamble a few dozen. Comment and blank lines, and a layout's skip_rows, are not held and do not
/// count (they stream past like rows).
inline constexpr std::size_t kRecordMetadataLines = 4096;
/// The most bytes of metadata held (keys and values together). gyrocal writes ~1 kB.
inline constexpr std::size_t kRecordMetadataBytes = std::size_t{1} << 20;

// ---- What a calibration holds of a record ----

/// The most revolutions of gamma a calibration holds, over all the spinning dwells of its test together
/// ([test] revolutions x the spinning dwells). A calibration keeps, per revolution of a spinning dwell until
/// the model's channels are evaluated, the measured-motion spline's 4 knots and the revolution's values for
/// the residual levels: ~150 B held, ~450 B more for the dwell being fitted; measured 240 B a revolution of
/// RSS at 9.9 rad/s (issue 29, D19). 150 000 keep calibrate near 50 MB, under its 64 MB target
/// (docs/performance.md); `plan` and `simulate` hold no such state and are not bounded by it.
inline constexpr double kCalibrationRevolutions = 150000;
/// The most rate windows ([reduce] window_s) over the spinning dwells of a test together: a calibration keeps
/// one piece of the output's basis angle (32 B) a window (Dwell::basis_angle); 300 000 are ~10 MB. At 9.9
/// rad/s a revolution holds 1.3 windows of 0.5 s; this bounds a slow rate's many windows a revolution.
inline constexpr double kCalibrationRateWindows = 300000;

// ---- Results given to `report` ----

/// The largest result file `report` reads, bytes. A calibration result is ~100 kB; a Monte Carlo result
/// with its trials' draws a few MB.
inline constexpr std::size_t kResultBytes = std::size_t{64} << 20;
/// The most coefficient or parameter names in one result (a sensor has 11; an IMU 6 x 13).
inline constexpr std::size_t kResultNames = 4096;

// ---- Runs ----

/// The most Monte Carlo trials (fast mode; about half an hour a core).
inline constexpr long long kTrials = 1000000000;
/// The most Monte Carlo trials with --samples (each simulates and reduces the whole test).
inline constexpr long long kTrialsWithSamples = 100000;

}  // namespace gyrocal::limits
