#pragma once
// The limits of every input, in one table (docs/limits.md gives each one's reason and the refusal that names
// it). Each input gyrocal reads is bounded here, so that no input, however written, runs without bound in
// time or memory. Other headers refer to these values; none restates a number.
#include <cstddef>
#include <cstdint>

namespace gyrocal::limits {

// ---- Configuration (TOML) ----

/// The largest configuration text, bytes: 1 MiB. A complete commented configuration is ~20 kB, and its lists
/// hold at most kPlanValuesPerList values each. The TOML library holds ~40 bytes of tree a byte of text: 16
/// MiB of empty inline tables took 680 MB and 3 s before the counts below could refuse them (issue 29).
inline constexpr std::size_t kConfigurationBytes = std::size_t{1} << 20;
/// The most dotted parts in one key or table header (`a.b.c` has 3). gyrocal's deepest key has 4
/// (centrifuge.errors.counter_wobble_x[0].harmonic written as a dotted key); the TOML library parses a dotted
/// key by recursion, so the text is checked against this before the library sees it.
inline constexpr std::size_t kConfigurationKeyParts = 32;
/// The deepest nesting of a configuration's values: each dotted part of a table header or key, each inline
/// table and each array is one level (gyrocal's deepest value, a harmonic term's amplitude, is 6 down). The
/// TOML library walks and frees nested tables and arrays by recursion; its own bound (256 nested values)
/// lets each of them add kConfigurationKeyParts levels, ~8,000 in all, so the text is checked against this
/// too, in the same scan.
inline constexpr std::size_t kConfigurationDepth = 64;

// ---- The test plan ----

/// The most distinct values in one of [test] rates_rad_s, beta_deg, gamma_deg: a value a degree apart.
inline constexpr std::size_t kPlanValuesPerList = 360;
/// The most positions of a test (rates x beta x gamma, the static set included): plan's work grows with the
/// positions (with their square for the gyro's fit), and docs/interface.md promises plan below a second for
/// any accepted test. Lowered from 1024 (issue 29, D4): at 1008 positions an accelerometer's plan took 1.6 s
/// of CPU, at 504 0.8 s; and `montecarlo`'s set-up grows with the cube of the positions (35 s at 512, 0.5 s
/// at 128). 256 positions of 200 revolutions at 10 rad/s are a 9-hour test; the default tests have 16 (gyro)
/// and 96 (accelerometer).
inline constexpr std::size_t kPositions = 256;
/// The most revolutions of one dwell.
inline constexpr std::int64_t kRevolutions = 100000000;
/// The most samples a test may hold (its dwells, holds and settle intervals): 1e10 rows are ~0.4 TB.
inline constexpr double kTestSamples = 1e10;

// ---- Machine errors ----

/// The highest harmonic of the main or counter axis in a runout or wobble series, or in --estimate's `:n`.
/// A geometric error of a bearing or a spindle lives in its first few harmonics; beyond the 64th it is
/// vibration, which a dwell's fit averages away. The model terms' Fourier route resolves up to this harmonic.
inline constexpr int kHarmonic = 64;
/// The most terms in one harmonic series of the configuration: a runout or a wobble is stated in its first
/// few harmonics. The model's work grows with the terms: eight series of 64 terms made `plan` take 4 s of CPU
/// and `sensitivity` and `montecarlo` 6-7 s (issue 29); of 8 terms each, `plan` stays below a second.
inline constexpr std::size_t kHarmonicTerms = 8;
/// The most machine errors named by --estimate (each a column of the design). Self-calibration's work grows
/// faster than their square (each Gauss-Newton iteration evaluates the model twice per error, and more errors
/// need more iterations): `plan` took 0.9 s of CPU with 8, 6.6 s with 16 and over a minute with 64 (issue
/// 29). The errors a test can separate from a sensor's coefficients are few: the radius and its stretch,
/// the counter platform's perpendicularities and rate mismatch (docs/self_calibration.md).
inline constexpr std::size_t kEstimatedErrors = 8;

// ---- Records ----

/// The longest line of a record, bytes (bounds memory on input that is not a record).
inline constexpr std::size_t kRecordLineBytes = std::size_t{1} << 16;
/// The most metadata lines (`# key = value`, held in memory) before a record's header. gyrocal writes ~40; a
/// logger's preamble a few dozen. Comment and blank lines, and a layout's skip_rows, are not held and do not
/// count (they stream past like rows).
inline constexpr std::size_t kRecordMetadataLines = 4096;
/// The most bytes of metadata held (keys and values together). gyrocal writes ~1 kB.
inline constexpr std::size_t kRecordMetadataBytes = std::size_t{1} << 20;

/// The longest [record] output_unit, bytes: 16. A unit's name ("V", "mV", "mA", "counts", "mV/V") is a few
/// characters; it becomes K1's unit ("V/g") in every table, whose unit column is 8-12 wide, in the result's
/// JSON and in the calibration history, so a longer text is a mistake (a column name or a sentence typed
/// there) rather than a unit.
inline constexpr std::size_t kOutputUnitBytes = 16;
/// The largest magnitude of a record's output, in its unit (deg/h, or g for an accelerometer; a layout's
/// after its offset and scale): 1e50. No sensor writes a value within many orders of magnitude of it; the
/// bound keeps what the reduction and the noise fit form of the outputs inside a double's range: the fourth
/// power (the Allan variance's variance) is 1e200, times the most samples a test may hold (kTestSamples)
/// 1e210, far below the largest double, 1.8e308 (a dwell of 1e200 was refused as "too few revolutions", a
/// static record with one 1e308 sample as "no combination of noise terms fits"). A larger output is refused
/// naming its line and column.
inline constexpr double kOutputMagnitude = 1e50;
/// The most output columns a record is read with at once (the channels of one unit: an IMU's six, a spare
/// two): each is reduced beside the others in the one pass over the record, so the bound is one of memory per
/// row (reduce/reducer.hpp) and of the reader's value slots.
inline constexpr std::size_t kMaxOutputColumns = 8;
/// The most [[channel]] tables of an IMU configuration ([sensor] kind = "imu"; docs/imu.md):
/// kMaxOutputColumns, since each channel is one output column of the one record (a six-channel IMU and two
/// spare, such as a second triad's temperature-compensated outputs); more could not be read in the one pass.
inline constexpr std::size_t kMaxImuChannels = kMaxOutputColumns;
/// The longest name of an IMU channel ([[channel]] name), bytes: 32. It keys the channel in every result
/// (JSON, the calibration history's tables) and heads its report section and table rows; "gx", "accel_z",
/// "gyro_x_fog" are a few characters, so a longer text is a mistake (a sentence typed there).
inline constexpr std::size_t kChannelNameBytes = 32;
/// The largest magnitude of an encoder angle, deg (a layout's counts or radians after their conversion):
/// 1e10 deg, 2.8e7 turns, which an unwrapped angle or an accumulating counter reaches after 200 days of
/// spinning at 10 rad/s; a double still resolves 2e-6 deg (0.007 arcsec) there, below any encoder's count.
/// A reading beyond it (a corrupt field such as 1e308, which wrapping cannot place) is no encoder's: inside a
/// dwell it is an encoder glitch, dropped and counted (more than reduce.encoder_glitch_rows in a row end the
/// dwell); outside, it is skipped (docs/records.md).
inline constexpr double kEncoderAngleDeg = 1e10;

// ---- Configuration values: physically generous ranges, each refused naming its key ----

/// |SI value| of a machine error ([centrifuge.errors]) and of its uncertainty ([uncertainty]): about 1 rad,
/// 1 m, 1 rad/s or 1 m/(rad/s)^2 (in the key's unit, rounded down to one significant digit: 200000 arcsec).
/// A machine's errors are arcsec and micrometres (docs/sensitivity.md); beyond a radian or a metre the
/// model's errors are no longer small, and their products can leave a double's range (issue 29, D13).
inline constexpr double kMachineErrorSi = 1.0;
/// The acquisition's delay ([record] output_delay_s, and its [uncertainty]), s: 0.1 s, and never negative (an
/// output is stamped after it was sensed). An anti-alias filter's group delay or a multiplexer's skew is
/// microseconds to a few milliseconds (a 4-pole 10 Hz Bessel filter's ~40 ms). The model takes the joints
/// that long before the stamp on the dwell's line (docs/calibration.md, "The acquisition's timing"), which
/// holds while the delay stays inside a dwell's guard at its ends ([reduce] leave_guard_s, default 0.25 s):
/// a longer offset is a clock's between two loggers, to be corrected in the time column.
inline constexpr double kOutputDelayS = 0.1;
/// |gyro drift coefficient| ([gyro] dF, deg/h; dI, dO, dS, deg/h/g; dII ... dOS, deg/h/g^2): 1e7, 2800 deg/s,
/// beyond any gyro's range ([gyro] dF = 1e308 gave "Observation 0 is not finite (inf)" in `plan`).
inline constexpr double kGyroCoefficient = 1e7;
/// The gyro's noise levels ([gyro.noise] angle random walk deg/sqrt(h), bias instability deg/h, rate random
/// walk deg/h/sqrt(h), quantization deg/h): up to 1e7 in the key's unit, as the coefficients (a random walk
/// of 1e300 gave a record of overflowing outputs).
inline constexpr double kGyroNoise = 1e7;
/// |accelerometer coefficient| other than K1 ([accelerometer] K0, ug; K2 ... Koo, ug/g^n): 1e7 ug, 10 g per
/// g^n; and its noise levels ([accelerometer.noise], ug/sqrt(Hz), ug). The misalignments (urad) are held to
/// kMachineErrorSi (1e6 urad).
inline constexpr double kAccelerometerCoefficient = 1e7;
/// |accelerometer K1|, output units per g: 1e12 (a 24-bit converter gives ~1e7 counts per g).
inline constexpr double kAccelerometerScale = 1e12;
/// The centrifuge's arm radius ([centrifuge] radius_m), m: the largest test centrifuges have arms of ~10 m.
inline constexpr double kRadiusM = 1000.0;
/// Local gravity ([site] gravity_m_s2), m/s^2: ten times the Earth's.
inline constexpr double kGravityMS2 = 100.0;
/// The local gravity's standard uncertainty ([uncertainty] gravity_m_s2), m/s^2: 1 m/s^2 (10 % of the
/// Earth's) is no survey's; it keeps a Monte Carlo draw of the gravity positive by ten of them.
inline constexpr double kGravityUncertaintyMS2 = 1.0;
/// The Earth rate ([site] earth_rate_rad_s), rad/s: 1.4e4 times the Earth's.
inline constexpr double kEarthRateRadS = 1.0;

// ---- The unit under test ([unit]; docs/report.md) ----

/// The longest [unit] serial, model and operator, bytes: the same bound as a history serial
/// (kHistoryUnitBytes): a name or a part number of a few dozen characters, printed on one line of the report.
inline constexpr std::size_t kUnitTextBytes = 128;
/// The longest [unit] notes, bytes: a short paragraph (warm-up, mounting, conditions), as a run's note
/// (kHistoryNoteBytes).
inline constexpr std::size_t kUnitNotesBytes = 4096;
/// [unit] temperature_c, deg C: from absolute zero (-273.15, excluded) to 1000; a test chamber holds
/// -55 to +125, so anything beyond is a typing error (a temperature in K, a value in deg F would still pass).
inline constexpr double kUnitTemperatureMinC = -273.15;
inline constexpr double kUnitTemperatureMaxC = 1000.0;

// ---- What a calibration holds of a record ----

/// The most revolutions of gamma a calibration holds, over all the spinning dwells of its test together
/// ([test] revolutions x the spinning dwells). A calibration keeps, per revolution of a spinning dwell until
/// the model terms are evaluated, the measured-motion spline's 4 knots and the revolution's values for
/// the residual levels: ~150 B held, ~450 B more for the dwell being fitted; measured 240 B a revolution of
/// RSS at 9.9 rad/s (issue 29, D19). 150 000 keep calibrate near 50 MB, under its 64 MB target
/// (docs/performance.md); `plan` and `simulate` hold no such state and are not bounded by it.
inline constexpr double kCalibrationRevolutions = 150000;
/// The most rate windows ([reduce] window_s) over the spinning dwells of a test together: a calibration keeps
/// one piece of the output's basis angle (32 B) a window (Dwell::basis_angle); 300 000 are ~10 MB. At 9.9
/// rad/s a revolution holds 1.3 windows of 0.5 s; this bounds a slow rate's many windows a revolution.
inline constexpr double kCalibrationRateWindows = 300000;

// ---- Results given to `report` ----

/// The largest result file `report` reads, bytes: 16 MiB. A calibration result is ~100 kB, a sensitivity
/// study of 1,024 rows ~2 MB; Monte Carlo results do not grow with their trials. A result of 64 MiB (500,000
/// positions) took `report` 0.9 GB and 11 s to draw as 100 MB of HTML (issue 29).
inline constexpr std::size_t kResultBytes = std::size_t{16} << 20;
/// The most distinct names in one result: the keys of its JSON objects, counted once each however often they
/// occur (a sensor has 11 coefficients, an IMU 6 x 13; with the fields, the machine errors --estimate names
/// and the Monte Carlo sources, a result has a few hundred). The report's tables are indexed by these names.
inline constexpr std::size_t kResultNames = 4096;
/// The deepest nesting of arrays and objects in a result (the root object counts as one level): a gyrocal
/// result nests five or six. The report prints some values with the JSON library's dump, which recurses once
/// per level, so deeper input is refused while it is parsed, before it can overflow the stack.
inline constexpr int kResultDepth = 64;
/// The most JSON values in one result (each number, string, boolean, null, array and object counts one): 4
/// Mi. The parsed result is held whole, ~100 B a value at worst (an empty object: 64 MiB of `{},` were 22
/// million values and 2.3 GB; of `0,` 1.1 GB), so this keeps it under ~450 MB whatever the result (issue 29).
/// A gyrocal result holds a few ten thousand values (a sensitivity study of 1,024 rows ~60,000).
inline constexpr std::size_t kResultValues = std::size_t{1} << 22;
/// The most cells of one table (or heat map) the report draws: rows x columns, counted from an array's length
/// and the union of its entries' keys before any cell is built, so that a result within the limits above
/// cannot make a table of rows x names cells (50,000 rejected steady runs cycling through 4,000 keys were
/// 200 million cells; `report` ran out of 2 GB; issue 29). 250,000 cells: a result with every table and heat
/// map at 1,000,000 cells peaked at 2.2 GB (a heat map's cell, with its tooltip, ~1 kB), so each is held to a
/// quarter of that. A real result's largest tables stay far inside: the dwell table of a 512-position test
/// ~10,000 cells, the heat maps of 8 harmonic series x 64 terms x 2 phases x 13 estimates x 3 compensations
/// ~40,000. A table beyond it is refused as a problem of its section, naming its rows x columns and this
/// limit; the other sections are drawn (docs/report.md).
inline constexpr std::size_t kReportTableCells = 250000;

// ---- Runs ----

/// The most Monte Carlo trials (fast mode; about half an hour a core).
inline constexpr long long kTrials = 1000000000;
/// The most Monte Carlo trials with --samples (each simulates and reduces the whole test).
inline constexpr long long kTrialsWithSamples = 100000;
/// The most worker threads of --threads (montecarlo, sensitivity): above the cores of any machine gyrocal
/// runs on; each thread reserves a stack, so a thread per trial (up to 1e9) would exhaust the process.
inline constexpr int kThreads = 1024;

// ---- The calibration history (docs/history.md) ----

/// The longest unit serial (--unit), bytes: a serial is a few dozen characters ("SN-2026-000123"); it is
/// printed in every line and message about the unit, and keys every run.
inline constexpr std::size_t kHistoryUnitBytes = 128;
/// The longest note of a run (--note), bytes: a sentence or a short paragraph ("after the shock test").
inline constexpr std::size_t kHistoryNoteBytes = 4096;
/// The most runs of one unit: `history show` reads them all and computes each coefficient's statistics and
/// control chart over them; a unit calibrated every day for 25 years has 9,000. A further run is refused.
inline constexpr std::size_t kHistoryRunsPerUnit = 10000;
/// The largest history database gyrocal opens, bytes: 4 GiB. Each opening checks the whole file (PRAGMA
/// quick_check), which reads every page; a run keeps its result's JSON (~100-250 kB), so 4 GiB hold ~20,000
/// runs.
inline constexpr std::uint64_t kHistoryDatabaseBytes = std::uint64_t{4} << 30;

}  // namespace gyrocal::limits
