#pragma once
// Can a record of this test be calibrated at all? One check, used before anything is done by `plan` (through
// predict_calibration), `simulate` and `calibrate` (the reducer), so that the three agree (issue 11, item 6).
#include <cstddef>
#include <cstdint>

#include "gyrocal/core/limits.hpp"

#include "gyrocal/plan/test_spec.hpp"
#include "gyrocal/reduce/dwell_accumulator.hpp"

namespace gyrocal {

/// The most samples a test may hold (its measured dwells and holds and their settle intervals): a record of
/// 1e10 rows is about 0.4 TB and takes hours to simulate or calibrate; beyond it the test is refused.
inline constexpr double kMaxTestSamples = limits::kTestSamples;

/// The samples per revolution the reduction needs at one rate: 2 (2 harmonic_order + 1), twice the harmonic
/// fit's unknowns per revolution (the window mean is held to the same, so that both methods see a test
/// alike).
int min_samples_per_revolution(const ReduceOptions& options);

/// The number of samples of the test's measured part (dwells, holds, settle intervals; moves not counted).
/// A static hold lasts static_hold_duration_s (plan/test_spec.hpp); centrifuge_rate_rad_s sizes it when the
/// test has neither [test] static_hold_s nor a non-zero rate.
double planned_test_samples(const TestSpec& test, double centrifuge_rate_rad_s);

/// The longest time into a test, s: limits::kTestSamples samples at [test] sample_rate_hz (5e7 s at 200 Hz).
/// Beyond it the main angle theta = Omega t of an instant loses every digit and then overflows.
double longest_test_s(const TestSpec& test);

/// Throws Error "<what> must be between -L s and L s, the longest test gyrocal runs (...), not <time_s>."
/// when |time_s| exceeds longest_test_s(test) or is not finite: the one bound on an instant that `gyrocal
/// inputs` and the Python module's exact_inputs share.
void check_time_within_test(double time_s, const TestSpec& test, const std::string& what);

/// The number of positions of the test, as test_positions (plan/positions.hpp) counts them: at each rate and
/// counter rate offset, beta x gamma (a spinning set's gamma: spinning_gammas).
double planned_positions(const TestSpec& test);

/// Throws gyrocal::Error naming the [test] key at fault when a record of `test` cannot be reduced with
/// `options`: more than limits::kPositions positions (checked first, before any work that grows with them),
/// too few samples per revolution at a rate (with the sample rate it needs), a non-zero rate slower than
/// options.static_rate_tolerance_rad_s (it reads as a stopped main axis), or more than kMaxTestSamples
/// samples in all (naming the keys of the test's longest part: revolutions, static_hold_s or settle_s).
void check_test_feasible(const TestSpec& test, const ReduceOptions& options, double reference_rate_rad_s);

/// Throws gyrocal::Error naming [test] gamma_deg and [reduce] harmonic_order when the harmonic fit reduced a
/// spinning dwell to `gammas` arm angles, more than its 2 harmonic_order + 1 unknowns per revolution: the
/// values at those angles are then linear combinations of fewer unknowns and their covariance is singular in
/// exact arithmetic. Called where that covariance fails to factor (identify/calibration.cpp), not up front:
/// with many revolutions rounding lets it factor and the fit agrees with a higher order's (8 gamma at order
/// 3, 200 revolutions: the estimates and standard errors of order 4), so such a test is not refused. An
/// accelerometer's spinning dwells are reduced to exactly 2 harmonic_order + 1 angles whatever gamma_deg
/// lists (identify/sensor_model_terms.hpp), so only the gyro's route meets this; the window mean has no
/// bound.
void refuse_gammas_beyond_fit(std::size_t gammas, const ReduceOptions& options);

/// Throws gyrocal::Error naming the [test] keys when reducing a record of `test` would hold more than
/// limits::kCalibrationRevolutions revolutions or limits::kCalibrationRateWindows rate windows over its
/// spinning dwells together: a reduction keeps a few numbers a revolution and a window of each dwell until
/// the model terms are evaluated (the spline's knots, the revolutions' values, the basis angle's
/// pieces), so this bounds a calibration's memory (< 64 MB). The Reducer calls it before the first row.
void check_calibration_memory(const TestSpec& test, const ReduceOptions& options);

}  // namespace gyrocal
