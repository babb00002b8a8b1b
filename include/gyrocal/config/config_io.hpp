#pragma once
// The configuration file (docs/contract.md, "Configuration (TOML)"): reading a scenario from TOML and writing
// one back as a commented file. Keys carry their unit in their name (deg, arcsec, m, rad_s, ...); the
// scenario holds SI values (docs/physics.md section 1). Every key is optional and defaults to
// default_scenario().
//
// Relation of [centrifuge] rate_rad_s and [test] rates_rad_s (one rate, one place; docs/interface.md):
// rate_rad_s is the main rate of a single instant (`gyrocal inputs`), rates_rad_s the rates of the test.
// When [test] has no rates_rad_s, the test runs at the configured centrifuge rate alone: rates_rad_s =
// [rate_rad_s]. When [centrifuge] has no rate_rad_s, it follows the test's first non-zero rate (the default
// scenario's rate for a test of rate 0 alone). A file that gives both, with a centrifuge rate that is not one
// of the test's rates is refused naming both keys (a test of rate 0 alone accepts any centrifuge
// rate: it sizes the static holds when [test] static_hold_s is 0). The writer writes rate_rad_s commented out
// when it is the test's first non-zero rate, so that a file from `init` holds the rate in one place.
//
// [uncertainty] has the keys of [centrifuge.errors] with their units; each value is the standard
// uncertainty of that error (all zero by default). In a harmonic term, amplitude is the standard
// uncertainty of that harmonic's amplitude and phase_deg its nominal phase.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "gyrocal/config/scenario.hpp"
#include "gyrocal/core/limits.hpp"

namespace gyrocal {

/// Parse a TOML configuration into a scenario (SI units). source_name names the file in error messages.
/// Throws Error, with one sentence naming the file, the line and the full key path (such as
/// centrifuge.errors.counter_wobble_x[0].harmonic), on a TOML syntax error, an unknown key, a value of the
/// wrong type, or a value that is not finite or out of its range.
Scenario parse_scenario(std::string_view toml_text, const std::string& source_name);

/// The largest configuration file load_scenario reads: 16 MiB (core/limits.hpp).
inline constexpr std::size_t kMaxConfigurationBytes = limits::kConfigurationBytes;

/// Refuses configuration text that no configuration holds, by the rule load_scenario applies to a file
/// (Python's Scenario.parse applies it to its text): larger than kMaxConfigurationBytes, or empty or white
/// space only (more likely a failed write than a choice of every default; comments alone are a choice).
/// Throws Error "<described> is empty; <advice>." or "<described> is larger than 16 MiB, ...", where
/// `described` names the text ("Configuration file rig.toml") and `advice` says how to get the built-in
/// scenario instead.
void check_configuration_text(std::string_view text, const std::string& described, std::string_view advice);

/// Read and parse the configuration file at path (any readable file: a regular file, a FIFO, /dev/stdin).
/// Throws Error naming the file if it cannot be read, is a directory, is larger than
/// kMaxConfigurationBytes (only that much plus one byte is read: /dev/zero ends quickly), or is empty or
/// white space only (more likely a failed write than a choice of every default; a file of comments alone
/// does give the default scenario).
Scenario load_scenario(const std::filesystem::path& path);

/// The scenario as a commented TOML configuration with every key, one comment per key giving its meaning
/// and unit. Numbers are written in their shortest exact form, so that parse_scenario gives back s bit for
/// bit whenever s's angles are reachable from the file's units (any scenario that parse_scenario returned,
/// default_scenario() included; an arbitrary SI angle may come back within one unit in the last place).
/// Throws Error if test.seed exceeds the largest TOML integer (2^63 - 1), or if centrifuge.rate_rad_s is not
/// one of a spinning test's rates_rad_s (a file holding both would be refused when read).
std::string scenario_to_toml(const Scenario& s);

/// A number as a TOML float that reads back bit for bit: the shortest form, with ".0" added where it would
/// otherwise read as an integer. Every writer of configuration text uses it.
std::string toml_float(double v);

}  // namespace gyrocal
