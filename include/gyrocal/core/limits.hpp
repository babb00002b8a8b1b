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
/// The most metadata and preamble lines before a record's header. gyrocal writes ~60; a logger's preamble
/// a few dozen.
inline constexpr std::size_t kRecordMetadataLines = 4096;
/// The most bytes of metadata held (keys and values together).
inline constexpr std::size_t kRecordMetadataBytes = std::size_t{1} << 20;

// ---- Results given to `report` ----

/// The largest result file `report` reads, bytes. A calibration result is ~100 kB; a Monte Carlo result
/// with its trials' draws a few MB.
inline constexpr std::size_t kResultBytes = std::size_t{64} << 20;
/// The most distinct names in one result: the keys of its JSON objects, counted once each however often they
/// occur (a sensor has 11 coefficients, an IMU 6 x 13; with the fields, the machine errors --estimate names
/// and the Monte Carlo sources, a result has a few hundred). The report's tables are indexed by these names.
inline constexpr std::size_t kResultNames = 4096;
/// The deepest nesting of arrays and objects in a result (the root object counts as one level): a gyrocal
/// result nests five or six. The report prints some values with the JSON library's dump, which recurses once
/// per level, so deeper input is refused while it is parsed, before it can overflow the stack.
inline constexpr int kResultDepth = 64;

// ---- Runs ----

/// The most Monte Carlo trials (fast mode; about half an hour a core).
inline constexpr long long kTrials = 1000000000;
/// The most Monte Carlo trials with --samples (each simulates and reduces the whole test).
inline constexpr long long kTrialsWithSamples = 100000;

}  // namespace gyrocal::limits
