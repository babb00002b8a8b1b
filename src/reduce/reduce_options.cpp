#include "gyrocal/reduce/dwell_accumulator.hpp"

// ReduceOptions::IsValid: every option of a reduction checked in one place.
#include <string>

namespace gyrocal {

bool ReduceOptions::IsValid(std::string* error) const {
  const auto fail = [error](const char* message) {
    if (error) *error = message;
    return false;
  };
  if (harmonic_order < 0 || harmonic_order > 12) return fail("harmonic_order must be between 0 and 12");
  if (!(window_deg > 0.0 && window_deg < 90.0)) return fail("window_deg must be in (0, 90) degrees");
  if (!(beta_tolerance_deg > 0.0)) return fail("beta_tolerance_deg must be positive");
  if (!(rate_tolerance > 0.0 && rate_tolerance < 0.5)) return fail("rate_tolerance must be in (0, 0.5)");
  if (!(static_rate_tolerance_rad_s > 0.0)) return fail("static_rate_tolerance_rad_s must be positive");
  if (static_batches < 2) return fail("static_batches must be at least 2");
  if (!(window_s > 0.0 && window_s <= 60.0)) return fail("window_s must be in (0, 60] s");
  if (!(angle_tolerance_deg > 0.0 && angle_tolerance_deg < 90.0))
    return fail("angle_tolerance_deg must be in (0, 90) degrees");
  if (!(rate_steadiness > 0.0 && rate_steadiness < 0.5)) return fail("rate_steadiness must be in (0, 0.5)");
  if (!(gap_intervals > 1.0)) return fail("gap_intervals must be above 1");
  if (encoder_glitch_rows < 0 || encoder_glitch_rows > 1000)
    return fail("encoder_glitch_rows must be between 0 and 1000");
  if (!(leave_guard_s >= 0.0 && leave_guard_s <= 60.0)) return fail("leave_guard_s must be in [0, 60] s");
  if (max_stretches_per_dwell < 1) return fail("max_stretches_per_dwell must be at least 1");
  if (!(wander_warning_deg > 0.0)) return fail("wander_warning_deg must be positive");
  if (model_samples_per_revolution < 0 ||
      (model_samples_per_revolution > 0 && model_samples_per_revolution < 16))
    return fail("model_samples_per_revolution must be 0 (every sample) or at least 16");
  if (!(outlier_threshold == 0.0 || (outlier_threshold >= 3.0 && outlier_threshold <= 1e6)))
    return fail("outlier_threshold must be 0 (no rejection) or between 3 and 1e6 robust standard deviations");
  if (outlier_block_samples < 16 || outlier_block_samples > 4096)
    return fail("outlier_block_samples must be between 16 and 4096");
  return true;
}

}  // namespace gyrocal
